//! CIE 1976 L\*a\*b\* and its polar form L\*C\*h: the conversions from and to CIE XYZ relative to
//! a white (the sRGB white, or another such as the 10° observer's D65 of the RAL Design
//! System), shared by the designer's colours (`designer`) and the colour systems
//! (`ral_design`).
//!
//! Formulas: CIE 15:2004 §8.2.1 (L\*a\*b\*, with the CIE's exact constants ε = 216/24389 and
//! κ = 24389/27 as given by Lindbloom, "CIE Lab to XYZ" / "XYZ to Lab"), §8.2.2 (C\*ab, hab).

use super::rgb::RgbColourSpace;

/// A linear channel outside [0, 1] by more than this counts as out of gamut (and is reported);
/// smaller excursions come from rounding of typed L\*a\*b\* values and are clamped silently.
pub const GAMUT_TOLERANCE: f64 = 1e-4;

/// CIE ε = (6/29)³ = 216/24389: below it L\*a\*b\*'s cube root is replaced by a line.
const CIE_EPSILON: f64 = 216.0 / 24389.0;
/// CIE κ = (29/3)³ = 24389/27.
const CIE_KAPPA: f64 = 24389.0 / 27.0;

/// XYZ of the L\*a\*b\* white: the sRGB white point at Y = 1.
#[must_use]
pub fn d65_white_xyz() -> [f64; 3] {
    RgbColourSpace::srgb().to_xyz([1.0; 3])
}

/// CIE XYZ (white Y = 1) → L\*a\*b\* (D65).
#[must_use]
pub fn lab_from_xyz(xyz: [f64; 3]) -> [f64; 3] {
    lab_from_xyz_under(xyz, d65_white_xyz())
}

/// CIE XYZ → L\*a\*b\* relative to the white `w` (CIE 15:2004 §8.2.1).
#[must_use]
pub fn lab_from_xyz_under(xyz: [f64; 3], w: [f64; 3]) -> [f64; 3] {
    let f = |t: f64| {
        if t > CIE_EPSILON {
            t.cbrt()
        } else {
            (CIE_KAPPA * t + 16.0) / 116.0
        }
    };
    let [fx, fy, fz] = [f(xyz[0] / w[0]), f(xyz[1] / w[1]), f(xyz[2] / w[2])];
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// L\*a\*b\* (D65) → CIE XYZ (white Y = 1).
#[must_use]
pub fn xyz_from_lab(lab: [f64; 3]) -> [f64; 3] {
    xyz_from_lab_under(lab, d65_white_xyz())
}

/// L\*a\*b\* relative to the white `w` → CIE XYZ (on the scale of `w`).
#[must_use]
pub fn xyz_from_lab_under(lab: [f64; 3], w: [f64; 3]) -> [f64; 3] {
    let fy = (lab[0] + 16.0) / 116.0;
    let fx = fy + lab[1] / 500.0;
    let fz = fy - lab[2] / 200.0;
    let inv = |f: f64| {
        let f3 = f * f * f;
        if f3 > CIE_EPSILON {
            f3
        } else {
            (116.0 * f - 16.0) / CIE_KAPPA
        }
    };
    let y = if lab[0] > CIE_KAPPA * CIE_EPSILON {
        fy * fy * fy
    } else {
        lab[0] / CIE_KAPPA
    };
    [inv(fx) * w[0], y * w[1], inv(fz) * w[2]]
}

/// L\*a\*b\* → L\*C\*h (hue in degrees, [0, 360)).
#[must_use]
pub fn lch_from_lab(lab: [f64; 3]) -> [f64; 3] {
    let c = lab[1].hypot(lab[2]);
    let h = lab[2].atan2(lab[1]).to_degrees().rem_euclid(360.0);
    [lab[0], c, h]
}

/// L\*C\*h (hue in degrees) → L\*a\*b\*.
#[must_use]
pub fn lab_from_lch(lch: [f64; 3]) -> [f64; 3] {
    let h = lch[2].to_radians();
    [lch[0], lch[1] * h.cos(), lch[1] * h.sin()]
}
