//! The studio's render preview: renders the current (solved) photo's montage on the studio's
//! [`crate::worker::Worker`] (a panicking render ends as a message, never a stuck panel) with the
//! library's own pipeline ([`crate::render_job`]: `photomontage::site::render::prepare_view` →
//! `photomontage::render::DifferentialTracer` → `photomontage::render::render_view`, the same
//! calls as `photomontage render`), shows the render progressively (each finished tile's pixels,
//! which the library's tile callback delivers, are blitted into the preview texture with a
//! partial texture update, over the photo as the renderer sees it), the finished montage with an
//! A/B split (photo left, montage right), and exports it through
//! `photomontage::verified::image_metadata::write_render` (EXR or 8-bit by extension, carrying
//! the view's geometry).
//!
//! Tone mapping for display and 8-bit export is the site's `render.exposure` with a clamp, as in
//! the CLI.
//!
//! The AVR level (LVMF Appendix C) is chosen here like the CLI's `render --avr`: AVR0/AVR1 are
//! drawn by `photomontage::verified::avr_overlay` (no tiles), AVR2 renders with
//! `photomontage::verified::apply_massing`, AVR3 is the montage. The Sheet button writes the
//! verified-view PDF of the finished view ([`crate::render_sheet`]).
//!
//! # Known limitations
//! During the render the preview covers the whole photo (the A/B split applies to the finished
//! montage). The display texture is subsampled (nearest pixel) to at most
//! [`MAX_DISPLAY_SIDE_PX`] on its long side ([`crate::render_display`]; export is at full
//! resolution). Spectral mode and the auxiliary EXR layers are not offered here (use the CLI).

use eframe::egui::{self, Color32};
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::ToneCurve;
use photomontage::render::{OutputLayers, RenderedImage, TileProgress};
use photomontage::site::SiteDocument;
use photomontage::site::render_photo::SPP_RANGE;
use photomontage::verified::image_metadata::{view_metadata, write_render};
use photomontage::verified::standard_view::StandardView;
use photomontage::verified::{AvrLevel, PaperSize, ViewGeometry, ViewMetadata};
use std::path::Path;

use crate::panel::{Action, Panel, PanelContext};
pub use crate::render_display::{
    MAX_DISPLAY_SIDE_PX, Preview, display_image, display_photo, display_rgb, display_step,
};
pub use crate::render_job::{
    Quality, RenderPanelError, overlay_photo, prepare_photo, render_photo, site_tone_map,
    trace_photo,
};
use crate::render_views::{ViewChoice, fitted_rect, make_reprojected};
use crate::viewport::ViewTransform;
use crate::widgets::name_widget;
use crate::worker::{Poll, Progress, Worker};

pub mod instant;
pub mod live;
use live::{JobOptions, LivePreview};

/// What the render job streams to the panel before its outcome.
pub enum RenderUpdate {
    /// The photo (linear, as the renderer sees it) tone-mapped for display: the preview's base.
    Photo {
        size_px: [u32; 2],
        image: egui::ColorImage,
    },
    /// A finished tile with its pixels.
    Tile(TileProgress),
    /// A refinement pass begins (index from 1, count): its tiles replace the last pass's.
    Pass { index: u32, count: u32 },
    /// The radiosity mode's transfers were updated ([`live`]).
    Relit(photomontage::site::live_relight::RelightReport),
    /// The radiosity mode's instant image ([`instant`]): for display, the replayed preview, and
    /// its cost.
    Instant {
        display: egui::ColorImage,
        image: Box<photomontage::render::preview::PreviewImage>,
        report: instant::InstantReport,
    },
}

/// The render's worker: the montage (with the geometry of a re-projected view), or why not, with
/// the tiles streamed on the way.
pub type RenderWorker =
    Worker<Result<(RenderedImage, Option<ViewGeometry>), RenderPanelError>, RenderUpdate>;

/// A finished montage.
pub struct Montage {
    /// The photo it belongs to.
    pub photo_id: String,
    /// The render, linear RGBA at the photo's size.
    pub image: RenderedImage,
    /// The AVR level it shows.
    pub avr: AvrLevel,
    /// The geometry of a re-projected view (planar or cylindrical); `None` for the photo itself.
    pub geometry: Option<ViewGeometry>,
    texture: Option<egui::TextureHandle>,
}

/// State of the Render panel.
pub struct RenderPanel {
    /// Quality settings.
    pub quality: Quality,
    /// A/B split as a fraction of the photo width: photo left of it, montage right.
    pub ab_split: f32,
    /// Export path typed by the user.
    pub export_path: String,
    /// Path of the verified-view sheet (PDF) typed by the user.
    pub sheet_path: String,
    /// The last view geometry report (Report button).
    pub report: Option<photomontage::verified::ViewGeometry>,
    /// Draw the observation marks over the photo on this tab.
    pub show_marks: bool,
    /// Outline the finished tiles of a running render.
    pub show_tiles: bool,
    /// The view (photo, planar 50/75 mm, cylindrical) and the sheet's paper.
    pub view_choice: ViewChoice,
    /// The live preview ([`live`]).
    pub live: LivePreview,
    worker: RenderWorker,
    /// Photo and AVR level of the running render.
    running: Option<(String, AvrLevel)>,
    tiles_done: Vec<TileProgress>,
    tile_count: usize,
    montage: Option<Montage>,
    preview: Option<Preview>,
    tone_map: ToneMap,
}

impl Default for RenderPanel {
    fn default() -> Self {
        Self {
            quality: Quality::default(),
            ab_split: 0.5,
            export_path: String::new(),
            sheet_path: String::new(),
            report: None,
            show_marks: true,
            show_tiles: true,
            view_choice: ViewChoice::default(),
            live: LivePreview::default(),
            worker: Worker::new("render"),
            running: None,
            tiles_done: Vec::new(),
            tile_count: 0,
            montage: None,
            preview: None,
            tone_map: ToneMap {
                exposure_stops: 0.0,
                curve: ToneCurve::Clamp,
            },
        }
    }
}

/// The render job: the photo for the preview, then the tiles, then the montage (AVR0/AVR1: the
/// overlay, no tiles); a re-projected view ([`crate::render_views`]) in one piece.
fn render_job(
    doc: &SiteDocument,
    id: &str,
    quality: Quality,
    tone_map: ToneMap,
    view: Option<(StandardView, PaperSize)>,
    options: &JobOptions,
    progress: &Progress<RenderUpdate>,
) -> Result<(RenderedImage, Option<ViewGeometry>), RenderPanelError> {
    let job_start = std::time::Instant::now();
    if let Some((view, paper)) = view {
        let (image, geometry) =
            make_reprojected(doc, id, &view, quality.avr, paper, progress.cancel_flag())?;
        return Ok((image, Some(geometry)));
    }
    if matches!(quality.avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
        return overlay_photo(doc, id, quality.avr).map(|image| (image, None));
    }
    let (mut job, photo_display) = match &options.photo {
        Some(shared) => {
            // A job that panicked while holding the lock leaves nothing to reuse.
            let mut kept = shared.lock().unwrap_or_else(|poisoned| {
                let mut kept = poisoned.into_inner();
                *kept = live::KeptView::default();
                kept
            });
            shared.clear_poison();
            let job =
                crate::render_job::prepare_photo_kept(doc, id, quality, Some(&mut kept.photo))?;
            let display = kept.display(&job.prepared.job.photo_linear, &tone_map);
            (job, display)
        }
        None => {
            let job = prepare_photo(doc, id, quality)?;
            let display = display_photo(&job.prepared.job.photo_linear, &tone_map);
            (job, display)
        }
    };
    let photo = &job.prepared.job.photo_linear;
    progress.send(RenderUpdate::Photo {
        size_px: [photo.width(), photo.height()],
        image: photo_display.clone(),
    });
    if job.plan.radiosity && !job.prepared.photo_only {
        if job.plan.spectral {
            // The kept transfers are RGB: a spectral render solves each of its passes, as the
            // CLI does.
            job.plan
                .solve_radiosity(doc, &mut job.prepared, progress.cancel_flag())
                .map_err(|e| RenderPanelError::Prepare {
                    photo: id.to_owned(),
                    message: e.to_string(),
                })?;
        } else {
            options.prepare_radiosity(doc, id, &mut job.prepared.job, progress)?;
            let instant = instant::InstantJob {
                records: options.records.as_ref(),
                photo_display: &photo_display,
                tone_map: &tone_map,
                job_start,
            };
            instant.run(id, &job, progress)?;
        }
    }
    let tiles = progress.clone();
    let on_tile = move |t: TileProgress| tiles.send(RenderUpdate::Tile(t));
    let passes = live::passes(options, quality);
    let count = u32::try_from(passes.len()).unwrap_or(u32::MAX);
    let mut last = None;
    for (index, (spp_min, spp_max)) in (1..).zip(passes) {
        progress.send(RenderUpdate::Pass { index, count });
        last = Some(trace_photo(
            &job,
            (spp_min, spp_max),
            &on_tile,
            progress.cancel_flag(),
        )?);
    }
    last.map(|image| (image, None))
        .ok_or_else(|| RenderPanelError::Render {
            photo: id.to_owned(),
            message: "no render pass".into(),
        })
}

impl RenderPanel {
    /// Whether a render is running.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Tiles finished and in total of the running (or last) render.
    #[must_use]
    pub fn progress(&self) -> (usize, usize) {
        (self.tiles_done.len(), self.tile_count)
    }

    /// The finished montage, if any.
    #[must_use]
    pub fn montage(&self) -> Option<&Montage> {
        self.montage.as_ref()
    }

    /// The progressive preview of the running (or last) render.
    #[must_use]
    pub fn preview(&self) -> Option<&Preview> {
        self.preview.as_ref()
    }

    /// Test hook: the next render job panics ([`Worker::inject_panic_for_tests`]).
    #[doc(hidden)]
    pub fn inject_panic_for_tests(&mut self) {
        self.worker.inject_panic_for_tests();
    }

    /// Starts rendering `photo_id` of `doc` on the render worker.
    ///
    /// # Errors
    /// `NotSolved` (checked here so that the message is immediate) or a render already running
    /// (reported as `Render`).
    pub fn start(
        &mut self,
        doc: &SiteDocument,
        photo_id: &str,
        ctx: &egui::Context,
    ) -> Result<(), RenderPanelError> {
        self.start_with(doc, photo_id, ctx, JobOptions::default())
    }

    /// [`RenderPanel::start`] with the live preview's options (coarse pass first); in the
    /// radiosity mode the site's transfers are kept ([`live`]).
    ///
    /// # Errors
    /// As [`RenderPanel::start`].
    pub fn start_with(
        &mut self,
        doc: &SiteDocument,
        photo_id: &str,
        ctx: &egui::Context,
        mut options: JobOptions,
    ) -> Result<(), RenderPanelError> {
        let busy = || RenderPanelError::Render {
            photo: photo_id.to_owned(),
            message: "a render is already running".into(),
        };
        if self.worker.busy() {
            return Err(busy());
        }
        if !doc
            .site
            .photos
            .iter()
            .any(|p| p.id == photo_id && p.exterior.is_some())
        {
            return Err(RenderPanelError::NotSolved {
                photo: photo_id.to_owned(),
            });
        }
        self.tone_map = site_tone_map(doc);
        let tone_map = self.tone_map;
        let (doc, id, quality) = (doc.clone(), photo_id.to_owned(), self.quality);
        let view = self
            .view_choice
            .standard_view(photo_id)
            .map(|v| (v, self.view_choice.paper));
        if options.coarse_first {
            options.photo = Some(self.live.kept_photo());
        }
        if doc.site.render.radiosity {
            options.transfers = Some(self.live.transfers());
            if options.coarse_first {
                options.records = Some(self.live.records());
            }
        }
        let started = self.worker.spawn(ctx, move |progress| {
            render_job(&doc, &id, quality, tone_map, view, &options, progress)
        });
        if !started {
            return Err(busy());
        }
        self.tiles_done.clear();
        self.tile_count = 0;
        self.preview = None;
        self.running = Some((photo_id.to_owned(), self.quality.avr));
        Ok(())
    }

    /// Asks the running render to stop at its next tile.
    pub fn cancel(&self) {
        self.worker.cancel();
    }

    /// Drains the worker's tiles into the preview; returns the render's outcome when it ended
    /// (a panicking or vanished render job is a `Render` error with the panic's message).
    pub fn poll(&mut self) -> Option<Result<String, RenderPanelError>> {
        let (photo_id, avr) = self.running.clone()?;
        let (preview, tiles_done) = (&mut self.preview, &mut self.tiles_done);
        let (tile_count, tone_map) = (&mut self.tile_count, &self.tone_map);
        let live = &mut self.live;
        let state = self.worker.poll_with(|update| match update {
            RenderUpdate::Pass { index, count } => {
                live.pass = Some((index, count));
                tiles_done.clear();
            }
            RenderUpdate::Relit(report) => live.relit(report),
            RenderUpdate::Instant {
                display,
                image,
                report,
            } => {
                if let Some(size_px) = preview.as_ref().map(|p| p.size_px) {
                    *preview = Some(Preview::new(&photo_id, size_px, display));
                }
                live.instant(report, *image);
            }
            RenderUpdate::Photo { size_px, image } => {
                *preview = Some(Preview::new(&photo_id, size_px, image));
            }
            RenderUpdate::Tile(mut t) => {
                *tile_count = t.tile_count;
                if let Some(p) = preview.as_mut() {
                    p.apply_tile(&t, tone_map);
                }
                // The pixels are in the preview now; keep the record small.
                t.rgb_linear = Vec::new();
                tiles_done.push(t);
            }
        });
        let result = match state {
            Poll::Idle | Poll::Running(_) => return None,
            Poll::Done(r) => r,
            Poll::Cancelled => Err(RenderPanelError::Cancelled {
                photo: photo_id.clone(),
            }),
            Poll::Failed(message) => Err(RenderPanelError::Render {
                photo: photo_id.clone(),
                message,
            }),
        };
        self.running = None;
        self.live.ended(result.is_ok());
        Some(result.map(|(image, geometry)| {
            let text = match &geometry {
                Some(g) => format!(
                    "made the {} view {} ({}): {} × {} px, HFoV {:.3}°",
                    format!("{:?}", g.projection).to_lowercase(),
                    g.photo_id,
                    avr.name(),
                    g.image_size_px[0],
                    g.image_size_px[1],
                    g.hfov_deg
                ),
                None => format!(
                    "rendered {photo_id} ({}): {} changed pixels, {} primary rays",
                    avr.name(),
                    image.changed_pixels,
                    image.primary_rays
                ),
            };
            self.montage = Some(Montage {
                photo_id,
                image,
                avr,
                geometry,
                texture: None,
            });
            text
        }))
    }

    /// Writes the montage to `path` (format by extension: .exr, .png, .jpg, .tif) carrying the
    /// view's geometry (EXIF and XMP, or EXR attributes) as `photomontage render` and `view`
    /// write it; without it when the photo's report cannot be made.
    ///
    /// # Errors
    /// `NothingToExport` or the writer's error.
    pub fn export(
        &self,
        doc: &SiteDocument,
        path: &Path,
        tone_map: &ToneMap,
    ) -> Result<(), RenderPanelError> {
        let m = self
            .montage
            .as_ref()
            .ok_or(RenderPanelError::NothingToExport)?;
        let metadata = match &m.geometry {
            Some(g) => Some(ViewMetadata::from(g)),
            None => view_metadata(doc, &m.photo_id).ok(),
        };
        write_render(
            path,
            &m.image,
            &OutputLayers::default(),
            tone_map,
            metadata.as_ref(),
        )
        .map_err(|e| RenderPanelError::Render {
            photo: m.photo_id.clone(),
            message: e.to_string(),
        })
    }

    /// Screen x of the A/B split line for a photo of width `width_px` under `t`.
    #[must_use]
    pub fn split_screen_x(&self, t: &ViewTransform, width_px: u32) -> f32 {
        t.screen_from_photo([f64::from(self.ab_split) * f64::from(width_px), 0.0])
            .x
    }

    /// Paints the progress (finished tiles outlined) or the montage right of the A/B split over
    /// the photo `photo_id` of size `size_px`.
    pub fn paint(
        &mut self,
        ctx: &egui::Context,
        painter: &egui::Painter,
        t: &ViewTransform,
        photo_id: &str,
        size_px: [u32; 2],
        tone_map: &ToneMap,
    ) {
        if self.running.as_ref().is_some_and(|(id, _)| id == photo_id) {
            if let Some(p) = self
                .preview
                .as_mut()
                .filter(|p| p.photo_id == photo_id && p.size_px == size_px)
            {
                let [w, h] = size_px.map(f64::from);
                let rect = t.screen_rect([0.0, 0.0], [w, h]);
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                painter.image(p.texture(ctx).id(), rect, uv, Color32::WHITE);
            }
            let stroke = egui::Stroke::new(1.0, Color32::from_rgb(80, 200, 255));
            let outlined = if self.show_tiles {
                self.tiles_done.as_slice()
            } else {
                &[]
            };
            for tile in outlined {
                let [x, y] = tile.origin_px.map(f64::from);
                let [w, h] = tile.size_px.map(f64::from);
                let r = t.screen_rect([x, y], [x + w, y + h]);
                painter.rect_stroke(r, 0.0, stroke, egui::StrokeKind::Inside);
            }
            return;
        }
        let Some(m) = self.montage.as_mut().filter(|m| m.photo_id == photo_id) else {
            return;
        };
        let reprojected = m.geometry.is_some();
        if m.image.size_px != size_px && !reprojected {
            return;
        }
        let texture = m.texture.get_or_insert_with(|| {
            ctx.load_texture(
                format!("montage {photo_id}"),
                display_image(&m.image, tone_map),
                egui::TextureOptions::LINEAR,
            )
        });
        if reprojected {
            // A re-projected view is another image: shown whole, fitted over the photo's frame.
            let [w, h] = size_px.map(f64::from);
            let frame = t.screen_rect([0.0, 0.0], [w, h]);
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            painter.rect_filled(frame, 0.0, Color32::from_gray(30));
            painter.image(
                texture.id(),
                fitted_rect(frame, m.image.size_px),
                uv,
                Color32::WHITE,
            );
            return;
        }
        let split = self.ab_split.clamp(0.0, 1.0);
        let [w, h] = size_px.map(f64::from);
        let rect = t.screen_rect([f64::from(split) * w, 0.0], [w, h]);
        let uv = egui::Rect::from_min_max(egui::pos2(split, 0.0), egui::pos2(1.0, 1.0));
        painter.image(texture.id(), rect, uv, Color32::WHITE);
        painter.vline(
            rect.left(),
            rect.y_range(),
            egui::Stroke::new(2.0, Color32::from_rgb(255, 210, 0)),
        );
    }
}

impl crate::Studio {
    /// Starts rendering the current photo (errors become messages).
    pub fn start_render(&mut self, ctx: &egui::Context) {
        let (Some(doc), Some(id)) = (self.doc.as_ref(), self.current_photo.clone()) else {
            self.say("open a site with a photo first", true);
            return;
        };
        match self.render.start(doc, &id, ctx) {
            Ok(()) => self.say(format!("rendering {id}…"), false),
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// Exports the montage to the path typed in the Render panel.
    pub fn export_render(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let path = std::path::PathBuf::from(self.render.export_path.trim());
        if path.as_os_str().is_empty() {
            self.say("type an export path (.exr, .png, .jpg, .tif) first", true);
            return;
        }
        match self.render.export(doc, &path, &site_tone_map(doc)) {
            Ok(()) => self.say(format!("exported {}", path.display()), false),
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// The Render panel (mutable: tests set quality, split and export path as a user would).
    pub fn render_panel_mut(&mut self) -> &mut RenderPanel {
        &mut self.render
    }

    /// The Render panel.
    #[must_use]
    pub fn render_panel(&self) -> &RenderPanel {
        &self.render
    }

    pub(crate) fn poll_render(&mut self, ctx: &egui::Context) {
        match self.render.poll() {
            // A live render replaced by a newer one is not news.
            Some(Err(RenderPanelError::Cancelled { .. })) if self.render.live.enabled => {}
            Some(Ok(text)) => self.say(text, false),
            Some(Err(e)) => self.say(e.to_string(), true),
            None => {}
        }
        self.live_tick(ctx);
        if self.render.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }
}

impl Panel for RenderPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        let id = ctx.current_photo.unwrap_or_default();
        let solved = ctx.current_photo_solved();
        ui.label(format!("view: photo {id}"));
        if !solved {
            ui.colored_label(
                crate::widgets::WARNING,
                "this photo is not solved yet: press Solve first",
            );
        }
        let q = &mut self.quality;
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::DragValue::new(&mut q.spp_min)
                    .range(SPP_RANGE)
                    .speed(0.2),
            );
            name_widget(ui, &r, "spp min");
            ui.label("–");
            let r = ui.add(
                egui::DragValue::new(&mut q.spp_max)
                    .range(SPP_RANGE)
                    .speed(0.2),
            );
            name_widget(ui, &r, "spp max");
            ui.label("rays per pixel (multiples of 4)");
        });
        ui.horizontal(|ui| {
            let r = ui.add(egui::DragValue::new(&mut q.seed));
            name_widget(ui, &r, "seed");
            ui.label("seed");
        });
        ui.horizontal(|ui| {
            ui.label("AVR level");
            let r = egui::ComboBox::from_id_salt("avr level")
                .selected_text(q.avr.name())
                .show_ui(ui, |ui| {
                    for level in [
                        AvrLevel::Avr0,
                        AvrLevel::Avr1,
                        AvrLevel::Avr2,
                        AvrLevel::Avr3,
                    ] {
                        ui.selectable_value(&mut q.avr, level, level.name())
                            .on_hover_text(level.description());
                    }
                })
                .response;
            name_widget(ui, &r, "AVR level");
        });
        self.view_choice.ui(ui);
        ui.horizontal(|ui| {
            let busy = self.busy();
            if ui.add_enabled(!busy, egui::Button::new("Start")).clicked() {
                actions.push(Action::StartRender);
            }
            if ui.add_enabled(busy, egui::Button::new("Cancel")).clicked() {
                actions.push(Action::CancelRender);
            }
            let (done, total) = self.progress();
            if busy {
                ui.spinner();
                let f = if total == 0 {
                    0.0
                } else {
                    done as f32 / total as f32
                };
                ui.add(egui::ProgressBar::new(f).text(format!("{done}/{total} tiles")));
            }
        });
        let busy = self.busy();
        self.live.ui(ui, self.progress(), busy);
        let r = ui.add(egui::Slider::new(&mut self.ab_split, 0.0..=1.0).text("A/B"));
        name_widget(ui, &r, "A/B split");
        ui.label("photo left of the split, montage right");
        ui.horizontal(|ui| {
            let r = ui.checkbox(&mut self.show_marks, "control marks");
            name_widget(ui, &r, "show control marks");
            let r = ui.checkbox(&mut self.show_tiles, "tile outlines");
            name_widget(ui, &r, "show tile outlines");
        });
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.export_path)
                    .hint_text("montage.exr / .png / .jpg / .tif")
                    .desired_width(260.0),
            );
            name_widget(ui, &r, "export path");
            let has = self.montage().is_some_and(|m| m.photo_id == id);
            if ui.add_enabled(has, egui::Button::new("Export")).clicked() {
                actions.push(Action::ExportRender);
            }
        });
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.sheet_path)
                    .hint_text("sheet.pdf")
                    .desired_width(260.0),
            );
            name_widget(ui, &r, "sheet path");
            let has = self.montage().is_some_and(|m| m.photo_id == id);
            if ui.add_enabled(has, egui::Button::new("Sheet")).clicked() {
                actions.push(Action::ExportSheet);
            }
        });
        if ui.button("Report").clicked() {
            actions.push(Action::MakeReport);
        }
        self.report_ui(ui, id);
        actions
    }
}
