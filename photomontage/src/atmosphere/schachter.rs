//! Schachter's atmospheric model (Schachter 1983, *Computer Image Generation*) as stated by
//! Durisch 1992 §3.2 eq. 2, with its inversions of §4.2:
//!
//! `L = L₀ · τₐ^(d/dₐ) + L∞ · (1 − τₐ^(d/dₐ))`                                   (eq. 2)
//!
//! L₀ true object colour (radiance leaving the object towards the observer), L apparent colour
//! at distance d, L∞ horizon colour (L for d → ∞), τₐ the transmittance over the reference
//! distance dₐ. Everything holds per wavelength (or per RGB channel): every function here works
//! on one channel (`f64`) and [`SchachterAtmosphere`] applies them to a [`Colour`].
//!
//! - **Forward** ([`apparent_radiance`], [`SchachterAtmosphere::apparent`]): the renderer applies
//!   it along every ray with the hit distance (Durisch §6 cases C, D1–D3).
//! - **Second inversion** (eq. 8, [`true_radiance`], [`SchachterAtmosphere::true_colour`]):
//!   `L₀ = (L − L∞) · τₐ^(−d/dₐ) + L∞`, the true colour of a photographed object at a known
//!   distance (Durisch §4.2; §6 case D).
//! - **First inversion** (eq. 7, [`crate::fit::atmosphere::solve_eq7`]): τₐ (and a common L₀) from n ≥ 2 samples
//!   of one material at known distances, given L∞, by [`crate::fit::atmosphere`] (argmin
//!   Gauss–Newton) started, as Durisch does, at τₐ = 1 and L₀ = the nearest sample.
//! - Koschmieder's law ([`transmittance_from_visibility`]) turns a reported visibility into τₐ.
//!
//! # Known limitations
//! The atmosphere is homogeneous and isotropic (Durisch §3.2): no altitude dependence of haze
//! density, no sun-direction dependence of the airlight (L∞ is one colour for all directions).
//! The second inversion divides by τₐ^(d/dₐ): it amplifies photo noise by that factor, so far
//! objects in thick haze come out noisy; [`SchachterAtmosphere::true_colour`] refuses
//! transmissions below [`MIN_INVERTIBLE_TRANSMISSION`]. The eq. 7 fit assumes, like Durisch,
//! that L₀ is the same at every sample.

use thiserror::Error;

use crate::colour::{Colour, MAX_CHANNELS};

/// Smallest `τₐ^(d/dₐ)` the colour-level second inversion accepts: below it the photo's
/// 8-bit quantisation (≈ 4e-3) would be amplified past the full range of the image.
pub const MIN_INVERTIBLE_TRANSMISSION: f64 = 1e-3;

/// Koschmieder's contrast threshold (2 %): visibility `V = ln(50)/σ ≈ 3.912/σ`.
pub const KOSCHMIEDER_CONTRAST: f64 = 0.02;

/// WMO meteorological optical range threshold (5 %): `MOR = ln(20)/σ ≈ 2.996/σ`.
pub const WMO_MOR_CONTRAST: f64 = 0.05;

/// Errors of the atmospheric model.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AtmosphereError {
    /// A transmittance outside (0, 1].
    #[error("transmittance {value} of channel {channel} is outside (0, 1]")]
    InvalidTransmittance {
        /// Channel index.
        channel: usize,
        /// The value.
        value: f64,
    },
    /// A distance that is negative or not finite.
    #[error("distance {value_m} m is invalid (need finite and ≥ 0; reference > 0)")]
    InvalidDistance {
        /// The distance in metres.
        value_m: f64,
    },
    /// The transmission over the distance is too small to invert.
    #[error(
        "transmission {transmission:e} of channel {channel} at {distance_m} m is below {min:e}: too hazy to invert"
    )]
    TooHazyToInvert {
        /// Channel index.
        channel: usize,
        /// Distance in metres.
        distance_m: f64,
        /// τₐ^(d/dₐ).
        transmission: f64,
        /// The accepted minimum.
        min: f64,
    },
    /// Too few samples for the eq. 7 fit.
    #[error("the eq. 7 fit needs {required} samples at distinct distances, found {found}")]
    NotEnoughSamples {
        /// Required count.
        required: usize,
        /// Count given.
        found: usize,
    },
    /// A sample that is not finite.
    #[error("sample {index} is not finite")]
    InvalidSample {
        /// Sample index.
        index: usize,
    },
    /// The samples do not determine τₐ (e.g. all at L∞, so haze is invisible).
    #[error("the samples do not determine the transmittance: {reason}")]
    Undetermined {
        /// Why.
        reason: &'static str,
    },
}

/// `τₐ^(d/dₐ)`: the fraction of light surviving distance `distance_m`.
#[must_use]
pub fn transmission(transmittance: f64, distance_m: f64, reference_distance_m: f64) -> f64 {
    transmittance.powf(distance_m / reference_distance_m)
}

/// Durisch eq. 2: apparent radiance at `distance_m` of an object of true radiance
/// `true_radiance`.
#[must_use]
pub fn apparent_radiance(
    true_radiance: f64,
    horizon_radiance: f64,
    transmittance: f64,
    distance_m: f64,
    reference_distance_m: f64,
) -> f64 {
    let t = transmission(transmittance, distance_m, reference_distance_m);
    true_radiance * t + horizon_radiance * (1.0 - t)
}

/// Durisch eq. 8 (second inversion): true radiance of an object seen with radiance
/// `apparent_radiance` at `distance_m`. Not clamped; infinite when the transmission underflows.
#[must_use]
pub fn true_radiance(
    apparent_radiance: f64,
    horizon_radiance: f64,
    transmittance: f64,
    distance_m: f64,
    reference_distance_m: f64,
) -> f64 {
    let t = transmission(transmittance, distance_m, reference_distance_m);
    (apparent_radiance - horizon_radiance) / t + horizon_radiance
}

/// Koschmieder: the transmittance over `reference_distance_m` for a visibility `visibility_m`
/// defined by `contrast_threshold` ([`KOSCHMIEDER_CONTRAST`] or [`WMO_MOR_CONTRAST`]): a black
/// object at the visibility distance has contrast `contrast_threshold` against the horizon,
/// i.e. `τₐ^(V/dₐ) = threshold`.
#[must_use]
pub fn transmittance_from_visibility(
    visibility_m: f64,
    reference_distance_m: f64,
    contrast_threshold: f64,
) -> f64 {
    contrast_threshold.powf(reference_distance_m / visibility_m)
}

/// A homogeneous atmosphere: per-channel transmittance τₐ over `reference_distance_m` and
/// horizon colour L∞.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SchachterAtmosphere {
    transmittance: Colour,
    horizon: Colour,
    reference_distance_m: f64,
    channels: usize,
    /// `−ln τₐ / dₐ` per channel (extinction coefficient σ, 1/m): `τₐ^(d/dₐ) = e^(−σ d)`,
    /// one `exp` per channel instead of a `powf`.
    extinction_per_m: [f64; MAX_CHANNELS],
}

impl SchachterAtmosphere {
    /// An atmosphere over the first `channels` channels (3 for RGB, the sample count in spectral
    /// mode).
    ///
    /// # Errors
    /// A transmittance outside (0, 1] in a used channel, a non-positive or non-finite reference
    /// distance, or `channels` above [`MAX_CHANNELS`] (reported as an invalid transmittance of
    /// that channel).
    pub fn new(
        transmittance: Colour,
        horizon: Colour,
        reference_distance_m: f64,
        channels: usize,
    ) -> Result<Self, AtmosphereError> {
        if channels > MAX_CHANNELS {
            return Err(AtmosphereError::InvalidTransmittance {
                channel: channels,
                value: f64::NAN,
            });
        }
        if !(reference_distance_m.is_finite() && reference_distance_m > 0.0) {
            return Err(AtmosphereError::InvalidDistance {
                value_m: reference_distance_m,
            });
        }
        for (channel, &t) in transmittance.channels.iter().enumerate().take(channels) {
            if !(t > 0.0 && t <= 1.0) {
                return Err(AtmosphereError::InvalidTransmittance {
                    channel,
                    value: f64::from(t),
                });
            }
        }
        let mut extinction_per_m = [0.0; MAX_CHANNELS];
        for (e, &t) in extinction_per_m
            .iter_mut()
            .zip(&transmittance.channels)
            .take(channels)
        {
            *e = -f64::from(t).ln() / reference_distance_m;
        }
        Ok(Self {
            transmittance,
            horizon,
            reference_distance_m,
            channels,
            extinction_per_m,
        })
    }

    /// No atmosphere: τₐ = 1 in every channel (apparent = true at every distance).
    #[must_use]
    pub fn clear(channels: usize) -> Self {
        let channels = channels.min(MAX_CHANNELS);
        let mut transmittance = Colour::BLACK;
        for t in transmittance.channels.iter_mut().take(channels) {
            *t = 1.0;
        }
        Self {
            transmittance,
            horizon: Colour::BLACK,
            reference_distance_m: 1.0,
            channels,
            extinction_per_m: [0.0; MAX_CHANNELS],
        }
    }

    /// Per-channel transmittance τₐ over the reference distance.
    #[must_use]
    pub fn transmittance(&self) -> Colour {
        self.transmittance
    }

    /// Horizon colour L∞.
    #[must_use]
    pub fn horizon(&self) -> Colour {
        self.horizon
    }

    /// Reference distance dₐ in metres.
    #[must_use]
    pub fn reference_distance_m(&self) -> f64 {
        self.reference_distance_m
    }

    /// Per-channel `τₐ^(d/dₐ)` (unused channels 0).
    #[must_use]
    pub fn transmission(&self, distance_m: f64) -> Colour {
        let mut out = Colour::BLACK;
        for k in 0..self.channels {
            out.channels[k] = self.transmission_f64(k, distance_m) as f32;
        }
        out
    }

    /// `τₐ^(d/dₐ)` of channel `k` in f64 (negative distances count as 0).
    fn transmission_f64(&self, k: usize, distance_m: f64) -> f64 {
        let sigma = self.extinction_per_m[k];
        // σ = 0 (clear air) must give 1 even at infinite distance, not e^(−0·∞) = NaN.
        if sigma == 0.0 {
            1.0
        } else {
            (-sigma * distance_m.max(0.0)).exp()
        }
    }

    /// Eq. 2: the colour seen at `distance_m` (negative distances count as 0, infinity gives the
    /// horizon colour).
    #[must_use]
    pub fn apparent(&self, true_colour: &Colour, distance_m: f64) -> Colour {
        let mut out = Colour::BLACK;
        for k in 0..self.channels {
            let (l0, linf, tk) = (
                f64::from(true_colour.channels[k]),
                f64::from(self.horizon.channels[k]),
                self.transmission_f64(k, distance_m),
            );
            out.channels[k] = (l0 * tk + linf * (1.0 - tk)) as f32;
        }
        out
    }

    /// Eq. 8: the true colour of an object seen as `apparent` at `distance_m`, clamped at 0 (photo
    /// noise can make the exact inverse slightly negative).
    ///
    /// # Errors
    /// [`AtmosphereError::InvalidDistance`] for a negative or non-finite distance;
    /// [`AtmosphereError::TooHazyToInvert`] when a channel's transmission is below
    /// [`MIN_INVERTIBLE_TRANSMISSION`].
    pub fn true_colour(
        &self,
        apparent: &Colour,
        distance_m: f64,
    ) -> Result<Colour, AtmosphereError> {
        if !(distance_m.is_finite() && distance_m >= 0.0) {
            return Err(AtmosphereError::InvalidDistance {
                value_m: distance_m,
            });
        }
        let mut out = Colour::BLACK;
        for k in 0..self.channels {
            let t = self.transmission_f64(k, distance_m);
            if t < MIN_INVERTIBLE_TRANSMISSION {
                return Err(AtmosphereError::TooHazyToInvert {
                    channel: k,
                    distance_m,
                    transmission: t,
                    min: MIN_INVERTIBLE_TRANSMISSION,
                });
            }
            let linf = f64::from(self.horizon.channels[k]);
            let l = f64::from(apparent.channels[k]);
            out.channels[k] = ((l - linf) / t + linf).max(0.0) as f32;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
