use super::*;
use crate::colour::designer::{ColourSpec, parse_colour};

/// Lindbloom prints the Bradford matrices to 7 decimals.
const PUBLISHED_MATRIX_TOL: f64 = 5e-7;
/// A grey's three linear channels and its Y agree to rounding.
const GREY_TOL: f64 = 1e-12;

#[test]
fn bradford_matches_the_published_d65_to_d50_matrix() {
    // B. Lindbloom, "Chromatic Adaptation", Bradford, D65 → D50 (his whites: D65 0.95047,
    // 1, 1.08883; D50 0.96422, 1, 0.82521).
    let published = Matrix3::new(
        1.047_811_2,
        0.022_886_6,
        -0.050_127_0, //
        0.029_542_4,
        0.990_484_4,
        -0.017_049_1, //
        -0.009_234_5,
        0.015_043_6,
        0.752_131_6,
    );
    let m = bradford([0.950_47, 1.0, 1.088_83], [0.964_22, 1.0, 0.825_21]);
    let worst = (m - published).abs().max();
    assert!(worst < PUBLISHED_MATRIX_TOL, "{m} vs {published}: {worst}");
}

#[test]
fn greys_become_the_grey_of_their_lightness() {
    // The adaptation maps the 10° white to the 2° white, so RAL 000 LL 00 is a neutral grey
    // with Y = ((LL + 16)/116)³ (CIE 15:2004 §8.2.1), whatever the observers' difference.
    for lightness in [20u8, 50, 92] {
        let code = RalDesign {
            hue_deg: 0,
            lightness,
            chroma: 0,
        };
        let rgb = ColourSpec::RalDesign(code).linear_srgb();
        let y = ((f64::from(lightness) + 16.0) / 116.0).powi(3);
        for c in rgb {
            assert!((c - y).abs() < GREY_TOL, "{code}: {rgb:?} vs Y {y}");
        }
        let lab = ColourSpec::RalDesign(code).lab();
        assert!((lab[0] - f64::from(lightness)).abs() < 1e-9, "{lab:?}");
        assert!(lab[1].abs() < 1e-9 && lab[2].abs() < 1e-9, "{lab:?}");
    }
    // RAL 000 50 00 is sRGB #777777 and LRV 18.42 (the mid grey of lightness 50).
    let r = parse_colour("RAL 000 50 00").unwrap();
    assert_eq!(hex_of(r), "#777777");
    assert!((r.resolve().lrv - 100.0 * (66.0f64 / 116.0).powi(3)).abs() < 1e-9);
}

fn hex_of(spec: ColourSpec) -> String {
    crate::colour::designer::hex_from_linear(spec.resolve().linear_rgb)
}

#[test]
fn a_code_is_the_nearest_code_to_its_own_colour() {
    // Hues every 10° (and the fan's 75/85/95), lightness 20–90, chroma 0–50: converting a code
    // to XYZ and back gives the same code, and the hue is kept within the adaptation's error.
    for hue_deg in (10..=360).step_by(10).chain([75, 85, 95]) {
        for lightness in (20..=90).step_by(10) {
            for chroma in [5u8, 10, 20, 30, 50] {
                let code = RalDesign {
                    hue_deg,
                    lightness,
                    chroma,
                };
                assert_eq!(RalDesign::nearest(code.xyz()), Some(code), "{code}");
            }
        }
    }
    let grey = RalDesign {
        hue_deg: 0,
        lightness: 60,
        chroma: 0,
    };
    assert_eq!(RalDesign::nearest(grey.xyz()), Some(grey));
    // White needs L* = 100, three digits.
    assert_eq!(RalDesign::nearest(d65_white_xyz()), None);
}

#[test]
fn chromatic_codes_keep_their_hue_lightness_and_chroma_under_the_2deg_observer() {
    // The 10° → 2° adaptation is an approximation; the colour seen by the 2° observer stays
    // within a fraction of a CIELAB unit in L* and a few in hue of the nominal code.
    for code in [
        "RAL 210 50 15",
        "RAL 090 80 60",
        "RAL 030 40 40",
        "RAL 270 30 30",
    ] {
        let spec = parse_colour(code).unwrap();
        let ColourSpec::RalDesign(ral) = spec else {
            panic!("{code} read as {spec:?}");
        };
        let lch2 = lch_from_lab(spec.lab());
        let [l, c, h] = ral.lch();
        assert!((lch2[0] - l).abs() < 0.5, "{code}: {lch2:?}");
        assert!((lch2[1] - c).abs() < 0.1 * c, "{code}: {lch2:?}");
        let dh = (lch2[2] - h + 540.0).rem_euclid(360.0) - 180.0;
        assert!(dh.abs() < 3.0, "{code}: {lch2:?}");
    }
}

#[test]
fn codes_are_read_in_their_written_forms_and_printed_back() {
    let code = RalDesign {
        hue_deg: 210,
        lightness: 50,
        chroma: 15,
    };
    for text in [
        "RAL 210 50 15",
        "ral 210-50-15",
        "RAL2105015",
        " RAL 210  50 15 ",
    ] {
        assert_eq!(
            parse_colour(text).unwrap(),
            ColourSpec::RalDesign(code),
            "{text}"
        );
    }
    assert_eq!(ColourSpec::RalDesign(code).to_string(), "RAL 210 50 15");
    let grey = parse_colour("RAL 000 90 00").unwrap();
    assert_eq!(grey.to_string(), "RAL 000 90 00");
    assert_eq!(parse_colour(&grey.to_string()).unwrap(), grey);
}

#[test]
fn bad_codes_say_what_is_wrong() {
    for (bad, says) in [
        ("RAL 9010", "RAL Classic"),
        ("RAL 370 50 10", "above 360"),
        ("RAL 000 50 10", "grey series"),
        ("RAL 21a 50 15", "digits"),
        ("RAL 2100 50 15", "at most 3 hue"),
        ("RAL 210 50", "RAL HHH LL CC"),
        ("RAL", "RAL HHH LL CC"),
    ] {
        let e = parse_colour(bad).unwrap_err();
        assert_eq!(e.text, bad);
        assert!(e.to_string().contains(says), "{bad}: {e}");
    }
}

#[test]
fn a_page_holds_the_in_gamut_codes_of_its_hue_lightest_first() {
    let page = RalDesign::page(210);
    assert!(!page.is_empty());
    assert!(page.iter().all(|c| c.hue_deg == 210));
    // Lightest row first, each row by chroma.
    assert!(page.windows(2).all(|w| w[0].lightness > w[1].lightness
        || (w[0].lightness == w[1].lightness && w[0].chroma < w[1].chroma)));
    // Every code shown is inside the sRGB gamut; the grid's codes left out are outside it.
    for lightness in PAGE_LIGHTNESS {
        for chroma in PAGE_CHROMA {
            let code = RalDesign {
                hue_deg: 210,
                lightness,
                chroma,
            };
            let inside = !ColourSpec::RalDesign(code).resolve().out_of_gamut;
            assert_eq!(page.contains(&code), inside, "{code}");
        }
    }
    // A mid blue of low chroma is in; the most chromatic dark blue-green is not.
    assert!(page.iter().any(|c| c.to_string() == "RAL 210 50 15"));
    assert!(!page.iter().any(|c| c.to_string() == "RAL 210 20 90"));
    // The grey page: every grey of its rows, chroma 0.
    let greys = RalDesign::page(0);
    assert_eq!(greys.len(), GREY_PAGE_LIGHTNESS.len());
    assert!(greys.iter().all(|c| c.chroma == 0 && c.hue_deg == 0));
    assert_eq!(greys[0].lightness, 90);
    assert!(RalDesign::page(370).is_empty());
    // The pages are the fan's: greys, then hues in order.
    assert!(HUE_PAGES_DEG.windows(2).all(|w| w[0] < w[1]));
    assert_eq!((HUE_PAGES_DEG[0], HUE_PAGES_DEG[39]), (0, 360));
}
