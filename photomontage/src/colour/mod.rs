//! Colour: CIE 1931 colorimetry, RGB colour spaces, spectra and their sample sets, and the
//! colour value the renderer carries (Durisch 1992 §3 and Appendix A; Cohen & Wallace 1993
//! §9.6).
//!
//! The renderer works in one [`ColourMode`]: **RGB** (three linear channels of an
//! [`RgbColourSpace`]) or **spectral** (the samples of a [`SampleSet`]). Either way a pixel or ray
//! carries a [`Colour`]: a fixed-size value of up to [`MAX_CHANNELS`] `f32` channels with
//! channel-wise `+`, `-`, `*` and scalar `*`, `/`. Radiance stays floating point (HDR)
//! throughout, as Cohen & Wallace §9.6.3 require; 8-bit sRGB appears only at output
//! ([`tonemap`]). A [`ColourSystem`] bundles the mode with its conversions:
//! `from_linear_rgb` (photo pixels and material colours → channels, Appendix A in spectral mode)
//! and `to_linear_rgb` (channels → display RGB, via XYZ in spectral mode).
//!
//! ```
//! use photomontage::colour::{ColourMode, ColourSystem, RgbColourSpace, SampleSet, ToneMap};
//! use photomontage::colour::{encode_srgb8, rgb::srgb_decode};
//!
//! let system = ColourSystem::new(ColourMode::Spectral(SampleSet::Durisch9), RgbColourSpace::srgb())?;
//! // A photo pixel (8-bit sRGB) → linear → 9 non-negative spectral samples.
//! let linear = [200u8, 120, 40].map(|v| srgb_decode(f64::from(v) / 255.0) as f32);
//! let reflectance = system.from_linear_rgb(linear);
//! let lit = reflectance * 0.5; // half the light
//! let out = encode_srgb8(system.to_linear_rgb(&lit), &ToneMap::clamp());
//! assert!(out[0] > out[1] && out[1] > out[2]);
//! # Ok::<(), photomontage::colour::SpectrumError>(())
//! ```
//!
//! # Known limitations
//! Channels are `f32` (about 7 significant digits), enough for radiance but not for accumulating
//! very many small contributions without care. Spectral mode uses at most 9 samples; finer
//! samplings are available through [`spectrum::RgbToSpectrum`] on `Vec<f64>` only.

pub mod cie1931;
pub mod cie_tables;
pub mod cielab;
pub mod designer;
pub mod ral_design;
pub mod rgb;
pub mod spectrum;
pub mod tonemap;

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

use serde::{Deserialize, Serialize};

pub use rgb::{Primaries, RgbColourSpace, RgbError};
pub use spectrum::{RgbToSpectrum, SampleSet, SpectralSampling, SpectrumError};
pub use tonemap::{ToneCurve, ToneMap, encode_srgb8};

/// Largest number of channels a [`Colour`] holds (Durisch's 9 samples).
pub const MAX_CHANNELS: usize = 9;

/// How the renderer represents colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ColourMode {
    /// Three linear RGB channels.
    Rgb,
    /// Spectral samples of a sample set.
    Spectral(SampleSet),
}

impl ColourMode {
    /// Number of channels used in this mode.
    #[must_use]
    pub const fn channels(self) -> usize {
        match self {
            Self::Rgb => 3,
            Self::Spectral(set) => set.len(),
        }
    }
}

/// A radiance (or reflectance, transmittance) value: up to [`MAX_CHANNELS`] floating-point
/// channels; channels beyond the mode's count are zero. Arithmetic is channel-wise.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Colour {
    /// The channels (RGB: r, g, b; spectral: the samples in wavelength order).
    pub channels: [f32; MAX_CHANNELS],
}

impl Colour {
    /// All channels zero (black).
    pub const BLACK: Self = Self {
        channels: [0.0; MAX_CHANNELS],
    };

    /// The first `mode.channels()` channels set to `value`, the rest zero.
    #[must_use]
    pub fn splat(value: f32, mode: ColourMode) -> Self {
        let mut c = Self::BLACK;
        for v in c.channels.iter_mut().take(mode.channels()) {
            *v = value;
        }
        c
    }

    /// From a slice (at most [`MAX_CHANNELS`] values are taken).
    #[must_use]
    pub fn from_slice(values: &[f32]) -> Self {
        let mut c = Self::BLACK;
        for (d, s) in c.channels.iter_mut().zip(values) {
            *d = *s;
        }
        c
    }

    /// Channel-wise map.
    #[must_use]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self {
            channels: self.channels.map(f),
        }
    }

    /// Largest channel.
    #[must_use]
    pub fn max_channel(&self) -> f32 {
        self.channels
            .iter()
            .copied()
            .fold(f32::NEG_INFINITY, f32::max)
    }

    /// True when every channel is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.channels.iter().all(|v| v.is_finite())
    }
}

impl Add for Colour {
    type Output = Self;
    fn add(mut self, rhs: Self) -> Self {
        self += rhs;
        self
    }
}

impl AddAssign for Colour {
    fn add_assign(&mut self, rhs: Self) {
        for (a, b) in self.channels.iter_mut().zip(rhs.channels) {
            *a += b;
        }
    }
}

impl Sub for Colour {
    type Output = Self;
    fn sub(mut self, rhs: Self) -> Self {
        for (a, b) in self.channels.iter_mut().zip(rhs.channels) {
            *a -= b;
        }
        self
    }
}

impl Mul for Colour {
    type Output = Self;
    fn mul(mut self, rhs: Self) -> Self {
        self *= rhs;
        self
    }
}

impl MulAssign for Colour {
    fn mul_assign(&mut self, rhs: Self) {
        for (a, b) in self.channels.iter_mut().zip(rhs.channels) {
            *a *= b;
        }
    }
}

impl Mul<f32> for Colour {
    type Output = Self;
    fn mul(self, rhs: f32) -> Self {
        self.map(|v| v * rhs)
    }
}

impl MulAssign<f32> for Colour {
    fn mul_assign(&mut self, rhs: f32) {
        for a in &mut self.channels {
            *a *= rhs;
        }
    }
}

impl Div<f32> for Colour {
    type Output = Self;
    fn div(self, rhs: f32) -> Self {
        self.map(|v| v / rhs)
    }
}

/// A colour mode with its conversions, built once per render.
#[derive(Debug, Clone)]
pub struct ColourSystem {
    mode: ColourMode,
    space: RgbColourSpace,
    upsampler: Option<RgbToSpectrum>,
}

impl ColourSystem {
    /// Builds the conversions for `mode`; `space` is the RGB space of the input photos and of
    /// the output (sRGB for ordinary images).
    ///
    /// # Errors
    /// [`SpectrumError`] when the spectral basis cannot be built (see [`RgbToSpectrum::new`]).
    pub fn new(mode: ColourMode, space: RgbColourSpace) -> Result<Self, SpectrumError> {
        let upsampler = match mode {
            ColourMode::Rgb => None,
            ColourMode::Spectral(set) => Some(RgbToSpectrum::for_sample_set(space, set)?),
        };
        Ok(Self {
            mode,
            space,
            upsampler,
        })
    }

    /// The mode.
    #[must_use]
    pub fn mode(&self) -> ColourMode {
        self.mode
    }

    /// The RGB space of input and output.
    #[must_use]
    pub fn space(&self) -> &RgbColourSpace {
        &self.space
    }

    /// Linear RGB (of [`Self::space`]) → channels. Spectral mode: Durisch Appendix A
    /// (non-negative spectrum; negative RGB clamped to zero).
    #[must_use]
    pub fn from_linear_rgb(&self, rgb: [f32; 3]) -> Colour {
        match &self.upsampler {
            None => Colour::from_slice(&rgb),
            Some(up) => {
                let mut s = [0.0_f64; MAX_CHANNELS];
                up.spectrum_into(rgb.map(f64::from), &mut s);
                let mut c = Colour::BLACK;
                for (d, v) in c.channels.iter_mut().zip(s) {
                    *d = v as f32;
                }
                c
            }
        }
    }

    /// Channels → linear RGB of [`Self::space`] (spectral mode: spectrum → XYZ → RGB).
    #[must_use]
    pub fn to_linear_rgb(&self, colour: &Colour) -> [f32; 3] {
        match &self.upsampler {
            None => [colour.channels[0], colour.channels[1], colour.channels[2]],
            Some(up) => {
                let n = up.sampling().len();
                let mut s = [0.0_f64; MAX_CHANNELS];
                for (d, v) in s.iter_mut().zip(colour.channels).take(n) {
                    *d = f64::from(v);
                }
                up.rgb(&s[..n]).map(|v| v as f32)
            }
        }
    }

    /// Tristimulus values of a colour (Y is relative luminance, 1 for RGB white).
    #[must_use]
    pub fn to_xyz(&self, colour: &Colour) -> [f64; 3] {
        match &self.upsampler {
            None => self
                .space
                .to_xyz([0, 1, 2].map(|i| f64::from(colour.channels[i]))),
            Some(up) => {
                let s = colour.channels.map(f64::from);
                up.sampling().xyz(&s)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f32 channels carry ~7 significant digits; a conversion through them loses ~1e-7
    /// relative, so 1e-5 absolute on values ≤ 1 leaves margin without hiding real errors.
    const F32_ROUND_TRIP_TOL: f32 = 1e-5;

    #[test]
    fn arithmetic_is_channel_wise() {
        let a = Colour::from_slice(&[1.0, 2.0, 3.0]);
        let b = Colour::from_slice(&[0.5, 0.25, 2.0]);
        assert_eq!((a + b).channels[..3], [1.5, 2.25, 5.0]);
        assert_eq!((a - b).channels[..3], [0.5, 1.75, 1.0]);
        assert_eq!((a * b).channels[..3], [0.5, 0.5, 6.0]);
        assert_eq!((a * 2.0).channels[..3], [2.0, 4.0, 6.0]);
        assert_eq!((a / 2.0).channels[..3], [0.5, 1.0, 1.5]);
        assert_eq!((a + b).channels[3..], [0.0; 6]);
        assert!((a * f32::NAN).channels.iter().take(3).all(|v| v.is_nan()));
        assert!(!(a * f32::NAN).is_finite());
        assert_eq!(
            Colour::splat(1.0, ColourMode::Spectral(SampleSet::Meyer4)).channels[..5],
            [1.0, 1.0, 1.0, 1.0, 0.0]
        );
    }

    #[test]
    fn settings_serialise() {
        let mode = ColourMode::Spectral(SampleSet::Durisch9);
        let json = serde_json::to_string(&mode).unwrap();
        assert_eq!(json, r#"{"Spectral":"Durisch9"}"#);
        assert_eq!(serde_json::from_str::<ColourMode>(&json).unwrap(), mode);
        let tm = ToneMap::aces(-1.5);
        let back: ToneMap = serde_json::from_str(&serde_json::to_string(&tm).unwrap()).unwrap();
        assert_eq!(back, tm);
    }

    #[test]
    fn modes_round_trip_rgb() {
        for mode in [ColourMode::Rgb, ColourMode::Spectral(SampleSet::Durisch9)] {
            let sys = ColourSystem::new(mode, RgbColourSpace::srgb()).unwrap();
            for rgb in [
                [0.2, 0.5, 0.9],
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 0.0],
                [4.0, 3.0, 0.5],
            ] {
                let c = sys.from_linear_rgb(rgb);
                assert!(c.channels.iter().all(|&v| v >= 0.0));
                let back = sys.to_linear_rgb(&c);
                for k in 0..3 {
                    let tol = F32_ROUND_TRIP_TOL * rgb[k].max(1.0);
                    assert!(
                        (back[k] - rgb[k]).abs() < tol,
                        "{mode:?} {rgb:?} → {back:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn white_has_unit_luminance_in_every_mode() {
        for mode in [
            ColourMode::Rgb,
            ColourMode::Spectral(SampleSet::Durisch9),
            ColourMode::Spectral(SampleSet::Meyer4),
        ] {
            let sys = ColourSystem::new(mode, RgbColourSpace::srgb()).unwrap();
            let y = sys.to_xyz(&sys.from_linear_rgb([1.0, 1.0, 1.0]))[1];
            // Meyer's green is clamped (see spectrum's limitations), which costs white some Y.
            let tol = if mode == ColourMode::Spectral(SampleSet::Meyer4) {
                0.1
            } else {
                1e-5
            };
            assert!((y - 1.0).abs() < tol, "{mode:?}: Y = {y}");
        }
    }
}
