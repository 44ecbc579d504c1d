//! The RAL Design System's colour codes, read as the CIELCh coordinates they are defined by.
//!
//! A RAL Design code `RAL HHH LL CC` names a hue angle h (degrees, red at 0°/360°, yellow 90°,
//! green 180°, blue 270°), a CIE 1976 lightness L\* and a chroma C\*ab. The system (RAL gGmbH,
//! 1993, conceived by L. Gall) was laid out on the CIELAB space for illuminant D65 and the CIE
//! 1964 10° observer, with colour distances by the CIELAB formula of DIN 6174; `000` is kept for
//! the grey series `RAL 000 LL 00`. Because the code is the colour's coordinate, no swatch
//! table is needed: any code, including ones between the fan's chips, converts by formula.
//!
//! Conversion: L\*C\*h → L\*a\*b\* (CIE 15:2004 §8.2.2) → XYZ₁₀ relative to the D65 white of the
//! 10° observer, X₁₀ = 94.811, Y₁₀ = 100, Z₁₀ = 107.304 (ASTM E308, Table 5; CIE 15:2004's
//! tables) → the Bradford chromatic adaptation (Lam 1985; Lindbloom, "Chromatic Adaptation")
//! from that white to the sRGB white of the 2° observer → linear sRGB (IEC 61966-2-1).
//!
//! # Known limitations
//! The 10° and 2° observers' tristimulus values are not related by any 3×3 matrix; the
//! adaptation maps the 10° white to the 2° white exactly (so every grey `RAL 000 LL 00` becomes
//! the grey of lightness LL) and chromatic colours approximately. The chips of today's fans
//! deviate from their nominal coordinates after RAL's revisions of the system (reported up to
//! about 2 L\* units for the darkest greys); the nominal coordinates are what is converted here.
//! RAL Classic's four-digit codes are a collection without a formula and are not read.

use nalgebra::{Matrix3, Vector3};

use super::cielab::{
    GAMUT_TOLERANCE, d65_white_xyz, lab_from_lch, lab_from_xyz_under, lch_from_lab,
    xyz_from_lab_under,
};
use super::rgb::RgbColourSpace;

/// XYZ of illuminant D65 for the CIE 1964 10° observer, Y = 1 (ASTM E308, Table 5).
pub const D65_10DEG_WHITE_XYZ: [f64; 3] = [0.948_11, 1.0, 1.073_04];

/// Below this C\* (after rounding) a colour's code is a grey, `RAL 000 LL 00`.
const GREY_CHROMA: f64 = 0.5;

/// The hue pages of the fan, degrees: the greys (0), then every 10° from 10 to 360 with 75, 85
/// and 95 between (the yellows, where a hue step shows most).
pub const HUE_PAGES_DEG: [u16; 40] = [
    0, 10, 20, 30, 40, 50, 60, 70, 75, 80, 85, 90, 95, 100, 110, 120, 130, 140, 150, 160, 170, 180,
    190, 200, 210, 220, 230, 240, 250, 260, 270, 280, 290, 300, 310, 320, 330, 340, 350, 360,
];
/// The lightness rows of a chromatic page of [`RalDesign::page`].
pub const PAGE_LIGHTNESS: [u8; 8] = [20, 30, 40, 50, 60, 70, 80, 90];
/// The lightness rows of the grey page.
pub const GREY_PAGE_LIGHTNESS: [u8; 15] =
    [20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 75, 80, 85, 90];
/// The chroma columns of a chromatic page of [`RalDesign::page`].
pub const PAGE_CHROMA: [u8; 12] = [5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80, 90];

/// A RAL Design System code: hue angle, lightness and chroma as whole numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RalDesign {
    /// Hue angle h in degrees, 0 (the grey series) to 360.
    pub hue_deg: u16,
    /// Lightness L\*, 0–99.
    pub lightness: u8,
    /// Chroma C\*ab, 0–99.
    pub chroma: u8,
}

impl std::fmt::Display for RalDesign {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "RAL {:03} {:02} {:02}",
            self.hue_deg, self.lightness, self.chroma
        )
    }
}

impl RalDesign {
    /// Reads the part of a code after `RAL`: `210 50 15`, `210-50-15` or the seven digits
    /// `2105015`. Returns why not otherwise (a four-digit RAL Classic code is named as such).
    ///
    /// # Errors
    /// The reason, for the colour parser's error.
    pub fn parse(code: &str) -> Result<Self, String> {
        let groups: Vec<&str> = code
            .split(|c: char| c.is_whitespace() || c == '-')
            .filter(|s| !s.is_empty())
            .collect();
        if groups
            .iter()
            .any(|g| !g.chars().all(|c| c.is_ascii_digit()))
        {
            return Err(
                "a RAL Design code is `RAL HHH LL CC`: hue, lightness and chroma in digits".into(),
            );
        }
        let digits: String = groups.concat();
        let (h, l, c) = match groups.len() {
            3 => (groups[0], groups[1], groups[2]),
            1 if digits.len() == 7 => (&digits[..3], &digits[3..5], &digits[5..]),
            1 if digits.len() == 4 => {
                return Err(format!(
                    "RAL {digits} is a RAL Classic code; RAL Classic's colour data are not \
                     published under a licence that lets us ship them: enter the L*a*b* values \
                     your fan deck lists for it, or a RAL Design code `RAL HHH LL CC`"
                ));
            }
            _ => {
                return Err("a RAL Design code is `RAL HHH LL CC` (hue, lightness, chroma)".into());
            }
        };
        if h.len() > 3 || l.len() > 2 || c.len() > 2 {
            return Err(
                "a RAL Design code has at most 3 hue, 2 lightness and 2 chroma digits".into(),
            );
        }
        let number = |s: &str| s.parse::<u16>().unwrap_or(u16::MAX);
        let (hue_deg, lightness, chroma) = (number(h), number(l), number(c));
        if hue_deg > 360 {
            return Err(format!("hue {hue_deg} is above 360°"));
        }
        if hue_deg == 0 && chroma != 0 {
            return Err(
                "hue 000 is the grey series `RAL 000 LL 00`; a chromatic red is hue 360".into(),
            );
        }
        // Both were read from at most two digits.
        #[allow(clippy::cast_possible_truncation)]
        Ok(Self {
            hue_deg,
            lightness: lightness as u8,
            chroma: chroma as u8,
        })
    }

    /// The nominal CIELCh (D65, 10° observer) coordinates: [L\*, C\*, h°].
    #[must_use]
    pub fn lch(&self) -> [f64; 3] {
        [
            f64::from(self.lightness),
            f64::from(self.chroma),
            f64::from(self.hue_deg),
        ]
    }

    /// CIE XYZ for the 2° observer (the sRGB white at Y = 1) of the code's nominal colour.
    #[must_use]
    pub fn xyz(&self) -> [f64; 3] {
        let xyz10 = xyz_from_lab_under(lab_from_lch(self.lch()), D65_10DEG_WHITE_XYZ);
        let m = bradford(D65_10DEG_WHITE_XYZ, d65_white_xyz());
        (m * Vector3::from(xyz10)).into()
    }

    /// The code nearest to a colour given as CIE XYZ (2° observer, sRGB white at Y = 1): its
    /// coordinates in the system's space rounded to whole numbers. `None` when L\* or C\* would
    /// need three digits.
    #[must_use]
    pub fn nearest(xyz: [f64; 3]) -> Option<Self> {
        let m = bradford(d65_white_xyz(), D65_10DEG_WHITE_XYZ);
        let xyz10: [f64; 3] = (m * Vector3::from(xyz)).into();
        let [l, c, h] = lch_from_lab(lab_from_xyz_under(xyz10, D65_10DEG_WHITE_XYZ));
        let (l, c, h) = (l.round(), c.round(), h.round());
        if !(0.0..=99.0).contains(&l) || c > 99.0 {
            return None;
        }
        let grey = c < GREY_CHROMA;
        let hue = if grey {
            0.0
        } else if h == 0.0 {
            360.0
        } else {
            h
        };
        // All three are whole numbers in range (checked above; h in [0, 360]).
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        Some(Self {
            hue_deg: hue as u16,
            lightness: l as u8,
            chroma: if grey { 0 } else { c as u8 },
        })
    }
}

impl RalDesign {
    /// The codes of one hue page of the nominal grid that lie inside the sRGB gamut (within
    /// [`GAMUT_TOLERANCE`]), lightest row first, each row by chroma: on a
    /// chromatic page the rows [`PAGE_LIGHTNESS`] and columns [`PAGE_CHROMA`], on the grey page
    /// (hue 0) the greys of [`GREY_PAGE_LIGHTNESS`]. The grid is the system's coordinates; a
    /// physical fan holds a subset of them (about 1 625 chips). Empty for a hue above 360.
    #[must_use]
    pub fn page(hue_deg: u16) -> Vec<Self> {
        if hue_deg > 360 {
            return Vec::new();
        }
        let codes: Vec<Self> = if hue_deg == 0 {
            GREY_PAGE_LIGHTNESS
                .iter()
                .rev()
                .map(|&lightness| Self {
                    hue_deg,
                    lightness,
                    chroma: 0,
                })
                .collect()
        } else {
            PAGE_LIGHTNESS
                .iter()
                .rev()
                .flat_map(|&lightness| {
                    PAGE_CHROMA.iter().map(move |&chroma| Self {
                        hue_deg,
                        lightness,
                        chroma,
                    })
                })
                .collect()
        };
        codes
            .into_iter()
            .filter(|code| {
                RgbColourSpace::srgb()
                    .from_xyz(code.xyz())
                    .iter()
                    .all(|c| (-GAMUT_TOLERANCE..=1.0 + GAMUT_TOLERANCE).contains(c))
            })
            .collect()
    }
}

/// The Bradford cone-response matrix (Lam 1985, as Lindbloom gives it).
fn bradford_cone_response() -> Matrix3<f64> {
    Matrix3::new(
        0.8951, 0.2664, -0.1614, //
        -0.7502, 1.7135, 0.0367, //
        0.0389, -0.0685, 1.0296,
    )
}

/// The Bradford adaptation from white `from` to white `to` (XYZ): M⁻¹ · diag(ρ_to/ρ_from) · M.
#[must_use]
pub fn bradford(from: [f64; 3], to: [f64; 3]) -> Matrix3<f64> {
    let m = bradford_cone_response();
    let m_inv = m.try_inverse().expect("the Bradford matrix is invertible");
    let source = m * Vector3::from(from);
    let destination = m * Vector3::from(to);
    let scale = Matrix3::from_diagonal(&destination.component_div(&source));
    m_inv * scale * m
}

#[cfg(test)]
#[path = "ral_design_tests.rs"]
mod tests;
