//! The site file's tables for the lighting fit (Durisch 1992 §4.2–4.3): colour samples, horizon
//! samples, sun/shadow pairs, the fit settings and the record of the last fit
//! (`docs/site-format.md`).

use serde::{Deserialize, Serialize};

use super::default_true;

fn default_window_px() -> u32 {
    5
}

/// What a colour sample is used for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplePurpose {
    /// The atmosphere's first inversion (eq. 7): one material, same illumination, different
    /// distances.
    Atmosphere,
    /// The daylight first inversion (eq. 9): one material, different illumination.
    #[default]
    Daylight,
}

/// A point on a scene polygon whose colour is read from a photo (Durisch 1992 §4.2–4.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sample {
    /// Unique sample id.
    pub id: String,
    /// The photo the colour is read from (and whose camera gives the distance).
    pub photo: String,
    /// Material of the polygon the sample lies on.
    pub material: String,
    /// Which fit uses the sample.
    #[serde(default)]
    pub purpose: SamplePurpose,
    /// World point (metres); projected into the photo. Give either this or `x_px`/`y_px`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    /// Pixel x in the photo; the ray through it is intersected with the scene polygons.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_px: Option<f64>,
    /// Pixel y in the photo.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_px: Option<f64>,
    /// Edge of the square window the median colour is taken over (odd, 1–101).
    #[serde(default = "default_window_px")]
    pub window_px: u32,
    /// Disabled samples are kept but not used.
    #[serde(default = "default_true")]
    pub enabled: bool,
}

/// A rectangle of sky at the horizon in a photo: its median colour is L∞.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HorizonSample {
    /// Unique id.
    pub id: String,
    /// The photo.
    pub photo: String,
    /// Top-left pixel [x, y] of the rectangle.
    pub origin_px: [u32; 2],
    /// Width and height in pixels (1–4096 each).
    pub size_px: [u32; 2],
    /// Disabled samples are kept but not used.
    #[serde(default = "default_true")]
    pub enabled: bool,
}

/// An object point and the point where its shadow falls, for the sun cross-check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunShadowPair {
    /// Unique id.
    pub id: String,
    /// Id of the point that casts the shadow (control or tie point).
    pub object_point: String,
    /// Id of the point where its shadow falls.
    pub shadow_point: String,
    /// The photo whose time is checked.
    pub photo: String,
}

/// Settings of the daylight fit (`[fit_settings]`; the record of a fit is `[fit]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitSettings {
    /// Subtract the light the photographed surroundings reflect onto each daylight sample
    /// (gathered from its photo) before fitting eq. 9; used only with absolute weights (every
    /// sample's material has a diffuse reflectance in the library).
    pub interreflection: bool,
    /// Fit the ambient weight k_u (Durisch eq. 4); `false` fixes k_u = 0, the sky model then
    /// carrying all diffuse light.
    pub ambient: bool,
}

impl Default for FitSettings {
    /// Interreflection on, ambient fitted (as the paper).
    fn default() -> Self {
        Self {
            interreflection: true,
            ambient: true,
        }
    }
}

impl FitSettings {
    /// Whether these are the defaults (not written to the site file then).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// The record of the last lighting fit (the fitted values themselves go into `[lighting]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// When the fit ran (RFC 3339, UTC).
    pub fitted_at: String,
    /// Reference distance dₐ of `transmittance`, metres.
    pub reference_distance_m: f64,
    /// τₐ over the reference distance per channel (from eq. 7), when the atmosphere was fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<[f64; 3]>,
    /// σ(τₐ) per channel (absent without redundancy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance_sigma: Option<[f64; 3]>,
    /// σ of `lighting.sun_weight` per channel (0 where the weight sits at its bound 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_weight_sigma: Option<[f64; 3]>,
    /// σ of `lighting.ambient_weight`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient_weight_sigma: Option<[f64; 3]>,
    /// σ of `lighting.sky_weight`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sky_weight_sigma: Option<[f64; 3]>,
    /// Whether the weights are relative (the material's reflectance unknown, ρ_d = 1 assumed).
    #[serde(default)]
    pub weights_relative: bool,
    /// RMS residual of the daylight fit per channel (true colour, linear units).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_residual: Option<[f64; 3]>,
    /// Samples dropped as outliers.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flagged_samples: Vec<String>,
    /// Warnings of the fit.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}
