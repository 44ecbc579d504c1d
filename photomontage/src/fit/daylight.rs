//! The first inversion of the illumination model, Durisch 1992 §4.3 eq. 9, extended by the
//! light the photographed surroundings reflect onto each sample:
//!
//! `L₀ᵢ = ρ_dᵢ/π · (k_s E_sᵢ + k_u E_uᵢ + k_h E_hᵢ + E_rᵢ)`,   i = 1…n, n ≥ 3
//!
//! for n samples of opaque diffuse materials under different illumination, their true colours
//! L₀ᵢ known from the atmosphere's second inversion (eq. 8). Per sample the *unit* irradiance
//! components are computed with the scene's visibility ([`irradiance_components`]):
//! `E_s = max(0, n·d_s)·δ_s` (eq. 3 for a sun of unit normal irradiance, δ_s by an any-hit shadow
//! ray), `E_u = π` (eq. 4, never occluded), `E_h = Σ wᵢ max(0, n·lᵢ) δᵢ` (eq. 5 over the facets of
//! the site's sky model normalised to unit unobstructed horizontal irradiance,
//! [`normalised_sky_facets`]). With the project's lighting units (k_s normal irradiance of the
//! sun, k_u ambient radiance, k_h horizontal sky irradiance) the system is linear in
//! `k = (k_s, k_u, k_h)`: row i is `ρ_dᵢ/π·(E_sᵢ, π, E_hᵢ)·k = L₀ᵢ − ρ_dᵢ/π·E_rᵢ` (the
//! residuals stay in true-colour units, so samples of dark and light materials weigh alike),
//! solved per channel by non-negative least squares ([`nnls3`], exact active-set enumeration for
//! three unknowns).
//!
//! **Reflectance and materials.** When every sample has its material's ρ_d (material library)
//! the weights are absolute and samples of *several* materials share them: vertical façades see
//! half the sky and horizontal ground all of it, which separates k_h from the isotropic k_u. When
//! no sample has ρ_d, the weights are relative as in the paper (ρ_d = 1 assumed, as Durisch §7 did
//! for grey and white materials; one material only) and E_r is **not** subtracted: E_r is in
//! absolute photo units, and `ρ_d/π·E_r` cannot be formed without ρ_d.
//!
//! **Interreflection** E_rᵢ (photo units, not scaled by the weights) is the irradiance the
//! photographed natural surfaces reflect onto the sample, gathered by the caller (the renderer's
//! gather, [`crate::render::DifferentialTracer::natural_interreflection_irradiance`]); without it
//! the light of sunlit façades and street reaching a shaded sample is absorbed into k_h and k_u.
//!
//! **Fixed components**: [`DaylightFitOptions::fit_ambient`] `= false` fixes k_u = 0 (the sky
//! model then carries all diffuse light).
//!
//! **Robustness**: after each fit the sample with the largest normalised residual
//! `|r|/σ̂` (σ̂ = 1.4826·MAD of the residuals, floored at [`NOISE_FLOOR_REL`] of the signal) is
//! dropped and the fit repeated while that residual exceeds the threshold (3.5 by default):
//! drop-and-refit one at a time avoids the masking of simultaneous rejection. σ of the weights
//! from `(AᵀA)⁻¹ s²` over the free weights of the final fit.
//!
//! # Known limitations
//! Diffuse materials only (specular samples bias the result); relative weights need one material;
//! the sky's angular distribution is taken from the site's sky model (only its strength is
//! fitted); E_r is taken as known (the caller gathers it from the photo with the current
//! weights for surfaces the photo does not show); sky visibility is sampled at facet centres.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Point3, Vector3};

use super::{FitIteration, FitObserver, FitStage};
use crate::render::differential::SURFACE_OFFSET_M;
use crate::scene::SceneTracer;
use crate::sky::SkyModel;
use crate::sky_dome::SkyDome;

/// Floor of the robust residual scale, relative to the RMS true colour of the samples: 0.1 %,
/// below one 8-bit step of a mid-grey, so exact (synthetic) data do not flag round-off.
pub const NOISE_FLOOR_REL: f64 = 1e-3;

/// Column-normalised condition number above which the design is reported ill-conditioned:
/// beyond 10³ a 0.1 % colour error moves a weight by ≳ 100 %.
pub const CONDITION_WARNING: f64 = 1e3;

/// Two sample normals closer than this (radians, 1°) count as the same orientation.
const SAME_ORIENTATION_RAD: f64 = 0.017_453_292_519_943_295;

/// Errors of the daylight fit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DaylightError {
    /// Too few usable samples.
    #[error("the daylight fit needs at least {required} samples, found {found}")]
    NotEnoughSamples {
        /// Required count.
        required: usize,
        /// Count given (after rejections).
        found: usize,
    },
    /// A sample with a non-finite colour, point or normal.
    #[error("sample `{sample}` has a non-finite colour, point or normal")]
    NonFinite {
        /// Sample id.
        sample: String,
    },
    /// The sky model gives no light on a horizontal plane (cannot be normalised).
    #[error("the sky model gives no light on a horizontal plane")]
    DarkSky,
    /// Some samples have a diffuse reflectance and others not: absolute and relative weights
    /// cannot be mixed.
    #[error(
        "sample `{sample}` has no diffuse reflectance but sample `{other}` has one: give every \
         sample's material a reflectance, or none"
    )]
    MixedReflectance {
        /// A sample without ρ_d.
        sample: String,
        /// A sample with ρ_d.
        other: String,
    },
}

/// A sky facet weighted so that the unobstructed horizontal irradiance of all facets is 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyFacetWeight {
    /// Unit direction to the facet centre, world frame (Z up).
    pub dir_in_world: Vector3<f64>,
    /// Irradiance at normal incidence from this facet for unit horizontal sky irradiance.
    pub weight: f64,
}

/// The facets of `dome` weighted by the relative luminance of `model` (sun at
/// `sun_dir_in_world`) × solid angle, normalised so that `Σ w·max(0, l_z) = 1`.
///
/// # Errors
/// [`DaylightError::DarkSky`] if the sum is not positive.
pub fn normalised_sky_facets(
    dome: &SkyDome,
    model: &SkyModel,
    sun_dir_in_world: &Vector3<f64>,
) -> Result<Vec<SkyFacetWeight>, DaylightError> {
    let raw: Vec<SkyFacetWeight> = dome
        .facets
        .iter()
        .map(|f| SkyFacetWeight {
            dir_in_world: f.centre_dir_in_world,
            weight: model.relative_luminance(&f.centre_dir_in_world, sun_dir_in_world)
                * f.solid_angle_sr,
        })
        .collect();
    let horizontal: f64 = raw
        .iter()
        .map(|f| f.weight * f.dir_in_world.z.max(0.0))
        .sum();
    if !(horizontal > 0.0 && horizontal.is_finite()) {
        return Err(DaylightError::DarkSky);
    }
    Ok(raw
        .into_iter()
        .map(|f| SkyFacetWeight {
            weight: f.weight / horizontal,
            ..f
        })
        .collect())
}

/// Unit irradiance components at one sample (the columns of eq. 9).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct IrradianceComponents {
    /// `max(0, n·d_s)·δ_s` for a sun of unit normal irradiance.
    pub sun: f64,
    /// `π` (eq. 4 for unit ambient radiance).
    pub ambient: f64,
    /// `Σ wᵢ max(0, n·lᵢ) δᵢ` for unit horizontal sky irradiance.
    pub sky: f64,
    /// Whether the sun is above the surface's horizon and not blocked.
    pub sun_visible: bool,
}

/// The unit irradiance components at `point_in_world_m` with unit normal `normal_in_world`
/// (facing the camera), with sun and sky-facet visibility by any-hit rays against `tracer`.
#[must_use]
pub fn irradiance_components(
    tracer: &SceneTracer,
    point_in_world_m: &Point3<f64>,
    normal_in_world: &Vector3<f64>,
    sun_dir_in_world: Option<&Vector3<f64>>,
    sky: &[SkyFacetWeight],
) -> IrradianceComponents {
    let origin = point_in_world_m + normal_in_world * SURFACE_OFFSET_M;
    let visible = |dir: &Vector3<f64>| {
        !tracer.any_hit(&tracer.ray_from_world(&origin, dir, 0.0, f32::INFINITY))
    };
    let (mut sun, mut sun_visible) = (0.0, false);
    if let Some(d) = sun_dir_in_world {
        let cos = normal_in_world.dot(d);
        if cos > 0.0 && visible(d) {
            sun = cos;
            sun_visible = true;
        }
    }
    let sky_sum = sky
        .iter()
        .filter_map(|f| {
            let cos = normal_in_world.dot(&f.dir_in_world);
            (cos > 0.0 && visible(&f.dir_in_world)).then_some(f.weight * cos)
        })
        .sum();
    IrradianceComponents {
        sun,
        ambient: PI,
        sky: sky_sum,
        sun_visible,
    }
}

/// One sample of the daylight fit.
#[derive(Debug, Clone, PartialEq)]
pub struct DaylightSample {
    /// Sample id (named in warnings).
    pub id: String,
    /// True colour L₀ (atmosphere removed), linear RGB.
    pub true_colour_rgb: [f64; 3],
    /// Unit irradiance components at the sample.
    pub components: IrradianceComponents,
    /// Unit surface normal, world frame.
    pub normal_in_world: Vector3<f64>,
    /// The sample's diffuse reflectance ρ_d when known (its material's); `None` falls back to
    /// [`DaylightFitOptions::diffuse_reflectance_rgb`].
    pub diffuse_reflectance_rgb: Option<[f64; 3]>,
    /// E_r: irradiance reflected onto the sample by its surroundings, photo units (not scaled by
    /// the weights); zeros for eq. 9 as in the paper. Ignored for relative weights.
    pub interreflection_rgb: [f64; 3],
}

/// Settings of the daylight fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DaylightFitOptions {
    /// Normalised residual above which the worst sample is dropped.
    pub outlier_threshold: f64,
    /// Diffuse reflectance (albedo) of samples that have none of their own: absolute weights.
    pub diffuse_reflectance_rgb: Option<[f64; 3]>,
    /// Fit the ambient weight k_u; `false` fixes k_u = 0.
    pub fit_ambient: bool,
}

impl Default for DaylightFitOptions {
    /// Threshold 3.5 (the site's usual outlier threshold), relative weights, k_u fitted (as the
    /// paper).
    fn default() -> Self {
        Self {
            outlier_threshold: 3.5,
            diffuse_reflectance_rgb: None,
            fit_ambient: true,
        }
    }
}

/// A sample's residual in the final fit.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SampleResidual {
    /// Sample id.
    pub sample: String,
    /// Model − observed true colour, per channel.
    pub residual_rgb: [f64; 3],
    /// |residual| / σ̂, per channel.
    pub normalised: [f64; 3],
    /// Dropped as an outlier.
    pub flagged: bool,
}

/// Result of the daylight first inversion.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DaylightFit {
    /// k_s per channel.
    pub sun_weight: [f64; 3],
    /// σ(k_s) (`None` where the weight is at its bound or undetermined).
    pub sun_weight_sigma: [Option<f64>; 3],
    /// k_u per channel.
    pub ambient_weight: [f64; 3],
    /// σ(k_u).
    pub ambient_weight_sigma: [Option<f64>; 3],
    /// k_h per channel.
    pub sky_weight: [f64; 3],
    /// σ(k_h).
    pub sky_weight_sigma: [Option<f64>; 3],
    /// Whether the weights are relative (ρ_d = 1 assumed) rather than absolute.
    pub relative: bool,
    /// Whether k_u was fixed at 0 ([`DaylightFitOptions::fit_ambient`] off).
    pub ambient_fixed: bool,
    /// Residuals of every sample (flagged ones included).
    pub residuals: Vec<SampleResidual>,
    /// Ids of the samples dropped as outliers.
    pub flagged: Vec<String>,
    /// Warnings naming the samples concerned.
    pub warnings: Vec<String>,
}

/// Non-negative least squares `min ‖A x − b‖, x ≥ 0` for up to three columns, exactly: every
/// subset of columns is solved unconstrained (SVD, rank-revealing) and the feasible solution of
/// least cost kept. Returns `x` and which columns are free (not at the bound 0).
#[must_use]
pub fn nnls3(a: &DMatrix<f64>, b: &DVector<f64>) -> (DVector<f64>, Vec<bool>) {
    let m = a.ncols().min(3);
    let mut best: Option<(f64, DVector<f64>, Vec<bool>)> = None;
    for mask in 1_u32..(1 << m) {
        let cols: Vec<usize> = (0..m).filter(|c| mask & (1 << c) != 0).collect();
        let sub = a.select_columns(&cols);
        let svd = sub.clone().svd(true, true);
        let eps = svd.singular_values.max() * 1e-12;
        let Ok(x_sub) = svd.solve(b, eps) else {
            continue;
        };
        if x_sub.iter().any(|v| *v < 0.0 || !v.is_finite()) {
            continue;
        }
        let cost = (&sub * &x_sub - b).norm_squared();
        let mut x = DVector::zeros(a.ncols());
        let mut free = vec![false; a.ncols()];
        for (i, &c) in cols.iter().enumerate() {
            x[c] = x_sub[i];
            free[c] = x_sub[i] > 0.0;
        }
        if best
            .as_ref()
            .is_none_or(|(c, _, _)| cost < *c * (1.0 - 1e-12))
        {
            best = Some((cost, x, free));
        }
    }
    best.map_or_else(
        || (DVector::zeros(a.ncols()), vec![false; a.ncols()]),
        |(_, x, free)| (x, free),
    )
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

struct ChannelFit {
    x: DVector<f64>,
    free: Vec<bool>,
    residuals: Vec<f64>,
    scale: f64,
    sigma: [Option<f64>; 3],
}

/// NNLS over the columns `fitted` of `design` (the others fixed at 0), rows where `active`.
fn fit_channel(design: &DMatrix<f64>, b: &[f64], active: &[bool], fitted: &[usize]) -> ChannelFit {
    let rows: Vec<usize> = (0..b.len()).filter(|&i| active[i]).collect();
    let a = design.select_rows(&rows).select_columns(fitted);
    let bv = DVector::from_iterator(rows.len(), rows.iter().map(|&i| b[i]));
    let (x_sub, free_sub) = nnls3(&a, &bv);
    let (mut x, mut free) = (DVector::zeros(3), vec![false; 3]);
    for (j, &c) in fitted.iter().enumerate() {
        x[c] = x_sub[j];
        free[c] = free_sub[j];
    }
    let a = design.select_rows(&rows);
    let residuals: Vec<f64> = (0..b.len())
        .map(|i| (design.row(i) * &x)[0] - b[i])
        .collect();
    let mut abs_active: Vec<f64> = rows.iter().map(|&i| residuals[i].abs()).collect();
    let rms_signal = (bv.norm_squared() / rows.len().max(1) as f64).sqrt();
    let scale = (1.4826 * median(&mut abs_active)).max(NOISE_FLOOR_REL * rms_signal);
    let free_cols: Vec<usize> = (0..3).filter(|&c| free[c]).collect();
    let mut sigma = [None; 3];
    let dof = rows.len().saturating_sub(free_cols.len());
    if dof > 0 && !free_cols.is_empty() {
        let s2 = rows.iter().map(|&i| residuals[i].powi(2)).sum::<f64>() / dof as f64;
        let af = a.select_columns(&free_cols);
        if let Some(cov) = (af.transpose() * &af).try_inverse() {
            for (k, &c) in free_cols.iter().enumerate() {
                sigma[c] = Some((cov[(k, k)] * s2).sqrt());
            }
        }
    }
    ChannelFit {
        x,
        free,
        residuals,
        scale,
        sigma,
    }
}

/// The condition number of the design's non-zero columns, each scaled to unit norm.
fn condition_number(design: &DMatrix<f64>, active: &[bool]) -> f64 {
    let rows: Vec<usize> = (0..active.len()).filter(|&i| active[i]).collect();
    let mut a = design.select_rows(&rows);
    let cols: Vec<usize> = (0..a.ncols())
        .filter(|&c| a.column(c).norm() > 0.0)
        .collect();
    a = a.select_columns(&cols);
    for mut c in a.column_iter_mut() {
        let n = c.norm();
        c /= n;
    }
    let sv = a.singular_values();
    let (max, min) = (sv.max(), sv.min());
    if min > 0.0 { max / min } else { f64::INFINITY }
}

fn names(samples: &[DaylightSample], pick: impl Fn(&DaylightSample) -> bool) -> String {
    samples
        .iter()
        .filter(|s| pick(s))
        .map(|s| format!("`{}`", s.id))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Durisch eq. 9 (with E_r) per channel with robust rejection; see the module doc.
///
/// # Errors
/// Fewer than three samples (before or after rejection), non-finite input, or some samples with
/// and some without a diffuse reflectance.
pub fn fit_daylight(
    samples: &[DaylightSample],
    options: &DaylightFitOptions,
    observer: Option<Arc<dyn FitObserver>>,
) -> Result<DaylightFit, DaylightError> {
    const REQUIRED: usize = 3;
    for s in samples {
        let c = &s.components;
        if !(s.true_colour_rgb.iter().all(|v| v.is_finite())
            && [c.sun, c.ambient, c.sky].iter().all(|v| v.is_finite())
            && s.interreflection_rgb.iter().all(|v| v.is_finite())
            && s.diffuse_reflectance_rgb
                .is_none_or(|r| r.iter().all(|v| v.is_finite() && *v > 0.0))
            && s.normal_in_world.iter().all(|v| v.is_finite()))
        {
            return Err(DaylightError::NonFinite {
                sample: s.id.clone(),
            });
        }
    }
    if samples.len() < REQUIRED {
        return Err(DaylightError::NotEnoughSamples {
            required: REQUIRED,
            found: samples.len(),
        });
    }
    let n = samples.len();
    let rho_of = |s: &DaylightSample| {
        s.diffuse_reflectance_rgb
            .or(options.diffuse_reflectance_rgb)
    };
    let relative = match (
        samples.iter().find(|s| rho_of(s).is_none()),
        samples.iter().find(|s| rho_of(s).is_some()),
    ) {
        (Some(without), Some(with)) => {
            return Err(DaylightError::MixedReflectance {
                sample: without.id.clone(),
                other: with.id.clone(),
            });
        }
        (without, _) => without.is_some(),
    };
    // Row i of channel k: ρᵢ/π·(E_s, π, E_h) · k = L₀ᵢ − ρᵢ/π·E_rᵢ (ρ = 1, E_r unused: relative).
    let rho = |i: usize, k: usize| rho_of(&samples[i]).map_or(1.0, |r| r[k]) / PI;
    let designs: [DMatrix<f64>; 3] = [0, 1, 2].map(|k| {
        DMatrix::from_fn(n, 3, |i, c| {
            let e = &samples[i].components;
            rho(i, k) * [e.sun, e.ambient, e.sky][c]
        })
    });
    let channels: [Vec<f64>; 3] = [0, 1, 2].map(|k| {
        (0..n)
            .map(|i| {
                let s = &samples[i];
                let reflected = if relative {
                    0.0
                } else {
                    rho(i, k) * s.interreflection_rgb[k]
                };
                s.true_colour_rgb[k] - reflected
            })
            .collect()
    });
    let fitted: &[usize] = if options.fit_ambient {
        &[0, 1, 2]
    } else {
        &[0, 2]
    };
    let mut active = vec![true; n];
    let mut round = 0_u64;
    let fits = loop {
        let fits = [0, 1, 2].map(|k| fit_channel(&designs[k], &channels[k], &active, fitted));
        if let Some(o) = &observer {
            for (k, f) in fits.iter().enumerate() {
                let cost = (0..n)
                    .filter(|&i| active[i])
                    .map(|i| f.residuals[i].powi(2))
                    .sum::<f64>()
                    .sqrt();
                o.on_iteration(&FitIteration {
                    stage: FitStage::Daylight,
                    channel: k,
                    iteration: round,
                    cost,
                });
            }
        }
        round += 1;
        let worst = (0..n)
            .filter(|&i| active[i])
            .map(|i| {
                let z = fits
                    .iter()
                    .map(|f| f.residuals[i].abs() / f.scale)
                    .fold(0.0, f64::max);
                (i, z)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let remaining = active.iter().filter(|a| **a).count();
        match worst {
            Some((i, z)) if z > options.outlier_threshold && remaining > REQUIRED + 1 => {
                active[i] = false;
            }
            _ => break fits,
        }
    };
    let remaining = active.iter().filter(|a| **a).count();
    if remaining < REQUIRED {
        return Err(DaylightError::NotEnoughSamples {
            required: REQUIRED,
            found: remaining,
        });
    }
    let mut out = DaylightFit {
        sun_weight: [0.0; 3],
        sun_weight_sigma: [None; 3],
        ambient_weight: [0.0; 3],
        ambient_weight_sigma: [None; 3],
        sky_weight: [0.0; 3],
        sky_weight_sigma: [None; 3],
        relative,
        ambient_fixed: !options.fit_ambient,
        residuals: Vec::with_capacity(n),
        flagged: Vec::new(),
        warnings: Vec::new(),
    };
    for (k, f) in fits.iter().enumerate() {
        // The unknowns are the weights themselves (the rows carry ρ/π).
        out.sun_weight[k] = f.x[0];
        out.ambient_weight[k] = f.x[1];
        out.sky_weight[k] = f.x[2];
        out.sun_weight_sigma[k] = f.sigma[0];
        out.ambient_weight_sigma[k] = f.sigma[1];
        out.sky_weight_sigma[k] = f.sigma[2];
    }
    for (i, s) in samples.iter().enumerate() {
        out.residuals.push(SampleResidual {
            sample: s.id.clone(),
            residual_rgb: [0, 1, 2].map(|k| fits[k].residuals[i]),
            normalised: [0, 1, 2].map(|k| fits[k].residuals[i].abs() / fits[k].scale),
            flagged: !active[i],
        });
        if !active[i] {
            out.flagged.push(s.id.clone());
        }
    }
    // Design warnings over the samples kept.
    let kept: Vec<DaylightSample> = samples
        .iter()
        .zip(&active)
        .filter(|(_, a)| **a)
        .map(|(s, _)| s.clone())
        .collect();
    if !out.flagged.is_empty() {
        out.warnings.push(format!(
            "samples dropped as outliers (normalised residual > {}): {}",
            options.outlier_threshold,
            names(samples, |s| out.flagged.contains(&s.id))
        ));
    }
    if kept.iter().all(|s| s.components.sun_visible) {
        out.warnings.push(format!(
            "all samples are in sun ({}): sun and diffuse light are separated only by the \
             samples' orientations; add samples in shadow",
            names(&kept, |_| true)
        ));
    }
    if kept.iter().all(|s| !s.components.sun_visible) {
        out.warnings.push(format!(
            "all samples are in shade ({}): the sun weight is not determined (set to 0); add \
             samples in sun",
            names(&kept, |_| true)
        ));
    }
    let first = kept[0].normal_in_world;
    if options.fit_ambient
        && kept
            .iter()
            .all(|s| s.normal_in_world.angle(&first) < SAME_ORIENTATION_RAD)
    {
        out.warnings.push(format!(
            "all samples have the same orientation ({}): ambient and sky light cannot be told \
             apart; add samples on differently oriented surfaces",
            names(&kept, |_| true)
        ));
    }
    let cond = designs
        .iter()
        .map(|d| condition_number(&d.select_columns(fitted), &active))
        .fold(0.0, f64::max);
    if cond > CONDITION_WARNING {
        out.warnings.push(format!(
            "the samples ({}) determine the weights poorly (condition number {cond:.3e}): the \
             irradiance components are nearly proportional",
            names(&kept, |_| true)
        ));
    }
    for (name, free) in [
        ("sun", fits.iter().map(|f| f.free[0]).collect::<Vec<_>>()),
        (
            "ambient",
            fits.iter()
                .map(|f| f.free[1] || !options.fit_ambient)
                .collect(),
        ),
        ("sky", fits.iter().map(|f| f.free[2]).collect()),
    ] {
        if free.iter().any(|f| !f) {
            out.warnings.push(format!(
                "the {name} weight is at its bound 0 in some channel (no σ there)"
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
