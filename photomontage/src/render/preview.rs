//! The radiosity mode's instant preview (issue 17: "the montage preview updates within a frame
//! for the radiosity part and refines progressively for the rest"): one primary sample per
//! block of `stride × stride` photo pixels, traced once with what a replay needs
//! ([`crate::render::differential::replay`]), then evaluated again after every light or
//! material edit without a ray ([`PreviewRecords::replay`]) while the full render refines.
//!
//! Each block's sample goes through the centre of its middle pixel (the block's last, smaller
//! ones at the image's right and bottom edges through theirs), so the preview is a nearest-pixel
//! subsampling of a one-ray-per-pixel render. A replay under the light and materials of the
//! recording returns the recorded values bit for bit; one after a relight of the same geometry
//! returns what a new recording would, except where a ray's outcome depends on the edit (shadows
//! after a sun move, mirrors, gloss and glass: see the replay module's limitations).
//!
//! # Known limitations
//! One ray per block: no antialiasing, and a block shows its middle pixel's value. The records
//! belong to one camera and geometry ([`PreviewRecords::fits`]), and to one photo, which the
//! caller keeps them with; the studio records again when any of them changes.

use std::sync::atomic::{AtomicBool, Ordering};

use image::Rgb32FImage;
use nalgebra::Point2;
use rayon::prelude::*;

use super::differential::replay::RecordedSample;
use super::differential::{DifferentialTracer, Lighting, Shade};
use super::{RenderError, Rgb};
use crate::camera::Camera;
use crate::scene::Scene;

/// What the records were traced for: a tracer fits them when all of it is the same.
#[derive(Debug, Clone, PartialEq)]
struct RecordKey {
    camera: Camera,
    /// Geometry hashes of the radiosity meshes (with, without the artificial objects).
    radiosity_geometry: [u64; 2],
    /// The scene's triangle and object counts.
    scene_counts: [usize; 2],
}

/// What a view of `scene` under `lighting` through `camera` is, for [`RecordKey`]; `None`
/// without radiosity solutions.
fn key_of(scene: &Scene, lighting: &Lighting, camera: &Camera) -> Option<RecordKey> {
    let radiosity = lighting.radiosity.as_deref()?;
    Some(RecordKey {
        camera: *camera,
        radiosity_geometry: [
            radiosity.with_artificial.mesh.geometry_hash,
            radiosity.without_artificial.mesh.geometry_hash,
        ],
        scene_counts: [scene.triangles().len(), scene.objects().len()],
    })
}

/// The preview's samples (module doc).
#[derive(Debug, Clone)]
pub struct PreviewRecords {
    key: RecordKey,
    stride_px: u32,
    size_px: [u32; 2],
    samples: Vec<RecordedSample>,
}

/// A replayed preview: linear RGBA per preview pixel, row-major (alpha: 1 where the sample's
/// first hit is artificial; a sample that did not change is the photo's value with alpha 0, as
/// the renderer's pixels).
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewImage {
    /// Photo pixels per preview pixel along each axis.
    pub stride_px: u32,
    /// Preview pixels (columns, rows).
    pub size_px: [u32; 2],
    /// The pixels.
    pub rgba: Vec<[f32; 4]>,
    /// Whether each pixel's sample differs from the photo.
    pub changed: Vec<bool>,
}

/// Photo values below this (linear) are not divided by in [`PreviewImage::linear_at`].
const PHOTO_FLOOR: f32 = 1e-3;

impl PreviewImage {
    /// The index of the preview pixel showing photo pixel `[x, y]`.
    fn index_at(&self, x: u32, y: u32) -> usize {
        let (px, py) = (
            (x / self.stride_px).min(self.size_px[0] - 1),
            (y / self.stride_px).min(self.size_px[1] - 1),
        );
        (py * self.size_px[0] + px) as usize
    }

    /// The preview's linear RGB at photo pixel `[x, y]` of `photo` (the photo the records were
    /// traced over), for display at full resolution: the photo's own value where the block's
    /// sample did not change; the sample where it hit an artificial object; on a changed natural
    /// point the sample's change factor (its value over the photo's at the sample) times the
    /// photo's own value, so that a new shadow keeps the photo's texture.
    #[must_use]
    pub fn linear_at(&self, x: u32, y: u32, photo: &Rgb32FImage) -> [f32; 3] {
        let own = photo.get_pixel(x, y).0;
        let i = self.index_at(x, y);
        if !self.changed[i] {
            return own;
        }
        let p = self.rgba[i];
        if p[3] > 0.0 {
            return [p[0], p[1], p[2]];
        }
        let s = self.stride_px;
        let (sx, sy) = (
            sample_px((x / s).min(self.size_px[0] - 1), s, photo.width()),
            sample_px((y / s).min(self.size_px[1] - 1), s, photo.height()),
        );
        let at_sample = photo.get_pixel(sx, sy).0;
        std::array::from_fn(|k| {
            if at_sample[k] > PHOTO_FLOOR {
                own[k] * (p[k] / at_sample[k])
            } else {
                p[k]
            }
        })
    }
}

/// The smallest stride that keeps a `photo_px` preview at or under `max_samples` samples.
#[must_use]
pub fn stride_for(photo_px: [u32; 2], max_samples: u64) -> u32 {
    let samples = |stride: u32| {
        u64::from(photo_px[0].div_ceil(stride)) * u64::from(photo_px[1].div_ceil(stride))
    };
    let mut stride = 1_u32;
    while samples(stride) > max_samples.max(1) {
        stride += 1;
    }
    stride
}

/// The photo pixel a block's sample goes through: the block's middle pixel.
fn sample_px(block: u32, stride_px: u32, extent_px: u32) -> u32 {
    let start = block * stride_px;
    let end = (start + stride_px).min(extent_px);
    start + (end - start - 1) / 2
}

impl PreviewRecords {
    /// Traces one sample per `stride_px` block with `tracer` (radiosity mode).
    ///
    /// # Errors
    /// [`RenderError::InvalidSetting`] for a zero stride or a tracer without radiosity
    /// solutions; [`RenderError::Cancelled`] when `cancel` is set.
    pub fn record(
        tracer: &DifferentialTracer<'_>,
        stride_px: u32,
        cancel: &AtomicBool,
    ) -> Result<Self, RenderError> {
        if stride_px == 0 {
            return Err(RenderError::InvalidSetting {
                name: "preview stride",
                reason: "must be positive",
            });
        }
        let key = key_of(tracer.scene(), tracer.lighting(), tracer.camera()).ok_or(
            RenderError::InvalidSetting {
                name: "preview",
                reason: "the instant preview needs the radiosity lighting mode",
            },
        )?;
        let photo = tracer.photo();
        let photo_px = [photo.width(), photo.height()];
        let camera = tracer.camera();
        if photo_px != camera.intrinsics.image_size_px {
            return Err(RenderError::SizeMismatch {
                photo_px,
                camera_px: camera.intrinsics.image_size_px,
            });
        }
        let [w, h] = photo_px;
        let size_px = [w.div_ceil(stride_px), h.div_ceil(stride_px)];
        let rows: Vec<Option<Vec<RecordedSample>>> = (0..size_px[1])
            .into_par_iter()
            .map(|by| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let y = sample_px(by, stride_px, h);
                Some(
                    (0..size_px[0])
                        .map(|bx| {
                            let x = sample_px(bx, stride_px, w);
                            let photo_rgb: Rgb = photo.get_pixel(x, y).0.map(f64::from);
                            let dir =
                                camera.ray_dir_in_world(Point2::new(f64::from(x), f64::from(y)));
                            tracer.trace_primary_recorded(&dir, photo_rgb)
                        })
                        .collect(),
                )
            })
            .collect();
        let mut samples = Vec::with_capacity((size_px[0] * size_px[1]) as usize);
        for row in rows {
            samples.extend(row.ok_or(RenderError::Cancelled)?);
        }
        Ok(Self {
            key,
            stride_px,
            size_px,
            samples,
        })
    }

    /// Whether a view of `scene` under `lighting` through `camera` has the camera, scene and
    /// radiosity geometry the records were traced with (so that [`Self::replay`] holds for it).
    #[must_use]
    pub fn fits(&self, scene: &Scene, lighting: &Lighting, camera: &Camera) -> bool {
        key_of(scene, lighting, camera).is_some_and(|k| k == self.key)
    }

    /// The samples, row-major over the preview.
    #[must_use]
    pub fn samples(&self) -> &[RecordedSample] {
        &self.samples
    }

    /// The preview under `lighting` (its radiosity light a relight of the recording's) with
    /// `scene`'s materials: no ray is traced, no tracer built.
    ///
    /// # Errors
    /// [`RenderError::InvalidSetting`] when the view does not fit the records ([`Self::fits`]).
    pub fn replay(
        &self,
        scene: &Scene,
        lighting: &Lighting,
        camera: &Camera,
    ) -> Result<PreviewImage, RenderError> {
        if !self.fits(scene, lighting, camera) {
            return Err(RenderError::InvalidSetting {
                name: "preview",
                reason: "the camera, scene or radiosity geometry changed since the preview was \
                         recorded",
            });
        }
        if let Some(radiosity) = &lighting.radiosity {
            radiosity.prepare_queries();
        }
        let shade = Shade {
            lighting,
            materials: scene.materials(),
        };
        #[allow(clippy::cast_possible_truncation)]
        let (rgba, changed) = self
            .samples
            .par_iter()
            .with_min_len(1024)
            .map(|s| {
                let (rgb, changed) = shade.replay(s);
                let alpha = if changed && s.hit_artificial {
                    1.0
                } else {
                    0.0
                };
                (
                    [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, alpha],
                    changed,
                )
            })
            .unzip();
        Ok(PreviewImage {
            stride_px: self.stride_px,
            size_px: self.size_px,
            rgba,
            changed,
        })
    }
}
