//! The inputs of the Perez all-weather sky in the site file (`[lighting.perez]`, read when
//! `sky_model = "perez"`): either the sky clearness ε and brightness Δ directly, or the direct
//! normal and diffuse horizontal irradiance they are computed from (Perez, Seals & Michalsky
//! 1993, as Radiance's `gendaylit`; see [`crate::sky::perez`]).
//!
//! # Known limitations
//! The irradiance form needs the day of the year (for the extraterrestrial irradiance): it is
//! taken from the site's sun time (`lighting.time`, the photo's `taken_at` or EXIF), so a site
//! with a manual sun and no time must give ε and Δ.

use serde::{Deserialize, Serialize};

/// `[lighting.perez]`: ε and Δ, or the two irradiances (not both forms).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerezInputs {
    /// Sky clearness ε (1 … 12; gendaylit's limits are applied).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearness: Option<f64>,
    /// Sky brightness Δ (> 0; limited to 0.01 … 0.6 as gendaylit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brightness: Option<f64>,
    /// Direct normal irradiance E_bn, W/m² (≥ 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direct_normal_w_m2: Option<f64>,
    /// Diffuse horizontal irradiance E_dh, W/m² (> 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diffuse_horizontal_w_m2: Option<f64>,
}

/// Which form `[lighting.perez]` takes, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PerezForm {
    /// Clearness ε and brightness Δ.
    Indices {
        /// ε.
        clearness: f64,
        /// Δ.
        brightness: f64,
    },
    /// Direct normal and diffuse horizontal irradiance, W/m².
    Irradiance {
        /// E_bn.
        direct_normal_w_m2: f64,
        /// E_dh.
        diffuse_horizontal_w_m2: f64,
    },
}

/// A bad `[lighting.perez]`: the field and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {reason}")]
pub struct PerezInputError {
    /// The site-file field, e.g. `lighting.perez.clearness`.
    pub field: &'static str,
    /// What is wrong with it.
    pub reason: String,
}

fn bad(field: &'static str, reason: impl Into<String>) -> PerezInputError {
    PerezInputError {
        field,
        reason: reason.into(),
    }
}

/// ε of [`PerezInputs::gendaylit_example`]: what Radiance's `gendaylit 6 21 12 -a 47 -o -8 -m
/// -15 -W 600 150` reports (`../shared/reference/lighting.md` §3.3, reproduced by
/// `sky::perez`'s test `gendaylit_clearness_and_brightness`).
pub const GENDAYLIT_EXAMPLE_CLEARNESS: f64 = 4.7065;
/// Δ of [`PerezInputs::gendaylit_example`], from the same `gendaylit` run.
pub const GENDAYLIT_EXAMPLE_BRIGHTNESS: f64 = 0.1243;

impl PerezInputs {
    /// The inputs the studio fills in when the Perez sky is chosen for a site without any:
    /// ε = 4.7065 and Δ = 0.1243, the indices Radiance's `gendaylit` computes for a sunny
    /// June noon in central Europe (47°N, 600 W/m² direct normal, 150 W/m² diffuse
    /// horizontal; a sun-bright sky with some haze, clearness bin 6 of 8). Given as ε and Δ,
    /// not as irradiance, so that they need no sun time and every site can use them.
    #[must_use]
    pub fn gendaylit_example() -> Self {
        Self {
            clearness: Some(GENDAYLIT_EXAMPLE_CLEARNESS),
            brightness: Some(GENDAYLIT_EXAMPLE_BRIGHTNESS),
            ..Self::default()
        }
    }

    /// The checked form: exactly one complete pair, each value finite and in range
    /// (ε ≥ 1, Δ > 0, E_bn ≥ 0, E_dh > 0).
    ///
    /// # Errors
    /// [`PerezInputError`] naming the field that is missing, mixed in or out of range.
    pub fn form(&self) -> Result<PerezForm, PerezInputError> {
        let indices = self.clearness.is_some() || self.brightness.is_some();
        let irradiance =
            self.direct_normal_w_m2.is_some() || self.diffuse_horizontal_w_m2.is_some();
        let finite = |field: &'static str, v: Option<f64>| match v {
            None => Err(bad(field, "missing")),
            Some(v) if v.is_finite() => Ok(v),
            Some(v) => Err(bad(field, format!("{v} is not a finite number"))),
        };
        match (indices, irradiance) {
            (true, true) => Err(bad(
                "lighting.perez",
                "give either clearness and brightness or direct_normal_w_m2 and \
                 diffuse_horizontal_w_m2, not both",
            )),
            (false, false) => Err(bad(
                "lighting.perez",
                "sky_model `perez` needs clearness and brightness, or direct_normal_w_m2 and \
                 diffuse_horizontal_w_m2",
            )),
            (true, false) => {
                let clearness = finite("lighting.perez.clearness", self.clearness)?;
                let brightness = finite("lighting.perez.brightness", self.brightness)?;
                if clearness < 1.0 {
                    return Err(bad(
                        "lighting.perez.clearness",
                        format!("{clearness} is below 1 (ε ≥ 1 by definition)"),
                    ));
                }
                if brightness <= 0.0 {
                    return Err(bad(
                        "lighting.perez.brightness",
                        format!("{brightness} must be positive"),
                    ));
                }
                Ok(PerezForm::Indices {
                    clearness,
                    brightness,
                })
            }
            (false, true) => {
                let direct = finite("lighting.perez.direct_normal_w_m2", self.direct_normal_w_m2)?;
                let diffuse = finite(
                    "lighting.perez.diffuse_horizontal_w_m2",
                    self.diffuse_horizontal_w_m2,
                )?;
                if direct < 0.0 {
                    return Err(bad(
                        "lighting.perez.direct_normal_w_m2",
                        format!("{direct} W/m² is negative"),
                    ));
                }
                if diffuse <= 0.0 {
                    return Err(bad(
                        "lighting.perez.diffuse_horizontal_w_m2",
                        format!("{diffuse} W/m² must be positive"),
                    ));
                }
                Ok(PerezForm::Irradiance {
                    direct_normal_w_m2: direct,
                    diffuse_horizontal_w_m2: diffuse,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gendaylit_example_is_a_valid_index_pair() {
        assert_eq!(
            PerezInputs::gendaylit_example().form(),
            Ok(PerezForm::Indices {
                clearness: GENDAYLIT_EXAMPLE_CLEARNESS,
                brightness: GENDAYLIT_EXAMPLE_BRIGHTNESS,
            })
        );
    }
}
