//! Sampled spectra, spectral sample sets, and RGB → non-negative spectrum by Durisch 1992
//! Appendix A (eq. 14–19, with its fallback for chromaticities near the spectrum locus).
//!
//! A [`SpectralSampling`] is a list of sample wavelengths with, for each, the weights that turn
//! the sample value into tristimulus values: `XYZ = Σ_k value_k · xyz_weight_k` (a quadrature of
//! Durisch eq. 11). Weights are normalised (`k` of eq. 11) so that a spectrum of constant value 1
//! over 360–830 nm has Y = 1. Sample sets:
//! - **Durisch's 9** ([`SampleSet::Durisch9`]): Durisch §7 reduces spectra "to a total of 9
//!   spectral samples within the visible spectrum" without saying where; we use nine equal-width
//!   bands covering his integration range 380–780 nm (eq. 11), each sample being the mean spectral
//!   radiance over its band (box reconstruction, matching the piecewise-constant spectra of
//!   Appendix A).
//! - **Meyer's 4** ([`SampleSet::Meyer4`]): point samples at 456.4, 490.9, 557.7, 631.4 nm with
//!   the XYZ weights of Cohen & Wallace 1993 eq. 9.24 (Meyer 1988).
//! - Any band or point list ([`SpectralSampling::bands`], [`SpectralSampling::cie_1nm`]).
//!
//! [`RgbToSpectrum`] implements Appendix A on any sampling: for each primary it searches all
//! transition pairs λ2 < λ3 (on the sampling's own boundaries) for a three-step spectrum with the
//! primary's tristimulus values and non-negative steps, keeping the one whose largest step is
//! smallest; when none exists (chromaticities near the locus) it takes the one-step
//! (band-pass or band-stop) candidate of equal Y closest in XYZ. Then `c = W⁻¹ · RGB` (eq. 17)
//! and `L = Σ c_i L_i` (eq. 14).
//!
//! # Known limitations
//! When a primary needs the fallback its basis spectrum has a different chromaticity, so
//! `W⁻¹` has negative entries and some in-gamut colours would need negative weights; those are
//! clamped to zero (spectra stay non-negative) and the round trip is then inexact near that
//! primary. This happens for NTSC red (0.67, 0.33), which lies just outside the 1931 spectrum
//! locus (z = 0 needs λ ≥ 650 nm, where x ≥ 0.726): round-trip error 2e-4 at 1 nm, 2.5e-3 on
//! Durisch's 9 bands; and for sRGB green with Meyer's 4 samples (it lies outside the cone of
//! eq. 9.24's columns, so no non-negative 4-sample spectrum reproduces it). sRGB needs no
//! fallback on the 1 nm or 9-band samplings. RGB components below zero (outside the gamut) are
//! clamped too. The spectra are piecewise constant (6 transitions), not smooth.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::cie_tables::CIE1931_2DEG_1NM;
use super::cie1931::{cmf, cmf_band_integral};
use super::rgb::RgbColourSpace;

/// Most samples a [`SpectralSampling`] may hold (bounds allocations from untrusted counts).
pub const MAX_SAMPLES: usize = 4096;

/// Meyer's four wavelengths (Cohen & Wallace 1993 §9.6.4), nm.
pub const MEYER4_WAVELENGTHS_NM: [f64; 4] = [456.4, 490.9, 557.7, 631.4];

/// Cohen & Wallace 1993 eq. 9.24: rows X, Y, Z; columns the energies at
/// [`MEYER4_WAVELENGTHS_NM`]. Published normalisation (equal energy 1 gives X ≈ Y ≈ Z ≈ 1.058).
#[rustfmt::skip]
pub const MEYER4_EQ_9_24: [[f64; 4]; 3] = [
    [ 0.1986, -0.0569, 0.4934,  0.4228],
    [-0.0034,  0.1856, 0.6770,  0.1998],
    [ 0.9632,  0.0931, 0.0806, -0.0791],
];

/// First and last wavelength of Durisch's integration range (eq. 11), nm.
pub const DURISCH_RANGE_NM: [f64; 2] = [380.0, 780.0];

/// Errors of spectral sampling and RGB → spectrum conversion.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SpectrumError {
    /// A sampling needs at least `required` samples.
    #[error("a sampling needs at least {required} samples, found {found}")]
    TooFewSamples {
        /// Minimum count.
        required: usize,
        /// Count given.
        found: usize,
    },
    /// More samples than [`MAX_SAMPLES`].
    #[error("{found} samples exceed the limit of {max}")]
    TooManySamples {
        /// The limit.
        max: usize,
        /// Count given.
        found: usize,
    },
    /// Wavelength and weight lists, or a spectrum and its sampling, differ in length.
    #[error("length mismatch: expected {expected}, found {found}")]
    LengthMismatch {
        /// Expected length.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A wavelength, band edge or weight is not finite or not increasing.
    #[error("sample {index} is invalid: {reason}")]
    InvalidSample {
        /// Index of the offending entry.
        index: usize,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// No basis spectrum could be found for a primary (no candidate with positive Y).
    #[error("no basis spectrum found for primary {primary}")]
    NoBasis {
        /// 0 red, 1 green, 2 blue.
        primary: usize,
    },
    /// The basis spectra are linearly dependent (eq. 16's W is singular).
    #[error("the basis spectra are linearly dependent (det W = {determinant:e})")]
    SingularBasis {
        /// Determinant of W.
        determinant: f64,
    },
}

/// Spectral sample sets for the renderer's spectral mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SampleSet {
    /// Nine equal bands over 380–780 nm (Durisch 1992 §7).
    Durisch9,
    /// Meyer's four wavelengths with Cohen & Wallace eq. 9.24 weights.
    Meyer4,
}

impl SampleSet {
    /// Number of samples.
    #[must_use]
    pub const fn len(self) -> usize {
        match self {
            Self::Durisch9 => 9,
            Self::Meyer4 => 4,
        }
    }

    /// Always false: every set has samples (for clippy's `len_without_is_empty`).
    #[must_use]
    pub const fn is_empty(self) -> bool {
        false
    }

    /// The sampling (wavelengths and XYZ weights) of this set.
    #[must_use]
    pub fn sampling(self) -> SpectralSampling {
        match self {
            Self::Durisch9 => {
                let [lo, hi] = DURISCH_RANGE_NM;
                let edges: Vec<f64> = (0..=9)
                    .map(|k| lo + (hi - lo) * f64::from(k) / 9.0)
                    .collect();
                SpectralSampling::bands_unchecked(&edges)
            }
            Self::Meyer4 => {
                let y_sum: f64 = MEYER4_EQ_9_24[1].iter().sum();
                let weights = (0..4)
                    .map(|k| {
                        [
                            MEYER4_EQ_9_24[0][k] / y_sum,
                            MEYER4_EQ_9_24[1][k] / y_sum,
                            MEYER4_EQ_9_24[2][k] / y_sum,
                        ]
                    })
                    .collect();
                SpectralSampling {
                    wavelengths_nm: MEYER4_WAVELENGTHS_NM.to_vec(),
                    xyz_weights: weights,
                }
            }
        }
    }
}

/// Σ ȳ Δλ of the 1 nm table (equal-energy Y), the normalisation of every sampling.
fn equal_energy_y() -> f64 {
    CIE1931_2DEG_1NM.iter().map(|r| r[1]).sum()
}

/// Sample wavelengths with their tristimulus weights: `XYZ = Σ value_k · xyz_weights[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralSampling {
    wavelengths_nm: Vec<f64>,
    xyz_weights: Vec<[f64; 3]>,
}

impl SpectralSampling {
    /// A sampling from explicit wavelengths and weights (already normalised by the caller).
    ///
    /// # Errors
    /// Length mismatch, more than [`MAX_SAMPLES`] or fewer than 3 samples, non-finite or
    /// non-increasing wavelengths, non-finite weights.
    pub fn new(
        wavelengths_nm: Vec<f64>,
        xyz_weights: Vec<[f64; 3]>,
    ) -> Result<Self, SpectrumError> {
        check_count(wavelengths_nm.len())?;
        if xyz_weights.len() != wavelengths_nm.len() {
            return Err(SpectrumError::LengthMismatch {
                expected: wavelengths_nm.len(),
                found: xyz_weights.len(),
            });
        }
        check_increasing(&wavelengths_nm)?;
        if let Some(index) = xyz_weights
            .iter()
            .position(|w| !w.iter().all(|v| v.is_finite()))
        {
            return Err(SpectrumError::InvalidSample {
                index,
                reason: "weight is not finite",
            });
        }
        Ok(Self {
            wavelengths_nm,
            xyz_weights,
        })
    }

    /// Box bands between consecutive `edges_nm`: each sample is the mean spectral value over its
    /// band, its wavelength the band centre, its weights `∫_band [x̄, ȳ, z̄] dλ / Σ ȳ Δλ`.
    ///
    /// # Errors
    /// Fewer than 4 or more than [`MAX_SAMPLES`] + 1 edges; non-finite or non-increasing edges.
    pub fn bands(edges_nm: &[f64]) -> Result<Self, SpectrumError> {
        check_count(edges_nm.len().saturating_sub(1))?;
        check_increasing(edges_nm)?;
        Ok(Self::bands_unchecked(edges_nm))
    }

    fn bands_unchecked(edges_nm: &[f64]) -> Self {
        let norm = equal_energy_y();
        let (wavelengths_nm, xyz_weights) = edges_nm
            .windows(2)
            .map(|e| {
                let w = cmf_band_integral(e[0], e[1]);
                (0.5 * (e[0] + e[1]), [w[0] / norm, w[1] / norm, w[2] / norm])
            })
            .unzip();
        Self {
            wavelengths_nm,
            xyz_weights,
        }
    }

    /// Point samples every 1 nm from `first_nm` to `last_nm` (integers within 360–830) with the
    /// CIE 015 summation weights `[x̄, ȳ, z̄](λ) · 1 nm / Σ ȳ Δλ`: Durisch's Appendix A on the
    /// full tabulated resolution.
    ///
    /// # Errors
    /// Fewer than 3 samples or more than [`MAX_SAMPLES`]; non-finite bounds.
    pub fn cie_1nm(first_nm: u32, last_nm: u32) -> Result<Self, SpectrumError> {
        let count = (last_nm.saturating_sub(first_nm) as usize) + 1;
        check_count(count)?;
        let norm = equal_energy_y();
        let wavelengths_nm: Vec<f64> = (first_nm..=last_nm).map(f64::from).collect();
        let xyz_weights = wavelengths_nm
            .iter()
            .map(|&l| {
                let w = cmf(l);
                [w[0] / norm, w[1] / norm, w[2] / norm]
            })
            .collect();
        Ok(Self {
            wavelengths_nm,
            xyz_weights,
        })
    }

    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.wavelengths_nm.len()
    }

    /// Always false: a valid sampling has at least three samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.wavelengths_nm.is_empty()
    }

    /// Sample wavelengths (band centres for band samplings), nm.
    #[must_use]
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// Tristimulus weight of each sample.
    #[must_use]
    pub fn xyz_weights(&self) -> &[[f64; 3]] {
        &self.xyz_weights
    }

    /// Tristimulus values of a sampled spectrum (Durisch eq. 11 as a quadrature). Extra values
    /// beyond [`Self::len`] are ignored, missing ones count as zero.
    #[must_use]
    pub fn xyz(&self, samples: &[f64]) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for (s, w) in samples.iter().zip(&self.xyz_weights) {
            for c in 0..3 {
                xyz[c] += s * w[c];
            }
        }
        xyz
    }

    /// Sampled values of a spectrum given as a function of wavelength (point samples; for band
    /// samplings this is the value at the band centre, not the band mean).
    #[must_use]
    pub fn sample(&self, spectrum: impl Fn(f64) -> f64) -> Vec<f64> {
        self.wavelengths_nm.iter().map(|&l| spectrum(l)).collect()
    }
}

fn check_count(n: usize) -> Result<(), SpectrumError> {
    if n > MAX_SAMPLES {
        return Err(SpectrumError::TooManySamples {
            max: MAX_SAMPLES,
            found: n,
        });
    }
    if n < 3 {
        return Err(SpectrumError::TooFewSamples {
            required: 3,
            found: n,
        });
    }
    Ok(())
}

fn check_increasing(values: &[f64]) -> Result<(), SpectrumError> {
    for (index, v) in values.iter().enumerate() {
        if !v.is_finite() {
            return Err(SpectrumError::InvalidSample {
                index,
                reason: "wavelength is not finite",
            });
        }
        if index > 0 && *v <= values[index - 1] {
            return Err(SpectrumError::InvalidSample {
                index,
                reason: "wavelengths must increase",
            });
        }
    }
    Ok(())
}

/// How a primary's basis spectrum was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BasisKind {
    /// Three non-negative steps with exactly the primary's tristimulus values.
    Exact {
        /// Sample index where the second step starts (λ2).
        lambda2_index: usize,
        /// Sample index where the third step starts (λ3).
        lambda3_index: usize,
    },
    /// Near-locus fallback: one step of height s between λ2 and λ3 (or outside them when
    /// `band_stop`), Y equal to the primary's, XYZ distance `xyz_error` from it.
    Fallback {
        /// Sample index of λ2.
        lambda2_index: usize,
        /// Sample index of λ3.
        lambda3_index: usize,
        /// True when the step lies outside [λ2, λ3).
        band_stop: bool,
        /// ‖F′ − F‖₂ of the chosen candidate.
        xyz_error: f64,
    },
}

/// RGB → non-negative spectrum converter for one RGB space and one sampling (Durisch Appendix A).
/// Build once (the search is done here), then convert per pixel.
#[derive(Debug, Clone)]
pub struct RgbToSpectrum {
    sampling: SpectralSampling,
    space: RgbColourSpace,
    basis: [Vec<f64>; 3],
    kinds: [BasisKind; 3],
    weights_from_rgb: Matrix3<f64>,
}

/// Relative tolerance below which a negative step weight counts as zero (round-off of a 3×3
/// solve whose exact answer has a zero step).
const STEP_ROUNDOFF: f64 = 1e-12;

impl RgbToSpectrum {
    /// Searches the basis spectra of `space`'s primaries on `sampling` and inverts eq. 16.
    ///
    /// # Errors
    /// [`SpectrumError::NoBasis`] when a primary has no candidate; [`SpectrumError::SingularBasis`]
    /// when the three bases are dependent.
    pub fn new(space: RgbColourSpace, sampling: SpectralSampling) -> Result<Self, SpectrumError> {
        let n = sampling.len();
        check_count(n)?;
        // Prefix sums of the weights: the XYZ of a unit step over samples [a, b) is P[b] − P[a].
        let mut prefix = vec![[0.0; 3]; n + 1];
        for k in 0..n {
            for c in 0..3 {
                prefix[k + 1][c] = prefix[k][c] + sampling.xyz_weights[k][c];
            }
        }
        let xyz_from_rgb = space.xyz_from_rgb();
        let mut basis: [Vec<f64>; 3] = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut kinds = [BasisKind::Exact {
            lambda2_index: 0,
            lambda3_index: 0,
        }; 3];
        for primary in 0..3 {
            let target = xyz_from_rgb.column(primary).into_owned();
            let (kind, spectrum) = search_basis(&prefix, target)
                .or_else(|| fallback_basis(&prefix, target))
                .ok_or(SpectrumError::NoBasis { primary })?;
            kinds[primary] = kind;
            basis[primary] = spectrum;
        }
        // Eq. 15–16: D has the bases' XYZ as columns, W = M D.
        let d = Matrix3::from_columns(&[
            Vector3::from(sampling.xyz(&basis[0])),
            Vector3::from(sampling.xyz(&basis[1])),
            Vector3::from(sampling.xyz(&basis[2])),
        ]);
        let w = space.rgb_from_xyz() * d;
        let determinant = w.determinant();
        let weights_from_rgb = w
            .try_inverse()
            .filter(|_| determinant.abs() > 1e-12)
            .ok_or(SpectrumError::SingularBasis { determinant })?;
        Ok(Self {
            sampling,
            space,
            basis,
            kinds,
            weights_from_rgb,
        })
    }

    /// Convenience: a converter for one of the built-in sample sets.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn for_sample_set(space: RgbColourSpace, set: SampleSet) -> Result<Self, SpectrumError> {
        Self::new(space, set.sampling())
    }

    /// The sampling the spectra live on.
    #[must_use]
    pub fn sampling(&self) -> &SpectralSampling {
        &self.sampling
    }

    /// The RGB space.
    #[must_use]
    pub fn space(&self) -> &RgbColourSpace {
        &self.space
    }

    /// Basis spectrum `L_i` of primary `i` (0 red, 1 green, 2 blue), scaled so that the
    /// primary at full intensity is `basis(i)` when the basis is exact.
    #[must_use]
    pub fn basis(&self, primary: usize) -> &[f64] {
        &self.basis[primary.min(2)]
    }

    /// How each primary's basis was found.
    #[must_use]
    pub fn basis_kinds(&self) -> [BasisKind; 3] {
        self.kinds
    }

    /// Basis weights `c = W⁻¹ · RGB` (eq. 17), negative ones clamped to zero.
    #[must_use]
    pub fn weights(&self, linear_rgb: [f64; 3]) -> [f64; 3] {
        let rgb = Vector3::from(linear_rgb.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 }));
        let c = self.weights_from_rgb * rgb;
        [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]
    }

    /// Writes the spectrum of `linear_rgb` (eq. 14) into `out` (length [`SpectralSampling::len`];
    /// extra entries are left untouched, missing ones skipped). Every value written is ≥ 0.
    pub fn spectrum_into(&self, linear_rgb: [f64; 3], out: &mut [f64]) {
        let c = self.weights(linear_rgb);
        for (k, o) in out.iter_mut().enumerate().take(self.sampling.len()) {
            *o = c[0] * self.basis[0][k] + c[1] * self.basis[1][k] + c[2] * self.basis[2][k];
        }
    }

    /// The spectrum of `linear_rgb` as a new vector.
    #[must_use]
    pub fn spectrum(&self, linear_rgb: [f64; 3]) -> Vec<f64> {
        let mut out = vec![0.0; self.sampling.len()];
        self.spectrum_into(linear_rgb, &mut out);
        out
    }

    /// Spectrum → XYZ → linear RGB.
    #[must_use]
    pub fn rgb(&self, samples: &[f64]) -> [f64; 3] {
        self.space.from_xyz(self.sampling.xyz(samples))
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2])
}

/// Three-step candidates with non-negative steps and exactly the target XYZ; the one with the
/// smallest largest step.
fn search_basis(prefix: &[[f64; 3]], target: Vector3<f64>) -> Option<(BasisKind, Vec<f64>)> {
    let n = prefix.len() - 1;
    let mut best: Option<(f64, usize, usize, Vector3<f64>)> = None;
    for j2 in 1..n - 1 {
        let b1 = sub(prefix[j2], prefix[0]);
        for j3 in j2 + 1..n {
            let b2 = sub(prefix[j3], prefix[j2]);
            let b3 = sub(prefix[n], prefix[j3]);
            let a = Matrix3::from_columns(&[b1, b2, b3]);
            let Some(inv) = a.try_inverse() else {
                continue;
            };
            let c = inv * target;
            let scale = c.amax();
            if !scale.is_finite() || c.iter().any(|&v| v < -STEP_ROUNDOFF * scale) {
                continue;
            }
            let c = c.map(|v| v.max(0.0));
            // The clamp must not have moved the XYZ (a singular-ish solve can pass the sign test).
            if (a * c - target).norm() > 1e-9 * target.norm().max(1e-300) {
                continue;
            }
            let cost = c.max();
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, j2, j3, c));
            }
        }
    }
    best.map(|(_, j2, j3, c)| {
        let spectrum = (0..n)
            .map(|k| {
                if k < j2 {
                    c[0]
                } else if k < j3 {
                    c[1]
                } else {
                    c[2]
                }
            })
            .collect();
        (
            BasisKind::Exact {
                lambda2_index: j2,
                lambda3_index: j3,
            },
            spectrum,
        )
    })
}

/// Near-locus fallback: one step (band-pass or band-stop) of height s with Y′ = Y, closest XYZ.
fn fallback_basis(prefix: &[[f64; 3]], target: Vector3<f64>) -> Option<(BasisKind, Vec<f64>)> {
    let n = prefix.len() - 1;
    let total = sub(prefix[n], prefix[0]);
    let mut best: Option<(f64, usize, usize, bool, f64)> = None;
    for j2 in 1..n - 1 {
        for j3 in j2 + 1..n {
            let inside = sub(prefix[j3], prefix[j2]);
            for band_stop in [false, true] {
                let unit = if band_stop { total - inside } else { inside };
                if unit[1] <= 0.0 {
                    continue;
                }
                let s = target[1] / unit[1];
                let err = (unit * s - target).norm();
                if err.is_finite() && best.as_ref().is_none_or(|b| err < b.0) {
                    best = Some((err, j2, j3, band_stop, s));
                }
            }
        }
    }
    best.map(|(err, j2, j3, band_stop, s)| {
        let spectrum = (0..n)
            .map(|k| {
                let in_band = (j2..j3).contains(&k);
                if in_band != band_stop { s } else { 0.0 }
            })
            .collect();
        (
            BasisKind::Fallback {
                lambda2_index: j2,
                lambda3_index: j3,
                band_stop,
                xyz_error: err,
            },
            spectrum,
        )
    })
}

#[cfg(test)]
mod tests;
