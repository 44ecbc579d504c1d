//! The studio's render preview: renders the current (solved) photo's montage on a worker thread
//! with the library's own pipeline (`photomontage::site::render::prepare_view` →
//! `photomontage::render::DifferentialTracer` → `photomontage::render::render_view`, the same
//! calls as `photomontage render`), shows the render progressively (each finished tile's pixels,
//! which the library's tile callback delivers, are blitted into the preview texture with a
//! partial texture update, over the photo as the renderer sees it), the finished montage with an
//! A/B split (photo left, montage right), and exports it through
//! `photomontage::render::output::write_output` (EXR or 8-bit by extension).
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
//! [`MAX_DISPLAY_SIDE_PX`] on its long side (export is at full resolution). Spectral mode and the
//! auxiliary EXR layers are not offered here (use the CLI).

use eframe::egui::{self, Color32};
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::{ToneCurve, encode_srgb8};
use photomontage::render::{
    DifferentialTracer, OutputLayers, RenderError, RenderedImage, TileProgress, output, render_view,
};
use photomontage::site::SiteDocument;
use photomontage::site::render::{ViewJob, prepare_view};
use photomontage::verified::{AvrLevel, apply_massing, avr_overlay};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};

use crate::viewport::ViewTransform;

/// Longest side of the preview texture; larger montages are subsampled for display only.
pub const MAX_DISPLAY_SIDE_PX: u32 = 2048;

/// Quality settings chosen in the panel (override the site's `[render]` table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quality {
    /// Rays per pixel at least (multiple of 4).
    pub spp_min: u32,
    /// Rays per pixel at most (multiple of 4, ≥ `spp_min`).
    pub spp_max: u32,
    /// Seed of the sample positions.
    pub seed: u64,
    /// Accurate Visual Representation level of the view.
    pub avr: AvrLevel,
}

impl Default for Quality {
    fn default() -> Self {
        Self {
            spp_min: 4,
            spp_max: 16,
            seed: 0,
            avr: AvrLevel::Avr3,
        }
    }
}

/// Why a render could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum RenderPanelError {
    /// The photo has no solved orientation.
    #[error("photo {photo} is not solved yet: press Solve first")]
    NotSolved { photo: String },
    /// Rays per pixel not a positive multiple of 4 or min above max.
    #[error(
        "rays per pixel {spp_min}–{spp_max}: both must be multiples of 4, 4 or more, min ≤ max"
    )]
    BadQuality { spp_min: u32, spp_max: u32 },
    /// The site could not be prepared (no models, unreadable model, …).
    #[error("cannot render {photo}: {message}")]
    Prepare { photo: String, message: String },
    /// The renderer failed.
    #[error("render of {photo} failed: {message}")]
    Render { photo: String, message: String },
    /// The user cancelled.
    #[error("render of {photo} cancelled")]
    Cancelled { photo: String },
    /// Nothing rendered for this photo yet.
    #[error("nothing to export: render the photo first")]
    NothingToExport,
    /// Writing the file failed.
    #[error(transparent)]
    Export(#[from] photomontage::render::OutputError),
    /// The verified-view sheet could not be made or written.
    #[error(transparent)]
    Sheet(#[from] Box<photomontage::verified::sheet::SheetError>),
}

enum WorkerMsg {
    /// The photo (linear, as the renderer sees it) tone-mapped for display: the preview's base.
    Photo {
        size_px: [u32; 2],
        image: egui::ColorImage,
    },
    Tile(TileProgress),
    Done(Result<RenderedImage, RenderPanelError>),
}

struct Worker {
    photo_id: String,
    avr: AvrLevel,
    cancel: Arc<AtomicBool>,
    rx: Receiver<WorkerMsg>,
}

/// A finished montage.
pub struct Montage {
    /// The photo it belongs to.
    pub photo_id: String,
    /// The render, linear RGBA at the photo's size.
    pub image: RenderedImage,
    /// The AVR level it shows.
    pub avr: AvrLevel,
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
    worker: Option<Worker>,
    tiles_done: Vec<TileProgress>,
    tile_count: usize,
    montage: Option<Montage>,
    preview: Option<Preview>,
    tone_map: ToneMap,
}

/// The progressive preview of a running render: the photo's display image with each finished
/// tile's pixels written in, uploaded to the GPU by partial texture updates.
pub struct Preview {
    /// The photo rendered.
    pub photo_id: String,
    /// Full-resolution size of the render.
    pub size_px: [u32; 2],
    step: u32,
    image: egui::ColorImage,
    texture: Option<egui::TextureHandle>,
    /// Regions changed since the last upload: (display-pixel origin, pixels).
    dirty: Vec<([usize; 2], egui::ColorImage)>,
}

impl Preview {
    /// A preview of `photo_id` (full size `size_px`) starting from `base`, the photo's display
    /// image made with [`display_rgb`].
    #[must_use]
    pub fn new(photo_id: &str, size_px: [u32; 2], base: egui::ColorImage) -> Self {
        Self {
            photo_id: photo_id.to_owned(),
            size_px,
            step: display_step(size_px),
            image: base,
            texture: None,
            dirty: Vec::new(),
        }
    }

    /// The preview's pixels now (display resolution).
    #[must_use]
    pub fn image(&self) -> &egui::ColorImage {
        &self.image
    }

    /// Writes a finished tile's pixels (tone-mapped with `tone_map`) into the preview and
    /// queues the changed region for upload.
    pub fn apply_tile(&mut self, tile: &TileProgress, tone_map: &ToneMap) {
        let step = self.step;
        let [x0, y0] = tile.origin_px;
        let [tw, th] = tile.size_px;
        if tile.rgb_linear.len() != (tw * th) as usize
            || x0 + tw > self.size_px[0]
            || y0 + th > self.size_px[1]
        {
            return;
        }
        // Display pixels whose sample (d·step) falls inside the tile.
        let (dx0, dx1) = (x0.div_ceil(step), (x0 + tw).div_ceil(step));
        let (dy0, dy1) = (y0.div_ceil(step), (y0 + th).div_ceil(step));
        if dx0 >= dx1 || dy0 >= dy1 {
            return;
        }
        let (dw, dh) = ((dx1 - dx0) as usize, (dy1 - dy0) as usize);
        let mut pixels = Vec::with_capacity(dw * dh);
        let width = self.image.size[0];
        for dy in dy0..dy1 {
            for dx in dx0..dx1 {
                let (x, y) = (dx * step - x0, dy * step - y0);
                let [r, g, b] = encode_srgb8(tile.rgb_linear[(y * tw + x) as usize], tone_map);
                let c = Color32::from_rgb(r, g, b);
                if let Some(p) = self.image.pixels.get_mut(dy as usize * width + dx as usize) {
                    *p = c;
                }
                pixels.push(c);
            }
        }
        self.dirty.push((
            [dx0 as usize, dy0 as usize],
            egui::ColorImage::new([dw, dh], pixels),
        ));
    }

    /// Uploads the changed regions (the whole image the first time) and returns the texture.
    fn texture(&mut self, ctx: &egui::Context) -> &egui::TextureHandle {
        let dirty = std::mem::take(&mut self.dirty);
        if let Some(t) = &mut self.texture {
            for (pos, img) in dirty {
                t.set_partial(pos, img, egui::TextureOptions::LINEAR);
            }
        }
        self.texture.get_or_insert_with(|| {
            ctx.load_texture(
                format!("preview {}", self.photo_id),
                self.image.clone(),
                egui::TextureOptions::LINEAR,
            )
        })
    }
}

impl Default for RenderPanel {
    fn default() -> Self {
        Self {
            quality: Quality::default(),
            ab_split: 0.5,
            export_path: String::new(),
            sheet_path: String::new(),
            report: None,
            worker: None,
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

/// The tone map of the site (its `render.exposure`, clamped), as the CLI uses.
#[must_use]
pub fn site_tone_map(doc: &SiteDocument) -> ToneMap {
    ToneMap {
        exposure_stops: doc.site.render.exposure.log2(),
        curve: ToneCurve::Clamp,
    }
}

/// Renders `photo_id` of `doc` as the panel does (prepare, quality override, trace), calling
/// `on_tile` per finished tile. Used by the worker; public so that tests can compare.
///
/// # Errors
/// [`RenderPanelError`] variants `NotSolved`, `BadQuality`, `Prepare`, `Render`, `Cancelled`.
pub fn render_photo(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderPanelError> {
    let job = prepare_photo(doc, photo_id, quality)?;
    trace_photo(&job, photo_id, on_tile, cancel)
}

/// Prepares the render of `photo_id` as the panel does (site → scene, lighting, camera,
/// linear photo; quality override).
///
/// # Errors
/// [`RenderPanelError`] variants `NotSolved`, `BadQuality`, `Prepare`.
pub fn prepare_photo(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
) -> Result<ViewJob, RenderPanelError> {
    let photo = photo_id.to_owned();
    if !doc
        .site
        .photos
        .iter()
        .any(|p| p.id == photo_id && p.exterior.is_some())
    {
        return Err(RenderPanelError::NotSolved { photo });
    }
    let Quality {
        spp_min,
        spp_max,
        seed,
        avr,
    } = quality;
    if spp_min < 4 || spp_min % 4 != 0 || spp_max % 4 != 0 || spp_min > spp_max {
        return Err(RenderPanelError::BadQuality { spp_min, spp_max });
    }
    let mut job = prepare_view(doc, photo_id).map_err(|e| RenderPanelError::Prepare {
        photo: photo.clone(),
        message: e.to_string(),
    })?;
    job.settings.min_rays_per_pixel = spp_min;
    job.settings.max_rays_per_pixel = spp_max;
    job.settings.seed = seed;
    if avr == AvrLevel::Avr2 {
        apply_massing(&mut job.scene.scene).map_err(|e| RenderPanelError::Prepare {
            photo: photo.clone(),
            message: e.to_string(),
        })?;
    }
    Ok(job)
}

/// AVR0/AVR1: the silhouette or wireline of `photo_id` drawn over the photo.
///
/// # Errors
/// [`RenderPanelError::Prepare`] with the library's message (unsolved photo, no model, …).
pub fn overlay_photo(
    doc: &SiteDocument,
    photo_id: &str,
    avr: AvrLevel,
) -> Result<RenderedImage, RenderPanelError> {
    avr_overlay(doc, photo_id, avr)
        .map(|o| o.image)
        .map_err(|e| RenderPanelError::Prepare {
            photo: photo_id.to_owned(),
            message: e.to_string(),
        })
}

/// Traces a prepared job, calling `on_tile` per finished tile.
///
/// # Errors
/// [`RenderPanelError`] variants `Prepare`, `Render`, `Cancelled`.
pub fn trace_photo(
    job: &ViewJob,
    photo_id: &str,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderPanelError> {
    let photo = photo_id.to_owned();
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .map_err(|e| RenderPanelError::Prepare {
        photo: photo.clone(),
        message: e.to_string(),
    })?;
    render_view(&tracer, &job.settings, on_tile, cancel).map_err(|e| match e {
        RenderError::Cancelled => RenderPanelError::Cancelled { photo },
        other => RenderPanelError::Render {
            photo,
            message: other.to_string(),
        },
    })
}

/// Subsampling step of the display image of a `size_px` render (1 up to
/// [`MAX_DISPLAY_SIDE_PX`]).
#[must_use]
pub fn display_step(size_px: [u32; 2]) -> u32 {
    size_px[0]
        .max(size_px[1])
        .div_ceil(MAX_DISPLAY_SIDE_PX)
        .max(1)
}

/// The display image (nearest-pixel subsampled by [`display_step`], sRGB through `tone_map`)
/// of linear RGB pixels `rgb_at(x, y)` of a `size_px` image.
#[must_use]
pub fn display_rgb(
    size_px: [u32; 2],
    rgb_at: impl Fn(u32, u32) -> [f32; 3],
    tone_map: &ToneMap,
) -> egui::ColorImage {
    let [w, h] = size_px;
    let step = display_step(size_px);
    let (dw, dh) = (w.div_ceil(step), h.div_ceil(step));
    let mut pixels = Vec::with_capacity((dw * dh) as usize);
    for y in 0..dh {
        for x in 0..dw {
            let [r, g, b] = encode_srgb8(rgb_at(x * step, y * step), tone_map);
            pixels.push(Color32::from_rgb(r, g, b));
        }
    }
    egui::ColorImage::new([dw as usize, dh as usize], pixels)
}

/// The display image of a finished render.
#[must_use]
pub fn display_image(image: &RenderedImage, tone_map: &ToneMap) -> egui::ColorImage {
    let w = image.size_px[0];
    display_rgb(
        image.size_px,
        |x, y| {
            let p = image.rgba[(y * w + x) as usize];
            [p[0], p[1], p[2]]
        },
        tone_map,
    )
}

/// The display image of the (linear) photo a render starts from.
#[must_use]
pub fn display_photo(photo_linear: &image::Rgb32FImage, tone_map: &ToneMap) -> egui::ColorImage {
    display_rgb(
        [photo_linear.width(), photo_linear.height()],
        |x, y| photo_linear.get_pixel(x, y).0,
        tone_map,
    )
}

impl RenderPanel {
    /// Whether a render is running.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.is_some()
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

    /// Starts rendering `photo_id` of `doc` on a worker thread.
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
        if self.worker.is_some() {
            return Err(RenderPanelError::Render {
                photo: photo_id.to_owned(),
                message: "a render is already running".into(),
            });
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
        let (tx, rx): (Sender<WorkerMsg>, Receiver<WorkerMsg>) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        self.tone_map = site_tone_map(doc);
        let tone_map = self.tone_map;
        let (doc, id, quality, ctx) = (doc.clone(), photo_id.to_owned(), self.quality, ctx.clone());
        let flag = Arc::clone(&cancel);
        std::thread::spawn(move || {
            let tile_tx = tx.clone();
            let tile_ctx = ctx.clone();
            let on_tile = move |t: TileProgress| {
                // A closed channel means the studio is gone; nothing to report to.
                let _ = tile_tx.send(WorkerMsg::Tile(t));
                tile_ctx.request_repaint();
            };
            let result = if matches!(quality.avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
                overlay_photo(&doc, &id, quality.avr)
            } else {
                prepare_photo(&doc, &id, quality).and_then(|job| {
                    let photo = &job.photo_linear;
                    let _ = tx.send(WorkerMsg::Photo {
                        size_px: [photo.width(), photo.height()],
                        image: display_photo(photo, &tone_map),
                    });
                    trace_photo(&job, &id, &on_tile, &flag)
                })
            };
            let _ = tx.send(WorkerMsg::Done(result));
            ctx.request_repaint();
        });
        self.tiles_done.clear();
        self.tile_count = 0;
        self.preview = None;
        self.worker = Some(Worker {
            photo_id: photo_id.to_owned(),
            avr: self.quality.avr,
            cancel,
            rx,
        });
        Ok(())
    }

    /// Asks the running render to stop at its next tile.
    pub fn cancel(&self) {
        if let Some(w) = &self.worker {
            w.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Drains the worker's messages; returns the render's outcome when it finished.
    pub fn poll(&mut self) -> Option<Result<String, RenderPanelError>> {
        let worker = self.worker.as_ref()?;
        let mut done = None;
        while let Ok(msg) = worker.rx.try_recv() {
            match msg {
                WorkerMsg::Photo { size_px, image } => {
                    self.preview = Some(Preview::new(&worker.photo_id, size_px, image));
                }
                WorkerMsg::Tile(mut t) => {
                    self.tile_count = t.tile_count;
                    if let Some(p) = self.preview.as_mut() {
                        p.apply_tile(&t, &self.tone_map);
                    }
                    // The pixels are in the preview now; keep the record small.
                    t.rgb_linear = Vec::new();
                    self.tiles_done.push(t);
                }
                WorkerMsg::Done(r) => done = Some(r),
            }
        }
        let photo_id = worker.photo_id.clone();
        let avr = worker.avr;
        let result = done?;
        self.worker = None;
        Some(result.map(|image| {
            let text = format!(
                "rendered {photo_id} ({}): {} changed pixels, {} primary rays",
                avr.name(),
                image.changed_pixels,
                image.primary_rays
            );
            self.montage = Some(Montage {
                photo_id,
                image,
                avr,
                texture: None,
            });
            text
        }))
    }

    /// Writes the montage to `path` (format by extension: .exr, .png, .jpg, .tif).
    ///
    /// # Errors
    /// `NothingToExport` or the output module's error.
    pub fn export(&self, path: &Path, tone_map: &ToneMap) -> Result<(), RenderPanelError> {
        let m = self
            .montage
            .as_ref()
            .ok_or(RenderPanelError::NothingToExport)?;
        output::write_output(path, &m.image, &OutputLayers::default(), tone_map)?;
        Ok(())
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
        if self.worker.as_ref().is_some_and(|w| w.photo_id == photo_id) {
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
            for tile in &self.tiles_done {
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
        if m.image.size_px != size_px {
            return;
        }
        let texture = m.texture.get_or_insert_with(|| {
            ctx.load_texture(
                format!("montage {photo_id}"),
                display_image(&m.image, tone_map),
                egui::TextureOptions::LINEAR,
            )
        });
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
        match self.render.export(&path, &site_tone_map(doc)) {
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
            Some(Ok(text)) => self.say(text, false),
            Some(Err(e)) => self.say(e.to_string(), true),
            None => {}
        }
        if self.render.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    pub(crate) fn render_tab_ui(&mut self, ui: &mut egui::Ui) {
        let id = self.current_photo.clone().unwrap_or_default();
        let solved = self.doc.as_ref().is_some_and(|d| {
            d.site
                .photos
                .iter()
                .any(|p| p.id == id && p.exterior.is_some())
        });
        ui.label(format!("view: photo {id}"));
        if !solved {
            ui.colored_label(
                Color32::from_rgb(230, 160, 40),
                "this photo is not solved yet: press Solve first",
            );
        }
        let q = &mut self.render.quality;
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::DragValue::new(&mut q.spp_min)
                    .range(4..=1024)
                    .speed(0.2),
            );
            crate::points::name_widget(ui, &r, "spp min");
            ui.label("–");
            let r = ui.add(
                egui::DragValue::new(&mut q.spp_max)
                    .range(4..=1024)
                    .speed(0.2),
            );
            crate::points::name_widget(ui, &r, "spp max");
            ui.label("rays per pixel (multiples of 4)");
        });
        ui.horizontal(|ui| {
            let r = ui.add(egui::DragValue::new(&mut q.seed));
            crate::points::name_widget(ui, &r, "seed");
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
            crate::points::name_widget(ui, &r, "AVR level");
        });
        ui.horizontal(|ui| {
            let busy = self.render.busy();
            if ui.add_enabled(!busy, egui::Button::new("Start")).clicked() {
                let ctx = ui.ctx().clone();
                self.start_render(&ctx);
            }
            if ui.add_enabled(busy, egui::Button::new("Cancel")).clicked() {
                self.render.cancel();
            }
            let (done, total) = self.render.progress();
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
        let r = ui.add(egui::Slider::new(&mut self.render.ab_split, 0.0..=1.0).text("A/B"));
        crate::points::name_widget(ui, &r, "A/B split");
        ui.label("photo left of the split, montage right");
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.render.export_path)
                    .hint_text("montage.exr / .png / .jpg / .tif")
                    .desired_width(260.0),
            );
            crate::points::name_widget(ui, &r, "export path");
            let has = self.render.montage().is_some_and(|m| m.photo_id == id);
            if ui.add_enabled(has, egui::Button::new("Export")).clicked() {
                self.export_render();
            }
        });
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.render.sheet_path)
                    .hint_text("sheet.pdf")
                    .desired_width(260.0),
            );
            crate::points::name_widget(ui, &r, "sheet path");
            let has = self.render.montage().is_some_and(|m| m.photo_id == id);
            if ui.add_enabled(has, egui::Button::new("Sheet")).clicked() {
                self.export_sheet();
            }
        });
        self.report_ui(ui);
    }
}
