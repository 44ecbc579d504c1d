//! Spectral mode of the differential renderer (Durisch 1992 §7: the montage computed on 9
//! spectral samples; Appendix A for the photo's RGB → spectrum; Meyer 1988 / Cohen & Wallace
//! 1993 eq. 9.24 for the 4-sample alternative).
//!
//! All the tracer's arithmetic is per channel, so the RGB tracer is run over the spectral
//! samples three at a time ([`SampleSet::Durisch9`]: 3 passes, [`SampleSet::Meyer4`]: 2, the
//! last one padded): each pass gets its own photo (Appendix A per pixel, sRGB primaries), lights
//! (Appendix A of each light colour: sun, ambient, sky facets, horizon, artificial lights,
//! emission) and materials (reflectances: the material's `diffuse_spectrum` averaged over the
//! band or sampled at the wavelength, or Appendix A of its RGB divided by Appendix A of white, so
//! that a grey reflectance is flat and white is exactly 1). Every ray position is traced through
//! all passes (identical sample positions), the samples are turned into CIE 1931 XYZ (eq. 11 as a
//! quadrature, [`crate::colour::SpectralSampling::xyz`]) and then linear sRGB, and the adaptive
//! antialiasing works on that RGB, exactly as [`super::render_view`] does.
//!
//! What holds: untouched pixels (and unchanged rays within a changed pixel) are the photo's
//! value copied, bit for bit (never round-tripped). Where all colours are in the gamut the
//! Appendix A conversion is linear, so a scene of grey materials renders as in RGB mode within
//! round-off (the RGB → spectrum → RGB round trip of sRGB on Durisch's 9 bands is exact to
//! ~1e-12, see [`crate::colour::spectrum`]); coloured materials differ from RGB mode, which is
//! the point of the mode (products of spectra are not products of RGB triples).
//!
//! In the radiosity lighting mode each pass reads its own radiosity solutions, solved with the
//! pass's reflectances and light colours ([`SpectralRadiosity`], built by
//! `site::spectral_radiosity` through [`SpectralPasses`], which converts as the passes here do).
//!
//! # Known limitations
//! The photo is taken to be linear sRGB. The atmosphere's transmittance is converted like a
//! reflectance (ratio to white), its horizon colour like a light. Meyer's 4 samples cannot
//! represent sRGB green without clamping (see [`crate::colour::spectrum`]), so that mode is not
//! exact even for grey scenes with green light. Specular Fresnel (F0) is achromatic. The passes
//! share the geometry but trace it once each (3× the ray casts of RGB mode for Durisch's 9), and
//! each pass holds its own f32 copy of the photo (the secondary rays look natural surfaces up in
//! it): 3 extra photo-sized images for Durisch's 9.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;
use nalgebra::Point2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::differential::radiosity_light::RadiosityLight;
pub use super::differential::radiosity_light::SpectralRadiosity;
use super::differential::{DifferentialTracer, Lighting};
use super::illumination::Rgb;
use super::luminaire_light::ArtificialLight;
use super::output::{LayerSet, OutputLayers};
use super::tiling::{Band, TileOut, drive_tiles};
use super::{RenderError, RenderSettings, RenderedImage, TileProgress};
use crate::atmosphere::schachter::SchachterAtmosphere;
use crate::colour::spectrum::{DURISCH_RANGE_NM, MEYER4_WAVELENGTHS_NM};
use crate::colour::{Colour, RgbColourSpace, RgbToSpectrum, SampleSet, SpectrumError};
use crate::scene::Material;
use crate::scene::material::Spectrum;

/// Errors of a spectral render.
#[derive(Debug, thiserror::Error)]
pub enum SpectralError {
    /// The render itself failed (size, settings, cancellation).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The Appendix A conversion could not be set up.
    #[error("spectral conversion: {0}")]
    Spectrum(#[from] SpectrumError),
    /// The radiosity solutions do not belong to the render's passes.
    #[error("spectral radiosity: {0}")]
    Radiosity(String),
    /// The atmosphere could not be expressed on a pass's bands.
    #[error("atmosphere on spectral samples {bands:?}: {message}")]
    Atmosphere {
        /// The pass's sample indices.
        bands: [usize; 3],
        /// Why.
        message: String,
    },
}

/// Colour conversions of one sample set.
#[derive(Debug)]
struct Converter {
    rgb_to_spectrum: RgbToSpectrum,
    white: Vec<f64>,
    set: SampleSet,
}

impl Converter {
    fn new(set: SampleSet) -> Result<Self, SpectrumError> {
        let rgb_to_spectrum = RgbToSpectrum::for_sample_set(RgbColourSpace::srgb(), set)?;
        let white = rgb_to_spectrum.spectrum([1.0; 3]);
        Ok(Self {
            rgb_to_spectrum,
            white,
            set,
        })
    }

    fn len(&self) -> usize {
        self.white.len()
    }

    /// A light's or a photo's colour: Appendix A.
    fn light(&self, rgb: Rgb) -> Vec<f64> {
        self.rgb_to_spectrum.spectrum(rgb)
    }

    /// A reflectance (or transmittance): Appendix A relative to white, in [0, 1].
    fn reflectance(&self, rgb: Rgb) -> Vec<f64> {
        let mean = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
        self.light(rgb)
            .iter()
            .zip(&self.white)
            .map(|(s, w)| if *w > 0.0 { s / w } else { mean }.clamp(0.0, 1.0))
            .collect()
    }

    /// A tabulated reflectance spectrum on the samples: band means (Durisch's 9) or point
    /// values (Meyer's 4).
    fn tabulated(&self, spectrum: &Spectrum) -> Vec<f64> {
        match self.set {
            SampleSet::Durisch9 => {
                let [lo, hi] = DURISCH_RANGE_NM;
                (0..9_u32)
                    .map(|k| {
                        let a = lo + (hi - lo) * f64::from(k) / 9.0;
                        let b = lo + (hi - lo) * f64::from(k + 1) / 9.0;
                        spectrum.band_mean(a, b)
                    })
                    .collect()
            }
            SampleSet::Meyer4 => MEYER4_WAVELENGTHS_NM
                .iter()
                .map(|&w| spectrum.at(w))
                .collect(),
        }
    }

    /// Spectral samples → linear sRGB.
    fn rgb(&self, samples: &[f64]) -> Rgb {
        self.rgb_to_spectrum.rgb(samples)
    }
}

fn pick(values: &[f64], bands: [usize; 3]) -> Rgb {
    bands.map(|b| values.get(b).copied().unwrap_or(0.0))
}

/// The spectral samples of a set, three at a time (the last pass padded with the last sample).
fn band_sets(n: usize) -> Vec<[usize; 3]> {
    (0..n.div_ceil(3))
        .map(|p| [0, 1, 2].map(|k| (3 * p + k).min(n - 1)))
        .collect()
}

/// The passes of a spectral render (three spectral samples each as the tracer's three
/// channels) and the colour conversions the render applies to each pass's inputs (module doc),
/// for what is computed before the render on the same passes: the radiosity solutions of the
/// spectral radiosity mode ([`SpectralRadiosity`]).
#[derive(Debug)]
pub struct SpectralPasses {
    conv: Converter,
    bands: Vec<[usize; 3]>,
}

impl SpectralPasses {
    /// The passes of `set` (Durisch's 9 samples: 3 passes; Meyer's 4: 2).
    ///
    /// # Errors
    /// The Appendix A conversion could not be set up.
    pub fn new(set: SampleSet) -> Result<Self, SpectrumError> {
        let conv = Converter::new(set)?;
        let bands = band_sets(conv.len());
        Ok(Self { conv, bands })
    }

    /// Number of passes.
    #[must_use]
    pub fn count(&self) -> usize {
        self.bands.len()
    }

    /// The sample indices of pass `pass` (0-based; a pass past the last repeats the last).
    #[must_use]
    pub fn bands(&self, pass: usize) -> [usize; 3] {
        self.bands[pass.min(self.bands.len() - 1)]
    }

    /// A light's colour (an irradiance, an intensity, a radiance) on pass `pass`: Appendix A.
    #[must_use]
    pub fn light(&self, pass: usize, rgb: Rgb) -> Rgb {
        pick(&self.conv.light(rgb), self.bands(pass))
    }

    /// A reflectance or transmittance on pass `pass`: Appendix A relative to white, in [0, 1].
    #[must_use]
    pub fn reflectance(&self, pass: usize, rgb: Rgb) -> Rgb {
        pick(&self.conv.reflectance(rgb), self.bands(pass))
    }

    /// A material on pass `pass`, as the render converts it (diffuse from its tabulated
    /// spectrum where it has one, mirror, glass, emission).
    #[must_use]
    pub fn material(&self, pass: usize, material: &Material) -> Material {
        pass_material(material, &self.conv, self.bands(pass))
    }

    /// A render's lighting on pass `pass`, as the render converts it; its radiosity solutions
    /// are left out (a pass's own come from [`Lighting::radiosity_spectral`]).
    ///
    /// # Errors
    /// [`SpectralError::Atmosphere`] when the atmosphere cannot be expressed on the pass.
    pub fn lighting(&self, pass: usize, lighting: &Lighting) -> Result<Lighting, SpectralError> {
        pass_lighting(lighting, &self.conv, self.bands(pass))
    }

    /// The photo on every pass (Appendix A per pixel).
    #[must_use]
    pub fn photos(&self, photo: &Rgb32FImage) -> Vec<Rgb32FImage> {
        pass_photos(photo, &self.conv, &self.bands)
    }
}

fn pass_photos(
    photo: &Rgb32FImage,
    conv: &Converter,
    band_sets: &[[usize; 3]],
) -> Vec<Rgb32FImage> {
    let (w, h) = (photo.width(), photo.height());
    let mut photos: Vec<Rgb32FImage> = band_sets.iter().map(|_| Rgb32FImage::new(w, h)).collect();
    let mut samples = vec![0.0; conv.len()];
    for (x, y, p) in photo.enumerate_pixels() {
        conv.rgb_to_spectrum
            .spectrum_into(p.0.map(f64::from), &mut samples);
        for (img, bands) in photos.iter_mut().zip(band_sets) {
            #[allow(clippy::cast_possible_truncation)]
            let v = pick(&samples, *bands).map(|s| s as f32);
            img.put_pixel(x, y, image::Rgb(v));
        }
    }
    photos
}

/// The inputs of one pass (three spectral samples as the tracer's three channels).
struct Pass {
    bands: [usize; 3],
    lighting: Lighting,
    photo: Rgb32FImage,
    materials: Vec<Material>,
}

fn pass_lighting(
    lighting: &Lighting,
    conv: &Converter,
    bands: [usize; 3],
) -> Result<Lighting, SpectralError> {
    let light = |rgb: Rgb| pick(&conv.light(rgb), bands);
    let mut out = lighting.clone();
    // RGB solutions are not a pass's, nor are all passes' solutions: the pass's own are set by
    // the caller.
    out.radiosity = None;
    out.radiosity_spectral = None;
    if let Some(sun) = &mut out.daylight.sun {
        sun.normal_irradiance_rgb = light(sun.normal_irradiance_rgb);
    }
    out.daylight.ambient_radiance_rgb = light(out.daylight.ambient_radiance_rgb);
    for facet in &mut out.daylight.sky {
        facet.normal_irradiance_rgb = light(facet.normal_irradiance_rgb);
    }
    for l in &mut out.artificial_lights {
        match l {
            ArtificialLight::Point(p) => p.intensity_rgb = light(p.intensity_rgb),
            ArtificialLight::Luminaire(lum) => lum.rgb_per_cd = light(lum.rgb_per_cd),
        }
    }
    out.horizon_rgb = light(out.horizon_rgb);
    if let Some(a) = &lighting.atmosphere {
        let rgb = |c: Colour| [0, 1, 2].map(|k| f64::from(c.channels[k]));
        let tau = pick(&conv.reflectance(rgb(a.transmittance())), bands);
        let horizon = light(rgb(a.horizon()));
        #[allow(clippy::cast_possible_truncation)]
        let to_colour = |v: Rgb| Colour::from_slice(&v.map(|x| x as f32));
        let atmosphere = SchachterAtmosphere::new(
            to_colour(tau.map(|t| t.max(1e-6))),
            to_colour(horizon),
            a.reference_distance_m(),
            3,
        )
        .map_err(|e| SpectralError::Atmosphere {
            bands,
            message: e.to_string(),
        })?;
        out.atmosphere = Some(atmosphere);
    }
    Ok(out)
}

fn pass_material(m: &Material, conv: &Converter, bands: [usize; 3]) -> Material {
    let refl = |rgb: Rgb| pick(&conv.reflectance(rgb), bands);
    let diffuse = match &m.diffuse_spectrum {
        Some(s) => pick(&conv.tabulated(s), bands),
        None => refl(m.diffuse_rgb),
    };
    let mut out = m.clone();
    out.diffuse_rgb = diffuse;
    out.diffuse_spectrum = None;
    out.mirror_rgb = m.mirror_rgb.map(refl);
    if let Some(g) = &mut out.glass {
        g.transmittance_rgb = refl(g.transmittance_rgb);
    }
    out.emission_rgb_w_m2_sr = m.emission_rgb_w_m2_sr.map(|e| pick(&conv.light(e), bands));
    out
}

/// Pass `pass`'s radiosity solutions: none in the facet mode; the pass's own in the radiosity
/// mode (RGB solutions in a spectral render are refused, not read as samples).
fn pass_radiosity(
    lighting: &Lighting,
    conv: &Converter,
    pass: usize,
    count: usize,
) -> Result<Option<Arc<RadiosityLight>>, SpectralError> {
    match (&lighting.radiosity_spectral, &lighting.radiosity) {
        (None, None) => Ok(None),
        (None, Some(_)) => Err(SpectralError::Radiosity(
            "the lighting holds RGB radiosity solutions; a spectral render needs the \
             solutions of each pass (SpectralRadiosity)"
                .to_owned(),
        )),
        (Some(s), _) if s.sample_set != conv.set || s.passes.len() != count => {
            Err(SpectralError::Radiosity(format!(
                "radiosity solutions for {} passes of {:?}, the render has {count} of {:?}",
                s.passes.len(),
                s.sample_set,
                conv.set
            )))
        }
        (Some(s), _) => Ok(Some(Arc::clone(&s.passes[pass]))),
    }
}

fn passes(tracer: &DifferentialTracer<'_>, conv: &Converter) -> Result<Vec<Pass>, SpectralError> {
    let band_sets = band_sets(conv.len());
    let photos = pass_photos(tracer.photo(), conv, &band_sets);
    let count = band_sets.len();
    band_sets
        .into_iter()
        .zip(photos)
        .enumerate()
        .map(|(k, (bands, photo))| {
            let mut lighting = pass_lighting(tracer.lighting(), conv, bands)?;
            lighting.radiosity = pass_radiosity(tracer.lighting(), conv, k, count)?;
            Ok(Pass {
                bands,
                lighting,
                photo,
                materials: tracer
                    .materials
                    .iter()
                    .map(|m| pass_material(m, conv, bands))
                    .collect(),
            })
        })
        .collect()
}

/// Renders the current view in spectral mode on `sample_set` (see the module doc): same
/// arguments, tiling, seed, adaptive sampling, progress and cancellation as
/// [`super::render_view`], same output (linear sRGB + coverage alpha; untouched pixels are the
/// photo bit for bit).
///
/// # Errors
/// [`SpectralError::Render`] for the errors of [`super::render_view`], and the conversion's.
pub fn render_view_spectral(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    sample_set: SampleSet,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, SpectralError> {
    render_band_spectral(tracer, settings, sample_set, Band::WHOLE, on_tile, cancel)
}

/// [`render_view_spectral`] of one horizontal [`Band`] of the view (see
/// [`super::render_band_with_layers`]).
///
/// # Errors
/// As [`render_view_spectral`].
pub fn render_band_spectral(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    sample_set: SampleSet,
    band: Band,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, SpectralError> {
    super::check_view(tracer, settings)?;
    let conv = Converter::new(sample_set)?;
    let passes = passes(tracer, &conv)?;
    let tracers: Vec<DifferentialTracer<'_>> = passes
        .iter()
        .map(|p| tracer.with_inputs(&p.lighting, &p.photo, &p.materials))
        .collect();
    let job = Job {
        tracer,
        passes: &passes,
        tracers: &tracers,
        conv: &conv,
        settings,
    };
    let (image, _) = drive_tiles(
        [tracer.photo().width(), tracer.photo().height()],
        settings,
        LayerSet::default(),
        band,
        on_tile,
        cancel,
        &|index, origin_px, tile_px| job.tile(index, origin_px, tile_px),
    )?;
    Ok(image)
}

struct Job<'j, 't> {
    tracer: &'j DifferentialTracer<'t>,
    passes: &'j [Pass],
    tracers: &'j [DifferentialTracer<'j>],
    conv: &'j Converter,
    settings: &'j RenderSettings,
}

impl Job<'_, '_> {
    /// One ray position through every pass: linear sRGB, changed, first hit artificial.
    fn sample(&self, x: u32, y: u32, pixel: Point2<f64>, bands: &mut [f64]) -> (Rgb, bool, bool) {
        let dir = self.tracer.camera().ray_dir_in_world(pixel);
        let (mut changed, mut hit_artificial) = (false, false);
        for (k, (pass, tracer)) in self.passes.iter().zip(self.tracers).enumerate() {
            let photo_rgb = pass.photo.get_pixel(x, y).0.map(f64::from);
            let s = tracer.trace_primary(&dir, photo_rgb);
            changed |= s.changed;
            if k == 0 {
                hit_artificial = s.hit_artificial;
            }
            for (c, &b) in pass.bands.iter().enumerate() {
                if let Some(v) = bands.get_mut(b) {
                    *v = s.radiance_rgb[c];
                }
            }
        }
        if changed {
            (self.conv.rgb(bands), true, hit_artificial)
        } else {
            let photo = self.tracer.photo().get_pixel(x, y).0.map(f64::from);
            (photo, false, hit_artificial)
        }
    }

    fn tile(&self, tile_index: usize, origin_px: [u32; 2], size_px: [u32; 2]) -> TileOut {
        let settings = self.settings;
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        rng.set_stream(tile_index as u64);
        // The tile's own irradiance cache (records kept per pass tracer).
        let _cache = super::irradiance_cache::TileScope::enter();
        let mut bands = vec![0.0; self.conv.len()];
        let mut out = TileOut {
            rgba: Vec::with_capacity((size_px[0] * size_px[1]) as usize),
            layers: OutputLayers::default(),
            changed: 0,
            rays: 0,
        };
        let photo = self.tracer.photo();
        let tallies = super::adaptive::sample_tile(
            settings,
            &mut rng,
            origin_px,
            size_px,
            photo,
            &mut |_, [x, y], pixel| {
                let (radiance_rgb, changed, hit_artificial) = self.sample(x, y, pixel, &mut bands);
                super::adaptive::RayOutcome {
                    radiance_rgb,
                    changed,
                    hit_artificial,
                }
            },
        );
        for (i, tally) in tallies.iter().enumerate() {
            let [x, y] = super::adaptive::tile_pixel(origin_px, size_px, i);
            out.rays += u64::from(tally.n);
            out.changed += usize::from(tally.changed);
            out.rgba
                .push(tally.rgba(tally.sum, photo.get_pixel(x, y).0));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Appendix A and the XYZ quadrature in f64: round-off of a few dozen operations.
    const ROUND_OFF_TOL: f64 = 1e-12;

    #[test]
    fn white_reflectance_is_one_and_grey_is_flat() {
        for set in [SampleSet::Durisch9, SampleSet::Meyer4] {
            let conv = Converter::new(set).unwrap();
            assert_eq!(conv.len(), set.len());
            for v in conv.reflectance([1.0; 3]) {
                assert!((v - 1.0).abs() < ROUND_OFF_TOL, "{set:?}: {v}");
            }
            for v in conv.reflectance([0.37; 3]) {
                assert!((v - 0.37).abs() < ROUND_OFF_TOL, "{set:?}: {v}");
            }
        }
    }

    #[test]
    fn light_round_trip_is_exact_for_srgb_on_durisch9() {
        let conv = Converter::new(SampleSet::Durisch9).unwrap();
        for rgb in [[0.2, 0.5, 0.9], [1.0, 0.1, 0.05], [0.3, 0.3, 0.3]] {
            let back = conv.rgb(&conv.light(rgb));
            for k in 0..3 {
                assert!(
                    (back[k] - rgb[k]).abs() < ROUND_OFF_TOL,
                    "{rgb:?} → {back:?}"
                );
            }
        }
    }

    #[test]
    fn tabulated_spectra_are_band_means() {
        let conv = Converter::new(SampleSet::Durisch9).unwrap();
        // A ramp from 0 at 380 nm to 0.8 at 780 nm: the band mean is the ramp at the centre.
        let ramp = Spectrum {
            wavelengths_nm: vec![380.0, 780.0],
            values: vec![0.0, 0.8],
        };
        for (k, v) in conv.tabulated(&ramp).iter().enumerate() {
            #[allow(clippy::cast_precision_loss)]
            let centre = 380.0 + 400.0 * (k as f64 + 0.5) / 9.0;
            assert!(
                (v - 0.8 * (centre - 380.0) / 400.0).abs() < 1e-9,
                "{k}: {v}"
            );
        }
    }
}
