//! The radiosity lighting mode in spectral mode (`render --spectral --radiosity`): the site's
//! radiosity is solved once per spectral pass of the render ([`SpectralPasses`], Durisch's 9
//! samples three at a time, docs/methodology.md "Spectral radiosity"), so that interreflection
//! is a product of spectra, not of RGB triples (Cohen & Wallace 1993 §9.3: a radiosity solve per
//! wavelength band). Each pass solves [`super::render_radiosity::solve_pair`] with
//!
//! - the scene's materials as the pass sees them (diffuse reflectance from the material's
//!   tabulated spectrum or Appendix A of its RGB relative to white, emission as a light);
//! - the sun's, the sky's and the luminaires' colours on the pass (Appendix A);
//! - the unmodelled ground's albedo on the pass;
//! - with the photo's reflectances on, the pass's photo and the pass's daylight, so that ρ_d is
//!   inverted per sample (Durisch's second inversion on each band).
//!
//! The meshes (the geometry and the sun's shadow edges) are the same on every pass, so the
//! vertex gathers of the first pass (their traced rays) serve all of them
//! ([`RadiosityLight::relit`]), and the photographed state's solve of every later pass reads
//! the first pass's sky rays and form factors ([`crate::radiosity::twin::Twin::identity`],
//! `PassReuse` of `render_radiosity`): the same rays and factors, not traced again, so the
//! solutions are those of solving the pass alone, bit for bit (test); the solve with the
//! planned objects reads them from its own pass's photographed state, as in RGB.
//!
//! # Known limitations
//! A later pass still builds its meshes, samples the photos, runs its own BF refinement (it
//! reads the pass's light, so a link may be refined on one pass and not on another: those
//! links' factors are computed) and solves; on the street site a spectral radiosity precompute
//! takes about 2.7 times the RGB one (docs/benchmarks.md). The studio's live preview keeps RGB
//! transfers only.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use super::SiteDocument;
use super::other_photos::other_photos_for;
use super::photo_reflectance::{PhotoReflectanceCount, PhotoView};
use super::radiosity_lighting::site_transfer_lighting;
use super::render_error::SiteRenderError;
use super::render_radiosity::{
    PassReuse, RadiosityReport, SunLightings, radiosity_error, site_solve_params, solve_pair,
};
use crate::colour::SampleSet;
use crate::radiosity::{SolveParams, TransferLighting};
use crate::render::SpectralPasses;
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::render::spectral::SpectralRadiosity;
use crate::scene::Scene;

fn spectrum_error(e: &dyn std::fmt::Display) -> SiteRenderError {
    SiteRenderError::Request {
        field: "render.spectral",
        reason: e.to_string(),
    }
}

/// The site's transfer lighting on pass `pass`: every light colour through Appendix A.
#[must_use]
pub fn pass_transfer_lighting(
    passes: &SpectralPasses,
    pass: usize,
    lighting: &TransferLighting,
) -> TransferLighting {
    let mut out = lighting.clone();
    if let Some(sun) = &mut out.sun {
        sun.normal_irradiance_rgb = passes.light(pass, sun.normal_irradiance_rgb);
    }
    if let Some(sky) = &mut out.sky {
        sky.horizontal_irradiance_rgb = passes.light(pass, sky.horizontal_irradiance_rgb);
    }
    for l in &mut out.luminaires {
        l.source.intensity_rgb = passes.light(pass, l.source.intensity_rgb);
    }
    out
}

/// The solve parameters on pass `pass`: the unmodelled ground's albedo as a reflectance.
#[must_use]
pub fn pass_solve_params(
    passes: &SpectralPasses,
    pass: usize,
    params: &SolveParams,
) -> SolveParams {
    let mut out = params.clone();
    if let Some(ground) = &mut out.ground {
        ground.albedo_rgb = passes.reflectance(pass, ground.albedo_rgb);
    }
    out
}

/// The scene with its materials as pass `pass` sees them.
#[must_use]
pub fn pass_scene(passes: &SpectralPasses, pass: usize, scene: &Scene) -> Scene {
    let mut out = scene.clone();
    out.map_materials(&|m| passes.material(pass, m));
    out
}

/// Solves the site's radiosity on every pass of `sample_set` (module doc), with and without the
/// artificial objects, as [`super::render_radiosity::site_radiosity_light`] does in RGB.
///
/// # Errors
/// As [`super::render_radiosity::site_radiosity_light`]; the spectral conversion's.
pub fn site_spectral_radiosity(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
    photo: Option<&PhotoView<'_>>,
    sample_set: SampleSet,
    cancel: &AtomicBool,
) -> Result<(SpectralRadiosity, RadiosityReport), SiteRenderError> {
    let start = Instant::now();
    let passes = SpectralPasses::new(sample_set).map_err(|e| spectrum_error(&e))?;
    let (lighting, mut notes) = site_transfer_lighting(doc, scene, view)?;
    let (params, element_edge_m) = site_solve_params(doc, scene)?;
    let photos = photo.map(|p| passes.photos(p.photo_linear));
    // The site's other photos ([`super::other_photos`]), each as every pass's image.
    let others = other_photos_for(doc, scene, view, photo)?;
    let other_photos: Vec<Vec<_>> = others
        .iter()
        .flat_map(|(o, _)| o.images())
        .map(|image| passes.photos(image))
        .collect();
    let mut lights: Vec<Arc<RadiosityLight>> = Vec::with_capacity(passes.count());
    let mut elements = [0, 0];
    let mut photo_reflectance: Option<PhotoReflectanceCount> = None;
    let mut first_pass: Option<PassReuse> = None;
    let mut reused_passes = 0;
    for pass in 0..passes.count() {
        let pass_photo_lighting = photo
            .map(|p| passes.lighting(pass, p.lighting))
            .transpose()
            .map_err(|e| spectrum_error(&e))?;
        // Each other sun's lightings, converted on every pass as the site's are.
        let sun_lights = others.as_ref().map(|(_, l)| l);
        let pass_reading = sun_lights
            .iter()
            .flat_map(|l| &l.reading)
            .map(|l| passes.lighting(pass, l))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| spectrum_error(&e))?;
        let pass_photo = photo
            .zip(photos.as_ref())
            .zip(pass_photo_lighting.as_ref())
            .zip(others.as_ref())
            .map(|(((p, photos), lighting), (others, _))| {
                others.views_with(
                    PhotoView {
                        camera: p.camera,
                        photo_linear: &photos[pass],
                        lighting,
                    },
                    &pass_reading,
                    |k| &other_photos[k][pass],
                )
            });
        let pass_others: Vec<TransferLighting> = sun_lights
            .iter()
            .flat_map(|l| &l.transfer)
            .map(|l| pass_transfer_lighting(&passes, pass, l))
            .collect();
        let mut pair = solve_pair(
            &pass_scene(&passes, pass, scene),
            &SunLightings {
                rendered: &pass_transfer_lighting(&passes, pass, &lighting),
                others: &pass_others,
            },
            &pass_solve_params(&passes, pass, &params),
            pass_photo.as_ref(),
            first_pass.as_ref(),
            cancel,
        )?;
        // The first pass's sky rays and form factors serve every later pass (the same mesh).
        if first_pass.is_none() {
            first_pass = pair.reuse.take();
        }
        reused_passes += usize::from(pair.read_reuse);
        elements = [
            pair.with.mesh.elements.len(),
            pair.without.mesh.elements.len(),
        ];
        // The count and notes of the first pass (the same elements are seen on every pass).
        if pass == 0 {
            notes.extend(pair.photo_notes);
        }
        photo_reflectance = photo_reflectance.or(pair.photo_reflectance);
        let traced = &RadiosityLight::traced_exactly;
        let light = match lights.first() {
            // The same meshes: the first pass's vertex gathers are kept.
            Some(first) => first.relit(&pair.with, &pair.without, traced, [None, None]),
            None => RadiosityLight::new(&pair.with, &pair.without, traced),
        }
        .map_err(|e| radiosity_error(&e))?;
        lights.push(Arc::new(light));
    }
    notes.push(format!(
        "spectral radiosity: solved on {} passes of {sample_set:?}; {} of the later passes read the \
         first pass's sky rays and form factors",
        passes.count(),
        reused_passes
    ));
    let report = RadiosityReport {
        element_edge_m,
        elements,
        seconds: start.elapsed().as_secs_f64(),
        notes,
        photo_reflectance,
    };
    Ok((
        SpectralRadiosity {
            sample_set,
            passes: lights,
        },
        report,
    ))
}

#[cfg(test)]
#[path = "spectral_radiosity_tests.rs"]
mod tests;
