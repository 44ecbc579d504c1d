//! The subcommands that read no site (`sun`, `sky`, `colour`): JSON fields with known answers,
//! and clear errors on bad input.

use std::process::Command;

fn photomontage(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the binary runs")
}

fn json(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

#[test]
fn sun_json_reproduces_the_spa_test_case() {
    // Reda & Andreas 2004 test case: zenith 50.111622°, azimuth 194.340241°, sunrise 06:12:43,
    // sunset 17:20:19 local (UTC−7).
    let out = photomontage(&[
        "sun",
        "--lat",
        "39.742476",
        "--lon",
        "-105.1786",
        "--time",
        "2003-10-17T12:30:30-07:00",
        "--elevation-m",
        "1830.14",
        "--pressure-mbar",
        "820",
        "--temperature-c",
        "11",
        "--delta-t-s",
        "67",
        "--json",
    ]);
    let v = json(&out);
    let num = |k: &str| v[k].as_f64().unwrap_or(f64::NAN);
    assert!((num("zenith_deg") - 50.111_622).abs() < 1e-5);
    assert!((num("azimuth_deg") - 194.340_241).abs() < 1e-5);
    assert!((num("elevation_deg") - (90.0 - 50.111_622)).abs() < 1e-5);
    assert_eq!(v["sunrise"].as_str(), Some("2003-10-17T06:12:43-07:00"));
    assert_eq!(v["sunset"].as_str(), Some("2003-10-17T17:20:19-07:00"));
}

#[test]
fn sky_json_matches_the_cie_table_and_writes_a_map() {
    let dir = tempfile::tempdir().expect("temp dir");
    let map = dir.path().join("sky.png");
    let map_arg = map.to_string_lossy().to_string();
    let out = photomontage(&[
        "sky",
        "--type",
        "12",
        "--sun-elevation-deg",
        "45",
        "--sun-azimuth-deg",
        "135",
        "--json",
        "--map",
        &map_arg,
        "--map-size-px",
        "64",
    ]);
    let v = json(&out);
    // lighting.md §1.1: type 12, elevation 45°: 4.8485 (0.1 %).
    let ratio = v["horizontal_illuminance_over_zenith_luminance"]
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!((ratio / 4.8485 - 1.0).abs() < 1e-3, "{ratio}");
    let img = image::open(&map).expect("PNG written");
    assert_eq!((img.width(), img.height()), (64, 64));
}

#[test]
fn bad_input_gives_clear_errors() {
    let cases: [(&[&str], &str); 3] = [
        (
            &[
                "sun",
                "--lat",
                "91",
                "--lon",
                "0",
                "--time",
                "2025-06-21T12:00:00Z",
            ],
            "--lat 91",
        ),
        (
            &["sun", "--lat", "47", "--lon", "8", "--time", "noon"],
            "RFC 3339",
        ),
        (
            &[
                "sky",
                "--type",
                "16",
                "--sun-elevation-deg",
                "30",
                "--sun-azimuth-deg",
                "180",
            ],
            "outside 1…15",
        ),
    ];
    for (args, expected) in cases {
        let out = photomontage(args);
        assert!(!out.status.success(), "{args:?} should fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
}

/// LRV is printed from f64 arithmetic on closed forms; this only absorbs rounding.
const LRV_TOL: f64 = 1e-9;

#[test]
fn colour_json_gives_hex_lab_ral_and_lrv_with_known_answers() {
    let out = photomontage(&["colour", "RAL 000 50 00", "#ffffff", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let grey = &v["colours"][0];
    let white = &v["colours"][1];
    // L* = 50 ⇒ Y = (66/116)³ in every channel, sRGB 119 = #777777, LRV 100·Y.
    let y = (66.0f64 / 116.0).powi(3);
    assert_eq!(grey["hex"].as_str(), Some("#777777"));
    assert!((grey["lrv"].as_f64().unwrap() - 100.0 * y).abs() < LRV_TOL);
    assert!((grey["lab"][0].as_f64().unwrap() - 50.0).abs() < 1e-9);
    assert_eq!(grey["nearest_ral_design"].as_str(), Some("RAL 000 50 00"));
    assert_eq!(grey["out_of_gamut"].as_bool(), Some(false));
    assert!((white["lrv"].as_f64().unwrap() - 100.0).abs() < LRV_TOL);
    // White needs L* = 100: no two-digit code.
    assert!(white["nearest_ral_design"].is_null());
    let difference = v["lrv_difference"].as_f64().unwrap();
    assert!((difference - (100.0 - 100.0 * y)).abs() < LRV_TOL);
}

#[test]
fn colour_flags_the_gamut_and_names_a_colour_it_cannot_read() {
    let out = photomontage(&["colour", "lab(50, 100, 0)"]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("outside the sRGB gamut"), "{stderr}");
    let out = photomontage(&["colour", "RAL 9010"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("RAL 9010") && stderr.contains("RAL Classic"),
        "{stderr}"
    );
}
