//! The differential renderer (Durisch 1992 §6): the planned building rendered into the current
//! photo by a ray tracer that adds and subtracts light ([`differential`]) with the illumination
//! model of §3.4 ([`illumination`]), optionally with one gathered bounce between the building and
//! its photographed surroundings ([`Lighting::photo_bounce_dome`]).
//!
//! [`render_view`] cuts the image into square tiles processed in parallel with rayon. Each tile
//! draws its random numbers from ChaCha8 seeded with the render seed and the tile index as the
//! stream, so the output is identical for any thread count. Antialiasing is adaptive stochastic
//! sampling (Cook 1986, as Durisch §7 used it): 4 jittered rays per pixel (one per 2×2 stratum),
//! then 4 more at a time up to 8, 12 or 16 while the standard error of the pixel mean exceeds
//! [`RenderSettings::max_standard_error`]; then a second pass gives the pixels whose estimate
//! differs from a neighbour's (an outline or shadow edge whose first rays all fell on one side)
//! up to `max_rays_per_pixel` (Mitchell 1987; `adaptive`); box reconstruction.
//!
//! **Only what changes is traced**: when none of a pixel's first 4 rays involves an artificial
//! object (no artificial hit, no natural light blocked only by an artificial object, no
//! artificial light), the pixel keeps the photo's value bit for bit and alpha 0.
//!
//! Materials: diffuse (eq. 6), GGX specular ([`specular`]), mirror, thin glass panes
//! ([`glass`]), emission and water-wave normals ([`water`]); artificial lights are points or
//! luminaires with photometric webs ([`luminaire_light`]). [`render_view_spectral`] runs the same
//! tracer on spectral samples ([`spectral`], Durisch §7 and Appendix A).
//!
//! Output: linear RGBA with alpha = coverage of artificial objects (fraction of rays whose first
//! hit is artificial), written as EXR ([`RenderedImage::write_exr`]) or sRGB PNG through
//! [`crate::colour::tonemap`] ([`RenderedImage::write_png`]); [`render_view_with_layers`] also
//! fills depth, object-id and shadow-change layers, and [`output`] writes them as a multi-channel
//! EXR or 8-bit sRGB PNG/JPEG/TIFF.
//!
//! # Known limitations
//! The "unchanged" decision uses the first 4 rays of a pixel: an artificial sliver thinner than
//! the gaps between them can be missed at the pixel level (as any 4-sample renderer would).
//! Box filter only. See [`differential`] for the per-ray limitations and [`glass`],
//! [`specular`], [`water`], [`luminaire_light`], [`spectral`] for those of each physical model.

mod adaptive;
pub mod differential;

pub mod illumination;
pub mod irradiance_cache;
pub mod luminaire_light;
pub mod output;
pub mod partial;
pub mod preview;
pub mod spectral;

pub mod tiling;
pub mod water;

use std::path::Path;
use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;
use nalgebra::Point2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub use differential::{
    DifferentialError, DifferentialTracer, Lighting, NaturalRatio, PrimaryHit, RaySample,
};
pub use illumination::{Daylight, DistantLight, PointLight, Rgb};
pub use irradiance_cache::IrradianceCacheSettings;
pub use luminaire_light::{ArtificialLight, LuminaireLight};
pub use output::{LayerSet, OutputError, OutputFormat, OutputLayers};
pub use spectral::{
    SpectralError, SpectralPasses, SpectralRadiosity, render_band_spectral, render_view_spectral,
};
pub use tiling::{Band, BandError};

use tiling::{TileOut, drive_tiles};

use crate::colour::ToneMap;

/// Errors of a render.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The photo is not the size of the camera's image.
    #[error("photo is {photo_px:?} px but the camera images {camera_px:?} px")]
    SizeMismatch {
        /// Photo width, height.
        photo_px: [u32; 2],
        /// Camera image width, height.
        camera_px: [u32; 2],
    },
    /// Invalid settings.
    #[error("invalid render setting {name}: {reason}")]
    InvalidSetting {
        /// Setting name.
        name: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// The cancel flag was raised.
    #[error("render cancelled")]
    Cancelled,
    /// The band cannot be cut from this view.
    #[error(transparent)]
    Band(#[from] BandError),
    /// Writing an output file failed.
    #[error("cannot write {path}: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

/// The largest mirror/glass recursion depth the renderer accepts. Each level is a native stack
/// frame chain of the tracer (5000 levels overflowed the stack); after 32 bounces on mirrors of
/// reflectance ≤ 0.9 less than 4 % of the light is left.
pub const MAX_DEPTH_LIMIT: u32 = 32;

/// Sampling and tiling settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// Tile edge, pixels.
    pub tile_size_px: u32,
    /// Rays per pixel at least (multiple of 4; Durisch: 4).
    pub min_rays_per_pixel: u32,
    /// Rays per pixel at most (multiple of 4; Durisch: 16).
    pub max_rays_per_pixel: u32,
    /// Stop adding rays when the standard error of the pixel mean (per channel, photo units)
    /// is at most this.
    pub max_standard_error: f64,
    /// Seed of the sample positions.
    pub seed: u64,
    /// Mirror recursion depth limit (at most [`MAX_DEPTH_LIMIT`]).
    pub max_depth: u32,
}

impl Default for RenderSettings {
    /// 32-px tiles, 4–16 rays, standard error ≤ 0.002 (half an 8-bit step at mid-grey in linear
    /// units), seed 0, two mirror bounces.
    fn default() -> Self {
        Self {
            tile_size_px: 32,
            min_rays_per_pixel: 4,
            max_rays_per_pixel: 16,
            max_standard_error: 0.002,
            seed: 0,
            max_depth: 2,
        }
    }
}

impl RenderSettings {
    /// The adaptive sampling rule, after `n` rays of a pixel (a multiple of 4) whose samples
    /// sum to `sum` and `sum_sq` per channel, `changed` when any of them differed from the
    /// photo: never beyond `max_rays_per_pixel`; always up to `min_rays_per_pixel`, even when
    /// no ray so far saw a change (a thin shadow or pole can fall between the first rays, and
    /// a pixel stops early only once `min_rays_per_pixel` of them missed it); between the two
    /// only while the pixel changed and the standard error of its mean exceeds
    /// `max_standard_error`.
    #[must_use]
    pub fn wants_more_rays(
        &self,
        n: u32,
        changed: bool,
        sum: &[f64; 3],
        sum_sq: &[f64; 3],
    ) -> bool {
        if n >= self.max_rays_per_pixel {
            return false;
        }
        if n < self.min_rays_per_pixel {
            return true;
        }
        if !changed {
            return false;
        }
        let nf = f64::from(n);
        let worst_var = (0..3)
            .map(|k| ((sum_sq[k] - sum[k] * sum[k] / nf) / (nf - 1.0)).max(0.0))
            .fold(0.0, f64::max);
        (worst_var / nf).sqrt() > self.max_standard_error
    }
}

/// A finished tile, reported to the progress callback with its pixels (so that a viewer can
/// show the render progressively).
#[derive(Debug, Clone, PartialEq)]
pub struct TileProgress {
    /// Index of the tile (row-major).
    pub tile_index: usize,
    /// Number of tiles.
    pub tile_count: usize,
    /// Top-left pixel of the tile.
    pub origin_px: [u32; 2],
    /// Tile width and height.
    pub size_px: [u32; 2],
    /// The tile's final linear RGB, row-major over the tile rect (`size_px[0] × size_px[1]`
    /// values): exactly what the finished [`RenderedImage`] holds there.
    pub rgb_linear: Vec<[f32; 3]>,
}

/// The RGB of linear RGBA pixels (a tile's pixels for [`TileProgress::rgb_linear`]).
pub(crate) fn rgb_of(rgba: &[[f32; 4]]) -> Vec<[f32; 3]> {
    rgba.iter().map(|p| [p[0], p[1], p[2]]).collect()
}

/// The rendered view.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedImage {
    /// Width and height, pixels.
    pub size_px: [u32; 2],
    /// Linear RGBA, row-major; alpha is the coverage of artificial objects.
    pub rgba: Vec<[f32; 4]>,
    /// Pixels that were traced beyond the unchanged test (the rest are the photo).
    pub changed_pixels: usize,
    /// Rays shot from the camera in total.
    pub primary_rays: u64,
}

impl RenderedImage {
    /// Writes a linear RGBA EXR (32-bit float).
    ///
    /// # Errors
    /// [`RenderError::Write`].
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        let [w, h] = self.size_px;
        let rgba = &self.rgba;
        exr::prelude::write_rgba_file(path, w as usize, h as usize, |x, y| {
            let p = rgba[y * w as usize + x];
            (p[0], p[1], p[2], p[3])
        })
        .map_err(|e| RenderError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Writes an sRGB PNG (alpha dropped) through `tone_map`.
    ///
    /// # Errors
    /// [`RenderError::Write`].
    pub fn write_png(&self, path: &Path, tone_map: &ToneMap) -> Result<(), RenderError> {
        let [w, h] = self.size_px;
        let img = image::RgbImage::from_fn(w, h, |x, y| {
            let p = self.rgba[(y * w + x) as usize];
            image::Rgb(crate::colour::tonemap::encode_srgb8(
                [p[0], p[1], p[2]],
                tone_map,
            ))
        });
        img.save(path).map_err(|e| RenderError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }
}

/// Renders the current view: `tracer` holds the scene, lights, camera and linear photo.
/// `on_tile` is called (from worker threads) as each tile finishes; raising `cancel` stops the
/// render at the next tile.
///
/// # Errors
/// [`RenderError::SizeMismatch`], [`RenderError::InvalidSetting`], [`RenderError::Cancelled`].
pub fn render_view(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderError> {
    render_view_with_layers(tracer, settings, LayerSet::default(), on_tile, cancel)
        .map(|(image, _)| image)
}

/// [`render_view`] that also fills the auxiliary output layers chosen in `layers` (see
/// [`output`] for their definitions).
///
/// # Errors
/// As [`render_view`].
pub fn render_view_with_layers(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    layers: LayerSet,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<(RenderedImage, OutputLayers), RenderError> {
    render_band_with_layers(tracer, settings, layers, Band::WHOLE, on_tile, cancel)
}

/// [`render_view_with_layers`] of one horizontal [`Band`] of the view: the returned image and
/// layers cover the band's pixel rows ([`Band::pixel_rows`]) and hold exactly the values the
/// whole-image render holds there.
///
/// # Errors
/// As [`render_view`]; [`RenderError::Band`] when the view has fewer tile rows than bands.
pub fn render_band_with_layers(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    layers: LayerSet,
    band: Band,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<(RenderedImage, OutputLayers), RenderError> {
    check_view(tracer, settings)?;
    let photo = tracer.photo();
    drive_tiles(
        [photo.width(), photo.height()],
        settings,
        layers,
        band,
        on_tile,
        cancel,
        &|index, origin_px, tile_px| {
            render_tile(tracer, settings, layers, index, origin_px, tile_px)
        },
    )
}

/// Checks that the photo is the camera's size and the settings are valid.
fn check_view(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
) -> Result<(), RenderError> {
    let photo = tracer.photo();
    let camera = tracer.camera();
    let photo_px = [photo.width(), photo.height()];
    if photo_px != camera.intrinsics.image_size_px {
        return Err(RenderError::SizeMismatch {
            photo_px,
            camera_px: camera.intrinsics.image_size_px,
        });
    }
    if settings.tile_size_px == 0 {
        return Err(RenderError::InvalidSetting {
            name: "tile_size_px",
            reason: "must be positive",
        });
    }
    let (lo, hi) = (settings.min_rays_per_pixel, settings.max_rays_per_pixel);
    if lo == 0 || lo % 4 != 0 || hi % 4 != 0 || hi < lo || hi > 64 {
        return Err(RenderError::InvalidSetting {
            name: "rays_per_pixel",
            reason: "min and max must be multiples of 4 with 4 ≤ min ≤ max ≤ 64",
        });
    }
    Ok(())
}

fn render_tile(
    tracer: &DifferentialTracer<'_>,
    settings: &RenderSettings,
    layers: LayerSet,
    tile_index: usize,
    origin_px: [u32; 2],
    size_px: [u32; 2],
) -> TileOut {
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    rng.set_stream(tile_index as u64);
    // The tile's own irradiance cache: same records for any thread count.
    let _cache = irradiance_cache::TileScope::enter();
    let photo = tracer.photo();
    let camera = tracer.camera();
    let count = (size_px[0] * size_px[1]) as usize;
    // Per pixel of the tile: its first ray's hit (layers), the summed change of its natural
    // samples (shadow-change layer), and the ratio-of-means parts of its natural samples.
    let mut first_hit: Vec<Option<Option<PrimaryHit>>> = vec![None; count];
    let mut natural_change = vec![[0.0_f64; 3]; count];
    let mut ratios = TileRatios::default();
    let tallies = adaptive::sample_tile(
        settings,
        &mut rng,
        origin_px,
        size_px,
        photo,
        &mut |i, [x, y], pixel| {
            let photo_rgb = photo.get_pixel(x, y).0.map(f64::from);
            let sample = tracer.trace_primary(&camera.ray_dir_in_world(pixel), photo_rgb);
            first_hit[i].get_or_insert(sample.first_hit);
            if !sample.hit_artificial {
                for k in 0..3 {
                    natural_change[i][k] += sample.radiance_rgb[k] - photo_rgb[k];
                }
            }
            ratios.add(i, &sample, pixel);
            adaptive::RayOutcome {
                radiance_rgb: sample.radiance_rgb,
                changed: sample.changed,
                hit_artificial: sample.hit_artificial,
            }
        },
    );
    let mut out = TileOut {
        rgba: Vec::with_capacity(count),
        layers: OutputLayers::new(layers, 0),
        changed: 0,
        rays: 0,
    };
    let mut pixel_ratios = ratios.by_pixel();
    for (i, tally) in tallies.iter().enumerate() {
        let [x, y] = adaptive::tile_pixel(origin_px, size_px, i);
        let photo_f32 = photo.get_pixel(x, y).0;
        let photo_rgb = photo_f32.map(f64::from);
        let own_ratios = pixel_ratios.next_pixel(i);
        let (mut sum, mut change) = (tally.sum, natural_change[i]);
        if tally.changed {
            let fix = own_ratios.correction(tracer, photo_rgb);
            for k in 0..3 {
                sum[k] += fix[k];
                change[k] += fix[k];
            }
        }
        out.rays += u64::from(tally.n);
        out.layers
            .push_pixel(first_hit[i].flatten(), change, tally.changed, tally.n);
        out.changed += usize::from(tally.changed);
        out.rgba.push(tally.rgba(sum, photo_f32));
    }
    out
}

/// A tile's natural samples for the ratio of means of [`NaturalRatio`], tagged with their
/// pixel (row-major in the tile): the changed ones' parts and the positions of the unchanged
/// ones (their parts are traced only when the pixel changed).
#[derive(Default)]
struct TileRatios {
    changed: Vec<(usize, (NaturalRatio, Rgb))>,
    unchanged_px: Vec<(usize, Point2<f64>)>,
}

impl TileRatios {
    fn add(&mut self, i: usize, sample: &RaySample, pixel: Point2<f64>) {
        if let Some(r) = sample.natural_ratio {
            self.changed.push((i, (r, sample.radiance_rgb)));
        } else if !sample.changed && !sample.hit_artificial && sample.first_hit.is_some() {
            self.unchanged_px.push((i, pixel));
        }
    }

    /// The records grouped by pixel, each pixel's in the order they were traced (the second
    /// sampling pass appends to pixels of the first, so a stable sort restores that order).
    fn by_pixel(mut self) -> RatioCursor {
        self.changed.sort_by_key(|r| r.0);
        self.unchanged_px.sort_by_key(|r| r.0);
        RatioCursor {
            ratios: self,
            next: [0, 0],
        }
    }
}

/// Walks [`TileRatios::by_pixel`] pixel by pixel, in increasing pixel order.
struct RatioCursor {
    ratios: TileRatios,
    next: [usize; 2],
}

impl RatioCursor {
    /// Pixel `i`'s records (`i` at least the previous call's).
    fn next_pixel(&mut self, i: usize) -> PixelRatios<'_> {
        fn take<T>(records: &[(usize, T)], start: &mut usize, i: usize) -> std::ops::Range<usize> {
            let from = *start + records[*start..].partition_point(|r| r.0 < i);
            let to = from + records[from..].partition_point(|r| r.0 == i);
            *start = to;
            from..to
        }
        let rc = take(&self.ratios.changed, &mut self.next[0], i);
        let ru = take(&self.ratios.unchanged_px, &mut self.next[1], i);
        PixelRatios {
            changed: &self.ratios.changed[rc],
            unchanged_px: &self.ratios.unchanged_px[ru],
        }
    }
}

/// One pixel's records of [`TileRatios`].
struct PixelRatios<'a> {
    changed: &'a [(usize, (NaturalRatio, Rgb))],
    unchanged_px: &'a [(usize, Point2<f64>)],
}

impl PixelRatios<'_> {
    /// What to add to the pixel's sum of sample radiances so that its natural samples count as
    /// `L_photo + mean(τ·L₀)·ΣΔE/ΣE` each instead of their own `L_photo + τ·L₀·ΔE/E`.
    fn correction(&self, tracer: &DifferentialTracer<'_>, photo_rgb: Rgb) -> Rgb {
        if self.changed.is_empty() {
            return [0.0; 3];
        }
        let camera = tracer.camera();
        let unchanged = self.unchanged_px.iter().filter_map(|(_, px)| {
            tracer
                .unchanged_natural_ratio(&camera.ray_dir_in_world(*px), photo_rgb)
                .map(|r| (r, photo_rgb))
        });
        let (mut tau_l0, mut e, mut de, mut old) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
        let mut count = 0.0;
        let changed = self.changed.iter().map(|&(_, pair)| pair);
        for (r, radiance) in changed.chain(unchanged) {
            for k in 0..3 {
                tau_l0[k] += r.tau_l0_rgb[k];
                e[k] += r.e_natural_rgb[k];
                de[k] += r.e_change_rgb[k];
                old[k] += radiance[k];
            }
            count += 1.0;
        }
        std::array::from_fn(|k| count * photo_rgb[k] + tau_l0[k] * de[k] / e[k] - old[k])
    }
}

/// Linear RGB of a loaded photo (sRGB-decoded when its transfer is sRGB).
#[must_use]
pub fn linear_photo(photo: &crate::photo::PhotoImage) -> Rgb32FImage {
    match photo.transfer {
        crate::photo::Transfer::Linear => photo.pixels.clone(),
        crate::photo::Transfer::Srgb => {
            use rayon::prelude::*;
            let mut out = photo.pixels.clone();
            let samples: &mut [f32] = &mut out;
            samples.par_chunks_mut(4096).for_each(|chunk| {
                #[allow(clippy::cast_possible_truncation)]
                for c in chunk {
                    *c = crate::colour::rgb::srgb_decode(f64::from(*c)) as f32;
                }
            });
            out
        }
    }
}

#[cfg(test)]
mod physics_tests;
#[cfg(test)]
mod radiosity_tests;
#[cfg(test)]
mod sampling_tests;
#[cfg(test)]
mod tests;
