//! The Study tab: a sun and shadow study of the current photo, as `photomontage study` makes it
//! (issue 17 item 5). Dates and local clock times are typed as the CLI's `--dates`/`--times`
//! (times in the site's `location.time_zone` unless they carry an offset) and parsed by the
//! library (`photomontage::study::parse_dates`, `parse_times`); the study runs on the studio's
//! one worker type ([`crate::worker::Worker`]) through `photomontage::study::series::run_study`,
//! the same call as the CLI, with a progress bar over all frames' tiles and Cancel. Each frame
//! reaches the animated preview as soon as it is made: a scrubber through the frames, play/pause,
//! and a caption with the frame's local time, UTC offset and SPA sun azimuth/elevation. Export
//! writes the frames, shadow maps and contact sheet with `StudyResult::write` (a new folder
//! appears whole, or not at all).
//!
//! # Known limitations
//! The study renders with the site's `[render]` quality (as the CLI without `--spp-*`); the
//! preview is nearest-pixel subsampled to [`crate::render_display::MAX_DISPLAY_SIDE_PX`] (the
//! files are full size); a cancelled study keeps nothing, not even its finished frames.

use eframe::egui;
use image::RgbImage;
use photomontage::site::SiteDocument;
use photomontage::study::series::{StudyEvent, StudyOptions, StudyResult, run_study};
use photomontage::study::shadow_map::DEFAULT_CELL_M;
use photomontage::study::{
    StudyError, StudyFrame, StudyRequest, parse_dates, parse_times, plan_frames,
};

use crate::panel::{Action, Panel, PanelContext};
use crate::render_display::MAX_DISPLAY_SIDE_PX;
use crate::widgets::name_widget;
use crate::worker::{Poll, Progress, Worker};

/// Frames per second of the animated preview by default.
pub const DEFAULT_FPS: f64 = 2.0;

/// What the study job streams to the panel before its outcome.
pub enum StudyUpdate {
    /// The frames are planned: this many daylight frames, this many tiles in all.
    Planned { daylight: usize, tiles_total: u64 },
    /// A tile of a montage is finished.
    Tile,
    /// A daylight frame is made.
    Frame(Box<PreviewFrame>),
}

/// The study's worker: the study, or the library's message why not.
pub type StudyWorker = Worker<Result<StudyResult, String>, StudyUpdate>;

/// One frame of the animated preview.
pub struct PreviewFrame {
    /// The frame's date, time and sun.
    pub frame: StudyFrame,
    /// The montage for display (sRGB, subsampled).
    pub montage: Option<egui::ColorImage>,
    /// The shadow map for display.
    pub shadow_map: Option<egui::ColorImage>,
    textures: [Option<egui::TextureHandle>; 2],
}

impl PreviewFrame {
    /// The caption: local date and time with its UTC offset, and the SPA sun.
    #[must_use]
    pub fn caption(&self) -> String {
        let f = &self.frame;
        format!(
            "{} {} (UTC{})  sun azimuth {:.1}°, elevation {:.1}°",
            f.date.format("%Y-%m-%d"),
            f.clock.format("%H:%M"),
            f.time.offset(),
            f.sun_azimuth_deg,
            f.sun_elevation_deg
        )
    }
}

/// Which picture of a frame the preview shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PreviewKind {
    Montage,
    ShadowMap,
}

/// The display image of an 8-bit picture: nearest-pixel subsampled to at most
/// [`MAX_DISPLAY_SIDE_PX`] on its long side.
#[must_use]
pub fn preview_image(img: &RgbImage) -> egui::ColorImage {
    let (w, h) = img.dimensions();
    let step = w.max(h).div_ceil(MAX_DISPLAY_SIDE_PX).max(1);
    let (dw, dh) = (w.div_ceil(step), h.div_ceil(step));
    let mut pixels = Vec::with_capacity((dw * dh) as usize);
    for y in 0..dh {
        for x in 0..dw {
            let [r, g, b] = img.get_pixel(x * step, y * step).0;
            pixels.push(egui::Color32::from_rgb(r, g, b));
        }
    }
    egui::ColorImage::new([dw as usize, dh as usize], pixels)
}

/// State of the Study tab.
pub struct StudyPanel {
    /// Dates as the CLI's `--dates` (YYYY-MM-DD, comma-separated).
    pub dates: String,
    /// Local clock times as the CLI's `--times` (HH:MM, comma-separated).
    pub times: String,
    /// Render a montage per frame.
    pub montages: bool,
    /// Map the shadows in plan view per frame.
    pub shadow_maps: bool,
    /// Cell edge of the shadow maps, metres.
    pub cell_m: f64,
    /// Folder the Export button writes to.
    pub export_folder: String,
    /// Also write each montage as linear EXR.
    pub exr: bool,
    /// The frame shown (index into the preview frames).
    pub frame: usize,
    /// Whether the preview plays.
    pub playing: bool,
    /// Frames per second while playing.
    pub fps: f64,
    /// Which picture the preview shows.
    pub show: PreviewKind,
    worker: StudyWorker,
    /// The photo of the running study.
    running: Option<String>,
    tiles_done: u64,
    tiles_total: u64,
    daylight: usize,
    frames: Vec<PreviewFrame>,
    result: Option<StudyResult>,
    last_switch_s: f64,
}

impl Default for StudyPanel {
    fn default() -> Self {
        Self {
            dates: "2026-03-20,2026-06-21,2026-12-21".into(),
            times: "09:00,12:00,15:00".into(),
            montages: true,
            shadow_maps: false,
            cell_m: DEFAULT_CELL_M,
            export_folder: String::new(),
            exr: false,
            frame: 0,
            playing: false,
            fps: DEFAULT_FPS,
            show: PreviewKind::Montage,
            worker: Worker::new("study"),
            running: None,
            tiles_done: 0,
            tiles_total: 0,
            daylight: 0,
            frames: Vec::new(),
            result: None,
            last_switch_s: 0.0,
        }
    }
}

/// The study job: run the library's study, streaming each frame's pictures to the preview.
fn study_job(
    doc: &SiteDocument,
    request: &StudyRequest,
    options: StudyOptions,
    progress: &Progress<StudyUpdate>,
) -> Result<StudyResult, String> {
    let on_event = |event: StudyEvent<'_>| match event {
        StudyEvent::Planned {
            daylight,
            tiles_total,
            ..
        } => progress.send(StudyUpdate::Planned {
            daylight,
            tiles_total,
        }),
        StudyEvent::FrameStarted {
            index,
            count,
            frame,
        } => progress.set(
            Some(index as f32 / count.max(1) as f32),
            format!("frame {} of {count}: {}", index + 1, frame.label()),
        ),
        StudyEvent::Tile(_) => progress.send(StudyUpdate::Tile),
        StudyEvent::FrameDone { output, .. } => {
            progress.send(StudyUpdate::Frame(Box::new(PreviewFrame {
                frame: output.frame.clone(),
                montage: output.montage.as_ref().map(|m| preview_image(&m.srgb)),
                shadow_map: output.shadow_map.as_ref().map(preview_image),
                textures: [None, None],
            })));
        }
    };
    run_study(doc, request, options, &on_event, progress.cancel_flag()).map_err(|e| e.to_string())
}

impl StudyPanel {
    /// Whether a study is running.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Tiles finished and in total of the running (or last) study.
    #[must_use]
    pub fn progress(&self) -> (u64, u64) {
        (self.tiles_done, self.tiles_total)
    }

    /// The frames of the preview (those made so far while running).
    #[must_use]
    pub fn frames(&self) -> &[PreviewFrame] {
        &self.frames
    }

    /// The last finished study (what Export writes).
    #[must_use]
    pub fn result(&self) -> Option<&StudyResult> {
        self.result.as_ref()
    }

    /// The request typed in the tab for `view`.
    ///
    /// # Errors
    /// The library's parse errors as text, naming the entry.
    pub fn request(&self, view: &str) -> Result<StudyRequest, String> {
        Ok(StudyRequest {
            view: view.to_owned(),
            dates: parse_dates(&self.dates).map_err(|e| e.to_string())?,
            times: parse_times(&self.times).map_err(|e| e.to_string())?,
            spp_min: None,
            spp_max: None,
            seed: None,
        })
    }

    /// The options ticked in the tab.
    #[must_use]
    pub fn options(&self) -> StudyOptions {
        StudyOptions {
            montages: self.montages,
            shadow_maps: self.shadow_maps,
            cell_m: self.cell_m,
        }
    }

    /// Starts the study of `view`; the request is parsed and planned first (cheap), so bad
    /// input and a study without daylight are refused at once with the library's message.
    ///
    /// # Errors
    /// As [`Self::request`], [`plan_frames`]; a study already running.
    pub fn start(
        &mut self,
        doc: &SiteDocument,
        view: &str,
        ctx: &egui::Context,
    ) -> Result<(), String> {
        if self.worker.busy() {
            return Err("a study is already running".into());
        }
        let request = self.request(view)?;
        let options = self.options();
        if !options.montages && !options.shadow_maps {
            return Err(StudyError::NothingToMake.to_string());
        }
        plan_frames(doc, &request).map_err(|e| e.to_string())?;
        let doc = doc.clone();
        let started = self.worker.spawn(ctx, move |progress| {
            study_job(&doc, &request, options, progress)
        });
        if !started {
            return Err("a study is already running".into());
        }
        self.running = Some(view.to_owned());
        self.tiles_done = 0;
        self.tiles_total = 0;
        self.daylight = 0;
        self.frames.clear();
        self.result = None;
        self.frame = 0;
        self.playing = false;
        Ok(())
    }

    /// Asks the running study to stop at its next tile.
    pub fn cancel(&self) {
        self.worker.cancel();
    }

    /// Drains the worker's updates; returns the outcome as a message when the study ended
    /// (`Err` for failures and cancellation, which keep nothing).
    pub fn poll(&mut self) -> Option<Result<String, String>> {
        let view = self.running.clone()?;
        let (frames, tiles_done) = (&mut self.frames, &mut self.tiles_done);
        let (tiles_total, daylight) = (&mut self.tiles_total, &mut self.daylight);
        let state = self.worker.poll_with(|update| match update {
            StudyUpdate::Planned {
                daylight: d,
                tiles_total: t,
            } => {
                *daylight = d;
                *tiles_total = t;
            }
            StudyUpdate::Tile => *tiles_done += 1,
            StudyUpdate::Frame(f) => frames.push(*f),
        });
        let outcome = match state {
            Poll::Idle | Poll::Running(_) => return None,
            Poll::Done(Ok(result)) => Ok(result),
            Poll::Done(Err(e)) => Err(e),
            Poll::Cancelled => Err(StudyError::Cancelled.to_string()),
            Poll::Failed(message) => Err(format!("study of {view} failed: {message}")),
        };
        self.running = None;
        Some(match outcome {
            Ok(result) => {
                let skipped = result.frames.len() - result.outputs.len();
                let text = format!(
                    "study of {view}: {} frame(s) made{}",
                    result.outputs.len(),
                    if skipped > 0 {
                        format!(", {skipped} night frame(s) skipped")
                    } else {
                        String::new()
                    }
                );
                self.result = Some(result);
                Ok(text)
            }
            Err(e) => {
                self.frames.clear();
                self.result = None;
                Err(e)
            }
        })
    }

    /// The caption of the frame shown, if any.
    #[must_use]
    pub fn caption(&self) -> Option<String> {
        self.frames.get(self.frame).map(PreviewFrame::caption)
    }

    fn controls_ui(
        &mut self,
        ui: &mut egui::Ui,
        ctx: &PanelContext<'_>,
        actions: &mut Vec<Action>,
    ) {
        let id = ctx.current_photo.unwrap_or_default();
        ui.label(format!("view: photo {id}"));
        if !ctx.current_photo_solved() {
            ui.colored_label(
                crate::widgets::WARNING,
                "this photo is not solved yet: press Solve first",
            );
        }
        let zone = ctx
            .doc
            .and_then(|d| d.site.location.as_ref())
            .and_then(|l| l.time_zone.clone());
        ui.label(zone.map_or_else(
            || "times: give a UTC offset (09:00+01:00), the site has no time zone".to_owned(),
            |z| format!("times in the site's time zone {z}"),
        ));
        egui::Grid::new("study fields")
            .num_columns(2)
            .show(ui, |ui| {
                ui.label("dates");
                let r = ui.add(
                    egui::TextEdit::singleline(&mut self.dates)
                        .hint_text("2026-03-20,2026-06-21")
                        .desired_width(300.0),
                );
                name_widget(ui, &r, "study dates");
                ui.end_row();
                ui.label("times");
                let r = ui.add(
                    egui::TextEdit::singleline(&mut self.times)
                        .hint_text("09:00,12:00,15:00")
                        .desired_width(300.0),
                );
                name_widget(ui, &r, "study times");
                ui.end_row();
            });
        ui.horizontal(|ui| {
            let r = ui.checkbox(&mut self.montages, "montages");
            name_widget(ui, &r, "study montages");
            let r = ui.checkbox(&mut self.shadow_maps, "plan-view shadow maps");
            name_widget(ui, &r, "study shadow maps");
            let r = ui.add(
                egui::DragValue::new(&mut self.cell_m)
                    .range(0.01..=10.0)
                    .speed(0.01)
                    .suffix(" m"),
            );
            name_widget(ui, &r, "shadow map cell");
            ui.label("cell");
        });
        ui.horizontal(|ui| {
            let busy = self.busy();
            let r = ui.add_enabled(!busy, egui::Button::new("Run study"));
            name_widget(ui, &r, "Run study");
            if r.clicked() {
                actions.push(Action::StartStudy);
            }
            let r = ui.add_enabled(busy, egui::Button::new("Cancel study"));
            name_widget(ui, &r, "Cancel study");
            if r.clicked() {
                actions.push(Action::CancelStudy);
            }
            if busy {
                ui.spinner();
                let (done, total) = self.progress();
                let f = if total == 0 {
                    self.frames.len() as f32 / self.daylight.max(1) as f32
                } else {
                    done as f32 / total as f32
                };
                ui.add(egui::ProgressBar::new(f).text(format!(
                    "frame {}/{}, {done}/{total} tiles",
                    self.frames.len(),
                    self.daylight
                )));
            }
        });
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.export_folder)
                    .hint_text("folder for frames and contact sheet")
                    .desired_width(260.0),
            );
            name_widget(ui, &r, "study folder");
            let r = ui.checkbox(&mut self.exr, "EXR too");
            name_widget(ui, &r, "study EXR");
            let r = ui.add_enabled(self.result.is_some(), egui::Button::new("Export study"));
            name_widget(ui, &r, "Export study");
            if r.clicked() {
                actions.push(Action::ExportStudy);
            }
        });
    }

    fn preview_ui(&mut self, ui: &mut egui::Ui) {
        let n = self.frames.len();
        if n == 0 {
            ui.label("no frames yet: Run study");
            return;
        }
        self.frame = self.frame.min(n - 1);
        ui.horizontal(|ui| {
            let label = if self.playing { "Pause" } else { "Play" };
            let r = ui.add_enabled(n > 1, egui::Button::new(label));
            name_widget(ui, &r, "Play/Pause");
            if r.clicked() {
                self.playing = !self.playing;
                self.last_switch_s = ui.input(|i| i.time);
            }
            let r = ui.add(egui::Slider::new(&mut self.frame, 0..=n - 1).text("frame"));
            name_widget(ui, &r, "study frame");
            if r.dragged() || r.changed() {
                self.playing = false;
            }
            let r = ui.add(
                egui::DragValue::new(&mut self.fps)
                    .range(0.25..=30.0)
                    .speed(0.1)
                    .suffix(" fps"),
            );
            name_widget(ui, &r, "study fps");
        });
        if self.playing && n > 1 {
            let now = ui.input(|i| i.time);
            let period_s = 1.0 / self.fps.max(0.25);
            if now - self.last_switch_s >= period_s {
                self.frame = (self.frame + 1) % n;
                self.last_switch_s = now;
            }
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_secs_f64(period_s));
        }
        let has_montage = self.frames.iter().any(|f| f.montage.is_some());
        let has_map = self.frames.iter().any(|f| f.shadow_map.is_some());
        if has_montage && has_map {
            ui.horizontal(|ui| {
                let r = ui.radio_value(&mut self.show, PreviewKind::Montage, "montage");
                name_widget(ui, &r, "show montage");
                let r = ui.radio_value(&mut self.show, PreviewKind::ShadowMap, "shadow map");
                name_widget(ui, &r, "show shadow map");
            });
        }
        let show = match self.show {
            PreviewKind::Montage if !has_montage => PreviewKind::ShadowMap,
            PreviewKind::ShadowMap if !has_map => PreviewKind::Montage,
            s => s,
        };
        let index = self.frame;
        let f = &mut self.frames[index];
        let caption = f.caption();
        ui.strong(format!("{}/{n}  {caption}", index + 1));
        let (slot, image) = match show {
            PreviewKind::Montage => (0, f.montage.as_ref()),
            PreviewKind::ShadowMap => (1, f.shadow_map.as_ref()),
        };
        let Some(image) = image else {
            return;
        };
        let texture = f.textures[slot].get_or_insert_with(|| {
            ui.ctx().load_texture(
                format!("study frame {index} {slot}"),
                image.clone(),
                egui::TextureOptions::LINEAR,
            )
        });
        let [w, h] = image.size.map(|v| v as f32);
        let width = ui.available_width().min(w.max(1.0) * 4.0);
        let size = egui::vec2(width, width * h / w.max(1.0));
        ui.add(egui::Image::new((texture.id(), size)));
    }
}

impl Panel for StudyPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        self.controls_ui(ui, ctx, &mut actions);
        ui.separator();
        self.preview_ui(ui);
        actions
    }
}

impl crate::Studio {
    /// Starts the study of the current photo (errors become messages).
    pub fn start_study(&mut self, ctx: &egui::Context) {
        let (Some(doc), Some(id)) = (self.doc.as_ref(), self.current_photo.clone()) else {
            self.say("open a site with a photo first", true);
            return;
        };
        match self.study.start(doc, &id, ctx) {
            Ok(()) => self.say(format!("study of {id} running…"), false),
            Err(e) => self.say(e, true),
        }
    }

    /// Writes the last study to the folder typed in the Study tab.
    pub fn export_study(&mut self) {
        let folder = std::path::PathBuf::from(self.study.export_folder.trim());
        if folder.as_os_str().is_empty() {
            self.say("type a folder for the study first", true);
            return;
        }
        let Some(result) = self.study.result() else {
            self.say("nothing to export: run a study first", true);
            return;
        };
        match result.write(&folder, self.study.exr) {
            Ok(written) => self.say(
                format!(
                    "wrote {} frame(s) and the contact sheet {} to {}",
                    written.frames.len(),
                    written
                        .contact_sheet
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default(),
                    folder.display()
                ),
                false,
            ),
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// The Study tab (mutable: tests type dates and times as a user would).
    pub fn study_panel_mut(&mut self) -> &mut StudyPanel {
        &mut self.study
    }

    /// The Study tab.
    #[must_use]
    pub fn study_panel(&self) -> &StudyPanel {
        &self.study
    }

    pub(crate) fn poll_study(&mut self, ctx: &egui::Context) {
        match self.study.poll() {
            Some(Ok(text)) => self.say(text, false),
            Some(Err(e)) => self.say(e, true),
            None => {}
        }
        if self.study.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }
}

impl crate::Studio {
    /// Shows the side tab labelled `label` (as on its button: "Points", "Results", "Render",
    /// "Models", "Scene", "Fit", "Tie points", "Study"); the window's `--tab` uses it. A new
    /// side tab adds its line here.
    ///
    /// # Errors
    /// An unknown label, naming the known ones.
    pub fn select_tab(&mut self, label: &str) -> Result<(), String> {
        use crate::SideTab;
        let known = [
            ("Points", SideTab::Points),
            ("Results", SideTab::Solve),
            ("Render", SideTab::Render),
            ("Models", SideTab::Models),
            ("Scene", SideTab::Scene),
            ("Fit", SideTab::Fit),
            ("Tie points", SideTab::Ties),
            ("Site & light", SideTab::Light),
            ("Materials", SideTab::Materials),
            ("Study", SideTab::Study),
            ("Variants", SideTab::Variants),
        ];
        match known.iter().find(|(name, _)| *name == label) {
            Some((_, tab)) => {
                self.tab = *tab;
                Ok(())
            }
            None => Err(format!(
                "--tab {label}: no such side tab (known: {})",
                known.map(|(n, _)| n).join(", ")
            )),
        }
    }
}
