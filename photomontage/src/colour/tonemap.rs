//! Display encoding: linear HDR RGB → 8-bit sRGB for screens, PNG and JPEG only
//! (Cohen & Wallace 1993 §9.6.3: keep floating point until "the final display stage").
//!
//! The steps, in order, for each channel of linear RGB (sRGB primaries):
//! 1. **Exposure**: multiply by `2^exposure_stops` (a photographic exposure change).
//! 2. **Tone curve** ([`ToneCurve`]): `Clamp` (identity, then clip to [0, 1]); `Reinhard`
//!    `x/(1 + x)` (Reinhard et al. 2002 eq. 3, per channel); `AcesFilmic`, Narkowicz's 2015 fit of
//!    the ACES reference rendering transform, `x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14)`.
//! 3. **Clip** to [0, 1] (NaN and negatives → 0).
//! 4. **Encode** with the sRGB transfer function (IEC 61966-2-1) and **quantise**
//!    `round(255 · V)`. [`encode_srgb8`] does steps 4 exactly but without a `powf`: the code is
//!    the number of the 255 linear thresholds `decode((k + ½)/255)` at or below the value
//!    (a binary search in a table built once).
//!
//! # Known limitations
//! The curves act per channel, so very bright saturated colours desaturate towards white (no
//! hue-preserving mapping) and out-of-gamut colours are clipped rather than gamut-mapped. No
//! dithering before quantisation.

use std::sync::OnceLock;

/// Tone curve applied after exposure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum ToneCurve {
    /// Identity, then clip to [0, 1]: colorimetrically exact inside [0, 1].
    #[default]
    Clamp,
    /// Reinhard `x / (1 + x)`: compresses all of [0, ∞) into [0, 1).
    Reinhard,
    /// Narkowicz's ACES filmic fit.
    AcesFilmic,
}

impl ToneCurve {
    /// The curve applied to one linear value (before clipping).
    #[must_use]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Self::Clamp => x,
            Self::Reinhard => x / (1.0 + x),
            Self::AcesFilmic => x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14),
        }
    }
}

/// Exposure and tone curve of the display encoding.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ToneMap {
    /// Exposure change in stops: linear values are multiplied by `2^exposure_stops`.
    pub exposure_stops: f64,
    /// Curve applied after exposure.
    pub curve: ToneCurve,
}

impl ToneMap {
    /// Exact colorimetry for values in [0, 1]: no exposure change, clip.
    #[must_use]
    pub fn clamp() -> Self {
        Self::default()
    }

    /// Clip after multiplying by `exposure` (a linear multiplier, as the site's
    /// `render.exposure`): the 8-bit output of renders.
    #[must_use]
    pub fn clamp_with_exposure(exposure: f64) -> Self {
        Self {
            exposure_stops: exposure.log2(),
            curve: ToneCurve::Clamp,
        }
    }

    /// Reinhard with an exposure change.
    #[must_use]
    pub fn reinhard(exposure_stops: f64) -> Self {
        Self {
            exposure_stops,
            curve: ToneCurve::Reinhard,
        }
    }

    /// ACES filmic fit with an exposure change.
    #[must_use]
    pub fn aces(exposure_stops: f64) -> Self {
        Self {
            exposure_stops,
            curve: ToneCurve::AcesFilmic,
        }
    }

    /// One linear channel → display value in [0, 1] (steps 1–3 and the sRGB encoding).
    #[must_use]
    pub fn display_value(&self, linear: f64) -> f64 {
        self.display_value_scaled(linear * self.exposure_stops.exp2())
    }

    /// Steps 2–4 for a value already multiplied by the exposure scale.
    fn display_value_scaled(&self, exposed: f64) -> f64 {
        let toned = self.curve.apply(exposed.max(0.0));
        let clipped = if toned.is_nan() {
            0.0
        } else {
            toned.clamp(0.0, 1.0)
        };
        super::rgb::srgb_encode(clipped)
    }
}

/// Linear values at which the 8-bit sRGB code steps from k to k + 1: `decode((k + ½)/255)`.
fn srgb8_thresholds() -> &'static [f64; 255] {
    static THRESHOLDS: OnceLock<[f64; 255]> = OnceLock::new();
    THRESHOLDS
        .get_or_init(|| std::array::from_fn(|k| super::rgb::srgb_decode((k as f64 + 0.5) / 255.0)))
}

/// Linear sRGB (HDR, any magnitude) → 8-bit sRGB through `tone_map`. NaN and negative
/// channels become 0.
#[must_use]
pub fn encode_srgb8(linear_rgb: [f32; 3], tone_map: &ToneMap) -> [u8; 3] {
    let scale = tone_map.exposure_stops.exp2();
    let thresholds = srgb8_thresholds();
    linear_rgb.map(|v| {
        let toned = tone_map.curve.apply((f64::from(v) * scale).max(0.0));
        // NaN compares false everywhere and gives 0; at most 255 thresholds, so the count fits.
        thresholds.partition_point(|&t| t <= toned) as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_search_equals_direct_rounding() {
        // The table lookup must give round(255 · encode(tone(x))) for every value; exact ties,
        // where the two could differ by floating-point rounding, do not occur on this grid.
        for tm in [
            ToneMap::clamp(),
            ToneMap::reinhard(1.0),
            ToneMap::aces(-0.5),
        ] {
            for k in 0..=200_000_u32 {
                let x = k as f32 / 150_000.0;
                let direct = (255.0 * tm.display_value(f64::from(x))).round() as u8;
                assert_eq!(encode_srgb8([x; 3], &tm)[0], direct, "{tm:?} x = {x}");
            }
        }
    }

    #[test]
    fn clamp_known_codes() {
        let t = ToneMap::clamp();
        assert_eq!(encode_srgb8([0.0, 1.0, 2.0], &t), [0, 255, 255]);
        // 18 % grey → 0.461356 → 117.65 → 118; linear 0.5 → 0.735357 → 187.5 → 188;
        // decode(128/255) = 0.2158605 encodes back to exactly 128.
        assert_eq!(encode_srgb8([0.18, 0.5, 0.215_860_5], &t), [118, 188, 128]);
        // Negative and NaN are black.
        assert_eq!(encode_srgb8([-1.0, f32::NAN, 0.0], &t), [0, 0, 0]);
        // Infinity saturates.
        assert_eq!(encode_srgb8([f32::INFINITY; 3], &t), [255, 255, 255]);
    }

    #[test]
    fn exposure_is_a_power_of_two() {
        // One stop down from 0.36 is 0.18.
        let t = ToneMap {
            exposure_stops: -1.0,
            curve: ToneCurve::Clamp,
        };
        assert_eq!(encode_srgb8([0.36, 0.36, 0.36], &t), [118, 118, 118]);
    }

    #[test]
    fn curves_known_values() {
        // Reinhard: x = 1 → 1/2 exactly; its sRGB code is 188 as above.
        assert!((ToneCurve::Reinhard.apply(1.0) - 0.5).abs() < 1e-15);
        assert_eq!(
            encode_srgb8([1.0; 3], &ToneMap::reinhard(0.0)),
            [188, 188, 188]
        );
        // ACES fit: f(0) = 0, f(1) = 2.54 / 3.16, f → 2.51/2.43 > 1 (clipped to white).
        assert!(ToneCurve::AcesFilmic.apply(0.0).abs() < 1e-15);
        assert!((ToneCurve::AcesFilmic.apply(1.0) - 2.54 / 3.16).abs() < 1e-15);
        assert_eq!(encode_srgb8([1e6; 3], &ToneMap::aces(0.0)), [255, 255, 255]);
        // Monotonic on a grid.
        for curve in [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::AcesFilmic] {
            let t = ToneMap {
                exposure_stops: 0.0,
                curve,
            };
            let mut last = 0;
            for k in 0..2000 {
                let code = encode_srgb8([k as f32 / 200.0; 3], &t)[0];
                assert!(code >= last, "{curve:?} not monotonic at {k}");
                last = code;
            }
        }
    }
}
