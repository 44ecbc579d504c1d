//! The first inversion of the atmospheric model, Durisch 1992 §4.2 eq. 7:
//!
//! `L₀ · τₐ^(dᵢ/dₐ) + L∞ · (1 − τₐ^(dᵢ/dₐ)) − Lᵢ = 0`,   i = 1…n, n ≥ 2
//!
//! solved per channel for τₐ and the common true colour L₀ of n samples of one material at
//! distances dᵢ, the horizon colour L∞ given, "started with τₐ = 1 and L₀ = Lⱼ, dⱼ = min(dᵢ)".
//!
//! The unknowns are reparametrised as `a = L₀ − L∞` and `u = σ·D` (σ the extinction per metre, D
//! the largest sample distance), so that both Jacobian columns `[e^(−u sᵢ), −a sᵢ e^(−u sᵢ)]`
//! (sᵢ = dᵢ/D ≤ 1) have the scale of the data; τₐ = e^(−u dₐ/D) and the start τₐ = 1 is u = 0.
//! The solver is argmin's `GaussNewtonLS` (Gauss–Newton with a backtracking Armijo line search,
//! Nocedal & Wright 2006 §10.3) on the Jacobian supplied here. The standard deviation of τₐ comes
//! from the covariance `(JᵀJ)⁻¹ · s²`, `s² = Σr²/(n − 2)`, propagated through `dτ/du`.
//!
//! # Known limitations
//! One common L₀ for all samples (Durisch's assumption): samples of one material under the same
//! illumination. A fit that wants τₐ > 1 (objects *gaining* contrast with distance — an
//! inconsistent sample set) is clamped to τₐ = 1 with a warning. With n = 2 the fit is exact and
//! no σ can be estimated.

use std::sync::Arc;

use argmin::core::{Error as ArgminError, Executor, Jacobian, Operator, observers::ObserverMode};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::{BacktrackingLineSearch, condition::ArmijoCondition};
use nalgebra::{DMatrix, DVector};

use super::{ArgminProgress, FitObserver, FitStage};
use crate::atmosphere::{AtmosphereError, SchachterAtmosphere};
use crate::colour::{Colour, MAX_CHANNELS};

/// Most Gauss–Newton iterations.
pub const MAX_ITERATIONS: u64 = 100;

/// Stop when ‖r‖ changes by less than this relative to the data's scale: far below an 8-bit
/// step (4e-3) and far above f64 round-off.
const COST_TOLERANCE_REL: f64 = 1e-12;

/// Armijo sufficient-decrease constant (the usual 1e-4, Nocedal & Wright §3.1).
const ARMIJO_C: f64 = 1e-4;

/// Result of eq. 7 for one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Eq7Solution {
    /// τₐ over the reference distance.
    pub transmittance: f64,
    /// Standard deviation of τₐ; `None` with two samples (no redundancy).
    pub transmittance_sigma: Option<f64>,
    /// The common true radiance L₀.
    pub true_radiance: f64,
    /// Residual `model − Lᵢ` per sample, in the order given.
    pub residuals: Vec<f64>,
    /// Root-mean-square residual.
    pub rms_residual: f64,
    /// Solver iterations.
    pub iterations: u64,
    /// Whether τₐ > 1 was clamped to 1.
    pub clamped: bool,
}

struct Eq7Problem {
    /// (sᵢ = dᵢ/D, yᵢ = Lᵢ − L∞).
    scaled: Vec<(f64, f64)>,
}

impl Operator for Eq7Problem {
    type Param = DVector<f64>;
    type Output = DVector<f64>;

    fn apply(&self, p: &Self::Param) -> Result<Self::Output, ArgminError> {
        let (a, u) = (p[0], p[1]);
        Ok(DVector::from_iterator(
            self.scaled.len(),
            self.scaled.iter().map(|&(s, y)| a * (-u * s).exp() - y),
        ))
    }
}

impl Jacobian for Eq7Problem {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;

    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, ArgminError> {
        let (a, u) = (p[0], p[1]);
        let mut j = DMatrix::zeros(self.scaled.len(), 2);
        for (i, &(s, _)) in self.scaled.iter().enumerate() {
            let t = (-u * s).exp();
            j[(i, 0)] = t;
            j[(i, 1)] = -a * s * t;
        }
        Ok(j)
    }
}

fn validate(
    horizon_radiance: f64,
    samples: &[(f64, f64)],
    reference_distance_m: f64,
) -> Result<(), AtmosphereError> {
    if !(reference_distance_m.is_finite() && reference_distance_m > 0.0) {
        return Err(AtmosphereError::InvalidDistance {
            value_m: reference_distance_m,
        });
    }
    for (index, &(d, l)) in samples.iter().enumerate() {
        if !(d.is_finite() && d >= 0.0 && l.is_finite()) {
            return Err(AtmosphereError::InvalidSample { index });
        }
    }
    if !horizon_radiance.is_finite() {
        return Err(AtmosphereError::InvalidSample { index: 0 });
    }
    let d_min = samples.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
    let d_max = samples
        .iter()
        .map(|s| s.0)
        .fold(f64::NEG_INFINITY, f64::max);
    if samples.len() < 2 || d_max <= d_min {
        return Err(AtmosphereError::NotEnoughSamples {
            required: 2,
            found: usize::from(!samples.is_empty()),
        });
    }
    if samples
        .iter()
        .all(|s| (s.1 - horizon_radiance).abs() <= f64::MIN_POSITIVE)
    {
        return Err(AtmosphereError::Undetermined {
            reason: "every sample equals the horizon colour",
        });
    }
    Ok(())
}

/// Durisch eq. 7 for one channel: τₐ (over `reference_distance_m`) and L₀ from samples
/// `(distance_m, apparent_radiance)` of one material, the horizon radiance L∞ given.
/// `observer` receives every iteration.
///
/// # Errors
/// Fewer than two distinct distances, non-finite samples or a non-positive reference distance,
/// samples that do not determine τₐ (all at the horizon colour, or a singular normal matrix).
pub fn solve_eq7(
    horizon_radiance: f64,
    samples: &[(f64, f64)],
    reference_distance_m: f64,
    observer: Option<(Arc<dyn FitObserver>, usize)>,
) -> Result<Eq7Solution, AtmosphereError> {
    validate(horizon_radiance, samples, reference_distance_m)?;
    let d_max = samples.iter().map(|s| s.0).fold(0.0, f64::max);
    let scaled: Vec<(f64, f64)> = samples
        .iter()
        .map(|&(d, l)| (d / d_max, l - horizon_radiance))
        .collect();
    let data_scale = scaled.iter().map(|s| s.1.abs()).fold(0.0, f64::max);
    // Durisch's start: τₐ = 1 (u = 0), L₀ = the nearest sample.
    let nearest = scaled
        .iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(0.0, |s| s.1);
    let start = DVector::from_vec(vec![nearest, 0.0]);
    let problem = Eq7Problem { scaled };
    let undetermined = |_| AtmosphereError::Undetermined {
        reason: "the normal matrix is singular (samples at the horizon colour?)",
    };
    let linesearch =
        BacktrackingLineSearch::new(ArmijoCondition::new(ARMIJO_C).map_err(undetermined)?);
    let solver = GaussNewtonLS::new(linesearch)
        .with_tolerance(COST_TOLERANCE_REL * data_scale.max(f64::MIN_POSITIVE))
        .map_err(undetermined)?;
    let mut executor = Executor::new(problem, solver)
        .configure(|state| state.param(start).max_iters(MAX_ITERATIONS));
    if let Some((inner, channel)) = observer {
        executor = executor.add_observer(
            ArgminProgress {
                inner,
                stage: FitStage::Atmosphere,
                channel,
            },
            ObserverMode::Always,
        );
    }
    let result = executor.ctrlc(false).run().map_err(undetermined)?;
    let iterations = argmin::core::State::get_iter(&result.state);
    let param = result
        .state
        .best_param
        .clone()
        .or_else(|| result.state.param.clone())
        .ok_or(AtmosphereError::Undetermined {
            reason: "the solver returned no parameters",
        })?;
    let problem = result
        .problem
        .problem
        .ok_or(AtmosphereError::Undetermined {
            reason: "the solver lost the problem",
        })?;
    let (mut a, mut u) = (param[0], param[1]);
    if !(a.is_finite() && u.is_finite()) {
        return Err(AtmosphereError::Undetermined {
            reason: "the iteration diverged",
        });
    }
    let clamped = u < 0.0;
    if clamped {
        // τₐ > 1 is unphysical: clear air, L₀ the mean apparent colour.
        u = 0.0;
        a = problem.scaled.iter().map(|s| s.1).sum::<f64>() / problem.scaled.len() as f64;
    }
    let p = DVector::from_vec(vec![a, u]);
    let r = problem.apply(&p).map_err(undetermined)?;
    let j = problem.jacobian(&p).map_err(undetermined)?;
    let n = problem.scaled.len();
    let ss: f64 = r.iter().map(|x| x * x).sum();
    let transmittance = (-u * reference_distance_m / d_max).exp();
    let transmittance_sigma = if n > 2 && !clamped {
        let s2 = ss / (n - 2) as f64;
        (j.transpose() * &j)
            .try_inverse()
            .map(|cov| (cov[(1, 1)] * s2).sqrt() * transmittance * reference_distance_m / d_max)
    } else {
        None
    };
    Ok(Eq7Solution {
        transmittance,
        transmittance_sigma,
        true_radiance: a + horizon_radiance,
        residuals: r.iter().copied().collect(),
        rms_residual: (ss / n as f64).sqrt(),
        iterations,
        clamped,
    })
}

/// Eq. 7 per RGB channel.
#[derive(Debug, Clone, PartialEq)]
pub struct AtmosphereFit {
    /// τₐ over the reference distance, per channel.
    pub transmittance: [f64; 3],
    /// σ(τₐ) per channel (`None` without redundancy).
    pub transmittance_sigma: [Option<f64>; 3],
    /// The common true colour L₀.
    pub true_colour: [f64; 3],
    /// Residuals per sample (model − apparent), per channel.
    pub residuals: Vec<[f64; 3]>,
    /// Reference distance dₐ, metres.
    pub reference_distance_m: f64,
    /// Iterations per channel.
    pub iterations: [u64; 3],
    /// Channels clamped to τₐ = 1.
    pub clamped: [bool; 3],
    /// Samples dropped as outliers by [`fit_atmosphere_robust`] (all `false` otherwise).
    pub flagged: Vec<bool>,
}

impl AtmosphereFit {
    /// Extinction coefficient per metre (`−ln τₐ / dₐ`), the site file's unit.
    #[must_use]
    pub fn extinction_per_m(&self) -> [f64; 3] {
        self.transmittance
            .map(|t| (-t.ln() / self.reference_distance_m).max(0.0))
    }
}

/// Eq. 7 for each RGB channel: samples `(distance_m, apparent linear RGB)`.
///
/// # Errors
/// As [`solve_eq7`], for the first channel that fails.
pub fn fit_atmosphere_rgb(
    horizon_rgb: [f64; 3],
    samples: &[(f64, [f64; 3])],
    reference_distance_m: f64,
    observer: Option<Arc<dyn FitObserver>>,
) -> Result<AtmosphereFit, AtmosphereError> {
    let mut fit = AtmosphereFit {
        transmittance: [1.0; 3],
        transmittance_sigma: [None; 3],
        true_colour: [0.0; 3],
        residuals: vec![[0.0; 3]; samples.len()],
        reference_distance_m,
        iterations: [0; 3],
        clamped: [false; 3],
        flagged: vec![false; samples.len()],
    };
    for k in 0..3 {
        let channel: Vec<(f64, f64)> = samples.iter().map(|(d, c)| (*d, c[k])).collect();
        let s = solve_eq7(
            horizon_rgb[k],
            &channel,
            reference_distance_m,
            observer.clone().map(|o| (o, k)),
        )?;
        fit.transmittance[k] = s.transmittance;
        fit.transmittance_sigma[k] = s.transmittance_sigma;
        fit.true_colour[k] = s.true_radiance;
        fit.iterations[k] = s.iterations;
        fit.clamped[k] = s.clamped;
        for (out, r) in fit.residuals.iter_mut().zip(&s.residuals) {
            out[k] = *r;
        }
    }
    Ok(fit)
}

/// Eq. 7 per channel with outlying samples dropped one at a time, as the daylight fit does
/// ([`super::daylight`]): after each fit the sample with the largest normalised residual
/// `|r|/σ̂` over the channels (σ̂ = 1.4826·MAD of the kept samples' residuals, floored at
/// [`super::daylight::NOISE_FLOOR_REL`] of their RMS colour) is dropped while that exceeds
/// `outlier_threshold` and more than three samples remain. Residuals are reported for every
/// sample against the final fit.
///
/// # Errors
/// As [`fit_atmosphere_rgb`].
pub fn fit_atmosphere_robust(
    horizon_rgb: [f64; 3],
    samples: &[(f64, [f64; 3])],
    reference_distance_m: f64,
    outlier_threshold: f64,
    observer: Option<Arc<dyn FitObserver>>,
) -> Result<AtmosphereFit, AtmosphereError> {
    let mut active = vec![true; samples.len()];
    loop {
        let kept: Vec<(f64, [f64; 3])> = samples
            .iter()
            .zip(&active)
            .filter(|(_, a)| **a)
            .map(|(s, _)| *s)
            .collect();
        let mut fit =
            fit_atmosphere_rgb(horizon_rgb, &kept, reference_distance_m, observer.clone())?;
        // Residuals of every sample against this fit: model − apparent.
        let residuals: Vec<[f64; 3]> = samples
            .iter()
            .map(|(d, c)| {
                [0, 1, 2].map(|k| {
                    crate::atmosphere::schachter::apparent_radiance(
                        fit.true_colour[k],
                        horizon_rgb[k],
                        fit.transmittance[k],
                        *d,
                        reference_distance_m,
                    ) - c[k]
                })
            })
            .collect();
        let scale = [0, 1, 2].map(|k| {
            let mut abs: Vec<f64> = residuals
                .iter()
                .zip(&active)
                .filter(|(_, a)| **a)
                .map(|(r, _)| r[k].abs())
                .collect();
            abs.sort_by(f64::total_cmp);
            let mad = abs.get(abs.len() / 2).copied().unwrap_or(0.0);
            #[allow(clippy::cast_precision_loss)]
            let rms = (kept.iter().map(|s| s.1[k].powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
            (1.4826 * mad).max(super::daylight::NOISE_FLOOR_REL * rms)
        });
        let worst = (0..samples.len())
            .filter(|&i| active[i])
            .map(|i| {
                let z = (0..3)
                    .map(|k| residuals[i][k].abs() / scale[k])
                    .fold(0.0, f64::max);
                (i, z)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((i, z)) if z > outlier_threshold && kept.len() > 3 => active[i] = false,
            _ => {
                fit.residuals = residuals;
                fit.flagged = active.iter().map(|a| !a).collect();
                return Ok(fit);
            }
        }
    }
}

/// Durisch §4.2 first inversion for every channel: fits τₐ per channel (and the common true
/// colour of the samples) to `samples` of one material, each `(distance_m, apparent colour)`,
/// given the horizon colour, by [`solve_eq7`] per channel. Returns the atmosphere and the fitted
/// true colour.
///
/// # Errors
/// As [`solve_eq7`] for any channel, or an invalid result (τₐ underflowing to 0).
pub fn fit_schachter_atmosphere(
    horizon: Colour,
    samples: &[(f64, Colour)],
    reference_distance_m: f64,
    channels: usize,
) -> Result<(SchachterAtmosphere, Colour), AtmosphereError> {
    let channels = channels.min(MAX_CHANNELS);
    let mut transmittance = Colour::BLACK;
    let mut true_colour = Colour::BLACK;
    let mut channel_samples = Vec::with_capacity(samples.len());
    for k in 0..channels {
        channel_samples.clear();
        channel_samples.extend(samples.iter().map(|(d, c)| (*d, f64::from(c.channels[k]))));
        let fit = solve_eq7(
            f64::from(horizon.channels[k]),
            &channel_samples,
            reference_distance_m,
            None,
        )?;
        transmittance.channels[k] = fit.transmittance as f32;
        true_colour.channels[k] = fit.true_radiance as f32;
    }
    let atmosphere =
        SchachterAtmosphere::new(transmittance, horizon, reference_distance_m, channels)?;
    Ok((atmosphere, true_colour))
}

#[cfg(test)]
#[path = "atmosphere_tests.rs"]
mod tests;
