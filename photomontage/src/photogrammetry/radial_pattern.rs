//! A diagnostic for uncorrected radial lens distortion computed from a solve's residuals.
//!
//! Uncorrected radial distortion displaces an image point along the ray from the principal
//! point by f·k1·r³ (+ f·k2·r⁵), r the normalised radius (Brown 1966; the k1 term of
//! [`crate::camera::BrownConrady`]). A camera solved without k1 therefore leaves residuals
//! whose radial component grows with r³. The test is the Pearson correlation of the radial
//! residual component (projected − observed, along the outward radius, pixels) with f·r³ over
//! all observations, outliers included (uncorrected distortion is itself a common cause of
//! "outliers" at the image border). The k1 that would remove the pattern is reported as a hint:
//! residual_r ≈ −f·Δk1·r³, fitted through the origin.
//!
//! # Known limitations
//! A correlation, not a test of significance: with few points, or points only near the image
//! centre, the pattern is weak whatever the lens. A freed focal length absorbs the linear part of
//! the displacement, so the r³ correlation is the part left over. Pose errors can mimic a
//! pattern in a small field of view.

use nalgebra::Point2;
use serde::Serialize;

use crate::camera::Intrinsics;

/// |correlation| at and above which a solve without k1 warns about radial distortion. Pure
/// noise of n ≥ 8 points gives |ρ| ≥ 0.5 with probability < 0.21 (t-distribution, 6 d.o.f.);
/// at n = 45 (Finse) < 5·10⁻⁴.
pub const RADIAL_PATTERN_CORRELATION: f64 = 0.5;
/// Fewest observations for the diagnostic.
pub const RADIAL_PATTERN_MIN_POINTS: usize = 8;

/// The radial residual pattern of one photo.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RadialPattern {
    /// Pearson correlation of the radial residual (px) with f·r³.
    pub correlation: f64,
    /// Observations used.
    pub points: usize,
    /// The k1 that would remove the fitted r³ part of the residuals (added to the current one).
    pub implied_k1: f64,
}

impl RadialPattern {
    /// Whether the pattern is strong enough to warn about.
    #[must_use]
    pub fn is_significant(&self) -> bool {
        self.points >= RADIAL_PATTERN_MIN_POINTS
            && self.correlation.abs() >= RADIAL_PATTERN_CORRELATION
    }

    /// The warning text.
    #[must_use]
    pub fn warning(&self) -> String {
        format!(
            "radial residual pattern: the radial residuals correlate with r³ (ρ = {:.2} over {} points), the mark of uncorrected lens distortion; self-calibrate k1 (the residuals suggest k1 ≈ {:.3})",
            self.correlation, self.points, self.implied_k1
        )
    }
}

/// The pattern of residuals (`residual_px[i]` = projected − observed at `observed_px[i]`);
/// non-finite residuals are skipped. `None` with fewer than two usable observations or none
/// off the principal point.
#[must_use]
pub fn radial_pattern(
    intrinsics: &Intrinsics,
    observed_px: &[Point2<f64>],
    residual_px: &[[f64; 2]],
) -> Option<RadialPattern> {
    let [cx, cy] = intrinsics.principal_point_px;
    let f = intrinsics.focal_px;
    let mut pairs = Vec::with_capacity(observed_px.len());
    for (p, v) in observed_px.iter().zip(residual_px) {
        if !(v[0].is_finite() && v[1].is_finite()) {
            continue;
        }
        let (dx, dy) = (p.x - cx, p.y - cy);
        let radius_px = dx.hypot(dy);
        if radius_px <= 0.0 {
            continue;
        }
        let radial = (v[0] * dx + v[1] * dy) / radius_px;
        let n = intrinsics.normalised_from_pixel(*p);
        let r = n.x.hypot(n.y);
        pairs.push((radial, f * r * r * r));
    }
    let count = pairs.len();
    if count < 2 {
        return None;
    }
    let mean_v = pairs.iter().map(|p| p.0).sum::<f64>() / count as f64;
    let mean_g = pairs.iter().map(|p| p.1).sum::<f64>() / count as f64;
    let (mut svg, mut svv, mut sgg, mut sg2, mut svg0) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (v, g) in &pairs {
        svg += (v - mean_v) * (g - mean_g);
        svv += (v - mean_v).powi(2);
        sgg += (g - mean_g).powi(2);
        sg2 += g * g;
        svg0 += v * g;
    }
    if svv <= 0.0 || sgg <= 0.0 || sg2 <= 0.0 {
        return None;
    }
    Some(RadialPattern {
        correlation: svg / (svv * sgg).sqrt(),
        points: count,
        implied_k1: intrinsics.distortion.k1 - svg0 / sg2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::BrownConrady;

    /// Residuals built exactly from the model give its k1 and ρ = 1 to rounding.
    const IMPLIED_K1_TOLERANCE: f64 = 1e-9;
    const CORRELATION_TOLERANCE: f64 = 1e-9;

    fn grid() -> Vec<Point2<f64>> {
        let mut v = Vec::new();
        for i in 0..7 {
            for j in 0..5 {
                v.push(Point2::new(
                    100.0 + 250.0 * f64::from(i),
                    90.0 + 240.0 * f64::from(j),
                ));
            }
        }
        v
    }

    #[test]
    fn residuals_of_a_pure_r3_displacement_give_back_k1() {
        let pinhole = Intrinsics::centred(1500.0, [1800, 1200]);
        let k1 = -0.2;
        let observed = grid();
        // Projected − observed = −f·k1·r³ along the outward radius: the model of the module doc.
        let residuals: Vec<[f64; 2]> = observed
            .iter()
            .map(|p| {
                let n = pinhole.normalised_from_pixel(*p);
                let r = n.x.hypot(n.y);
                let along = -1500.0 * k1 * r * r * r;
                [along * n.x / r, along * n.y / r]
            })
            .collect();
        let pattern = radial_pattern(&pinhole, &observed, &residuals).unwrap();
        assert!(
            (pattern.correlation - 1.0).abs() < CORRELATION_TOLERANCE,
            "{pattern:?}"
        );
        assert!(pattern.is_significant());
        assert!(
            (pattern.implied_k1 - k1).abs() < IMPLIED_K1_TOLERANCE,
            "{pattern:?}"
        );
    }

    #[test]
    fn real_barrel_distortion_left_in_the_pixels_is_flagged() {
        let pinhole = Intrinsics::centred(1500.0, [1800, 1200]);
        let mut barrel = pinhole;
        barrel.distortion = BrownConrady {
            k1: -0.2,
            ..BrownConrady::default()
        };
        let observed: Vec<Point2<f64>> = grid()
            .into_iter()
            .map(|p| barrel.pixel_from_normalised(pinhole.normalised_from_pixel(p)))
            .collect();
        let residuals: Vec<[f64; 2]> = grid()
            .iter()
            .zip(&observed)
            .map(|(p, o)| [p.x - o.x, p.y - o.y])
            .collect();
        let pattern = radial_pattern(&pinhole, &observed, &residuals).unwrap();
        assert!(pattern.is_significant(), "{pattern:?}");
        assert!(pattern.implied_k1 < 0.0, "barrel: {pattern:?}");
    }

    #[test]
    fn tangential_noise_shows_no_pattern() {
        let pinhole = Intrinsics::centred(1500.0, [1800, 1200]);
        let observed = grid();
        // Residuals perpendicular to the radius: no radial component at all.
        let residuals: Vec<[f64; 2]> = observed
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let (dx, dy) = (p.x - 899.5, p.y - 599.5);
                let s = if k % 2 == 0 { 1.0 } else { -1.0 } / dx.hypot(dy).max(1.0);
                [-dy * s, dx * s]
            })
            .collect();
        let pattern = radial_pattern(&pinhole, &observed, &residuals);
        assert!(pattern.is_none_or(|p| !p.is_significant()), "{pattern:?}");
    }
}
