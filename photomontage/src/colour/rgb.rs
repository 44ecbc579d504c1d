//! RGB colour spaces from primaries and white point: XYZ ↔ linear RGB (Durisch 1992 Appendix A
//! eq. 13; the derivation of Hall 1989 §3.5 / SMPTE RP 177-1993), with the sRGB / Rec. 709
//! (IEC 61966-2-1:1999, ITU-R BT.709-6) and NTSC 1953 (FCC, illuminant C; Cohen & Wallace 1993
//! eq. 9.22–9.23) definitions, and the sRGB transfer function.
//!
//! The matrix `xyz_from_rgb` has as columns the primaries' tristimulus values, scaled so that
//! RGB = (1, 1, 1) gives the white point with Y = 1:
//! `xyz_from_rgb = P · diag(P⁻¹ · W)`, where the columns of `P` are `(x, y, 1 − x − y)` of the
//! primaries and `W` is the white point's XYZ with Y = 1.
//!
//! # Known limitations
//! No chromatic adaptation (Bradford, CAT16) is provided: converting between spaces with
//! different white points (sRGB D65 ↔ NTSC C) maps XYZ unchanged, so white does not stay white.
//! Linear RGB may be negative or above one for colours outside the gamut; nothing clips here.

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

/// Errors building an RGB colour space.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RgbError {
    /// A chromaticity is not finite or has y ≤ 0.
    #[error("chromaticity {name} = ({x}, {y}) is invalid (need finite x, y with y > 0)")]
    InvalidChromaticity {
        /// Which of red, green, blue, white.
        name: &'static str,
        /// Chromaticity x.
        x: f64,
        /// Chromaticity y.
        y: f64,
    },
    /// The three primaries are collinear, so they span no gamut.
    #[error("the primaries are collinear (determinant {determinant:e})")]
    DegeneratePrimaries {
        /// Determinant of the chromaticity matrix.
        determinant: f64,
    },
}

/// Chromaticities `(x, y)` of three primaries and a white point.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Primaries {
    /// Red primary.
    pub red_xy: [f64; 2],
    /// Green primary.
    pub green_xy: [f64; 2],
    /// Blue primary.
    pub blue_xy: [f64; 2],
    /// White point (RGB = 1, 1, 1).
    pub white_xy: [f64; 2],
}

impl Primaries {
    /// sRGB and Rec. 709 (IEC 61966-2-1 table 1; ITU-R BT.709-6 item 1.3), white D65
    /// (0.3127, 0.3290).
    pub const SRGB: Self = Self {
        red_xy: [0.64, 0.33],
        green_xy: [0.30, 0.60],
        blue_xy: [0.15, 0.06],
        white_xy: [0.3127, 0.3290],
    };

    /// NTSC 1953 (FCC 47 CFR 73.682; the "standard NTSC monitor" of Hall 1989 that Durisch used),
    /// white illuminant C (0.310, 0.316).
    pub const NTSC_1953: Self = Self {
        red_xy: [0.67, 0.33],
        green_xy: [0.21, 0.71],
        blue_xy: [0.14, 0.08],
        white_xy: [0.310, 0.316],
    };

    /// The chromaticity matrix `P`: columns `(x, y, 1 − x − y)` of red, green, blue
    /// (Cohen & Wallace eq. 9.22 prints it for NTSC).
    #[must_use]
    pub fn chromaticity_matrix(&self) -> Matrix3<f64> {
        let col = |c: [f64; 2]| Vector3::new(c[0], c[1], 1.0 - c[0] - c[1]);
        Matrix3::from_columns(&[col(self.red_xy), col(self.green_xy), col(self.blue_xy)])
    }
}

/// A linear RGB colour space with its conversion matrices, built once and reused per pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbColourSpace {
    primaries: Primaries,
    xyz_from_rgb: Matrix3<f64>,
    rgb_from_xyz: Matrix3<f64>,
}

impl RgbColourSpace {
    /// Builds the space and its matrices from primaries and white point.
    ///
    /// # Errors
    /// [`RgbError::InvalidChromaticity`] for a non-finite chromaticity or y ≤ 0;
    /// [`RgbError::DegeneratePrimaries`] when the primaries are collinear.
    pub fn new(primaries: Primaries) -> Result<Self, RgbError> {
        for (name, c) in [
            ("red", primaries.red_xy),
            ("green", primaries.green_xy),
            ("blue", primaries.blue_xy),
            ("white", primaries.white_xy),
        ] {
            if !(c[0].is_finite() && c[1].is_finite() && c[1] > 0.0) {
                return Err(RgbError::InvalidChromaticity {
                    name,
                    x: c[0],
                    y: c[1],
                });
            }
        }
        let p = primaries.chromaticity_matrix();
        let determinant = p.determinant();
        let p_inv = p
            .try_inverse()
            .filter(|_| determinant.abs() > 1e-9)
            .ok_or(RgbError::DegeneratePrimaries { determinant })?;
        let w = primaries.white_xy;
        let white = Vector3::new(w[0] / w[1], 1.0, (1.0 - w[0] - w[1]) / w[1]);
        let scale = p_inv * white;
        let xyz_from_rgb = p * Matrix3::from_diagonal(&scale);
        let rgb_from_xyz = xyz_from_rgb
            .try_inverse()
            .ok_or(RgbError::DegeneratePrimaries { determinant })?;
        Ok(Self {
            primaries,
            xyz_from_rgb,
            rgb_from_xyz,
        })
    }

    /// sRGB / Rec. 709 linear space.
    #[must_use]
    pub fn srgb() -> Self {
        Self::from_valid(Primaries::SRGB)
    }

    /// NTSC 1953 linear space (illuminant C).
    #[must_use]
    pub fn ntsc_1953() -> Self {
        Self::from_valid(Primaries::NTSC_1953)
    }

    /// Builds one of the built-in spaces, whose primaries are known to be valid.
    fn from_valid(primaries: Primaries) -> Self {
        match Self::new(primaries) {
            Ok(space) => space,
            // The built-in primaries are valid constants; this arm is unreachable.
            Err(_) => Self {
                primaries,
                xyz_from_rgb: Matrix3::identity(),
                rgb_from_xyz: Matrix3::identity(),
            },
        }
    }

    /// The primaries and white point.
    #[must_use]
    pub fn primaries(&self) -> Primaries {
        self.primaries
    }

    /// Matrix `M⁻¹` of Durisch eq. 13: XYZ = `xyz_from_rgb` · RGB.
    #[must_use]
    pub fn xyz_from_rgb(&self) -> Matrix3<f64> {
        self.xyz_from_rgb
    }

    /// Matrix `M` of Durisch eq. 13: RGB = `rgb_from_xyz` · XYZ.
    #[must_use]
    pub fn rgb_from_xyz(&self) -> Matrix3<f64> {
        self.rgb_from_xyz
    }

    /// Linear RGB → XYZ.
    #[must_use]
    pub fn to_xyz(&self, rgb: [f64; 3]) -> [f64; 3] {
        (self.xyz_from_rgb * Vector3::from(rgb)).into()
    }

    /// XYZ → linear RGB (may leave [0, 1] for colours outside the gamut).
    #[must_use]
    pub fn from_xyz(&self, xyz: [f64; 3]) -> [f64; 3] {
        (self.rgb_from_xyz * Vector3::from(xyz)).into()
    }

    /// Relative luminance Y of a linear RGB colour (the middle row of `xyz_from_rgb`).
    #[must_use]
    pub fn luminance(&self, rgb: [f64; 3]) -> f64 {
        let r = self.xyz_from_rgb.row(1);
        r[0] * rgb[0] + r[1] * rgb[1] + r[2] * rgb[2]
    }
}

/// sRGB encoding (IEC 61966-2-1 eq. 8): linear `[0, 1]` → non-linear `[0, 1]`.
/// `12.92·L` below 0.003 130 8, else `1.055·L^(1/2.4) − 0.055`. Values outside [0, 1] are
/// extended symmetrically (negative stays negative, no clipping); NaN stays NaN.
#[must_use]
pub fn srgb_encode(linear: f64) -> f64 {
    let a = linear.abs();
    let v = if a <= 0.003_130_8 {
        12.92 * a
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    v.copysign(linear)
}

/// sRGB decoding (IEC 61966-2-1 eq. 5): non-linear → linear, inverse of [`srgb_encode`].
/// `V/12.92` below 0.040 45, else `((V + 0.055)/1.055)^2.4`.
#[must_use]
pub fn srgb_decode(encoded: f64) -> f64 {
    let a = encoded.abs();
    let v = if a <= 0.040_45 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    v.copysign(encoded)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::cie1931;

    /// IEC 61966-2-1 prints the matrices to four decimals: half a unit of the last place plus
    /// the derivation from the exact primaries (the standard's own numbers were derived the same
    /// way and rounded).
    const PUBLISHED_4DP_TOL: f64 = 1e-4;
    /// The standard's inverse matrix was computed from its *rounded* forward matrix, so it
    /// differs from the exact inverse by up to ~4e-4 (3.2406 vs 3.24097): compare the exact one
    /// to it at 5e-4 and the inverse of the published forward matrix to it at 1e-4.
    const PUBLISHED_INVERSE_TOL: f64 = 5e-4;
    /// Cohen & Wallace print eq. 9.22–9.23 to two and three decimals.
    const COHEN_WALLACE_TOL: f64 = 1e-3;
    /// NTSC luma coefficients 0.299 / 0.587 / 0.114 are the Y row (0.2989, 0.5866, 0.1146)
    /// rounded to three decimals and made to sum to one (0.1146 became 0.114): 1e-3.
    const LUMA_TOL: f64 = 1e-3;
    /// Pure floating point round-off for a handful of operations.
    const ROUNDOFF_TOL: f64 = 1e-12;

    #[rustfmt::skip]
    const SRGB_XYZ_FROM_RGB_PUBLISHED: [[f64; 3]; 3] = [
        [0.4124, 0.3576, 0.1805],
        [0.2126, 0.7152, 0.0722],
        [0.0193, 0.1192, 0.9505],
    ];
    #[rustfmt::skip]
    const SRGB_RGB_FROM_XYZ_PUBLISHED: [[f64; 3]; 3] = [
        [ 3.2406, -1.5372, -0.4986],
        [-0.9689,  1.8758,  0.0415],
        [ 0.0557, -0.2040,  1.0570],
    ];

    fn assert_close(m: &Matrix3<f64>, published: &[[f64; 3]; 3], tol: f64) {
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (m[(r, c)] - published[r][c]).abs() < tol,
                    "({r},{c}): {} vs {}",
                    m[(r, c)],
                    published[r][c]
                );
            }
        }
    }

    #[test]
    fn srgb_matrices_match_iec_61966_2_1() {
        let s = RgbColourSpace::srgb();
        assert_close(
            &s.xyz_from_rgb(),
            &SRGB_XYZ_FROM_RGB_PUBLISHED,
            PUBLISHED_4DP_TOL,
        );
        assert_close(
            &s.rgb_from_xyz(),
            &SRGB_RGB_FROM_XYZ_PUBLISHED,
            PUBLISHED_INVERSE_TOL,
        );
        let published = Matrix3::from_fn(|r, c| SRGB_XYZ_FROM_RGB_PUBLISHED[r][c]);
        let inv = published.try_inverse().unwrap();
        assert_close(&inv, &SRGB_RGB_FROM_XYZ_PUBLISHED, PUBLISHED_4DP_TOL);
    }

    #[test]
    fn srgb_white_is_d65_of_the_cie_tables() {
        // RGB (1,1,1) must land on D65 as computed from the CIE tables (4-decimal white point).
        let s = RgbColourSpace::srgb();
        let xy = cie1931::chromaticity(s.to_xyz([1.0, 1.0, 1.0])).unwrap();
        let table = cie1931::chromaticity(cie1931::d65_white_xyz()).unwrap();
        assert!((xy[0] - table[0]).abs() < PUBLISHED_4DP_TOL);
        assert!((xy[1] - table[1]).abs() < PUBLISHED_4DP_TOL);
        assert!((s.luminance([1.0, 1.0, 1.0]) - 1.0).abs() < ROUNDOFF_TOL);
    }

    #[test]
    fn ntsc_matches_cohen_wallace_and_luma() {
        let p = Primaries::NTSC_1953.chromaticity_matrix();
        #[rustfmt::skip]
        let eq_9_22 = [[0.67, 0.21, 0.14], [0.33, 0.71, 0.08], [0.00, 0.08, 0.78]];
        assert_close(&p, &eq_9_22, COHEN_WALLACE_TOL);
        #[rustfmt::skip]
        let eq_9_23 = [
            [ 1.730, -0.482, -0.261],
            [-0.814,  1.652, -0.023],
            [ 0.083, -0.169,  1.284],
        ];
        assert_close(&p.try_inverse().unwrap(), &eq_9_23, COHEN_WALLACE_TOL);
        let ntsc = RgbColourSpace::ntsc_1953();
        let y = ntsc.xyz_from_rgb().row(1).into_owned();
        for (got, want) in y.iter().zip([0.299, 0.587, 0.114]) {
            assert!((got - want).abs() < LUMA_TOL, "{got} vs {want}");
        }
    }

    #[test]
    fn rec709_luma_row() {
        // ITU-R BT.709 item 3.2 luminance equation: Y = 0.2126 R + 0.7152 G + 0.0722 B.
        let y = RgbColourSpace::srgb().xyz_from_rgb().row(1).into_owned();
        for (got, want) in y.iter().zip([0.2126, 0.7152, 0.0722]) {
            assert!((got - want).abs() < PUBLISHED_4DP_TOL);
        }
    }

    #[test]
    fn degenerate_and_invalid_primaries_are_errors() {
        let mut p = Primaries::SRGB;
        p.blue_xy = [0.47, 0.465]; // on the line red–green
        assert!(matches!(
            RgbColourSpace::new(p),
            Err(RgbError::DegeneratePrimaries { .. })
        ));
        let mut q = Primaries::SRGB;
        q.white_xy = [0.3, 0.0];
        assert!(matches!(
            RgbColourSpace::new(q),
            Err(RgbError::InvalidChromaticity { name: "white", .. })
        ));
    }

    #[test]
    fn srgb_transfer_known_values_and_round_trip() {
        // Breakpoints of IEC 61966-2-1: 0.0031308 ↔ 0.04045 (continuous to ~1e-7).
        assert!((srgb_encode(0.003_130_8) - 0.040_45).abs() < 1e-6);
        assert!((srgb_encode(1.0) - 1.0).abs() < ROUNDOFF_TOL);
        assert!((srgb_decode(1.0) - 1.0).abs() < ROUNDOFF_TOL);
        // 18 % grey encodes to 0.4613 (117.6/255), a common check value.
        assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-6);
        for k in 0..=1000 {
            let v = f64::from(k) / 1000.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < ROUNDOFF_TOL);
        }
        assert!(srgb_encode(-0.5) < 0.0);
    }
}
