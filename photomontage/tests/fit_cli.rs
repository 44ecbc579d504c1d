//! `photomontage fit` end to end: JSON keys, the sun cross-check against a shadow built from the
//! SPA sun, `--no-write` leaves the file alone, the write-back adds the `[fit]` record, and a site
//! with nothing to fit is an error.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::Path;
use std::process::Command;

use chrono::DateTime;
use photomontage::sun::{SpaParams, solar_position};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
}

/// A site with one photo (its time only; the file is not needed) and a 6 m pole whose shadow
/// tip is placed from the SPA sun at `true_time`; the photo claims `stated_time`.
fn write_site(dir: &Path, true_time: &str, stated_time: &str) -> std::path::PathBuf {
    let params = SpaParams::at(46.95, 7.45);
    let pos = solar_position(&DateTime::parse_from_rfc3339(true_time).unwrap(), &params).unwrap();
    let d = pos.direction_enu();
    let top = [600_000.0, 200_000.0, 506.0];
    let k = 6.0 / d[2];
    let shadow = [top[0] - k * d[0], top[1] - k * d[1], 500.0];
    let text = format!(
        r#"schema_version = 1
name = "pole"

[location]
latitude_deg = 46.95
longitude_deg = 7.45

[[photos]]
id = "P1"
file = "p1.jpg"
taken_at = "{stated_time}"

[[control_points]]
id = "top"
xyz = [{}, {}, {}]

[[control_points]]
id = "tip"
xyz = [{}, {}, {}]

[[sun_shadow_pairs]]
id = "pole"
object_point = "top"
shadow_point = "tip"
photo = "P1"
"#,
        top[0], top[1], top[2], shadow[0], shadow[1], shadow[2]
    );
    let path = dir.join("site.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn run_json(args: &[&str]) -> serde_json::Value {
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn json_report_has_the_documented_keys_and_finds_a_wrong_clock() {
    let dir = tempfile::tempdir().unwrap();
    // The camera clock is 2 h fast (stated 16:20 for a photo taken at 14:20).
    let site = write_site(
        dir.path(),
        "2024-09-10T14:20:00+02:00",
        "2024-09-10T16:20:00+02:00",
    );
    let before = std::fs::read(&site).unwrap();
    let v = run_json(&["fit", site.to_str().unwrap(), "--json", "--no-write"]);
    for key in [
        "transmittance",
        "transmittance_sigma",
        "horizon_colour",
        "sun_weight",
        "sun_weight_sigma",
        "ambient_weight",
        "ambient_weight_sigma",
        "sky_weight",
        "sky_weight_sigma",
        "residuals",
        "warnings",
        "sun_checks",
        "written_to",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}: {v}");
    }
    let check = &v["sun_checks"][0];
    assert_eq!(check["pair"], "pole");
    assert!(check["angle_deg"].as_f64().unwrap() > 2.0);
    assert_eq!(check["clock_offset_s"], -7200);
    let warnings = v["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("sun check `pole`")
                && w.as_str().unwrap().contains("fast by 2h00m00s")),
        "{warnings:?}"
    );
    assert!(v["written_to"].is_null());
    assert_eq!(std::fs::read(&site).unwrap(), before, "--no-write wrote");
}

#[test]
fn write_back_adds_the_fit_record_and_a_right_clock_passes() {
    let dir = tempfile::tempdir().unwrap();
    let t = "2024-09-10T10:05:00+02:00";
    let site = write_site(dir.path(), t, t);
    let v = run_json(&["fit", site.to_str().unwrap(), "--json"]);
    assert!(v["sun_checks"][0]["angle_deg"].as_f64().unwrap() < 1e-6);
    assert!(v["sun_checks"][0]["clock_offset_s"].is_null());
    assert_eq!(v["written_to"], site.to_str().unwrap());
    let doc = photomontage::site::SiteDocument::load(&site).unwrap();
    let record = doc.site.fit.unwrap();
    assert!(DateTime::parse_from_rfc3339(&record.fitted_at).is_ok());
    assert!((record.reference_distance_m - 1000.0).abs() < 1e-12);
}

#[test]
fn a_site_with_nothing_to_fit_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("site.toml");
    std::fs::write(&path, "schema_version = 1\n").unwrap();
    let out = bin().arg("fit").arg(&path).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no enabled samples"), "{err}");
}
