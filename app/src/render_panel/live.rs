//! The Render tab's live preview (issue 17: "the montage preview updates within a frame for the
//! radiosity part and refines progressively for the rest. Show the frame time"): while **Live**
//! is on, every edit that changes what the render depends on (the site — light, sky, sun and
//! time, luminaires, materials, exposure, models —, the photo, the quality) cancels the running
//! render and starts a new one, coarse first (4 rays per pixel over the whole view, shown tile
//! by tile), then at the panel's quality, which is the montage. A cancelled render leaves no
//! tiles behind: the new job starts from the photo.
//!
//! In the radiosity mode (`[render] radiosity = true`) the site's two transfers
//! (`photomontage::site::live_relight::SiteTransfers`) stay alive here between renders, Live or
//! not: built once on the render worker, relit with `Transfer::relight` for a light or material
//! edit, built again only when the geometry changes; the renderer reads the relit solutions
//! through `Lighting::radiosity`.
//!
//! In that mode a live render also shows an instant image right after the relight, replayed
//! from records of the view without a ray ([`super::instant`]), before its first tile.
//!
//! The tab shows the last egui frame's time (the studio's whole `ui` call), the last radiosity
//! update's time and kind, the instant image's time, the last build's report (folded: element counts, where the natural
//! surfaces' reflectances came from, its notes), and the refinement's pass and tiles.
//!
//! A live render takes the photo decoded by the last one while its file is unchanged
//! ([`photomontage::site::render::KeptPhoto`], shared, not copied) and its display image while
//! the tone map is unchanged too ([`KeptView`]).
//!
//! # Known limitations
//! The re-projected views (planar, cylindrical) are not rendered live (Start renders them).

use std::sync::{Arc, Mutex};
use std::time::Duration;

use eframe::egui;
use photomontage::colour::ToneMap;
use photomontage::render::preview::PreviewImage;
use photomontage::site::SiteDocument;
use photomontage::site::live_relight::{RelightReport, SiteTransfers, TransferUpdate};
use photomontage::site::photo_reflectance::PhotoView;
use photomontage::site::render::KeptPhoto;
use photomontage::site::render::ViewJob;
use photomontage::site::render_radiosity::RadiosityReport;

use super::instant::{InstantReport, SharedRecords};
use super::{Quality, RenderPanelError, RenderUpdate};
use crate::widgets::name_widget;
use crate::worker::Progress;

/// Rays per pixel of the coarse pass.
pub const COARSE_SPP: u32 = 4;

/// The site's transfers, shared with the render worker.
pub type SharedTransfers = Arc<Mutex<Option<SiteTransfers>>>;

/// The last decoded photo and its display image, shared with the render worker (an edit's render
/// reuses them while the file and the tone map are unchanged).
pub type SharedPhoto = Arc<Mutex<KeptView>>;

/// What a live render keeps of its view's photo between edits: the decoded photo (while its
/// file is unchanged) and the display image made from it (while the tone map is unchanged).
#[derive(Default)]
pub struct KeptView {
    /// The decoded photo.
    pub photo: Option<KeptPhoto>,
    /// The photo the display image was made from (held, so that no other photo can take its
    /// address), its tone map and the image.
    display: Option<(Arc<image::Rgb32FImage>, ToneMap, egui::ColorImage)>,
}

impl KeptView {
    /// The display image of `photo` through `tone_map` ([`super::display_photo`]): the kept one
    /// when it was made from this very photo (the same allocation) with the same tone map.
    pub fn display(
        &mut self,
        photo: &Arc<image::Rgb32FImage>,
        tone_map: &ToneMap,
    ) -> egui::ColorImage {
        if let Some((from, map, image)) = &self.display
            && Arc::ptr_eq(from, photo)
            && map == tone_map
        {
            return image.clone();
        }
        let image = super::display_photo(photo, tone_map);
        self.display = Some((Arc::clone(photo), *tone_map, image.clone()));
        image
    }
}

/// What the live preview rendered last: the site, photo and quality.
#[derive(Debug, Clone, PartialEq)]
struct LiveKey {
    site: photomontage::site::Site,
    photo: String,
    quality: Quality,
}

/// State of the live preview.
#[derive(Default)]
pub struct LivePreview {
    /// Live on: edits restart the render.
    pub enabled: bool,
    /// What the running (or last started) live render shows.
    started: Option<LiveKey>,
    /// What the last finished live render shows.
    finished: Option<LiveKey>,
    /// The site's radiosity transfers (radiosity mode).
    pub(super) transfers: SharedTransfers,
    last_frame: Option<Duration>,
    last_relight: Option<RelightReport>,
    /// The last build's report (element counts, the photos' reflectances, notes).
    last_build: Option<RadiosityReport>,
    /// Pass of the running render: (index from 1, count).
    pub(super) pass: Option<(u32, u32)>,
    cancelled: usize,
    /// The instant image's records (radiosity mode, [`super::instant`]).
    records: SharedRecords,
    /// The last decoded photo.
    photo: SharedPhoto,
    last_instant: Option<InstantReport>,
    instant_image: Option<PreviewImage>,
}

/// What a render job does beyond the panel's quality.
#[derive(Clone, Default)]
pub struct JobOptions {
    /// Render a coarse pass ([`COARSE_SPP`]) first.
    pub coarse_first: bool,
    /// The site's transfers, in the radiosity mode.
    pub transfers: Option<SharedTransfers>,
    /// The instant image's records, in a live render of the radiosity mode.
    pub records: Option<SharedRecords>,
    /// The last decoded photo, reused by a live render while its file is unchanged.
    pub photo: Option<SharedPhoto>,
}

impl JobOptions {
    /// In the radiosity mode: updates the site's transfers for `job`'s scene (build, relight or
    /// nothing, reported to the panel) and hands their solutions to the renderer.
    ///
    /// # Errors
    /// [`RenderPanelError::Prepare`] with the library's message.
    pub(super) fn prepare_radiosity(
        &self,
        doc: &SiteDocument,
        photo_id: &str,
        job: &mut ViewJob,
        progress: &Progress<RenderUpdate>,
    ) -> Result<(), RenderPanelError> {
        let Some(shared) = &self.transfers else {
            return Ok(());
        };
        // A job that panicked while holding the lock may have left the transfers half-relit:
        // start again from a build.
        let mut slot = shared.lock().unwrap_or_else(|poisoned| {
            let mut slot = poisoned.into_inner();
            *slot = None;
            slot
        });
        shared.clear_poison();
        // The natural surfaces' reflectances from the photo, as the CLI's render.
        let photo = PhotoView {
            camera: &job.camera,
            photo_linear: &job.photo_linear,
            lighting: &job.lighting,
        };
        let (light, report) = SiteTransfers::update(
            &mut slot,
            doc,
            &job.scene.scene,
            photo_id,
            doc.site.render.photo_reflectance.then_some(&photo),
            progress.cancel_flag(),
        )
        .map_err(|e| RenderPanelError::Prepare {
            photo: photo_id.to_owned(),
            message: e.to_string(),
        })?;
        job.lighting.radiosity = Some(light);
        progress.send(RenderUpdate::Relit(report));
        Ok(())
    }
}

impl LivePreview {
    /// The last egui frame's time.
    #[must_use]
    pub fn last_frame(&self) -> Option<Duration> {
        self.last_frame
    }

    /// The last radiosity update (build, relight or unchanged) and its time.
    #[must_use]
    pub fn last_relight(&self) -> Option<&RelightReport> {
        self.last_relight.as_ref()
    }

    /// Live renders cancelled by a newer edit.
    #[must_use]
    pub fn cancelled(&self) -> usize {
        self.cancelled
    }

    /// Whether the last finished live render shows `site` (photo and quality as started).
    #[must_use]
    pub fn shows(&self, site: &photomontage::site::Site) -> bool {
        self.finished.as_ref().is_some_and(|k| k.site == *site) && self.started == self.finished
    }

    /// The site's transfers (radiosity mode), shared with the render worker; tests compare
    /// their solutions with a fresh solve.
    #[must_use]
    pub fn transfers(&self) -> SharedTransfers {
        Arc::clone(&self.transfers)
    }

    /// The last decoded photo, shared with the render worker.
    #[must_use]
    pub fn kept_photo(&self) -> SharedPhoto {
        Arc::clone(&self.photo)
    }

    /// The instant image's records, shared with the render worker.
    #[must_use]
    pub fn records(&self) -> SharedRecords {
        Arc::clone(&self.records)
    }

    /// What the last instant image cost (radiosity mode).
    #[must_use]
    pub fn last_instant(&self) -> Option<&InstantReport> {
        self.last_instant.as_ref()
    }

    /// The last instant image (tests compare it with the library's replay).
    #[must_use]
    pub fn instant_image(&self) -> Option<&PreviewImage> {
        self.instant_image.as_ref()
    }

    pub(super) fn instant(&mut self, report: InstantReport, image: PreviewImage) {
        self.last_instant = Some(report);
        self.instant_image = Some(image);
    }

    /// Records the time of the studio's last frame.
    pub fn frame_done(&mut self, elapsed: Duration) {
        self.last_frame = Some(elapsed);
    }

    pub(super) fn relit(&mut self, report: RelightReport) {
        if let Some(build) = &report.build {
            self.last_build = Some(build.clone());
        }
        self.last_relight = Some(report);
    }

    /// The last build of the transfers: its report.
    #[must_use]
    pub fn last_build(&self) -> Option<&RadiosityReport> {
        self.last_build.as_ref()
    }

    /// A render ended: finished (`ok`) or not.
    pub(super) fn ended(&mut self, ok: bool) {
        self.pass = None;
        if ok {
            self.finished.clone_from(&self.started);
        }
    }

    /// The Live toggle, the frame and relight times and the refinement's progress.
    pub fn ui(&mut self, ui: &mut egui::Ui, tiles: (usize, usize), busy: bool) {
        ui.horizontal(|ui| {
            let r = ui.checkbox(&mut self.enabled, "Live");
            name_widget(ui, &r, "Live preview");
            if r.changed() && !self.enabled {
                self.started = None;
            }
            let ms = |d: Duration| d.as_secs_f64() * 1e3;
            let frame = self
                .last_frame
                .map_or_else(|| "–".to_owned(), |d| format!("{:.1} ms", ms(d)));
            ui.label(format!("frame {frame}"));
        });
        if let Some(r) = &self.last_relight {
            let what = match r.update {
                TransferUpdate::Built => "built",
                TransferUpdate::Relit => "relit",
                TransferUpdate::Unchanged => "unchanged",
            };
            ui.label(format!(
                "radiosity update {:.1} ms ({what})",
                r.seconds * 1e3
            ));
        }
        if let Some(r) = &self.last_instant {
            let how = if r.recorded { "traced" } else { "replayed" };
            ui.label(format!(
                "instant image {:.1} ms ({how}: {} samples, 1 per {s}×{s} px), {:.0} ms after \
                 the render started",
                r.seconds * 1e3,
                r.samples,
                r.job_seconds * 1e3,
                s = r.stride_px
            ));
        }
        if let Some(b) = &self.last_build {
            build_report_ui(ui, b);
        }
        if busy && let Some((index, count)) = self.pass {
            let name = if index < count { "coarse" } else { "full" };
            let (done, total) = tiles;
            ui.label(format!(
                "refining: pass {index}/{count} ({name}), {done}/{total} tiles"
            ));
        }
    }
}

/// The transfers' last build: element counts, where the natural surfaces' reflectances came
/// from, and its notes (other photos left out and why, the sky below the horizon…), folded.
fn build_report_ui(ui: &mut egui::Ui, b: &RadiosityReport) {
    egui::CollapsingHeader::new(format!(
        "Radiosity build: {} / {} elements, {:.2} m",
        b.elements[0], b.elements[1], b.element_edge_m
    ))
    .id_salt("radiosity build report")
    .show(ui, |ui| {
        match &b.photo_reflectance {
            Some(p) => ui.label(format!(
                "reflectance from the photos on {} of {} natural elements ({} from the site's \
                 other photos, {} clamped to 1), the others from the material library",
                p.from_photo, p.elements, p.from_other_photos, p.clamped
            )),
            None => ui.label("reflectances from the material library"),
        };
        for note in &b.notes {
            ui.label(note);
        }
    });
}

impl crate::Studio {
    /// Live preview: restarts the render when what it shows changed (called every frame after
    /// the render worker was polled).
    pub(crate) fn live_tick(&mut self, ctx: &egui::Context) {
        if !self.render.live.enabled {
            return;
        }
        let (Some(doc), Some(id)) = (self.doc.as_ref(), self.current_photo.as_deref()) else {
            return;
        };
        if !doc
            .site
            .photos
            .iter()
            .any(|p| p.id == id && p.exterior.is_some())
        {
            return;
        }
        let quality = self.render.quality;
        let current = self
            .render
            .live
            .started
            .as_ref()
            .is_some_and(|k| k.photo == id && k.quality == quality && k.site == doc.site);
        if current {
            return;
        }
        if self.render.busy() {
            // The worker stops at its next tile; the new render starts when it has ended.
            if !self.render.worker.cancelling() {
                self.render.cancel();
                self.render.live.cancelled += 1;
            }
            return;
        }
        let key = LiveKey {
            site: doc.site.clone(),
            photo: id.to_owned(),
            quality,
        };
        let options = JobOptions {
            coarse_first: true,
            ..JobOptions::default()
        };
        let id = id.to_owned();
        let result = self.render.start_with(doc, &id, ctx, options);
        // Started or refused (an error to read), either way not retried until the next edit.
        self.render.live.started = Some(key);
        if let Err(e) = result {
            self.say(e.to_string(), true);
        }
    }
}

/// The coarse pass then the full one, as `progress` reports them.
pub(super) fn passes(options: &JobOptions, quality: Quality) -> Vec<(u32, u32)> {
    if options.coarse_first && (quality.spp_min, quality.spp_max) != (COARSE_SPP, COARSE_SPP) {
        vec![(COARSE_SPP, COARSE_SPP), (quality.spp_min, quality.spp_max)]
    } else {
        vec![(quality.spp_min, quality.spp_max)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kept display image is handed out again only for the very photo (the same allocation)
    /// and tone map it was made from; otherwise it is made again (mutation checked: without
    /// the pointer test, the equal copy gets the marked image).
    #[test]
    fn the_display_image_is_kept_for_the_same_photo_and_tone_map() {
        let photo = Arc::new(image::Rgb32FImage::from_fn(8, 6, |x, y| {
            #[allow(clippy::cast_precision_loss)]
            image::Rgb([0.01 * x as f32, 0.02 * y as f32, 0.3])
        }));
        let clamp = ToneMap::clamp();
        let mut kept = KeptView::default();
        let first = kept.display(&photo, &clamp);
        assert!(first.pixels == super::super::display_photo(&photo, &clamp).pixels);
        let mark = |kept: &mut KeptView| {
            kept.display.as_mut().expect("a kept image").2.pixels[0] = egui::Color32::RED;
        };
        // The same photo and tone map: the kept image (marked), not a new one.
        mark(&mut kept);
        assert_eq!(kept.display(&photo, &clamp).pixels[0], egui::Color32::RED);
        // Another tone map: made again.
        let reinhard = ToneMap::reinhard(0.5);
        let other = kept.display(&photo, &reinhard);
        assert!(other.pixels == super::super::display_photo(&photo, &reinhard).pixels);
        // An equal photo in another allocation (a file read again): made again.
        mark(&mut kept);
        let copy = Arc::new((*photo).clone());
        assert_ne!(kept.display(&copy, &reinhard).pixels[0], egui::Color32::RED);
    }
}
