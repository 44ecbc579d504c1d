//! The 15 CIE standard general skies: CIE S 011/E:2003 (= ISO 15469:2004), relative luminance
//! distribution by gradation and indicatrix functions.
//!
//! ```text
//! L(Z, χ)/L_z = φ(Z)·f(χ) / (φ(0)·f(Z_s))
//! φ(Z) = 1 + a·exp(b / cos Z)            (φ = 1 at the horizon)
//! f(χ) = 1 + c·[exp(d·χ) − exp(d·π/2)] + e·cos²χ
//! ```
//! Z is the zenith angle of the sky element, Z_s that of the sun and χ the angle between them.
//! The parameter table (six gradation groups I–VI, six indicatrix groups 1–6) is the standard's;
//! two public copies (rcaiman `15_CIE_standard_skies.csv`, DigitalRune `CieSkyParameters.cs`)
//! agree exactly (see `reference/lighting.md` §1.1).
//!
//! # Known limitations
//! Relative distribution only: absolute zenith luminance comes from a normalisation
//! ([`super::NormalisedSky`]). The standard defines the sky above the horizon; below it the
//! luminance is 0 here (the ground is a separate model).

use super::SkyError;
use std::f64::consts::FRAC_PI_2;

/// Gradation (a, b) and indicatrix (c, d, e) parameters of one CIE standard sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CieSkyParameters {
    /// Gradation a.
    pub a: f64,
    /// Gradation b.
    pub b: f64,
    /// Indicatrix c.
    pub c: f64,
    /// Indicatrix d.
    pub d: f64,
    /// Indicatrix e.
    pub e: f64,
}

/// CIE S 011 table: types 1…15 in order.
const CIE_TABLE: [CieSkyParameters; 15] = [
    p(4.0, -0.70, 0.0, -1.0, 0.00),
    p(4.0, -0.70, 2.0, -1.5, 0.15),
    p(1.1, -0.80, 0.0, -1.0, 0.00),
    p(1.1, -0.80, 2.0, -1.5, 0.15),
    p(0.0, -1.00, 0.0, -1.0, 0.00),
    p(0.0, -1.00, 2.0, -1.5, 0.15),
    p(0.0, -1.00, 5.0, -2.5, 0.30),
    p(0.0, -1.00, 10.0, -3.0, 0.45),
    p(-1.0, -0.55, 2.0, -1.5, 0.15),
    p(-1.0, -0.55, 5.0, -2.5, 0.30),
    p(-1.0, -0.55, 10.0, -3.0, 0.45),
    p(-1.0, -0.32, 10.0, -3.0, 0.45),
    p(-1.0, -0.32, 16.0, -3.0, 0.30),
    p(-1.0, -0.15, 16.0, -3.0, 0.30),
    p(-1.0, -0.15, 24.0, -2.8, 0.15),
];

const fn p(a: f64, b: f64, c: f64, d: f64, e: f64) -> CieSkyParameters {
    CieSkyParameters { a, b, c, d, e }
}

/// A validated CIE standard sky type, 1…15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct CieSkyType(u8);

impl CieSkyType {
    /// The sky type `number` (1…15).
    ///
    /// # Errors
    /// [`SkyError::CieTypeOutOfRange`] outside 1…15.
    pub fn new(number: u8) -> Result<Self, SkyError> {
        if (1..=15).contains(&number) {
            Ok(Self(number))
        } else {
            Err(SkyError::CieTypeOutOfRange { number })
        }
    }

    /// The type number 1…15.
    #[must_use]
    pub fn number(self) -> u8 {
        self.0
    }

    /// Gradation and indicatrix parameters from the standard's table.
    #[must_use]
    pub fn parameters(self) -> CieSkyParameters {
        CIE_TABLE[usize::from(self.0 - 1)]
    }

    /// All 15 types in order.
    pub fn all() -> impl Iterator<Item = Self> {
        (1..=15).map(Self)
    }
}

impl TryFrom<u8> for CieSkyType {
    type Error = SkyError;
    fn try_from(number: u8) -> Result<Self, SkyError> {
        Self::new(number)
    }
}

impl From<CieSkyType> for u8 {
    fn from(t: CieSkyType) -> u8 {
        t.0
    }
}

impl CieSkyParameters {
    /// Gradation φ(Z) from cos Z (φ = 1 at and below the horizon).
    #[must_use]
    pub fn gradation(&self, cos_zenith: f64) -> f64 {
        if cos_zenith <= 0.0 {
            1.0
        } else {
            1.0 + self.a * (self.b / cos_zenith).exp()
        }
    }

    /// Scattering indicatrix f(χ) for the angle χ (radians) between element and sun.
    #[must_use]
    pub fn indicatrix(&self, chi: f64) -> f64 {
        let cos_chi = chi.cos();
        1.0 + self.c * ((self.d * chi).exp() - (self.d * FRAC_PI_2).exp())
            + self.e * cos_chi * cos_chi
    }

    /// L/L_z for an element at cos Z = `cos_zenith`, angle `chi` from a sun at zenith angle
    /// `sun_zenith` (radians). 0 below the horizon.
    #[must_use]
    pub fn relative_luminance(&self, cos_zenith: f64, chi: f64, sun_zenith: f64) -> f64 {
        if cos_zenith <= 0.0 {
            return 0.0;
        }
        self.gradation(cos_zenith) * self.indicatrix(chi)
            / (self.gradation(1.0) * self.indicatrix(sun_zenith))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_groups_and_range() {
        assert!(CieSkyType::new(0).is_err());
        assert!(CieSkyType::new(16).is_err());
        assert_eq!(CieSkyType::all().count(), 15);
        // Type 5 is the uniform sky: a = 0 and c = 0, so L/L_z = 1 everywhere above the horizon.
        let uniform = CieSkyType::new(5).expect("valid").parameters();
        assert!((uniform.relative_luminance(0.1, 2.0, 0.3) - 1.0).abs() < 1e-15);
        // Type 1 horizon ratio 1/(1 + 4e^−0.7) = 0.3349 (lighting.md §1.1).
        let t1 = CieSkyType::new(1).expect("valid").parameters();
        let horizon = t1.relative_luminance(1e-9, 1.0, 0.5);
        assert!((horizon - 1.0 / (1.0 + 4.0 * (-0.7_f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn anti_sun_horizon_ratios_match_reference() {
        // lighting.md §1.1 last column, printed to 4 decimals (so 5e-5 rounding). Labelled "sun
        // el 60°", the values are those of a sun at *zenith* angle 60° (e.g. type 6, a = 0:
        // f(150°)/f(60°) = 0.7615, whereas elevation 60° would give f(120°)/f(30°) = 0.5092):
        // the horizon point opposite a sun at zenith 60° is at χ = 150°.
        let expected = [
            0.3349, 0.2550, 0.6692, 0.5096, 1.0000, 0.7615, 0.8452, 0.8603, 1.8001, 1.9980, 2.0335,
            3.1414, 2.4472, 4.8113, 2.9591,
        ];
        let sun_zenith = 60.0_f64.to_radians();
        let chi = 150.0_f64.to_radians();
        for (t, want) in CieSkyType::all().zip(expected) {
            let got = t.parameters().relative_luminance(1e-12, chi, sun_zenith);
            assert!(
                (got - want).abs() < 6e-5,
                "type {}: {got} vs {want}",
                t.number()
            );
        }
    }
}
