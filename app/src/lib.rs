//! The photomontage studio: view state and wiring over the `photomontage` library (which does
//! all computation). [`Studio`] is the whole app, testable headless with egui_kittest: it
//! opens a site (restoring an autosave sidecar newer than it), shows a photo strip, the photo
//! view with zoom/pan/loupe, the control-point table, solves on a worker ([`solve`]), renders a
//! montage preview progressively ([`render_panel`]), places CAD models with a wireframe overlay
//! ([`models_panel`]) and builds scene geometry ([`scene_panel`], vertices picked on the photo
//! with [`scene_pick`]), picks lighting-fit samples on the photo and runs, shows and applies the
//! fit ([`fit_panel`], [`fit_pick`]); the File menu opens native dialogs on a worker and lists
//! recent sites ([`files`]) and creates a site from photos ([`new_site`]); each photo's interior
//! orientation is edited in its camera settings ([`photo_settings`]).
//!
//! Structure:
//! - **One worker type** ([`worker::Worker`]): solve, fit, render, file dialogs and photo
//!   decoding run on it, with progress, cancellation and panic capture (a crashed job is a
//!   message, never a panel busy forever); the `jobs` module starts and polls them.
//! - **Panels as types** ([`panel::Panel`]): the six side tabs, the toolbar and the photo strip
//!   ([`chrome`]), the File menu ([`files::FileMenu`]) and the New site and Camera settings
//!   windows draw from a read-only [`panel::PanelContext`] and return [`panel::Action`]s, which
//!   [`Studio`] applies after the frame's layout; shared widgets are in [`widgets`].
//! - **One command path**: every edit goes through [`Studio::apply`] (→ [`commands::History`]),
//!   so undo/redo and the autosave see all of them (rerun's `SystemCommand`).
//! - Computation lives in the library: model placement and wireframe edges
//!   (`photomontage::site::models`), points projected into a photo
//!   (`photomontage::site::photo_points`), solve, fit, render.
//!
//! # Known limitations
//! See each module's own list. The photo view and its pickers (placing points, scene vertices,
//! fit samples: `photo_view`, [`scene_pick`], [`fit_pick`]) are still `impl Studio` methods
//! rather than panels, and the actions' handlers (`start_render`, `import_model`, …) are
//! `impl Studio` methods beside their panels. Native file dialogs ([`files`]) cannot be driven by the
//! headless tests, which use the typed-path fields and a substituted [`dialogs::FilePicker`].

pub mod autosave;
pub mod chrome;
pub mod commands;
pub mod dialogs;
pub mod elevation_view;
pub mod files;
pub mod fit_commands;
pub mod fit_panel;
pub mod fit_pick;
pub mod fit_tables;
pub mod fit_worker;
mod jobs;
pub mod light_commands;
pub mod light_inputs;
pub mod light_panel;
pub mod material_commands;
mod material_pick;
pub mod materials_panel;
pub mod models_panel;
pub mod new_site;
pub mod panel;
pub mod photo_settings;
mod photo_view;
pub mod placing;
pub mod points;
pub mod ral_design_page;
pub mod render_display;
pub mod render_job;
pub mod render_panel;
pub mod render_sheet;
pub mod render_views;
pub mod scene_panel;
pub mod scene_pick;
pub mod solve;
pub mod state;
pub mod study_panel;
pub mod table_sort;
pub mod tie_panel;
pub mod variant_commands;
pub mod variants_panel;
pub mod viewport;
pub mod widgets;
pub mod window;
pub mod worker;

use eframe::egui::{self, Color32, Key, Pos2};
use photomontage::site::{Observation, SiteDocument, SiteSolution};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use commands::{Command, History};
use panel::{Action, Panel, PanelContext};
use viewport::{DecodedPhoto, PhotoLoader, ViewTransform, Viewport};

/// The read-only view of the studio that panels draw from (a macro, not a method, so that the
/// borrows are of single fields and a panel field can be borrowed mutably beside it).
macro_rules! panel_context {
    ($s:ident) => {
        PanelContext {
            doc: $s.doc.as_ref(),
            current_photo: $s.current_photo.as_deref(),
            selected_point: $s.selected_point.as_deref(),
            armed_point: $s.armed_point.as_deref(),
            solution: $s.solution.as_ref(),
            residuals: panel::ResidualDisplay {
                show: $s.ui_state.show_residuals,
                exaggeration: $s.ui_state.residual_exaggeration,
            },
            can_undo: $s.history.can_undo(),
            can_redo: $s.history.can_redo(),
            solving: $s.solver.busy(),
            dialog_open: $s.dialogs.busy(),
            has_montage: $s
                .render
                .montage()
                .is_some_and(|m| $s.current_photo.as_deref() == Some(m.photo_id.as_str())),
            recent_sites: &$s.ui_state.recent_sites,
        }
    };
}

/// How the studio starts.
#[derive(Debug, Clone)]
pub struct StudioOptions {
    /// Site to open.
    pub site_path: PathBuf,
    /// UI state file; `None` keeps the state in memory only (tests).
    pub state_path: Option<PathBuf>,
}

/// The bundled sample site (path fixed at build time; `PHOTOMONTAGE_SAMPLE_SITE` overrides).
#[must_use]
pub fn default_site_path() -> PathBuf {
    std::env::var_os("PHOTOMONTAGE_SAMPLE_SITE").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/courtyard/site.toml"),
        PathBuf::from,
    )
}

enum PhotoView {
    Loading,
    Ready(Box<DecodedPhoto>),
    Failed(String),
}

/// A job of the studio that runs on a [`worker::Worker`] (for [`Studio::inject_panic_for_tests`]).
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorkerJob {
    Solve,
    Fit,
    Render,
}

/// A line for the message area.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SideTab {
    Points,
    Solve,
    Render,
    Models,
    Scene,
    Fit,
    Ties,
    Light,
    Study,
    Materials,
    Variants,
}

/// The studio app.
pub struct Studio {
    options: StudioOptions,
    doc: Option<SiteDocument>,
    history: History,
    autosave: autosave::Autosave,
    /// Coalescing key of the last edit (consecutive drags of one value are one undo step).
    last_merge_key: Option<String>,
    ui_state: state::UiState,
    current_photo: Option<String>,
    photos: HashMap<String, PhotoView>,
    loader: PhotoLoader,
    viewport: Viewport,
    last_transform: Option<ViewTransform>,
    selected_point: Option<String>,
    /// The point the next click on the photo places ([`placing`]); cleared by placing it, by
    /// Escape and by clicking a mark.
    armed_point: Option<String>,
    dragging: Option<(String, [f64; 2])>,
    solver: solve::SolveWorker,
    solution: Option<SiteSolution>,
    messages: Vec<Message>,
    tab: SideTab,
    points: points::PointsPanel,
    results: solve::ResultsPanel,
    toolbar: chrome::Toolbar,
    file_menu: files::FileMenu,
    photo_strip: chrome::PhotoStrip,
    pending: Vec<(Command, Option<String>)>,
    /// What the panels asked for this frame ([`panel::Panel`]), done after the layout.
    actions: Vec<Action>,
    render: render_panel::RenderPanel,
    models: models_panel::ModelsPanel,
    scene: scene_panel::ScenePanel,
    dialogs: files::DialogWorker,
    /// Enter was pressed on the photo in the Scene tab: close the polygon after the frame.
    close_polygon: bool,
    new_site: new_site::NewSiteDialog,
    photo_settings: photo_settings::PhotoSettings,
    /// The window clears to the panel colour, so panels need not fill their backgrounds.
    host_clears_to_panel_fill: bool,
    fit: fit_panel::FitPanel,
    ties: tie_panel::TiePointsPanel,
    light: light_panel::LightPanel,
    study: study_panel::StudyPanel,
    materials: materials_panel::MaterialsPanel,
    variants: variants_panel::VariantsPanel,
}

impl Studio {
    /// Creates the studio and opens `options.site_path` (errors become messages).
    #[must_use]
    pub fn new(options: StudioOptions) -> Self {
        let ui_state = options
            .state_path
            .as_deref()
            .map(state::UiState::load)
            .unwrap_or_default();
        let mut s = Self {
            options: options.clone(),
            doc: None,
            history: History::default(),
            autosave: autosave::Autosave::new(0),
            last_merge_key: None,
            ui_state,
            current_photo: None,
            photos: HashMap::new(),
            loader: PhotoLoader::default(),
            viewport: Viewport::default(),
            last_transform: None,
            selected_point: None,
            armed_point: None,
            dragging: None,
            solver: solve::solve_worker(),
            solution: None,
            messages: Vec::new(),
            tab: SideTab::Points,
            points: points::PointsPanel::default(),
            results: solve::ResultsPanel,
            toolbar: chrome::Toolbar::default(),
            file_menu: files::FileMenu,
            photo_strip: chrome::PhotoStrip,
            pending: Vec::new(),
            actions: Vec::new(),
            render: render_panel::RenderPanel::default(),
            models: models_panel::ModelsPanel::default(),
            scene: scene_panel::ScenePanel::default(),
            dialogs: files::DialogWorker::default(),
            close_polygon: false,
            new_site: new_site::NewSiteDialog::default(),
            photo_settings: photo_settings::PhotoSettings::default(),
            host_clears_to_panel_fill: false,
            fit: fit_panel::FitPanel::default(),
            ties: tie_panel::TiePointsPanel,
            light: light_panel::LightPanel::default(),
            study: study_panel::StudyPanel::default(),
            materials: materials_panel::MaterialsPanel::default(),
            variants: variants_panel::VariantsPanel::default(),
        };
        s.variants.compare =
            variants_panel::CompareState::from_settings(&s.ui_state.variant_compare);
        s.open(&options.site_path);
        s
    }

    fn say(&mut self, text: impl Into<String>, is_error: bool) {
        self.messages.push(Message {
            text: text.into(),
            is_error,
        });
        if self.messages.len() > 50 {
            self.messages.remove(0);
        }
    }

    /// Opens a site, restoring a newer autosave sidecar (and saying so).
    pub fn open(&mut self, path: &Path) {
        match autosave::open_with_recovery(path) {
            Ok((doc, recovery)) => {
                match recovery {
                    autosave::Recovery::Restored => self.say(
                        format!(
                            "restored unsaved edits from {} (save to keep them in the site file)",
                            autosave::sidecar_path(path).display()
                        ),
                        false,
                    ),
                    autosave::Recovery::Unreadable(why) => self.say(why, true),
                    autosave::Recovery::None => {}
                }
                self.say(format!("opened {}", path.display()), false);
                self.history.clear();
                self.autosave = autosave::Autosave::new(self.history.revision());
                self.current_photo = doc.site.photos.first().map(|p| p.id.clone());
                self.photos.clear();
                self.solution = None;
                self.selected_point = None;
                self.armed_point = None;
                self.photo_settings = photo_settings::PhotoSettings::default();
                self.viewport = Viewport::default();
                self.fit.worker.cancel();
                self.fit = fit_panel::FitPanel::default();
                self.light = light_panel::LightPanel::default();
                self.doc = Some(doc);
                self.ui_state.remember(path);
                self.persist_ui_state();
            }
            Err(e) => self.say(e.to_string(), true),
        }
    }

    fn persist_ui_state(&mut self) {
        if let Some(p) = self.options.state_path.clone()
            && let Err(e) = self.ui_state.save(&p)
        {
            self.say(e, true);
        }
    }

    /// The open site.
    #[must_use]
    pub fn document(&self) -> Option<&SiteDocument> {
        self.doc.as_ref()
    }

    /// Messages shown to the user, oldest first.
    #[must_use]
    pub fn messages(&self) -> &[Message] {
        &self.messages
    }

    /// The last solve's result.
    #[must_use]
    pub fn solution(&self) -> Option<&SiteSolution> {
        self.solution.as_ref()
    }

    /// The photo shown.
    #[must_use]
    pub fn current_photo(&self) -> Option<&str> {
        self.current_photo.as_deref()
    }

    /// The point selected for placing.
    #[must_use]
    pub fn selected_point(&self) -> Option<&str> {
        self.selected_point.as_deref()
    }

    /// The point the next click on the photo places, if any ([`placing`]).
    #[must_use]
    pub fn armed_point(&self) -> Option<&str> {
        self.armed_point.as_deref()
    }

    /// Screen position of a photo pixel position in the last frame's view (tests use it to
    /// click on the photo).
    #[must_use]
    pub fn photo_to_screen(&self, p_px: [f64; 2]) -> Option<Pos2> {
        self.last_transform.map(|t| t.screen_from_photo(p_px))
    }

    /// The last frame's view transform.
    #[must_use]
    pub fn view_transform(&self) -> Option<ViewTransform> {
        self.last_transform
    }

    /// Zoom and pan of the photo view (mutable: benches drive it).
    pub fn viewport_mut(&mut self) -> &mut Viewport {
        &mut self.viewport
    }

    /// Tells the studio that its host clears every frame to `visuals.panel_fill` (the real
    /// window does: see [`window::clear_colour`]), so the panels skip painting their own
    /// backgrounds. The picture is the same; on a CPU rasteriser it saves filling about half
    /// the window every frame (docs/benchmarks.md, window frame time). Off by default: test
    /// harnesses clear to transparent.
    pub fn set_host_clears_to_panel_fill(&mut self, clears: bool) {
        self.host_clears_to_panel_fill = clears;
    }

    /// Whether edits are not yet in the autosave sidecar.
    #[must_use]
    pub fn autosave_pending(&self) -> bool {
        self.autosave.is_dirty(self.history.revision())
    }

    /// Applies an edit through the undo history (the one path every edit takes). `merge_key`:
    /// consecutive edits with the same key are one undo step.
    pub fn apply(&mut self, command: Command, merge_key: Option<String>) {
        let Some(doc) = self.doc.as_mut() else {
            return;
        };
        let merge = merge_key.is_some() && merge_key == self.last_merge_key;
        let result = if merge {
            self.history.apply_merged(&mut doc.site, command)
        } else {
            self.history.apply(&mut doc.site, command)
        };
        match result {
            Ok(()) => self.last_merge_key = merge_key,
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// Undoes the last edit.
    pub fn undo(&mut self) {
        self.last_merge_key = None;
        if let Some(doc) = self.doc.as_mut()
            && let Err(e) = self.history.undo(&mut doc.site)
        {
            self.say(e.to_string(), true);
        }
    }

    /// Redoes the last undone edit.
    pub fn redo(&mut self) {
        self.last_merge_key = None;
        if let Some(doc) = self.doc.as_mut()
            && let Err(e) = self.history.redo(&mut doc.site)
        {
            self.say(e.to_string(), true);
        }
    }

    /// Saves the site atomically and removes the autosave sidecar.
    pub fn save(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let path = doc.path.clone();
        match doc.save() {
            Ok(()) => {
                if let Err(e) = self.autosave.saved(self.history.revision(), &path) {
                    self.say(e.to_string(), true);
                }
                self.say(format!("saved {}", path.display()), false);
            }
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// Writes the autosave sidecar now if edits are pending.
    pub fn autosave_now(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let revision = self.history.revision();
        if self.autosave.is_dirty(revision)
            && let Err(e) = self.autosave.write_now(revision, &doc.site, &doc.path)
        {
            self.say(e.to_string(), true);
        }
    }

    /// Selects the photo shown.
    pub fn select_photo(&mut self, id: &str) {
        if self.current_photo.as_deref() != Some(id) {
            self.current_photo = Some(id.to_owned());
            self.viewport = Viewport::default();
        }
    }

    fn autosave_tick(&mut self, ctx: &egui::Context) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let now = Instant::now();
        let revision = self.history.revision();
        match self.autosave.tick(now, revision, &doc.site, &doc.path) {
            Ok(_) => {}
            Err(e) => self.say(e.to_string(), true),
        }
        if let Some(due) = self.autosave.due_in(now, revision) {
            ctx.request_repaint_after(due.max(std::time::Duration::from_millis(20)));
        }
    }

    fn shortcuts(&mut self, ctx: &egui::Context) {
        let typing = ctx.text_edit_focused();
        let (undo, redo, save, delete, escape) = ctx.input_mut(|i| {
            let cmd = egui::Modifiers::COMMAND;
            let shift_cmd = egui::Modifiers::COMMAND | egui::Modifiers::SHIFT;
            (
                i.consume_key(cmd, Key::Z),
                i.consume_key(shift_cmd, Key::Z) || i.consume_key(cmd, Key::Y),
                i.consume_key(cmd, Key::S),
                !typing && i.key_pressed(Key::Delete),
                !typing && i.key_pressed(Key::Escape),
            )
        });
        if escape && self.armed_point.take().is_some() {
            self.say("placing cancelled".to_owned(), false);
        }
        if undo && !typing {
            self.undo();
        }
        if redo && !typing {
            self.redo();
        }
        if save {
            self.save();
        }
        if delete
            && let (Some(photo), Some(point)) =
                (self.current_photo.clone(), self.selected_point.clone())
            && self.observation(&photo, &point).is_some()
        {
            self.apply(Command::RemoveObservation { photo, point }, None);
        }
    }

    fn observation(&self, photo: &str, point: &str) -> Option<&Observation> {
        self.doc
            .as_ref()?
            .site
            .observations
            .iter()
            .find(|o| o.photo == photo && o.point == point)
    }

    /// Draws the whole studio into `ui` and handles its input (called by eframe every frame,
    /// and by the tests).
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let frame_start = Instant::now();
        let ctx = ui.ctx().clone();
        self.poll_workers(&ctx);
        self.shortcuts(&ctx);
        let mut side_frame = egui::Frame::side_top_panel(ui.style());
        if self.host_clears_to_panel_fill {
            side_frame = side_frame.fill(Color32::TRANSPARENT);
        }
        egui::Panel::top("toolbar")
            .frame(side_frame)
            .show(ui, |ui| self.toolbar_ui(ui));
        egui::Panel::bottom("messages")
            .frame(side_frame)
            .resizable(true)
            .default_size(70.0)
            .show(ui, |ui| chrome::messages_ui(ui, &self.messages));
        egui::Panel::left("photos")
            .frame(side_frame)
            .default_size(150.0)
            .show(ui, |ui| {
                let ctx = panel_context!(self);
                let actions = self.photo_strip.ui(ui, &ctx);
                self.actions.extend(actions);
            });
        egui::Panel::right("side")
            .frame(side_frame)
            .default_size(560.0)
            .show(ui, |ui| self.side_ui(ui));
        // No panel fill: the photo view paints its own background around the photo only (each
        // full-window fill layer costs ~0.2 s per frame on a CPU rasteriser; docs/benchmarks.md).
        let frame = egui::Frame::central_panel(ui.style()).fill(Color32::TRANSPARENT);
        egui::CentralPanel::default()
            .frame(frame)
            .show(ui, |ui| self.photo_view_ui(ui));
        let panel_ctx = panel_context!(self);
        let actions = self.new_site.ui(ui, &panel_ctx);
        self.actions.extend(actions);
        self.photo_settings.size_px = self.photo_settings.photo.as_ref().and_then(|id| match self
            .photos
            .get(id)
        {
            Some(PhotoView::Ready(p)) => Some(p.size_px),
            _ => None,
        });
        let panel_ctx = panel_context!(self);
        let actions = self.photo_settings.ui(ui, &panel_ctx);
        self.actions.extend(actions);
        for (c, key) in std::mem::take(&mut self.pending) {
            self.apply(c, key);
        }
        for action in std::mem::take(&mut self.actions) {
            self.run_action(action, &ctx);
        }
        if std::mem::take(&mut self.close_polygon) {
            self.create_polygon();
        }
        self.autosave_tick(&ctx);
        self.keep_compare_settings(&ctx);
        self.render.live.frame_done(frame_start.elapsed());
    }

    /// Writes the Variants tab's comparison settings to the UI state file when they changed
    /// (once a drag has ended, not on every frame of it).
    fn keep_compare_settings(&mut self, ctx: &egui::Context) {
        let settings = self.variants.compare.settings();
        if settings != self.ui_state.variant_compare && !ctx.input(|i| i.pointer.any_down()) {
            self.ui_state.variant_compare = settings;
            self.persist_ui_state();
        }
    }

    fn toolbar_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let ctx = panel_context!(self);
            let mut actions = self.file_menu.ui(ui, &ctx);
            actions.extend(self.toolbar.ui(ui, &ctx));
            self.actions.extend(actions);
        });
    }

    fn side_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.tab, SideTab::Points, "Points");
            ui.selectable_value(&mut self.tab, SideTab::Solve, "Results");
            ui.selectable_value(&mut self.tab, SideTab::Render, "Render");
            ui.selectable_value(&mut self.tab, SideTab::Models, "Models");
            ui.selectable_value(&mut self.tab, SideTab::Scene, "Scene");
            let r = ui.selectable_value(&mut self.tab, SideTab::Fit, "Fit");
            widgets::name_widget(ui, &r, "Fit tab");
            let r = ui.selectable_value(&mut self.tab, SideTab::Ties, "Tie points");
            widgets::name_widget(ui, &r, "Tie points tab");
            let r = ui.selectable_value(&mut self.tab, SideTab::Light, "Site & light");
            widgets::name_widget(ui, &r, "Site & light tab");
            let r = ui.selectable_value(&mut self.tab, SideTab::Study, "Study");
            widgets::name_widget(ui, &r, "Study tab");
            let r = ui.selectable_value(&mut self.tab, SideTab::Materials, "Materials");
            widgets::name_widget(ui, &r, "Materials tab");
            let r = ui.selectable_value(&mut self.tab, SideTab::Variants, "Variants");
            widgets::name_widget(ui, &r, "Variants tab");
        });
        ui.separator();
        let ctx = panel_context!(self);
        let panel: &mut dyn Panel = match self.tab {
            SideTab::Points => &mut self.points,
            SideTab::Solve => &mut self.results,
            SideTab::Render => &mut self.render,
            SideTab::Models => &mut self.models,
            SideTab::Scene => &mut self.scene,
            SideTab::Fit => &mut self.fit,
            SideTab::Ties => &mut self.ties,
            SideTab::Light => &mut self.light,
            SideTab::Study => &mut self.study,
            SideTab::Materials => &mut self.materials,
            SideTab::Variants => &mut self.variants,
        };
        let actions = panel.ui(ui, &ctx);
        self.actions.extend(actions);
    }

    /// Does what a panel asked for (after the frame's layout).
    fn run_action(&mut self, action: Action, ctx: &egui::Context) {
        match action {
            Action::Edit { command, merge_key } => self.apply(*command, merge_key),
            Action::Save => self.save(),
            Action::Undo => self.undo(),
            Action::Redo => self.redo(),
            Action::StartSolve => self.start_solve(ctx),
            Action::FitView => self.viewport.fitted = true,
            Action::OpenSite(path) => self.open(&path),
            Action::SelectPhoto(id) => self.select_photo(&id),
            Action::OpenPhotoSettings(id) => self.open_photo_settings(&id),
            Action::RequestDialog(purpose) => self.request_dialog(purpose, ctx),
            Action::CreateNewSite => self.create_new_site(),
            Action::ShowNewSite => self.new_site.open = true,
            Action::ImportPoints => self.import(),
            Action::SetResiduals(r) => {
                self.ui_state.show_residuals = r.show;
                self.ui_state.residual_exaggeration = r.exaggeration;
            }
            Action::SelectPoint(id) => {
                self.armed_point = Some(id.clone());
                self.selected_point = Some(id);
            }
            Action::ImportModel(path) => self.import_model(&path),
            Action::IntersectTiePoint(id) => self.intersect_tie_point(&id),
            Action::CreatePolygon => self.create_polygon(),
            Action::StartRender => self.start_render(ctx),
            Action::CancelRender => self.render.cancel(),
            Action::ExportRender => self.export_render(),
            Action::ExportSheet => self.export_sheet(),
            Action::MakeReport => self.make_report(),
            Action::StartFit => self.start_fit(ctx),
            Action::CancelFit => self.fit.worker.cancel(),
            Action::ApplyFit => self.apply_fit_report(),
            Action::StartStudy => self.start_study(ctx),
            Action::CancelStudy => self.study.cancel(),
            Action::ExportStudy => self.export_study(),
            Action::StartVariantRenders => self.start_variant_renders(ctx),
            Action::CancelVariantRenders => self.variants.cancel(),
            Action::ExportComparison => self.export_comparison(),
        }
    }

    /// Imports control points (and observations) from the file named in the import field.
    pub fn import(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let path = PathBuf::from(self.points.import_path.trim());
        match points::import_file(&doc.site, &path, self.current_photo.as_deref()) {
            Ok(Command::Batch(b)) if b.is_empty() => {
                self.say(format!("{}: nothing to import", path.display()), true);
            }
            Ok(c) => {
                let text = format!("imported {}", path.display());
                self.apply(c, None);
                self.say(text, false);
            }
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// Sets the import field (what a user types).
    pub fn set_import_path(&mut self, path: &str) {
        path.clone_into(&mut self.points.import_path);
    }

    /// Writes the UI state (call on exit).
    pub fn on_exit(&mut self) {
        self.persist_ui_state();
    }
}

impl eframe::App for Studio {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        Studio::ui(self, ui);
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        Studio::on_exit(self);
    }
}
