//! The `radiosity` subcommand on the small test site (a 20 m ground square and a black 1 m box,
//! manual sun): report fields, PLY and CSV outputs that agree with it, named warnings and errors
//! on bad input, and Ctrl-C leaving no file.
#![allow(clippy::unwrap_used)]

mod common;

use std::process::{Command, Stdio};

fn photomontage(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

#[test]
fn radiosity_reports_and_writes_mesh_and_convergence() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let ply = dir.path().join("mesh.ply");
    let csv = dir.path().join("convergence.csv");
    let png = dir.path().join("convergence.png");
    let out = photomontage(&[
        "radiosity".as_ref(),
        site.as_os_str(),
        "--element-edge-m".as_ref(),
        "2".as_ref(),
        "--mesh-out".as_ref(),
        ply.as_os_str(),
        "--convergence".as_ref(),
        csv.as_os_str(),
        "--convergence-plot".as_ref(),
        png.as_os_str(),
        "--json".as_ref(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let elements = report["elements"].as_u64().unwrap();
    // Ground: 28.3 m diagonals to ≤ 2 m is 4 splits (256 per triangle); box: √2 m to ≤ 2 m, none.
    assert_eq!(elements, 2 * 256 + 12, "{report}");
    assert!(report["patches"].as_u64().unwrap() > 0);
    assert!(report["interactions"].as_u64().unwrap() > 0);
    assert_eq!(report["converged"], true);
    let groups = report["groups"].as_array().unwrap();
    assert_eq!(groups.len(), 1, "sun only (sky_weight is 0): {report}");
    assert_eq!(groups[0]["name"], "sun");
    // The box is black (Kd 0): a warning names it.
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("`box`")),
        "{report}"
    );
    let mesh = std::fs::read_to_string(&ply).unwrap();
    assert!(mesh.contains(&format!("element face {elements}\n")));
    let rows = std::fs::read_to_string(&csv).unwrap();
    let mut lines = rows.lines();
    assert_eq!(
        lines.next().unwrap(),
        "group,pass,residual,mean_change,mean_brightness,interactions"
    );
    let sun_passes = lines.filter(|l| l.starts_with("sun,")).count() as u64;
    assert_eq!(sun_passes, groups[0]["passes"].as_u64().unwrap());
    let plot = image::open(&png).unwrap();
    assert_eq!((plot.width(), plot.height()), (720, 440));
}

/// `--corner-element-m`: the ground's elements around the box's foot are split (more elements,
/// all in the PLY); the box's own faces see nothing in front and keep theirs.
#[test]
fn corners_are_refined_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let ply = dir.path().join("mesh.ply");
    let run = |extra: &[&str]| -> serde_json::Value {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "radiosity".as_ref(),
            site.as_os_str(),
            "--element-edge-m".as_ref(),
            "2".as_ref(),
            "--json".as_ref(),
        ];
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        let out = photomontage(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let plain = run(&[])["elements"].as_u64().unwrap();
    let refined = run(&[
        "--corner-element-m",
        "0.25",
        "--mesh-out",
        ply.to_str().unwrap(),
    ])["elements"]
        .as_u64()
        .unwrap();
    assert_eq!(plain, 2 * 256 + 12);
    assert!(refined > plain + 12, "{plain} → {refined}");
    let mesh = std::fs::read_to_string(&ply).unwrap();
    assert!(mesh.contains(&format!("element face {refined}\n")));
}

#[test]
fn bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let run = |extra: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["radiosity".as_ref(), site.as_os_str()];
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        let out = photomontage(&args);
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = run(&["--element-edge-m", "0"]);
    assert!(err.contains("max_element_edge_m"), "{err}");
    let err = run(&["--corner-element-m=-1"]);
    assert!(err.contains("corner_element_m"), "{err}");
    let err = run(&["--object-element-edge", "nope=1"]);
    assert!(err.contains("`nope`"), "{err}");
    let err = run(&["--object-element-edge", "box"]);
    assert!(err.contains("NAME=METRES"), "{err}");
    let missing = dir.path().join("no such folder").join("mesh.ply");
    let err = run(&["--mesh-out", missing.to_str().unwrap()]);
    assert!(err.contains("mesh.ply"), "{err}");
    assert!(!missing.exists());
}

/// SIGINT once the solve has started (progressive, 0.25 m elements: tens of thousands of
/// elements, each shot a column of as many form factors): it stops, says so, exits non-zero and
/// writes neither output.
#[cfg(unix)]
#[test]
fn ctrl_c_cancels_without_writing() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let ply = dir.path().join("mesh.ply");
    let csv = dir.path().join("convergence.csv");
    let png = dir.path().join("convergence.png");
    let child = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("radiosity")
        .arg(&site)
        .args([
            "--solver",
            "progressive",
            "--element-edge-m",
            "0.25",
            "--mesh-out",
        ])
        .arg(&ply)
        .arg("--convergence")
        .arg(&csv)
        .arg("--convergence-plot")
        .arg(&png)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (status, rest) = common::interrupt_once_started(child);
    assert!(!status.success(), "{rest:?}");
    assert!(rest.iter().any(|l| l.contains("cancelled")), "{rest:?}");
    assert!(!ply.exists() && !csv.exists() && !png.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Every enabled `[[luminaires]]` entry is its own light group, named after its id.
#[test]
fn luminaires_are_light_groups() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    std::fs::write(
        dir.path().join("downlight.ies"),
        include_str!("fixtures/downlight.ies"),
    )
    .unwrap();
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str(
        "\n[[luminaires]]\nid = \"porch\"\nfile = \"downlight.ies\"\nposition_m = [5.0, 5.0, 2.0]\nscale = 1e-4\n\
         \n[[luminaires]]\nid = \"off\"\nfile = \"downlight.ies\"\nposition_m = [-5.0, 5.0, 2.0]\nscale = 1e-4\nenabled = false\n",
    );
    std::fs::write(&site, text).unwrap();
    let out = photomontage(&[
        "radiosity".as_ref(),
        site.as_os_str(),
        "--element-edge-m".as_ref(),
        "2".as_ref(),
        "--json".as_ref(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = report["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["sun", "luminaire:porch"], "{report}");
    let porch = &report["groups"][1];
    assert!(
        porch["mean_radiosity_luminance"].as_f64().unwrap() > 0.0,
        "{report}"
    );
}

/// The light groups come from the one site builder (`site_light_groups`): a sun below the
/// horizon is named as a warning and gives no group, so with the sky weight 0 and no luminaire
/// nothing lights the site and the command says so.
#[test]
fn a_sun_below_the_horizon_is_named_and_lights_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let text = std::fs::read_to_string(&site).unwrap();
    let start = text.find("sun_manual = {").unwrap();
    let end = start + text[start..].find('}').unwrap() + 1;
    let text = format!(
        "{}sun_manual = {{ azimuth_deg = 180.0, elevation_deg = -5.0 }}{}",
        &text[..start],
        &text[end..]
    );
    std::fs::write(&site, text).unwrap();
    let out = photomontage(&["radiosity".as_ref(), site.as_os_str(), "--json".as_ref()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("the sun is below the horizon (elevation -5.00°)"),
        "{err}"
    );
    assert!(err.contains("nothing lights"), "{err}");
}

/// A 1 km ground at the default 1 m elements would be about 8 million elements: the solve gives
/// the ground an element size of its own (with a note naming it) instead of refusing the site.
#[test]
fn a_large_ground_is_sized_to_fit_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let text = std::fs::read_to_string(&site).unwrap();
    let big = text
        .replace("[-10.0, -10.0, 0.0]", "[-500.0, -500.0, 0.0]")
        .replace("[10.0, -10.0, 0.0]", "[500.0, -500.0, 0.0]")
        .replace("[10.0, 10.0, 0.0]", "[500.0, 500.0, 0.0]")
        .replace("[-10.0, 10.0, 0.0]", "[-500.0, 500.0, 0.0]");
    assert_ne!(big, text);
    std::fs::write(&site, big).unwrap();
    let out = photomontage(&["radiosity".as_ref(), site.as_os_str(), "--json".as_ref()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("ground") && err.contains("element edge") && err.contains("instead of 1 m"),
        "{err}"
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let elements = json["elements"].as_u64().unwrap();
    assert!(elements <= 200_000, "{elements}");
}
