//! The report of a site's lighting fit (the JSON of `photomontage fit`) and its write-back into
//! the site: fitted values into `[lighting]`, uncertainties, residual summary and warnings into
//! the `[fit]` record (documented in `docs/site-format.md`).
//!
//! # Known limitations
//! The `[fit]` record keeps the RMS residual per channel, not every sample's residual (those are
//! in the command's report); a σ that cannot be estimated is written as 0.

use serde::Serialize;

use super::sun_check::SunCheck;
use crate::site::{FitRecord, Site};

/// One residual of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitResidual {
    /// Sample id.
    pub sample: String,
    /// `atmosphere` or `daylight`.
    pub fit: &'static str,
    /// Model − observation per channel (apparent colour for the atmosphere, true colour for the
    /// daylight fit), linear units.
    pub residual_rgb: [f64; 3],
    /// |residual|/σ̂ (daylight fit only).
    pub normalised: Option<[f64; 3]>,
    /// Dropped as an outlier.
    pub flagged: bool,
}

/// A sample as located and read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampleReading {
    /// Sample id.
    pub id: String,
    /// Point on the polygon, world frame, metres.
    pub point_in_world_m: [f64; 3],
    /// Distance to the photo's camera, metres.
    pub distance_m: f64,
    /// Apparent colour (linear RGB, median of the window).
    pub apparent_rgb: [f64; 3],
    /// Pixels rejected as saturated / underexposed.
    pub rejected_px: [usize; 2],
    /// E_r, the irradiance the photographed surroundings reflect onto a daylight sample (linear
    /// RGB, photo units), when the fit subtracted it.
    pub interreflection_rgb: Option<[f64; 3]>,
}

/// A sun cross-check with its pair id.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NamedSunCheck {
    /// Pair id.
    pub pair: String,
    /// The check.
    #[serde(flatten)]
    pub check: SunCheck,
}

/// What `photomontage fit` reports (JSON keys as named here).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SiteFitReport {
    /// τₐ over [`REPORT_REFERENCE_DISTANCE_M`] per channel, when the atmosphere was fitted.
    pub transmittance: Option<[f64; 3]>,
    /// σ(τₐ).
    pub transmittance_sigma: Option<[Option<f64>; 3]>,
    /// Reference distance of `transmittance`, metres.
    pub reference_distance_m: f64,
    /// Horizon colour L∞ used (linear RGB).
    pub horizon_colour: [f64; 3],
    /// Standard deviation of the horizon rectangles' colours (two or more rectangles).
    pub horizon_colour_sigma: Option<[f64; 3]>,
    /// k_s per channel, when the daylight was fitted.
    pub sun_weight: Option<[f64; 3]>,
    /// σ(k_s).
    pub sun_weight_sigma: Option<[Option<f64>; 3]>,
    /// k_u.
    pub ambient_weight: Option<[f64; 3]>,
    /// σ(k_u).
    pub ambient_weight_sigma: Option<[Option<f64>; 3]>,
    /// k_h.
    pub sky_weight: Option<[f64; 3]>,
    /// σ(k_h).
    pub sky_weight_sigma: Option<[Option<f64>; 3]>,
    /// Whether the weights are relative (ρ_d unknown).
    pub weights_relative: bool,
    /// Residuals of both fits.
    pub residuals: Vec<FitResidual>,
    /// Warnings, each naming what it concerns.
    pub warnings: Vec<String>,
    /// Sun cross-checks.
    pub sun_checks: Vec<NamedSunCheck>,
    /// The samples as located and read.
    pub samples: Vec<SampleReading>,
    /// The extinction per metre written to the site (from `transmittance`).
    #[serde(skip)]
    pub extinction_per_m: Option<[f64; 3]>,
}

/// Writes a fit into the site: `[lighting]` weights (when the daylight was fitted),
/// `[lighting.atmosphere]` (extinction when the atmosphere was fitted, the horizon colour always)
/// and the `[fit]` record stamped `fitted_at`.
pub fn apply_fit(site: &mut Site, report: &SiteFitReport, fitted_at: &str) {
    if let Some(e) = report.extinction_per_m {
        site.lighting.atmosphere.extinction_per_m = e;
    }
    site.lighting.atmosphere.horizon_colour = report.horizon_colour;
    if let (Some(s), Some(u), Some(h)) =
        (report.sun_weight, report.ambient_weight, report.sky_weight)
    {
        site.lighting.sun_weight = s;
        site.lighting.ambient_weight = u;
        site.lighting.sky_weight = h;
    }
    let sigma = |s: Option<[Option<f64>; 3]>| s.map(|s| s.map(|v| v.unwrap_or(0.0)));
    let daylight_rms = report
        .residuals
        .iter()
        .filter(|r| r.fit == "daylight" && !r.flagged)
        .fold((0_usize, [0.0_f64; 3]), |(n, acc), r| {
            (n + 1, [0, 1, 2].map(|k| acc[k] + r.residual_rgb[k].powi(2)))
        });
    #[allow(clippy::cast_precision_loss)]
    let rms_residual =
        (daylight_rms.0 > 0).then(|| daylight_rms.1.map(|s| (s / daylight_rms.0 as f64).sqrt()));
    site.fit = Some(FitRecord {
        fitted_at: fitted_at.to_owned(),
        reference_distance_m: report.reference_distance_m,
        transmittance: report.transmittance,
        transmittance_sigma: sigma(report.transmittance_sigma),
        sun_weight_sigma: sigma(report.sun_weight_sigma),
        ambient_weight_sigma: sigma(report.ambient_weight_sigma),
        sky_weight_sigma: sigma(report.sky_weight_sigma),
        weights_relative: report.weights_relative,
        rms_residual,
        flagged_samples: report
            .residuals
            .iter()
            .filter(|r| r.flagged)
            .map(|r| r.sample.clone())
            .collect(),
        warnings: report.warnings.clone(),
    });
}
