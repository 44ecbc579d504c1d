//! Least-squares polynomial fit of luminous intensity curves.
//!
//! Source: Üncü & Kayakuş (seed 004), §2.1: the intensity curve of a goniophotometer plane is
//! approximated by `Y = C0 + C1 x + … + Cm x^m` (eq. 6) minimising `S = Σ (Y_i − y_i)²` (eq. 5,
//! 7), whose normal equations are eq. 8. We solve the same least-squares problem by an SVD of
//! the Vandermonde matrix in the scaled variable `t = (x − centre)/half_range` ∈ [−1, 1], which
//! gives the eq. 8 solution without squaring the condition number; [`PolynomialFit::
//! coefficients_in_degrees`] returns the C_k of eq. 6 in powers of the angle in degrees.
//!
//! [`FittedWeb`] fits every plane of a [`PhotometricWeb`] and evaluates I(C, γ) from the
//! polynomials (linear between planes), as a smooth alternative to bilinear interpolation.
//!
//! # Known limitations
//! A polynomial of high degree oscillates between samples (Runge); degrees above ~12 are
//! refused. The fitted intensity is clamped at zero but not otherwise constrained.

use super::distribution::{PhotometricType, PhotometricWeb};
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

/// Highest polynomial degree accepted.
pub const MAX_DEGREE: usize = 12;

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CurveFitError {
    /// Fewer points than coefficients.
    #[error("a degree-{degree} fit needs at least {required} points, found {found}")]
    NotEnoughPoints {
        /// Requested degree.
        degree: usize,
        /// Points needed (degree + 1).
        required: usize,
        /// Points given.
        found: usize,
    },
    /// Angle and value lists differ in length.
    #[error("{angles} angles but {values} values")]
    LengthMismatch {
        /// Angles given.
        angles: usize,
        /// Values given.
        values: usize,
    },
    /// Degree above [`MAX_DEGREE`].
    #[error("degree {degree} is above the maximum {max}")]
    DegreeTooHigh {
        /// Requested degree.
        degree: usize,
        /// Largest accepted.
        max: usize,
    },
    /// NaN or infinite input, or all angles equal.
    #[error("degenerate input: {reason}")]
    Degenerate {
        /// What is wrong.
        reason: &'static str,
    },
}

/// A fitted polynomial I(x) over angles x in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct PolynomialFit {
    /// Coefficients in the scaled variable t, lowest power first.
    coefficients_scaled: Vec<f64>,
    centre_deg: f64,
    half_range_deg: f64,
    /// Root-mean-square residual over the fitted points (same unit as the values).
    pub rms_residual: f64,
}

impl PolynomialFit {
    /// Fits a polynomial of `degree` to `(angles_deg[i], values[i])` by least squares.
    ///
    /// # Errors
    /// Too few points, mismatched lengths, a degree above [`MAX_DEGREE`], or degenerate input.
    pub fn fit(angles_deg: &[f64], values: &[f64], degree: usize) -> Result<Self, CurveFitError> {
        if degree > MAX_DEGREE {
            return Err(CurveFitError::DegreeTooHigh {
                degree,
                max: MAX_DEGREE,
            });
        }
        if angles_deg.len() != values.len() {
            return Err(CurveFitError::LengthMismatch {
                angles: angles_deg.len(),
                values: values.len(),
            });
        }
        let n = angles_deg.len();
        if n < degree + 1 {
            return Err(CurveFitError::NotEnoughPoints {
                degree,
                required: degree + 1,
                found: n,
            });
        }
        if angles_deg.iter().chain(values).any(|v| !v.is_finite()) {
            return Err(CurveFitError::Degenerate {
                reason: "a value is not finite",
            });
        }
        let lo = angles_deg.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = angles_deg.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let half_range_deg = 0.5 * (hi - lo);
        let centre_deg = 0.5 * (hi + lo);
        if half_range_deg <= 0.0 && degree > 0 {
            return Err(CurveFitError::Degenerate {
                reason: "all angles are equal",
            });
        }
        let scale = if half_range_deg > 0.0 {
            half_range_deg
        } else {
            1.0
        };
        let a = DMatrix::from_fn(n, degree + 1, |i, k| {
            ((angles_deg[i] - centre_deg) / scale).powi(k as i32)
        });
        let b = DVector::from_column_slice(values);
        let svd = a.clone().svd(true, true);
        let x = svd
            .solve(&b, 1e-12)
            .map_err(|_| CurveFitError::Degenerate {
                reason: "the least-squares system could not be solved",
            })?;
        let residual = &a * &x - &b;
        let rms_residual = (residual.norm_squared() / n as f64).sqrt();
        Ok(Self {
            coefficients_scaled: x.iter().copied().collect(),
            centre_deg,
            half_range_deg: scale,
            rms_residual,
        })
    }

    /// The fitted value at `angle_deg` (Horner in the scaled variable).
    #[must_use]
    pub fn evaluate(&self, angle_deg: f64) -> f64 {
        let t = (angle_deg - self.centre_deg) / self.half_range_deg;
        self.coefficients_scaled
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * t + c)
    }

    /// The coefficients C0…Cm of eq. 6, in powers of the angle in degrees (lowest first).
    #[must_use]
    pub fn coefficients_in_degrees(&self) -> Vec<f64> {
        // p(x) = Σ a_k ((x − c)/s)^k = Σ_k a_k s^−k Σ_j binom(k, j) x^j (−c)^(k−j).
        let m = self.coefficients_scaled.len();
        let mut out = vec![0.0; m];
        for (k, a) in self.coefficients_scaled.iter().enumerate() {
            let ak = a / self.half_range_deg.powi(k as i32);
            let mut binom = 1.0;
            for j in 0..=k {
                if j > 0 {
                    binom = binom * (k + 1 - j) as f64 / j as f64;
                }
                out[j] += ak * binom * (-self.centre_deg).powi((k - j) as i32);
            }
        }
        out
    }
}

/// Per-plane polynomial fits of a Type C web, I(C, γ) from the polynomials.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedWeb {
    planes_deg: Vec<f64>,
    fits: Vec<PolynomialFit>,
    gamma_range_deg: (f64, f64),
}

impl FittedWeb {
    /// Fits each expanded plane of `web` (Type C; other types are evaluated through
    /// C–γ sampling of the web on its own vertical angles) with a polynomial of `degree`.
    ///
    /// # Errors
    /// As [`PolynomialFit::fit`].
    pub fn fit(web: &PhotometricWeb, degree: usize) -> Result<Self, CurveFitError> {
        let gammas: Vec<f64> = if web.photometric_type() == PhotometricType::C {
            web.vertical_deg().to_vec()
        } else {
            (0..=36).map(|i| f64::from(i) * 5.0).collect()
        };
        let planes_deg: Vec<f64> = if web.photometric_type() == PhotometricType::C {
            web.horizontal_deg().to_vec()
        } else {
            (0..24).map(|i| f64::from(i) * 15.0).collect()
        };
        let mut fits = Vec::with_capacity(planes_deg.len());
        for &c in &planes_deg {
            let values: Vec<f64> = gammas
                .iter()
                .map(|&g| web.intensity_c_gamma_cd(c, g))
                .collect();
            fits.push(PolynomialFit::fit(&gammas, &values, degree)?);
        }
        let lo = gammas.first().copied().unwrap_or(0.0);
        let hi = gammas.last().copied().unwrap_or(180.0);
        Ok(Self {
            planes_deg,
            fits,
            gamma_range_deg: (lo, hi),
        })
    }

    /// The per-plane fits, in C order.
    #[must_use]
    pub fn fits(&self) -> &[PolynomialFit] {
        &self.fits
    }

    /// Fitted intensity (cd) at (C, γ): polynomial in γ, linear between planes (cyclic),
    /// zero outside the fitted γ range and never negative.
    #[must_use]
    pub fn intensity_cd(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        let (lo, hi) = self.gamma_range_deg;
        if gamma_deg < lo - 1e-9 || gamma_deg > hi + 1e-9 || self.fits.is_empty() {
            return 0.0;
        }
        let n = self.planes_deg.len();
        if n == 1 {
            return self.fits[0].evaluate(gamma_deg).max(0.0);
        }
        let c = c_deg.rem_euclid(360.0);
        let i = self.planes_deg.partition_point(|&a| a <= c);
        let (l, h) = if i == 0 || i == n {
            (n - 1, 0)
        } else {
            (i - 1, i)
        };
        let a0 = self.planes_deg[l];
        let mut a1 = self.planes_deg[h];
        if a1 <= a0 {
            a1 += 360.0;
        }
        let x = if c < a0 { c + 360.0 } else { c };
        let t = ((x - a0) / (a1 - a0)).clamp(0.0, 1.0);
        ((1.0 - t) * self.fits[l].evaluate(gamma_deg) + t * self.fits[h].evaluate(gamma_deg))
            .max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminaire::Symmetry;
    use approx::assert_relative_eq;

    /// Exact-data recovery is limited only by rounding in the SVD.
    const EXACT: f64 = 1e-8;

    #[test]
    fn recovers_an_exact_cubic_in_degree_units() {
        // y = 5 − 0.2 x + 0.003 x² − 1e-5 x³ sampled at 0…90°.
        let xs: Vec<f64> = (0..=18).map(|i| f64::from(i) * 5.0).collect();
        let ys: Vec<f64> = xs
            .iter()
            .map(|x| 5.0 - 0.2 * x + 0.003 * x * x - 1e-5 * x * x * x)
            .collect();
        let fit = PolynomialFit::fit(&xs, &ys, 3).unwrap();
        let c = fit.coefficients_in_degrees();
        for (got, want) in c.iter().zip([5.0, -0.2, 0.003, -1e-5]) {
            assert_relative_eq!(*got, want, max_relative = EXACT);
        }
        assert!(fit.rms_residual < EXACT);
        assert_relative_eq!(
            fit.evaluate(42.0),
            ys[0] + (-0.2 * 42.0 + 0.003 * 42.0 * 42.0 - 1e-5 * 42.0f64.powi(3)),
            max_relative = EXACT
        );
    }

    #[test]
    fn straight_line_fit_matches_the_closed_form() {
        // Least squares line through (0,1), (1,3), (2,2): slope 0.5, intercept 1.5.
        let fit = PolynomialFit::fit(&[0.0, 1.0, 2.0], &[1.0, 3.0, 2.0], 1).unwrap();
        let c = fit.coefficients_in_degrees();
        assert_relative_eq!(c[0], 1.5, epsilon = EXACT);
        assert_relative_eq!(c[1], 0.5, epsilon = EXACT);
        // Residuals −0.5, 1, −0.5 → rms √(1.5/3).
        assert_relative_eq!(fit.rms_residual, 0.5f64.sqrt(), epsilon = EXACT);
    }

    #[test]
    fn refuses_bad_input() {
        assert_eq!(
            PolynomialFit::fit(&[0.0, 1.0], &[1.0, 2.0], 2),
            Err(CurveFitError::NotEnoughPoints {
                degree: 2,
                required: 3,
                found: 2
            })
        );
        assert!(matches!(
            PolynomialFit::fit(&[1.0; 5], &[1.0; 5], 2),
            Err(CurveFitError::Degenerate { .. })
        ));
        assert!(matches!(
            PolynomialFit::fit(&[0.0, 1.0], &[1.0], 1),
            Err(CurveFitError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn fitted_web_reproduces_a_polynomial_distribution() {
        // I = 1000 cos γ is smooth: a degree-8 fit over 0…90° is within 0.01 cd of it.
        let gammas: Vec<f64> = (0..=18).map(|i| f64::from(i) * 5.0).collect();
        let values: Vec<f64> = gammas
            .iter()
            .map(|g| 1000.0 * g.to_radians().cos())
            .collect();
        let web = PhotometricWeb::from_planes(
            PhotometricType::C,
            Symmetry::Axial,
            &[0.0],
            &gammas,
            &values,
        )
        .unwrap();
        let fitted = FittedWeb::fit(&web, 8).unwrap();
        for g in [2.5, 33.0, 61.0, 88.0] {
            assert_relative_eq!(
                fitted.intensity_cd(123.0, g),
                1000.0 * f64::to_radians(g).cos(),
                epsilon = 0.01
            );
        }
        assert_relative_eq!(fitted.intensity_cd(0.0, 120.0), 0.0);
    }
}
