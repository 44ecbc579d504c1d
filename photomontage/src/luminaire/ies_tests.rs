use super::*;
use crate::luminaire::MAX_ANGLES;
use crate::luminaire::distribution::LampGeometry;
use approx::assert_relative_eq;
use proptest::prelude::*;

/// A hand-written LM-63-2019 file (lighting.md §4.1): TILT=INCLUDE with geometry 1 and the
/// 0/45/90/180° → 1.00/0.90/0.80/1.00 table of eulumdat-rs's TILT_TEST_SYNTHETIC, an
/// isotropic 100 cd lower hemisphere (5 vertical angles, axial), metres, CR LF endings.
const LM63_2019_TILT: &str = "IES:LM-63-2019\r\n\
    [TEST] PM-2026-001\r\n\
    [TESTLAB] Photomontage test fixture\r\n\
    [ISSUEDATE] 21-NOV-2026\r\n\
    [MANUFAC] Nobody\r\n\
    [LUMINAIRE] Hand-written tilt test\r\n\
    [MORE] second line of the description\r\n\
    TILT=INCLUDE\r\n\
    1\r\n\
    4\r\n\
    0 45 90 180\r\n\
    1.00 0.90 0.80 1.00\r\n\
    1 1000 1 5 1 1 2 0.1 0.1 0\r\n\
    1.0 1.10000 20\r\n\
    0 22.5 45 67.5 90\r\n\
    0\r\n\
    100 100 100 100 100\r\n";

#[test]
fn lm63_2019_with_tilt_include_applies_the_tilt() {
    use crate::luminaire::Luminaire;
    use nalgebra::{Point3, Rotation3, Vector3};
    let f = IesFile::parse(LM63_2019_TILT.as_bytes()).unwrap();
    assert_eq!(f.version, IesVersion::Lm63_2019);
    assert!(f.warnings.is_empty(), "{:?}", f.warnings);
    assert_eq!(
        f.keyword("luminaire"),
        Some("Hand-written tilt test\nsecond line of the description")
    );
    let tilt = f.tilt.clone().unwrap();
    assert_eq!(tilt.geometry, LampGeometry::Vertical);
    assert_eq!(tilt.angles_deg, vec![0.0, 45.0, 90.0, 180.0]);
    assert_relative_eq!(f.file_generation_type, 1.1);
    let web = f.distribution().unwrap();
    // 100 cd over the lower hemisphere: 200π lm.
    assert_relative_eq!(
        web.total_flux_lm(),
        200.0 * std::f64::consts::PI,
        max_relative = 1e-12
    );
    let mut lum = Luminaire::new(web, Point3::origin());
    lum.tilt = f.tilt.clone();
    // Tilted 45° about x: the multiplier is 0.90 in every direction the web lights.
    lum.world_from_luminaire = Rotation3::from_axis_angle(&Vector3::x_axis(), 45f64.to_radians());
    assert_relative_eq!(lum.tilt_deg(), 45.0, epsilon = 1e-9);
    let aim = lum.world_from_luminaire * Vector3::new(0.0, 0.0, -1.0);
    assert_relative_eq!(lum.intensity_toward_cd(&aim), 90.0, epsilon = 1e-9);
    // 67.5° lies halfway between 45° (0.90) and 90° (0.80).
    lum.world_from_luminaire = Rotation3::from_axis_angle(&Vector3::x_axis(), 67.5f64.to_radians());
    let aim = lum.world_from_luminaire * Vector3::new(0.0, 0.0, -1.0);
    assert_relative_eq!(lum.intensity_toward_cd(&aim), 85.0, epsilon = 1e-9);
}

#[test]
fn old_style_numbers_split_over_lines() {
    // IESNA91, record 1 split over 4 lines, Fortran numbers, leading spaces, commas.
    let text = "IESNA91\n[TEST] x\n   TILT=NONE\n1 1000. 1\n3 1\n1\n1\n.5 .5 .0\n1 1 10\n\
                0, 45, 90\n0\n 10 5.\n 0\n";
    let f = IesFile::parse(text.as_bytes()).unwrap();
    assert_eq!(f.version, IesVersion::Lm63_1991);
    assert_relative_eq!(f.opening_m[0], 0.5 * M_PER_FT);
    assert_eq!(f.candela, vec![10.0, 5.0, 0.0]);
    assert_eq!(f.symmetry(), Symmetry::Axial);
}

#[test]
fn latin1_bytes_are_decoded_with_a_warning() {
    let mut bytes =
        b"ERCO 70\xb0 wide\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 1\n0 90\n0\n7 3\n".to_vec();
    bytes.push(b'\n');
    let f = IesFile::parse(&bytes).unwrap();
    assert_eq!(f.version, IesVersion::Lm63_1986);
    assert_eq!(f.free_text, vec!["ERCO 70° wide".to_owned()]);
    assert!(f.is_absolute());
    assert!(f.warnings.iter().any(|w| w.contains("Latin-1")));
}

#[test]
fn errors_name_the_line_and_what_was_expected() {
    let missing = IesFile::parse(b"IESNA:LM-63-2002\n[TEST] a\n");
    assert_eq!(missing, Err(IesError::MissingTilt { line: 3 }));
    let bad = IesFile::parse(b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 x 1 1 2 0 0 0\n");
    assert_eq!(
        bad,
        Err(IesError::BadNumber {
            line: 3,
            field: "number of vertical angles".to_owned(),
            token: "x".to_owned()
        })
    );
    let short =
        IesFile::parse(b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 1\n0 45\n");
    assert!(
        matches!(short, Err(IesError::UnexpectedEnd { line: 5, ref expected }) if expected.starts_with("3 vertical angles")),
        "{short:?}"
    );
    let tilt_file = IesFile::parse(b"IESNA:LM-63-2002\nTILT=lamp.tlt\n");
    assert!(matches!(tilt_file, Err(IesError::TiltFile { line: 2, .. })));
}

#[test]
fn tilt_file_is_loaded_through_the_resolver() {
    let text = b"IESNA:LM-63-2002\nTILT=lamp.tlt\n1 1000 1 2 1 1 2 0 0 0\n1 1 1\n0 90\n0\n7 3\n";
    let f = IesFile::parse_with_tilt_resolver(text, &mut |name| {
        assert_eq!(name, "lamp.tlt");
        Ok(b"3\n2\n0 90\n1 0.5\n".to_vec())
    })
    .unwrap();
    let t = f.tilt.unwrap();
    assert_eq!(t.geometry, LampGeometry::HorizontalTilting);
    assert_relative_eq!(t.multiplier_at(45.0), 0.75);
}

#[test]
fn absurd_counts_are_refused_before_allocating() {
    let text = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 1000000000 1000000000 1 2 0 0 0\n";
    assert_eq!(
        IesFile::parse(text),
        Err(IesError::BadCount {
            line: 3,
            field: "number of vertical angles",
            value: 1e9,
            max: MAX_ANGLES
        })
    );
    let product = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 50000 50000 1 2 0 0 0\n";
    assert!(matches!(
        IesFile::parse(product),
        Err(IesError::BadCount { line: 3, .. })
    ));
    // Plausible counts but too few numbers: refused by comparing with what is there.
    let few = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 90000 10 1 2 0 0 0\n1 1 1\n0\n";
    assert!(matches!(
        IesFile::parse(few),
        Err(IesError::UnexpectedEnd { .. })
    ));
}

proptest! {
    #[test]
    fn never_panics_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let _ = IesFile::parse(&bytes);
    }

    #[test]
    fn never_panics_on_mutated_fixture(
        edits in proptest::collection::vec((0usize..600, any::<u8>()), 1..8),
        cut in 0usize..600,
    ) {
        let mut bytes = LM63_2019_TILT.as_bytes().to_vec();
        for (pos, b) in edits {
            let i = pos % bytes.len();
            bytes[i] = b;
        }
        bytes.truncate(cut.max(1).min(bytes.len()));
        if let Ok(f) = IesFile::parse(&bytes) {
            let _ = f.distribution().map(|w| w.total_flux_lm());
        }
    }
}
