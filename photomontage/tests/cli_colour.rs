//! The `colour` subcommand: known answers (greys of a given lightness, white), the LRV
//! difference of two colours, the gamut flag, and a clear error naming a colour it cannot read.

use std::process::Command;

fn photomontage(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the binary runs")
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
