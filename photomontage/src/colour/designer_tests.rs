use super::*;

/// Published L*a*b* values are printed to two decimals; ours differ in the white point's last
/// digits (IEC 61966-2-1 chromaticity vs the CIE table's XYZ), below this.
const PUBLISHED_LAB_TOL: f64 = 0.05;
/// Round trips through the closed-form inverses.
const ROUND_TRIP_TOL: f64 = 1e-10;

fn close3(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
}

#[test]
fn srgb_primaries_match_published_lab() {
    // sRGB primaries and grey in CIE L*a*b* (D65), as printed by B. Lindbloom's colour
    // calculator (brucelindbloom.com, "CIE Color Calculator", sRGB, D65, no adaptation).
    // Checked against an independent implementation: OpenCV 5.0 `cvtColor(…, COLOR_RGB2Lab)` on
    // float32 input (the peer venv) gives 53.2410/80.0938/67.2031, 87.7380/−86.1875/83.1719,
    // 32.2937/79.1875/−107.8594, 100/0/0 and 53.5828/0/0 (float32 and its tabulated curves:
    // within 0.01 of these, 0.05 being the tolerance).
    let cases: [(&str, [f64; 3]); 5] = [
        ("#ff0000", [53.2408, 80.0925, 67.2032]),
        ("#00ff00", [87.7347, -86.1827, 83.1793]),
        ("#0000ff", [32.2970, 79.1875, -107.8602]),
        ("#ffffff", [100.0, 0.0, 0.0]),
        ("#808080", [53.5850, 0.0, 0.0]),
    ];
    for (hex, published) in cases {
        let lab = parse_colour(hex).unwrap().lab();
        assert!(
            close3(lab, published, PUBLISHED_LAB_TOL),
            "{hex}: {lab:?} vs {published:?}"
        );
    }
}

#[test]
fn lab_xyz_round_trip_both_branches() {
    // One colour above and one below the CIE ε/κ break (L* < 8 uses the linear segment).
    for lab in [[52.2, 30.1, 42.7], [3.0, 2.0, -1.5], [95.0, -10.0, 5.0]] {
        let back = lab_from_xyz(xyz_from_lab(lab));
        assert!(close3(back, lab, ROUND_TRIP_TOL), "{lab:?} → {back:?}");
    }
    // L* of Y alone (closed form): Y = ((L* + 16)/116)³ above the break, L*/κ below.
    let y = xyz_from_lab([50.0, 0.0, 0.0])[1];
    assert!((y - (66.0f64 / 116.0).powi(3)).abs() < 1e-15);
    let y = xyz_from_lab([5.0, 0.0, 0.0])[1];
    assert!((y - 5.0 * 27.0 / 24389.0).abs() < 1e-15);
}

#[test]
fn lch_is_the_polar_form_of_lab() {
    let lch = lch_from_lab([52.2, 30.1, 42.7]);
    assert!((lch[1] - 30.1f64.hypot(42.7)).abs() < 1e-12);
    assert!((lch[2] - 42.7f64.atan2(30.1).to_degrees()).abs() < 1e-12);
    // The brief's example: lch(52.2, 52.2, 54.8) is lab(52.2, 30.1, 42.7) to the printed digits.
    let lab = lab_from_lch([52.2, 52.2, 54.8]);
    assert!(close3(lab, [52.2, 30.1, 42.7], 0.06), "{lab:?}");
    // Negative b* gives a hue in (180°, 360°).
    assert!((lch_from_lab([50.0, 0.0, -10.0])[2] - 270.0).abs() < 1e-12);
}

#[test]
fn hex_round_trips_every_grey_level() {
    for v in 0..=255u8 {
        let lin = linear_from_srgb8([v, v, v]);
        assert_eq!(srgb8_from_linear(lin), [v, v, v]);
    }
    assert_eq!(
        hex_from_linear(linear_from_srgb8([0xa0, 0x52, 0x2d])),
        "#a0522d"
    );
    assert_eq!(
        parse_colour("#FA0").unwrap(),
        ColourSpec::Hex([0xff, 0xaa, 0x00])
    );
}

#[test]
fn lrv_is_hundred_times_y() {
    assert!((lrv([1.0; 3]) - 100.0).abs() < 1e-12);
    assert!(lrv([0.0; 3]).abs() < 1e-15);
    // Y of a grey equals its linear value, so LRV(0.18) = 18 exactly.
    assert!((lrv([0.18; 3]) - 18.0).abs() < 1e-12);
    // L* = 50 ⇒ Y = (66/116)³ ⇒ LRV 18.42 (BS 8300 tables list mid grey N5 near 18–19).
    let r = parse_colour("lab(50, 0, 0)").unwrap().resolve();
    assert!(
        (r.lrv - 100.0 * (66.0f64 / 116.0).powi(3)).abs() < 1e-9,
        "{}",
        r.lrv
    );
    assert!(!r.out_of_gamut);
}

#[test]
fn out_of_gamut_colours_are_flagged_and_clamped() {
    let r = parse_colour("lab(50, 100, 0)").unwrap().resolve();
    assert!(r.out_of_gamut);
    assert!(r.unclamped_rgb.iter().any(|c| *c < 0.0 || *c > 1.0));
    assert!(r.linear_rgb.iter().all(|c| (0.0..=1.0).contains(c)));
    // The published sRGB red typed to two decimals is inside (within the tolerance).
    let r = parse_colour("lab(53.24, 80.09, 67.20)").unwrap().resolve();
    assert!(!r.out_of_gamut, "{:?}", r.unclamped_rgb);
    assert!(
        !parse_colour("lch(70, 20, 90)")
            .unwrap()
            .resolve()
            .out_of_gamut
    );
}

#[test]
fn unparsable_colours_name_the_text() {
    for bad in [
        "#12345",
        "#gg0000",
        "lab(1, 2)",
        "lab 1 2 3",
        "rgb(1,2,3)",
        "lab(120, 0, 0)",
        "lch(50, -3, 0)",
        "lab(x, 0, 0)",
    ] {
        let e = parse_colour(bad).unwrap_err();
        assert_eq!(e.text, bad);
        assert!(e.to_string().contains(bad), "{e}");
    }
    assert_eq!(
        parse_colour(" LAB(52.2 30.1 42.7) ").unwrap(),
        ColourSpec::Lab([52.2, 30.1, 42.7])
    );
}
