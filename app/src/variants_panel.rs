//! The Variants tab (issue 17 item 4): the site's design variants (`[[variants]]`) listed,
//! added (from the site's current model visibility), renamed, duplicated and deleted, and per
//! variant which models are visible, their placement and the materials it recolours
//! ([`edit`]). Every edit is one undoable `Command::Variant` ([`crate::variant_commands`]).
//!
//! "Render all variants" renders every variant of the current (solved) photo on the studio's
//! one worker type with one progress bar and Cancel, through the library's
//! `photomontage::site::variant_renders` (each variant's document is `variant_document`, its
//! render the one entry point `RenderPlan`, the same request for all): the pixels are those of
//! `photomontage render --variant NAME` with the same rays per pixel and seed. The renders are
//! compared as an A/B slider, side by side, a grid or a flicker ([`compare`]), each picture
//! labelled with its variant's name, and exported as the comparison sheet (PDF, one page per
//! variant, and the PNG grid) by `photomontage::verified::comparison_sheet`, the writer of the
//! CLI's `compare`, through a save dialog ([`crate::dialogs::DialogPurpose::ExportComparison`])
//! or the typed path.
//!
//! # Known limitations
//! A variant cannot add a model the site does not have (the library's rule). The renders are
//! kept until the next "Render all variants"; after an edit of a variant they show what was
//! rendered, and the tab says they are out of date. Material overrides are picked from the
//! scene's materials and recoloured by a typed colour (hex, `lab()`, `lch()`); gloss and glass
//! of an override are the scene material's.

mod compare;
mod edit;

use eframe::egui;
use photomontage::site::SiteDocument;
use photomontage::site::Variant;
use photomontage::site::render_photo::RenderRequest;
use photomontage::site::variant_renders::{VariantJob, VariantRender, plan_variants};
use photomontage::verified::comparison_sheet::{
    ComparisonCell, comparison_pdf, comparison_subtitle, write_comparison_png,
};
use photomontage::verified::sheet::write_sheet;

pub use compare::{CompareMode, CompareSettings, CompareState, FLICKER_PERIOD_S};

use crate::commands::Command;
use crate::dialogs::DialogPurpose;
use crate::panel::{Action, Panel, PanelContext};
use crate::variant_commands::{VariantCommand, next_variant_name};
use crate::widgets::{ERROR, WARNING, name_widget};
use crate::worker::{Poll, Progress, Worker};

/// What the variants job streams to the panel before its outcome.
pub enum VariantsUpdate {
    /// Tiles of all variants together.
    Planned { tiles_total: u64 },
    /// A tile is finished.
    Tile,
    /// A variant is finished: the tiles of the variants so far (a variant showing no model
    /// gives the photo back without rendering its tiles).
    VariantDone { tiles_done: u64 },
}

/// The variants' worker: every variant's render, or the message why not.
pub type VariantsWorker = Worker<Result<Vec<VariantRender>, String>, VariantsUpdate>;

/// One rendered variant as the tab shows it.
pub struct ShownVariant {
    /// The library's render (pixels, plan, sRGB).
    pub render: VariantRender,
    /// The variant as it was when rendered (to tell stale renders).
    pub variant: Variant,
    display: egui::ColorImage,
    texture: Option<egui::TextureHandle>,
}

/// The renders of one view.
pub struct VariantRenders {
    /// The photo they were rendered into.
    pub view: String,
    /// One per variant, in the site's order.
    pub shown: Vec<ShownVariant>,
}

/// Rays per pixel and seed of the variant renders (the same for every variant).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VariantQuality {
    /// Fewest rays per pixel (multiple of 4).
    pub spp_min: u32,
    /// Most rays per pixel (multiple of 4, ≥ `spp_min`).
    pub spp_max: u32,
    /// Seed of the sample positions.
    pub seed: u64,
}

impl Default for VariantQuality {
    fn default() -> Self {
        Self {
            spp_min: 4,
            spp_max: 16,
            seed: 0,
        }
    }
}

/// The Variants tab.
pub struct VariantsPanel {
    /// The variant being edited.
    pub selected: Option<String>,
    /// The name field of the selected variant (Rename).
    pub name_field: String,
    name_field_for: Option<String>,
    /// Rays per pixel and seed of "Render all variants".
    pub quality: VariantQuality,
    /// Where "Export comparison" writes (.pdf or .png).
    pub export_path: String,
    /// With a .pdf export, also write the PNG grid beside it (same name, .png).
    pub png_too: bool,
    /// How the renders are compared.
    pub compare: CompareState,
    /// The last refused edit, shown in the tab until the next edit.
    pub error: Option<String>,
    worker: VariantsWorker,
    running: Option<String>,
    tiles_done: u64,
    tiles_total: u64,
    renders: Option<VariantRenders>,
    edit: edit::EditorCache,
}

impl Default for VariantsPanel {
    fn default() -> Self {
        Self {
            selected: None,
            name_field: String::new(),
            name_field_for: None,
            quality: VariantQuality::default(),
            export_path: String::new(),
            png_too: true,
            compare: CompareState::default(),
            error: None,
            worker: Worker::new("variants"),
            running: None,
            tiles_done: 0,
            tiles_total: 0,
            renders: None,
            edit: edit::EditorCache::default(),
        }
    }
}

fn variants_job(
    jobs: &[VariantJob],
    progress: &Progress<VariantsUpdate>,
) -> Result<Vec<VariantRender>, String> {
    progress.send(VariantsUpdate::Planned {
        tiles_total: jobs.iter().map(|j| j.plan.tile_count()).sum(),
    });
    let n = jobs.len();
    let mut out = Vec::with_capacity(n);
    let mut tiles_done = 0;
    for (i, job) in jobs.iter().enumerate() {
        progress.set(
            Some(i as f32 / n.max(1) as f32),
            format!("variant {} of {n}: {}", i + 1, job.name),
        );
        let render = job
            .render(
                &|_| progress.send(VariantsUpdate::Tile),
                progress.cancel_flag(),
            )
            .map_err(|e| e.to_string())?;
        tiles_done += job.plan.tile_count();
        progress.send(VariantsUpdate::VariantDone { tiles_done });
        out.push(render);
    }
    Ok(out)
}

/// An edit of the variants as the action the studio applies (`merge_key`: one undo step for a
/// drag).
pub(crate) fn edit_action(command: VariantCommand, merge_key: Option<String>) -> Action {
    Action::Edit {
        command: Box::new(Command::Variant(command)),
        merge_key,
    }
}

impl VariantsPanel {
    /// Whether the variants are being rendered.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Tiles finished and in total of the running (or last) renders.
    #[must_use]
    pub fn progress(&self) -> (u64, u64) {
        (self.tiles_done, self.tiles_total)
    }

    /// The last finished renders.
    #[must_use]
    pub fn renders(&self) -> Option<&VariantRenders> {
        self.renders.as_ref()
    }

    /// The request every variant is rendered with.
    #[must_use]
    pub fn request(&self, view: &str) -> RenderRequest {
        RenderRequest {
            spp_min: Some(self.quality.spp_min),
            spp_max: Some(self.quality.spp_max),
            seed: Some(self.quality.seed),
            ..RenderRequest::view(view)
        }
    }

    /// Starts rendering every variant of `view`; every variant and plan is checked first
    /// (cheap), so a bad variant is refused at once with the library's message.
    ///
    /// # Errors
    /// The library's message; renders already running.
    pub fn start(
        &mut self,
        doc: &SiteDocument,
        view: &str,
        ctx: &egui::Context,
    ) -> Result<usize, String> {
        if self.worker.busy() {
            return Err("the variants are already being rendered".into());
        }
        let jobs = plan_variants(doc, None, &self.request(view)).map_err(|e| e.to_string())?;
        let n = jobs.len();
        if !self
            .worker
            .spawn(ctx, move |progress| variants_job(&jobs, progress))
        {
            return Err("the variants are already being rendered".into());
        }
        self.running = Some(view.to_owned());
        self.tiles_done = 0;
        self.tiles_total = 0;
        Ok(n)
    }

    /// Asks the running renders to stop at their next tile.
    pub fn cancel(&self) {
        self.worker.cancel();
    }

    /// Drains the worker; the outcome as a message once the renders ended (`Err`: failed or
    /// cancelled, the previous renders are kept).
    pub fn poll(&mut self, doc: Option<&SiteDocument>) -> Option<Result<String, String>> {
        let view = self.running.clone()?;
        let (done, total) = (&mut self.tiles_done, &mut self.tiles_total);
        let state = self.worker.poll_with(|u| match u {
            VariantsUpdate::Planned { tiles_total } => *total = tiles_total,
            VariantsUpdate::Tile => *done += 1,
            VariantsUpdate::VariantDone { tiles_done } => *done = tiles_done,
        });
        let outcome = match state {
            Poll::Idle | Poll::Running(_) => return None,
            Poll::Done(r) => r,
            Poll::Cancelled => Err(format!("variant renders of {view} cancelled")),
            Poll::Failed(e) => Err(format!("variant renders of {view} failed: {e}")),
        };
        self.running = None;
        Some(outcome.map(|renders| {
            let names: Vec<String> = renders.iter().map(|r| r.name.clone()).collect();
            let shown = renders
                .into_iter()
                .map(|render| ShownVariant {
                    variant: doc
                        .and_then(|d| d.site.variants.iter().find(|v| v.name == render.name))
                        .cloned()
                        .unwrap_or_else(|| Variant::named(&render.name)),
                    display: crate::study_panel::preview_image(&render.srgb),
                    render,
                    texture: None,
                })
                .collect();
            self.renders = Some(VariantRenders {
                view: view.clone(),
                shown,
            });
            self.compare.fit_to(&names);
            format!(
                "rendered {} variant(s) of {view}: {}",
                names.len(),
                names.join(", ")
            )
        }))
    }

    /// Whether the variant named `name` still is as it was rendered.
    fn stale(&self, doc: &SiteDocument) -> bool {
        self.renders.as_ref().is_some_and(|r| {
            r.shown.len() != doc.site.variants.len()
                || r.shown
                    .iter()
                    .zip(&doc.site.variants)
                    .any(|(s, v)| &s.variant != v)
        })
    }

    fn list_ui(&mut self, ui: &mut egui::Ui, doc: &SiteDocument, actions: &mut Vec<Action>) {
        let site = &doc.site;
        ui.horizontal(|ui| {
            ui.strong(format!("{} variant(s)", site.variants.len()));
            let r = ui.button("Add variant");
            name_widget(ui, &r, "Add variant");
            if r.clicked() {
                let name = next_variant_name(site, "Variant");
                let mut variant = Variant::named(&name);
                // From the current models: the ones visible now.
                variant.visible_models = Some(
                    site.models
                        .iter()
                        .filter(|m| m.visible)
                        .map(|m| m.id.clone())
                        .collect(),
                );
                actions.push(edit_action(VariantCommand::Put { variant, at: None }, None));
                self.selected = Some(name);
                self.error = None;
            }
        });
        for v in &site.variants {
            let selected = self.selected.as_deref() == Some(v.name.as_str());
            let r = ui.selectable_label(selected, &v.name);
            name_widget(ui, &r, &format!("Variant {}", v.name));
            if r.clicked() {
                self.selected = Some(v.name.clone());
                self.error = None;
            }
        }
        if site.variants.is_empty() {
            ui.label("no variants yet: Add variant");
        }
    }

    fn render_ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>, actions: &mut Vec<Action>) {
        let id = ctx.current_photo.unwrap_or_default();
        ui.label(format!("view: photo {id}"));
        if !ctx.current_photo_solved() {
            ui.colored_label(WARNING, "this photo is not solved yet: press Solve first");
        }
        ui.horizontal(|ui| {
            ui.label("rays per pixel");
            let q = &mut self.quality;
            let r = ui.add(egui::DragValue::new(&mut q.spp_min).range(4..=64).speed(4));
            name_widget(ui, &r, "variant spp min");
            ui.label("to");
            let r = ui.add(egui::DragValue::new(&mut q.spp_max).range(4..=64).speed(4));
            name_widget(ui, &r, "variant spp max");
            ui.label("seed");
            let r = ui.add(egui::DragValue::new(&mut q.seed));
            name_widget(ui, &r, "variant seed");
        });
        ui.horizontal(|ui| {
            let busy = self.busy();
            let r = ui.add_enabled(!busy, egui::Button::new("Render all variants"));
            name_widget(ui, &r, "Render all variants");
            if r.clicked() {
                actions.push(Action::StartVariantRenders);
            }
            let r = ui.add_enabled(busy, egui::Button::new("Cancel variants"));
            name_widget(ui, &r, "Cancel variants");
            if r.clicked() {
                actions.push(Action::CancelVariantRenders);
            }
            if busy {
                ui.spinner();
                let (done, total) = self.progress();
                let f = done as f32 / total.max(1) as f32;
                ui.add(egui::ProgressBar::new(f).text(format!("{done}/{total} tiles")));
            }
        });
        ui.horizontal(|ui| {
            let has = self.renders.is_some();
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.export_path)
                    .hint_text("comparison sheet .pdf or .png")
                    .desired_width(220.0),
            );
            name_widget(ui, &r, "comparison sheet path");
            let r = ui.checkbox(&mut self.png_too, "PNG grid too");
            name_widget(ui, &r, "PNG grid too");
            let r = ui.add_enabled(has, egui::Button::new("Export comparison"));
            name_widget(ui, &r, "Export comparison");
            if r.clicked() {
                actions.push(Action::ExportComparison);
            }
            let r = ui.add_enabled(
                has && !ctx.dialog_open,
                egui::Button::new("Export comparison…"),
            );
            name_widget(ui, &r, "Export comparison…");
            if r.clicked() {
                actions.push(Action::RequestDialog(DialogPurpose::ExportComparison));
            }
        });
    }
}

impl Panel for VariantsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        let Some(doc) = ctx.doc else {
            ui.label("open a site first");
            return actions;
        };
        egui::ScrollArea::vertical()
            .id_salt("variants scroll")
            .show(ui, |ui| {
                self.list_ui(ui, doc, &mut actions);
                if let Some(e) = &self.error {
                    ui.colored_label(ERROR, e);
                }
                ui.separator();
                self.editor_ui(ui, doc, &mut actions);
                ui.separator();
                self.render_ui(ui, ctx, &mut actions);
                if self.stale(doc) {
                    ui.colored_label(
                        WARNING,
                        "the variants changed since they were rendered: Render all variants again",
                    );
                }
                if let Some(renders) = self.renders.as_mut() {
                    self.compare.ui(ui, &mut renders.shown);
                }
            });
        actions
    }
}

impl ShownVariant {
    /// The variant's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.render.name
    }

    /// The texture of the display image (uploaded on first use).
    pub(crate) fn texture(&mut self, ctx: &egui::Context) -> &egui::TextureHandle {
        let (display, name) = (&self.display, &self.render.name);
        self.texture.get_or_insert_with(|| {
            ctx.load_texture(
                format!("variant {name}"),
                display.clone(),
                egui::TextureOptions::LINEAR,
            )
        })
    }

    /// Width over height of the display image.
    pub(crate) fn aspect(&self) -> f32 {
        let [w, h] = self.display.size;
        w as f32 / h.max(1) as f32
    }
}

/// Writes the comparison sheet of `cells` to `path`: with a `subtitle`, the PDF (and the PNG
/// grid beside it when `png_too`), else the PNG grid; returns the files written.
fn write_comparison(
    path: &std::path::Path,
    subtitle: Option<&str>,
    png_too: bool,
    cells: &[ComparisonCell<'_>],
) -> Result<Vec<std::path::PathBuf>, String> {
    let Some(subtitle) = subtitle else {
        write_comparison_png(path, cells).map_err(|e| e.to_string())?;
        return Ok(vec![path.to_path_buf()]);
    };
    let pdf = comparison_pdf(cells, subtitle).map_err(|e| e.to_string())?;
    write_sheet(path, &pdf).map_err(|e| e.to_string())?;
    let mut written = vec![path.to_path_buf()];
    if png_too {
        let png = path.with_extension("png");
        write_comparison_png(&png, cells).map_err(|e| e.to_string())?;
        written.push(png);
    }
    Ok(written)
}

impl crate::Studio {
    /// Renders every variant of the current photo (errors become messages).
    pub fn start_variant_renders(&mut self, ctx: &egui::Context) {
        let (Some(doc), Some(id)) = (self.doc.as_ref(), self.current_photo.clone()) else {
            self.say("open a site with a photo first", true);
            return;
        };
        match self.variants.start(doc, &id, ctx) {
            Ok(n) => self.say(format!("rendering {n} variant(s) of {id}…"), false),
            Err(e) => self.say(e, true),
        }
    }

    /// Writes the comparison sheet of the last renders to the Variants tab's path: a .pdf
    /// (one page per variant; with "PNG grid too" also the grid as .png beside it) or a .png
    /// grid.
    pub fn export_comparison(&mut self) {
        let path = std::path::PathBuf::from(self.variants.export_path.trim());
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let Some(ext) = ext.filter(|e| e == "pdf" || e == "png") else {
            self.say(
                "type a comparison sheet path ending in .pdf or .png first",
                true,
            );
            return;
        };
        let (Some(doc), Some(renders)) = (self.doc.as_ref(), self.variants.renders()) else {
            self.say("nothing to export: Render all variants first", true);
            return;
        };
        let Some(first) = renders.shown.first() else {
            self.say("nothing to export: Render all variants first", true);
            return;
        };
        let cells: Vec<ComparisonCell<'_>> = renders
            .shown
            .iter()
            .map(|s| ComparisonCell {
                name: s.render.name.clone(),
                image: &s.render.srgb,
            })
            .collect();
        let subtitle = (ext == "pdf").then(|| {
            comparison_subtitle(&doc.site.name, &renders.view, &first.render.plan.settings)
        });
        let result = write_comparison(&path, subtitle.as_deref(), self.variants.png_too, &cells);
        let n = cells.len();
        match result {
            Ok(written) => self.say(
                format!(
                    "wrote the comparison sheet of {n} variant(s): {}",
                    written
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                false,
            ),
            Err(e) => self.say(e, true),
        }
    }

    /// The Variants tab (mutable: tests set the quality and paths as a user would).
    pub fn variants_panel_mut(&mut self) -> &mut VariantsPanel {
        &mut self.variants
    }

    /// The Variants tab.
    #[must_use]
    pub fn variants_panel(&self) -> &VariantsPanel {
        &self.variants
    }

    pub(crate) fn poll_variants(&mut self, ctx: &egui::Context) {
        match self.variants.poll(self.doc.as_ref()) {
            Some(Ok(text)) => self.say(text, false),
            Some(Err(e)) => self.say(e, true),
            None => {}
        }
        if self.variants.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }
}
