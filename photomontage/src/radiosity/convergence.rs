//! The stop rule and the convergence record of every solve.
//!
//! Üncü & Kayakuş (seed 004, "the level for stopping the radiosity method was decided through
//! histogram analyses … when the change in the mean brightness value in the histogram value was
//! 1 % and below, iteration was stopped"): a pass ends with the area-weighted mean luminance of
//! the radiosity; the solve stops when its relative change from the previous pass is below
//! [`StopRule::mean_change`] (1 %) **and** a residual norm is below [`StopRule::residual`]. The
//! residual is the solver's own: for the progressive solver the unshot power over the total
//! (the exact residual of the Southwell iteration, Cohen & Wallace §5.3), for the gathering
//! solvers the area-weighted L1 norm of the last update over that of the solution (the Jacobi
//! residual ‖E + K B − B‖ for Jacobi steps).
//!
//! # Known limitations
//! The mean-change test alone stops early in bright enclosures (a pass changes the mean by
//! about ρ^k); the residual test is what bounds the error, roughly by residual/(1 − ρ_max).

use super::{RadiosityError, Rgb, luminance};

/// When to stop iterating.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopRule {
    /// Largest relative change of the mean brightness between passes (Üncü & Kayakuş: 0.01).
    pub mean_change: f64,
    /// Largest relative residual norm.
    pub residual: f64,
    /// Give up after this many passes (the result is kept, flagged as not converged).
    pub max_passes: u32,
}

impl Default for StopRule {
    /// 1 % mean change (the seed's rule), residual 1e-3, at most 200 passes.
    fn default() -> Self {
        Self {
            mean_change: 0.01,
            residual: 1e-3,
            max_passes: 200,
        }
    }
}

impl StopRule {
    /// Checks the thresholds.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] for a negative or non-finite threshold or zero passes.
    pub fn validate(&self) -> Result<(), RadiosityError> {
        for (name, value) in [
            ("mean_change", self.mean_change),
            ("residual", self.residual),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(RadiosityError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and ≥ 0",
                });
            }
        }
        super::check_positive("max_passes", f64::from(self.max_passes))
    }

    /// Whether a pass with these figures ends the solve.
    #[must_use]
    pub fn met(&self, row: &ConvergenceRow) -> bool {
        row.mean_change <= self.mean_change && row.residual <= self.residual
    }
}

/// One pass of a solve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ConvergenceRow {
    /// The light group.
    pub group: String,
    /// Pass number, from 1.
    pub pass: u32,
    /// Relative residual norm after the pass (module doc).
    pub residual: f64,
    /// Relative change of the mean brightness from the previous pass (1 for the first).
    pub mean_change: f64,
    /// Area-weighted mean luminance of the radiosity after the pass.
    pub mean_brightness: f64,
    /// Links (hierarchical), shots (progressive) or matrix entries (direct) in use.
    pub interactions: u64,
}

/// Area-weighted mean luminance of per-element radiosities.
#[must_use]
pub fn mean_brightness(radiosity_rgb: &[Rgb], areas_m2: &[f64]) -> f64 {
    let total: f64 = areas_m2.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    radiosity_rgb
        .iter()
        .zip(areas_m2)
        .map(|(b, a)| luminance(b) * a)
        .sum::<f64>()
        / total
}

/// Relative change from `previous` to `current` (1 when there was no previous light, 0 when
/// both are dark).
#[must_use]
pub fn relative_change(previous: Option<f64>, current: f64) -> f64 {
    match previous {
        None => 1.0,
        Some(p) if current.abs() > 0.0 => ((current - p) / current).abs(),
        Some(p) if p.abs() > 0.0 => 1.0,
        Some(_) => 0.0,
    }
}

/// The convergence record as CSV (`group,pass,residual,mean_change,mean_brightness,interactions`).
#[must_use]
pub fn csv(rows: &[ConvergenceRow]) -> String {
    let mut out = String::from("group,pass,residual,mean_change,mean_brightness,interactions\n");
    for r in rows {
        out.push_str(&format!(
            "{},{},{:e},{:e},{:e},{}\n",
            r.group, r.pass, r.residual, r.mean_change, r.mean_brightness, r.interactions
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stop_rule_and_change() {
        let rule = StopRule::default();
        let mut row = ConvergenceRow {
            group: "sky".into(),
            pass: 3,
            residual: 5e-4,
            mean_change: 0.009,
            mean_brightness: 1.0,
            interactions: 10,
        };
        assert!(rule.met(&row));
        row.mean_change = 0.011;
        assert!(!rule.met(&row));
        row.mean_change = 0.0;
        row.residual = 2e-3;
        assert!(!rule.met(&row));
        assert!((relative_change(Some(0.99), 1.0) - 0.01).abs() < 1e-15);
        assert!((relative_change(None, 1.0) - 1.0).abs() < f64::EPSILON);
        assert!(relative_change(Some(0.0), 0.0).abs() < f64::EPSILON);
        let text = csv(&[row]);
        assert_eq!(text.lines().count(), 2);
        assert!(
            text.lines()
                .nth(1)
                .unwrap()
                .starts_with("sky,3,2e-3,0e0,1e0,10")
        );
        assert!(
            StopRule {
                max_passes: 0,
                ..rule
            }
            .validate()
            .is_err()
        );
    }

    #[test]
    fn mean_brightness_is_area_weighted() {
        let b = [[1.0; 3], [3.0; 3]];
        let m = mean_brightness(&b, &[3.0, 1.0]);
        assert!((m - 1.5).abs() < 1e-12, "{m}");
    }
}
