#![allow(clippy::float_cmp)] // enabled/disabled counts and copied weights

use super::*;
use std::path::Path;

/// The hand-written fixture: 1000 cd from nadir to γ = 30° (flat), linearly down to 0 cd at 60°.
const DOWNLIGHT_IES: &str = include_str!("../../tests/fixtures/downlight.ies");
const NADIR_CD: f64 = 1000.0;
/// A few products, one square root and one rotation in f64.
const ROUND_OFF_REL_TOL: f64 = 1e-12;

fn entry(id: &str, position_m: [f64; 3]) -> SiteLuminaire {
    SiteLuminaire {
        id: id.into(),
        file: "downlight.ies".into(),
        position_m,
        rotation_z_deg: 0.0,
        tilt_deg: 0.0,
        colour_rgb: [1.0, 0.8, 0.5],
        scale: 2e-3,
        enabled: true,
    }
}

fn doc(dir: &Path, luminaires: Vec<SiteLuminaire>) -> SiteDocument {
    std::fs::write(dir.join("downlight.ies"), DOWNLIGHT_IES).unwrap();
    SiteDocument {
        path: dir.join("site.toml"),
        site: Site {
            luminaires,
            ..Site::default()
        },
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn a_lamp_gives_its_nadir_candela_times_scale_and_colour_over_h_squared() {
    let dir = tempfile::tempdir().unwrap();
    let h = 2.5;
    let mut off = entry("off", [5.0, 5.0, 3.0]);
    off.enabled = false;
    let d = doc(dir.path(), vec![entry("lamp", [1.0, 2.0, h]), off]);
    let lights = site_luminaire_lights(&d).unwrap();
    assert_eq!(lights.len(), 1, "the disabled luminaire gives no light");
    let e = lights[0].irradiance_rgb(&Point3::new(1.0, 2.0, 0.0), &Vector3::z());
    for (k, c) in [1.0, 0.8, 0.5].iter().enumerate() {
        let expected = NADIR_CD * 2e-3 * c / (h * h);
        assert!(rel(e[k], expected) < ROUND_OFF_REL_TOL, "{e:?}");
    }
    // Beyond the 60° cut-off (γ = atan(5/2.5) = 63.4°): no light at all.
    let e = lights[0].irradiance_rgb(&Point3::new(6.0, 2.0, 0.0), &Vector3::z());
    assert_eq!(e, [0.0; 3]);
    assert!(luminaire_warnings(&d.site).is_empty());
}

#[test]
fn tilt_swings_the_nadir_towards_c0_and_rotation_turns_it_about_z() {
    // Tilt 30°: nadir (0, 0, −1) → (sin 30°, 0, −cos 30°); C0 (+X) stays in the XZ plane.
    let r = world_from_luminaire(0.0, 30.0);
    let nadir = r * Vector3::new(0.0, 0.0, -1.0);
    let expected = Vector3::new(0.5, 0.0, -(0.75_f64.sqrt()));
    assert!((nadir - expected).norm() < ROUND_OFF_REL_TOL);
    // Rotation 90° (counter-clockwise from above): C0 points to +Y.
    let r = world_from_luminaire(90.0, 0.0);
    assert!((r * Vector3::x() - Vector3::y()).norm() < ROUND_OFF_REL_TOL);

    // A floodlight tilted 90° and turned to +Y: a wall 4 m north gets I(γ = 0)/d², the ground
    // straight below (γ = 90°) nothing.
    let dir = tempfile::tempdir().unwrap();
    let mut flood = entry("flood", [0.0, 0.0, 3.0]);
    flood.tilt_deg = 90.0;
    flood.rotation_z_deg = 90.0;
    let d = doc(dir.path(), vec![flood]);
    let light = &site_luminaire_lights(&d).unwrap()[0];
    let e = light.irradiance_rgb(&Point3::new(0.0, 4.0, 3.0), &-Vector3::y());
    assert!(
        rel(e[0], NADIR_CD * 2e-3 / 16.0) < ROUND_OFF_REL_TOL,
        "{e:?}"
    );
    let e = light.irradiance_rgb(&Point3::new(0.0, 0.0, 0.0), &Vector3::z());
    assert!(e[0].abs() < ROUND_OFF_REL_TOL * NADIR_CD, "{e:?}");
}

#[test]
fn bad_luminaires_are_errors_naming_the_entry_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut missing = entry("porch", [0.0, 0.0, 2.0]);
    missing.file = "nope.ies".into();
    let err = site_luminaire_lights(&doc(dir.path(), vec![missing])).unwrap_err();
    assert!(matches!(err, SiteRenderError::LuminaireFile { .. }));
    let text = err.to_string();
    assert!(
        text.contains("`porch`") && text.contains("nope.ies"),
        "{text}"
    );

    std::fs::write(
        dir.path().join("junk.ies"),
        "IESNA:LM-63-2002\nTILT=NONE\n1 2\n",
    )
    .unwrap();
    let mut junk = entry("street", [0.0, 0.0, 2.0]);
    junk.file = "junk.ies".into();
    let err = site_luminaire_lights(&doc(dir.path(), vec![junk])).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("`street`") && text.contains("junk.ies"),
        "{text}"
    );

    let nan = entry("nan", [f64::NAN, 0.0, 2.0]);
    let d = doc(dir.path(), vec![nan]);
    let err = site_luminaire_lights(&d).unwrap_err();
    assert!(
        matches!(&err, SiteRenderError::LuminaireSetting { luminaire, field: "position_m", .. } if luminaire == "nan"),
        "{err}"
    );
    let issues = d.site.validate();
    assert_eq!(issues[0].field, "luminaires[0].position_m");
    assert!(issues[0].message.contains("`nan`"), "{issues:?}");

    let mut dark = entry("dark", [0.0, 0.0, 2.0]);
    dark.scale = 0.0;
    let d = doc(dir.path(), vec![dark, entry("dark", [1.0, 0.0, 2.0])]);
    let w = luminaire_warnings(&d.site);
    assert_eq!(w.len(), 1);
    assert!(w[0].to_string().contains("`dark`"), "{}", w[0]);
    // Duplicate ids are a validation error.
    assert!(
        d.site
            .validate()
            .iter()
            .any(|i| i.message.contains("duplicate luminaire id `dark`"))
    );
}

#[test]
fn luminaires_parse_from_toml_with_defaults_and_round_trip() {
    let text = "schema_version = 1\n\n[[luminaires]]\nid = \"lamp\"\nfile = \"a.ldt\"\n\
                position_m = [1.0, 2.0, 4.5]\nscale = 1e-4\n";
    let site = Site::from_toml(text, Path::new("site.toml")).unwrap();
    let l = &site.luminaires[0];
    assert_eq!(l.colour_rgb, [1.0; 3]);
    assert!(l.enabled && l.tilt_deg == 0.0 && l.rotation_z_deg == 0.0);
    let again = Site::from_toml(&site.to_toml().unwrap(), Path::new("site.toml")).unwrap();
    assert_eq!(again, site);
    let bad = text.replace("[1.0, 2.0, 4.5]", "[nan, 2.0, 4.5]");
    let err = Site::from_toml(&bad, Path::new("site.toml")).unwrap_err();
    assert!(
        err.to_string().contains("luminaires[0].position_m"),
        "{err}"
    );
}
