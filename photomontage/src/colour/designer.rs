//! Colours as designers specify them: sRGB hex (`#a0522d`), CIE 1976 L\*a\*b\* and its polar form
//! L\*C\*h (both relative to D65, the sRGB white), converted through CIE XYZ to the renderer's
//! linear sRGB reflectance, and the light reflectance value (LRV).
//!
//! Formulas: CIE 15:2004 §8.2.1 (L\*a\*b\*, with the CIE's exact constants ε = 216/24389 and
//! κ = 24389/27 as given by Lindbloom, "CIE Lab to XYZ" / "XYZ to Lab"), §8.2.2 (C\*ab, hab);
//! IEC 61966-2-1 for the sRGB transfer curve and primaries ([`super::rgb`]). The white point of
//! L\*a\*b\* is the sRGB white (x, y) = (0.3127, 0.3290) at Y = 1, so sRGB white is exactly
//! (100, 0, 0). LRV = 100·Y of the reflectance under that white (BS 8300-2:2018 defines LRV as
//! the CIE Y of the surface, 0 for perfect black to 100 for a perfect white).
//!
//! One colour-order system is read: the RAL Design System's codes (`RAL 210 50 15`), which are
//! CIELCh coordinates by definition ([`super::ral_design`]).
//!
//! # Known limitations
//! No colour system defined only by its swatches (RAL Classic, NCS, Munsell) is built in: no
//! swatch table we found may be shipped under a licence that allows it (docs/methodology.md,
//! "Colour systems").

pub use super::cielab::{
    GAMUT_TOLERANCE, d65_white_xyz, lab_from_lch, lab_from_xyz, lab_from_xyz_under, lch_from_lab,
    xyz_from_lab, xyz_from_lab_under,
};
use super::ral_design::RalDesign;
use super::rgb::{RgbColourSpace, srgb_decode, srgb_encode};

/// Why a colour text could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("colour `{text}`: {reason}")]
pub struct ColourSpecError {
    /// The text as given.
    pub text: String,
    /// What is wrong with it.
    pub reason: String,
}

/// A colour as a designer typed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ColourSpec {
    /// sRGB, 8 bits per channel (`#rrggbb` or `#rgb`).
    Hex([u8; 3]),
    /// CIE L\*a\*b\* (D65).
    Lab([f64; 3]),
    /// CIE L\*C\*h (D65), hue in degrees.
    Lch([f64; 3]),
    /// A RAL Design System code (hue, lightness, chroma in CIELCh, D65/10°).
    RalDesign(RalDesign),
}

impl std::fmt::Display for ColourSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Hex([r, g, b]) => write!(f, "#{r:02x}{g:02x}{b:02x}"),
            Self::Lab([l, a, b]) => write!(f, "lab({l:.2}, {a:.2}, {b:.2})"),
            Self::Lch([l, c, h]) => write!(f, "lch({l:.2}, {c:.2}, {h:.2})"),
            Self::RalDesign(code) => write!(f, "{code}"),
        }
    }
}

impl std::str::FromStr for ColourSpec {
    type Err = ColourSpecError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        parse_colour(text)
    }
}

/// Reads `#rrggbb`, `#rgb`, `lab(L, a, b)`, `lch(L, C, h)` (case-insensitive, commas or
/// spaces between the numbers) or a RAL Design code `RAL HHH LL CC` ([`RalDesign::parse`]).
///
/// # Errors
/// [`ColourSpecError`] naming the text and the problem.
pub fn parse_colour(text: &str) -> Result<ColourSpec, ColourSpecError> {
    let err = |reason: &str| ColourSpecError {
        text: text.to_owned(),
        reason: reason.to_owned(),
    };
    let t = text.trim().to_ascii_lowercase();
    if let Some(hex) = t.strip_prefix('#') {
        if !hex.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(err(
                "a hex colour has only the digits 0-9 and a-f after `#`",
            ));
        }
        let digit = |i: usize, n: usize| u8::from_str_radix(&hex[i..i + n], 16).unwrap_or(0);
        return match hex.len() {
            6 => Ok(ColourSpec::Hex([digit(0, 2), digit(2, 2), digit(4, 2)])),
            3 => Ok(ColourSpec::Hex([
                digit(0, 1) * 17,
                digit(1, 1) * 17,
                digit(2, 1) * 17,
            ])),
            _ => Err(err("a hex colour needs 3 or 6 digits after `#`")),
        };
    }
    if let Some(code) = t.strip_prefix("ral") {
        return RalDesign::parse(code)
            .map(ColourSpec::RalDesign)
            .map_err(|reason| err(&reason));
    }
    let (kind, rest) = if let Some(r) = t.strip_prefix("lab") {
        ("lab", r)
    } else if let Some(r) = t.strip_prefix("lch") {
        ("lch", r)
    } else {
        return Err(err(
            "expected `#rrggbb`, `lab(L, a, b)` or `lch(L, C, h)` (D65), or `RAL HHH LL CC`",
        ));
    };
    let inner = rest
        .trim()
        .strip_prefix('(')
        .and_then(|r| r.strip_suffix(')'))
        .ok_or_else(|| err("the numbers go in parentheses, e.g. lab(52.2, 30.1, 42.7)"))?;
    let numbers: Vec<f64> = inner
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(str::parse::<f64>)
        .collect::<Result<_, _>>()
        .map_err(|_| err("the three values must be numbers"))?;
    let [a, b, c] = numbers[..] else {
        return Err(err("exactly three numbers are needed"));
    };
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return Err(err("the values must be finite"));
    }
    if !(0.0..=100.0).contains(&a) {
        return Err(err("L* must be in [0, 100]"));
    }
    if kind == "lab" {
        Ok(ColourSpec::Lab([a, b, c]))
    } else if b < 0.0 {
        Err(err("chroma C* must not be negative"))
    } else {
        Ok(ColourSpec::Lch([a, b, c]))
    }
}

/// Linear sRGB → L\*a\*b\* (D65).
#[must_use]
pub fn lab_from_linear_srgb(rgb: [f64; 3]) -> [f64; 3] {
    lab_from_xyz(RgbColourSpace::srgb().to_xyz(rgb))
}

/// L\*a\*b\* (D65) → linear sRGB (unclamped: may leave [0, 1] outside the gamut).
#[must_use]
pub fn linear_srgb_from_lab(lab: [f64; 3]) -> [f64; 3] {
    RgbColourSpace::srgb().from_xyz(xyz_from_lab(lab))
}

/// 8-bit sRGB → linear sRGB.
#[must_use]
pub fn linear_from_srgb8(rgb8: [u8; 3]) -> [f64; 3] {
    rgb8.map(|c| srgb_decode(f64::from(c) / 255.0))
}

/// Linear sRGB (clamped to [0, 1]) → 8-bit sRGB, rounded to nearest.
#[must_use]
pub fn srgb8_from_linear(rgb: [f64; 3]) -> [u8; 3] {
    // The value is clamped to [0, 255] before the cast.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    rgb.map(|c| {
        (srgb_encode(c.clamp(0.0, 1.0)) * 255.0)
            .round()
            .clamp(0.0, 255.0) as u8
    })
}

/// `#rrggbb` of a linear sRGB colour (clamped).
#[must_use]
pub fn hex_from_linear(rgb: [f64; 3]) -> String {
    ColourSpec::Hex(srgb8_from_linear(rgb)).to_string()
}

/// Light reflectance value: 100 · Y of a linear sRGB reflectance (Y of the white = 1).
#[must_use]
pub fn lrv(linear_rgb: [f64; 3]) -> f64 {
    100.0 * RgbColourSpace::srgb().luminance(linear_rgb)
}

/// A colour resolved to the renderer's diffuse reflectance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolvedColour {
    /// Linear sRGB reflectance, clamped to [0, 1].
    pub linear_rgb: [f64; 3],
    /// Linear sRGB before clamping.
    pub unclamped_rgb: [f64; 3],
    /// True when a channel left [0, 1] by more than [`GAMUT_TOLERANCE`].
    pub out_of_gamut: bool,
    /// LRV of the clamped colour.
    pub lrv: f64,
}

impl ColourSpec {
    /// Linear sRGB, unclamped.
    #[must_use]
    pub fn linear_srgb(&self) -> [f64; 3] {
        match *self {
            Self::Hex(rgb8) => linear_from_srgb8(rgb8),
            Self::Lab(lab) => linear_srgb_from_lab(lab),
            Self::Lch(lch) => linear_srgb_from_lab(lab_from_lch(lch)),
            Self::RalDesign(code) => RgbColourSpace::srgb().from_xyz(code.xyz()),
        }
    }

    /// L\*a\*b\* (D65) of the colour.
    #[must_use]
    pub fn lab(&self) -> [f64; 3] {
        match *self {
            Self::Hex(rgb8) => lab_from_linear_srgb(linear_from_srgb8(rgb8)),
            Self::Lab(lab) => lab,
            Self::Lch(lch) => lab_from_lch(lch),
            Self::RalDesign(code) => lab_from_xyz(code.xyz()),
        }
    }

    /// The reflectance the renderer uses: clamped into the sRGB gamut, with a flag when it was
    /// outside.
    #[must_use]
    pub fn resolve(&self) -> ResolvedColour {
        resolve_linear(self.linear_srgb())
    }
}

/// Clamps a linear sRGB reflectance into [0, 1], flagging excursions beyond [`GAMUT_TOLERANCE`].
#[must_use]
pub fn resolve_linear(unclamped_rgb: [f64; 3]) -> ResolvedColour {
    let linear_rgb = unclamped_rgb.map(|c| c.clamp(0.0, 1.0));
    let out_of_gamut = unclamped_rgb
        .iter()
        .any(|c| !(-GAMUT_TOLERANCE..=1.0 + GAMUT_TOLERANCE).contains(c));
    ResolvedColour {
        linear_rgb,
        unclamped_rgb,
        out_of_gamut,
        lrv: lrv(linear_rgb),
    }
}

#[cfg(test)]
#[path = "designer_tests.rs"]
mod tests;
