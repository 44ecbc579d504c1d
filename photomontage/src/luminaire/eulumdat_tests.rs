use super::*;
use crate::luminaire::MAX_ANGLES;
use approx::assert_relative_eq;
use proptest::prelude::*;

/// Builds a small LDT text: Isym 4, Mc 4 (C 0/90/180/270), Ng 3 (γ 0/90/180 given as
/// non-equidistant Dg = 0), two lamp sets, comma decimals, CR LF.
fn quadrant_fixture() -> String {
    let mut l: Vec<String> = vec![
        "Fixture company".into(),
        "1".into(),
        "4".into(),
        "4".into(),
        "90".into(),
        "3".into(),
        "0".into(),
        "R1".into(),
        "Test luminaire".into(),
        "T-1".into(),
        "t.ldt".into(),
        "2026-11-21".into(),
    ];
    for v in [
        "600", "600", "50", "500", "400", "10", "20", "10", "20", "100", "95,5", "1,0", "0",
    ] {
        l.push(v.into());
    }
    l.push("2".into());
    for v in ["1", "LED A", "2000", "3000K", "80", "20,5"] {
        l.push(v.into());
    }
    for v in ["1", "LED B", "3000", "4000K", "80", "n/a"] {
        l.push(v.into());
    }
    for _ in 0..10 {
        l.push("0".into());
    }
    for v in ["0", "90", "180", "270", "0", "90", "180"] {
        l.push(v.into());
    }
    // Stored planes C0 and C90: I(γ) = 100, 50, 0 cd/klm; C90: 200, 60, 0.
    for v in ["100", "50", "0", "200", "60", "0"] {
        l.push(format!("  {v} "));
    }
    l.join("\r\n") + "\r\n"
}

#[test]
fn fixture_parses_with_comma_decimals_and_two_lamp_sets() {
    let f = EulumdatFile::parse(quadrant_fixture().as_bytes()).unwrap();
    assert_eq!(f.symmetry(), Symmetry::Quadrant);
    assert_eq!(f.lamp_sets.len(), 2);
    assert_relative_eq!(f.light_output_ratio_percent, 95.5);
    assert_eq!(f.lamp_sets[0].power_w, Some(20.5));
    assert_eq!(f.lamp_sets[1].power_w, None);
    assert_eq!(f.stored_c_deg, vec![0.0, 90.0]);
    let web = f.distribution().unwrap();
    // 100 cd/klm × 2 klm at nadir; C270 mirrors C90: 60 × 2 at γ 90.
    assert_relative_eq!(web.intensity_cd(0.0, 0.0), 200.0);
    assert_relative_eq!(web.intensity_cd(270.0, 90.0), 120.0);
    assert_relative_eq!(web.intensity_cd(180.0, 45.0), 150.0);
    let second = f.distribution_for_lamp_set(1).unwrap();
    assert_relative_eq!(second.intensity_cd(90.0, 0.0), 600.0);
    assert!(matches!(
        f.distribution_for_lamp_set(2),
        Err(EulumdatError::NoLampSet { index: 2, count: 2 })
    ));
}

#[test]
fn projected_area_of_a_flat_rectangle_and_a_disc() {
    let mut f = EulumdatFile::parse(quadrant_fixture().as_bytes()).unwrap();
    // 0.5 × 0.4 m bottom; side heights 10/20 mm at C0/C90.
    assert_relative_eq!(f.projected_luminous_area_m2(0.0, 0.0), 0.2, epsilon = 1e-12);
    assert_relative_eq!(
        f.projected_luminous_area_m2(90.0, 90.0),
        0.4 * 0.02,
        epsilon = 1e-12
    );
    f.luminous_area_mm = [400.0, 0.0];
    let disc = std::f64::consts::PI * 0.04;
    assert_relative_eq!(
        f.projected_luminous_area_m2(33.0, 60.0),
        disc * 0.5 + 0.4 * 0.01 * 60f64.to_radians().sin(),
        epsilon = 1e-12
    );
}

#[test]
fn errors_name_line_and_field() {
    let text = quadrant_fixture().replace(
        "Fixture company\r\n1\r\n4\r\n4\r\n",
        "Fixture company\r\n1\r\n4\r\nfour\r\n",
    );
    assert_eq!(
        EulumdatFile::parse(text.as_bytes()),
        Err(EulumdatError::BadNumber {
            line: 4,
            field: "number of C planes Mc".to_owned(),
            found: "four".to_owned()
        })
    );
    let absurd = quadrant_fixture().replace("4\r\n90\r\n3\r\n", "4\r\n90\r\n1000000000\r\n");
    assert_eq!(
        EulumdatFile::parse(absurd.as_bytes()),
        Err(EulumdatError::BadCount {
            line: 6,
            field: "number of gamma angles Ng",
            value: 1e9,
            min: 1,
            max: MAX_ANGLES
        })
    );
    let bad_sym = quadrant_fixture().replacen("\r\n4\r\n", "\r\n7\r\n", 1);
    assert_eq!(
        EulumdatFile::parse(bad_sym.as_bytes()),
        Err(EulumdatError::BadSymmetry { value: 7.0 })
    );
    let truncated: String = quadrant_fixture()
        .lines()
        .take(20)
        .collect::<Vec<_>>()
        .join("\n");
    assert!(matches!(
        EulumdatFile::parse(truncated.as_bytes()),
        Err(EulumdatError::UnexpectedEnd { line: 21, .. })
    ));
}

proptest! {
    #[test]
    fn never_panics_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let _ = EulumdatFile::parse(&bytes);
    }

    #[test]
    fn never_panics_on_mutated_fixture(
        edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..8),
        cut in 0usize..400,
    ) {
        let mut bytes = quadrant_fixture().into_bytes();
        for (pos, b) in edits {
            let i = pos % bytes.len();
            bytes[i] = b;
        }
        bytes.truncate(cut.max(1).min(bytes.len()));
        if let Ok(f) = EulumdatFile::parse(&bytes) {
            let _ = f.distribution().map(|w| w.total_flux_lm());
            let _ = f.luminance_cd_per_m2(10.0, 70.0);
        }
    }
}
