//! The `irradiance` subcommand on the small test site (a 20 m ground square and a black 1 m box,
//! manual sun, here with a uniform sky): unoccluded points against the closed form E = E_h,sky +
//! E_n·sin(elevation), bad rows named by line, Ctrl-C printing nothing.
#![allow(clippy::unwrap_used)]

mod common;

use std::process::{Command, Stdio};

/// Sky weight (horizontal irradiance of the uniform sky) of the test site.
const SKY_E_H: f64 = 0.5;
/// A ground point 11 m from the black box: the box hides ≈ 2e-4 of the sky's horizontal
/// irradiance there and sky clusters are shadow-tested from the element's sample points;
/// 1 % bounds both.
const GROUND_REL_TOL: f64 = 0.01;
/// A point in the open air is final-gathered: the clusters keep the horizontal irradiance exactly
/// (icosahedral.rs), so only JSON and summation rounding remain.
const AIR_REL_TOL: f64 = 1e-9;

fn site(dir: &std::path::Path) -> std::path::PathBuf {
    let path = common::make_site(dir);
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "sky_weight = [0.0, 0.0, 0.0]",
        &format!("sky_weight = [{SKY_E_H}, {SKY_E_H}, {SKY_E_H}]"),
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn photomontage(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

#[test]
fn unoccluded_points_meet_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let site = site(dir.path());
    let points = dir.path().join("points.csv");
    std::fs::write(
        &points,
        "id,X,Y,Z,nx,ny,nz\nground,8,-8,0,0,0,1\nair,0.5,0.5,5,0,0,1\n",
    )
    .unwrap();
    let out = photomontage(&[
        "irradiance".as_ref(),
        site.as_os_str(),
        "--points".as_ref(),
        points.as_os_str(),
        "--element-edge-m".as_ref(),
        "2".as_ref(),
        "--json".as_ref(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = report["points"].as_array().unwrap();
    assert_eq!(rows.len(), 2, "{report}");
    let want = SKY_E_H + common::K_S * common::SUN_ELEVATION_DEG.to_radians().sin();
    for (row, id, tol) in [
        (&rows[0], "ground", GROUND_REL_TOL),
        (&rows[1], "air", AIR_REL_TOL),
    ] {
        assert_eq!(row["id"], id);
        let get = |key: &str| -> Vec<f64> {
            row[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        };
        let (total, direct, indirect) = (
            get("irradiance_rgb"),
            get("direct_rgb"),
            get("indirect_rgb"),
        );
        for c in 0..3 {
            assert!(
                (total[c] - want).abs() / want < tol,
                "{id}: {total:?} vs {want}"
            );
            // Nothing reflects onto an upward point: the box is black, the ground coplanar.
            assert!(indirect[c].abs() < 1e-12, "{id}: {indirect:?}");
            assert!((direct[c] + indirect[c] - total[c]).abs() <= 1e-12 * want);
        }
    }
}

#[test]
fn bad_rows_are_named_by_line() {
    let dir = tempfile::tempdir().unwrap();
    let site = site(dir.path());
    for (text, words) in [
        (
            "id,X,Y,Z,nx,ny,nz\np1,0,0,0,0,0,1\np2,1,1,0,0,0,3\n",
            "line 3",
        ),
        ("p1,0,NaN,0,0,0,1\n", "line 1"),
        ("p1,0,0,0,0,0,1\np2,1,1,0,0,1\n", "line 2: 6 columns"),
    ] {
        let points = dir.path().join("points.csv");
        std::fs::write(&points, text).unwrap();
        let out = photomontage(&[
            "irradiance".as_ref(),
            site.as_os_str(),
            "--points".as_ref(),
            points.as_os_str(),
            "--json".as_ref(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(
            stderr.contains(words) && stderr.contains("points.csv"),
            "{stderr}"
        );
        assert!(out.stdout.is_empty());
    }
}

/// SIGINT once the solve has started (0.25 m elements: 32 768 ground elements): it stops, says
/// so, exits non-zero and prints nothing on stdout.
#[cfg(unix)]
#[test]
fn ctrl_c_cancels_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let site = site(dir.path());
    let points = dir.path().join("points.csv");
    std::fs::write(&points, "p1,8,-8,0,0,0,1\n").unwrap();
    let stdout = dir.path().join("stdout.json");
    let child = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("irradiance")
        .arg(&site)
        .arg("--points")
        .arg(&points)
        .args(["--element-edge-m", "0.25", "--json"])
        .stdout(Stdio::from(std::fs::File::create(&stdout).unwrap()))
        .stderr(Stdio::piped())
        .env("RUST_BACKTRACE", "0")
        .spawn()
        .unwrap();
    let (status, rest) = common::interrupt_once_started(child);
    assert!(!status.success());
    assert!(rest.iter().any(|l| l.contains("cancelled")), "{rest:?}");
    assert_eq!(std::fs::read_to_string(&stdout).unwrap(), "");
}
