//! The live preview's instant image in the radiosity mode (issue 17: "the montage preview
//! updates within a frame for the radiosity part and refines progressively for the rest"):
//! right after the site's transfers are relit ([`super::live`]), the render job replays the
//! preview records it keeps ([`photomontage::render::preview`]: one sample per block of the
//! photo, traced once) under the edited light and materials, without a ray, and shows that
//! image before the coarse pass's first tile. The records are traced again when the camera, the
//! photo or the geometry changed (a model moved, hidden or added).
//!
//! # Known limitations
//! One sample per block of [`INSTANT_SAMPLES`]' stride (about a third of the
//! photo's resolution on each axis for 1280 × 960): the instant image is coarse where it changed,
//! until the tiles come. A sun move keeps the recorded shadows until the passes re-trace them
//! (the replay module's limitations).

use std::sync::{Arc, Mutex};
use std::time::Instant;

use eframe::egui;
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::encode_srgb8;
use photomontage::render::preview::{PreviewImage, PreviewRecords, stride_for};
use photomontage::render::{DifferentialTracer, RenderError};

use super::{RenderPanelError, RenderUpdate, display_step};
use crate::render_job::PhotoJob;
use crate::worker::Progress;

/// The preview records of one photo, kept between live renders.
#[derive(Debug)]
pub struct KeptRecords {
    photo: String,
    records: PreviewRecords,
}

/// The kept records, shared with the render worker.
pub type SharedRecords = Arc<Mutex<Option<KeptRecords>>>;

/// What the last instant image cost.
#[derive(Debug, Clone, PartialEq)]
pub struct InstantReport {
    /// Whether the records were traced for it (else replayed).
    pub recorded: bool,
    /// Samples replayed.
    pub samples: usize,
    /// Photo pixels per sample along each axis.
    pub stride_px: u32,
    /// Wall time from the relit transfers to the image (tracing the records if they were),
    /// seconds.
    pub seconds: f64,
    /// Wall time from the render job's start (the edit's render, after the one it replaced
    /// stopped) to the image: loading the view, the relight and the image, seconds.
    pub job_seconds: f64,
}

/// Samples of the radiosity mode's instant image at most: one per block of the smallest stride
/// that keeps under this (3 × 3 pixels for 1280 × 960).
pub const INSTANT_SAMPLES: u64 = 150_000;

/// The render job's part (module doc).
pub(super) struct InstantJob<'a> {
    /// The kept records (a live render of the radiosity mode); `None`: no instant image.
    pub records: Option<&'a SharedRecords>,
    /// The photo's display image, which the instant image is drawn over.
    pub photo_display: &'a egui::ColorImage,
    /// The panel's tone map.
    pub tone_map: &'a ToneMap,
    /// When the render job started.
    pub job_start: Instant,
}

impl InstantJob<'_> {
    /// In a live render of the radiosity mode: the instant image of `job` (its lighting holds
    /// the relit transfers' light), from the kept records or from records traced now, drawn
    /// over the photo's display image and sent to the panel as [`RenderUpdate::Instant`].
    ///
    /// # Errors
    /// [`RenderPanelError::Cancelled`] when cancelled while tracing the records,
    /// [`RenderPanelError::Prepare`] with the library's message otherwise.
    pub(super) fn run(
        &self,
        photo_id: &str,
        job: &PhotoJob,
        progress: &Progress<RenderUpdate>,
    ) -> Result<(), RenderPanelError> {
        let Some(shared) = self.records else {
            return Ok(());
        };
        let (photo_display, tone_map, job_start) =
            (self.photo_display, self.tone_map, self.job_start);
        let start = Instant::now();
        let view = &job.prepared.job;
        let (scene, lighting, camera) = (&view.scene.scene, &view.lighting, &view.camera);
        let photo = &view.photo_linear;
        let error = |e: &dyn std::fmt::Display| RenderPanelError::Prepare {
            photo: photo_id.to_owned(),
            message: e.to_string(),
        };
        // Records a panicking job may have left half-written are traced again.
        let mut slot = shared.lock().unwrap_or_else(|poisoned| {
            let mut slot = poisoned.into_inner();
            *slot = None;
            slot
        });
        shared.clear_poison();
        let fits = slot
            .as_ref()
            .is_some_and(|k| k.photo == photo_id && k.records.fits(scene, lighting, camera));
        if !fits {
            *slot = None;
            let tracer = DifferentialTracer::new(
                scene,
                lighting,
                camera,
                photo,
                job.plan.settings.max_depth,
            )
            .map_err(|e| error(&e))?;
            let stride = stride_for([photo.width(), photo.height()], INSTANT_SAMPLES);
            let records = PreviewRecords::record(&tracer, stride, progress.cancel_flag()).map_err(
                |e| match e {
                    RenderError::Cancelled => RenderPanelError::Cancelled {
                        photo: photo_id.to_owned(),
                    },
                    other => error(&other),
                },
            )?;
            *slot = Some(KeptRecords {
                photo: photo_id.to_owned(),
                records,
            });
        }
        let Some(kept) = slot.as_ref() else {
            return Ok(());
        };
        let image: PreviewImage = kept
            .records
            .replay(scene, lighting, camera)
            .map_err(|e| error(&e))?;
        let display = instant_display(photo_display, &image, photo, tone_map);
        let report = InstantReport {
            recorded: !fits,
            samples: image.rgba.len(),
            stride_px: image.stride_px,
            seconds: start.elapsed().as_secs_f64(),
            job_seconds: job_start.elapsed().as_secs_f64(),
        };
        progress.send(RenderUpdate::Instant {
            display,
            image: Box::new(image),
            report,
        });
        Ok(())
    }
}

/// The display image of `image` over the photo's (`photo_display`, made by
/// [`super::display_photo`] from `photo`): the photo's pixels where a block's sample did not
/// change, [`PreviewImage::linear_at`] tone-mapped in the blocks where it did (so that only the
/// changed part of the view is converted).
fn instant_display(
    photo_display: &egui::ColorImage,
    image: &PreviewImage,
    photo: &image::Rgb32FImage,
    tone_map: &ToneMap,
) -> egui::ColorImage {
    let mut out = photo_display.clone();
    let size_px = [photo.width(), photo.height()];
    let step = display_step(size_px);
    let width = out.size[0];
    let s = image.stride_px;
    let columns = image.size_px[0] as usize;
    for (i, _) in image.changed.iter().enumerate().filter(|(_, c)| **c) {
        #[allow(clippy::cast_possible_truncation)]
        let (bx, by) = ((i % columns) as u32, (i / columns) as u32);
        let (x0, x1) = (bx * s, ((bx + 1) * s).min(size_px[0]));
        let (y0, y1) = (by * s, ((by + 1) * s).min(size_px[1]));
        // Display pixels whose photo pixel (d·step) falls in the block.
        for dy in y0.div_ceil(step)..y1.div_ceil(step) {
            for dx in x0.div_ceil(step)..x1.div_ceil(step) {
                let [r, g, b] =
                    encode_srgb8(image.linear_at(dx * step, dy * step, photo), tone_map);
                if let Some(p) = out.pixels.get_mut(dy as usize * width + dx as usize) {
                    *p = egui::Color32::from_rgb(r, g, b);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render_panel::{display_photo, display_rgb};
    use photomontage::colour::tonemap::ToneCurve;

    /// Drawing only the changed blocks over the photo's display image gives the display image
    /// of the whole preview at full resolution, pixel for pixel (3-pixel blocks, a photo whose
    /// size is no multiple of them, changed artificial and natural blocks).
    #[test]
    fn the_changed_blocks_over_the_photo_are_the_whole_preview() {
        let (w, h, s) = (20_u32, 13_u32, 3_u32);
        let photo = image::Rgb32FImage::from_fn(w, h, |x, y| {
            #[allow(clippy::cast_precision_loss)]
            image::Rgb([0.05 + 0.03 * x as f32, 0.1 + 0.02 * y as f32, 0.3])
        });
        let size_px = [w.div_ceil(s), h.div_ceil(s)];
        let n = (size_px[0] * size_px[1]) as usize;
        let changed: Vec<bool> = (0..n).map(|i| i % 3 != 0).collect();
        let rgba = (0..n)
            .map(|i| {
                #[allow(clippy::cast_precision_loss)]
                let v = 0.01 * i as f32;
                [v, 0.5 * v, 0.2, if i % 2 == 0 { 1.0 } else { 0.0 }]
            })
            .collect();
        let image = PreviewImage {
            stride_px: s,
            size_px,
            rgba,
            changed,
        };
        let tone_map = ToneMap {
            exposure_stops: 0.5,
            curve: ToneCurve::Clamp,
        };
        let drawn = instant_display(&display_photo(&photo, &tone_map), &image, &photo, &tone_map);
        let whole = display_rgb([w, h], |x, y| image.linear_at(x, y, &photo), &tone_map);
        assert_eq!(drawn.size, whole.size);
        assert!(drawn.pixels == whole.pixels);
        // Some blocks changed the photo, and the unchanged ones are the photo.
        let photo_display = display_photo(&photo, &tone_map);
        assert!(drawn.pixels != photo_display.pixels);
        assert_eq!(drawn.pixels[0], photo_display.pixels[0]);
    }
}
