//! `photomontage luminaire FILE --json --plot OUT.png` end to end on a hand-written file whose
//! answers are known in closed form: an isotropic 100 cd lower hemisphere emits 200π lm.

use std::process::Command;

/// Flux of a constant interpolant is integrated exactly; only the JSON's decimal printing and
/// rounding remain.
const FLUX_REL: f64 = 1e-9;

const FIXTURE: &str = "IES:LM-63-2019\r\n[TEST] CLI-1\r\n[TESTLAB] fixture\r\n[ISSUEDATE] 2026-11-21\r\n\
[MANUFAC] none\r\nTILT=NONE\r\n1 -1 1 3 1 1 2 0.1 0.1 0\r\n1 1.00001 10\r\n0 45 90\r\n0\r\n100 100 100\r\n";

#[test]
fn luminaire_subcommand_reports_json_and_writes_a_plot() {
    let dir = tempfile::tempdir().unwrap();
    let ies = dir.path().join("fixture.ies");
    let png = dir.path().join("polar.png");
    std::fs::write(&ies, FIXTURE).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(["luminaire", ies.to_str().unwrap(), "--json", "--plot"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["format"], "ies:LM-63-2019");
    assert_eq!(json["symmetry"], "axial");
    assert_eq!(json["warnings"].as_array().map(Vec::len), Some(0));
    let flux = json["total_flux_lm"].as_f64().unwrap();
    assert!(
        (flux / (200.0 * std::f64::consts::PI) - 1.0).abs() < FLUX_REL,
        "{flux}"
    );
    assert!((json["max_intensity_cd"].as_f64().unwrap() - 100.0).abs() < 1e-12);
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (512, 512));
}

#[test]
fn luminaire_subcommand_fails_with_the_parse_error() {
    let dir = tempfile::tempdir().unwrap();
    let ies = dir.path().join("broken.ies");
    std::fs::write(&ies, "IESNA:LM-63-2002\n[TEST] x\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(["luminaire", ies.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("line 3: end of file, expected a TILT="),
        "{stderr}"
    );
}
