//! The Materials tab's "Unfolded elevation" (Tonn & Donath; issue 17 item 3): one visible CAD
//! model's façades side by side, with their current colours or with the irradiance of a
//! radiosity solve, drawn by the library's `photomontage::site::elevation::site_elevation` (the
//! function `photomontage elevation` calls) on the studio's worker, shown as an image and
//! exported as the same PNG bytes the CLI writes (`SiteElevation::png_bytes`).
//!
//! The irradiance view has the CLI's solve options (`--view`, `--patch-edge-m`,
//! `--element-edge-m`, `--object-element-edge`, `--samples`, `--seed`, `--bf-tolerance`,
//! `--sky-tolerance`, `--mean-change`, `--residual`), held as the library's
//! `photomontage::site::solve_options::SolveOptions` (its defaults are the CLI's) and turned into
//! the solve by the same `SolveOptions::elevation_transfer_params`, so the studio's PNG is the
//! CLI's for the same options.
//!
//! # Known limitations
//! The CLI's `--threads` is not offered (the worker uses the studio's thread pool). The picture
//! is not redrawn by itself when the site changes: press Draw again.

use eframe::egui;
use photomontage::design::unfolded::UnfoldParams;
use photomontage::site::SiteDocument;
use photomontage::site::elevation::{ElevationLighting, SiteElevation, site_elevation};
use photomontage::site::solve_options::SolveOptions;

use crate::widgets::name_widget;
use crate::worker::{Poll, Worker};

/// The elevation's state: the chosen model and view, the job, the last picture.
pub struct ElevationView {
    model: String,
    irradiance: bool,
    /// The irradiance view's solve options (the CLI's, with its defaults).
    options: SolveOptions,
    /// The photo whose sun time lights the irradiance view (empty: the first photo).
    view: String,
    /// `--object-element-edge` as typed: `NAME=METRES`, comma-separated.
    object_edges: String,
    export_path: String,
    worker: Worker<Result<SiteElevation, String>>,
    drawn: Option<(SiteElevation, egui::TextureHandle)>,
    message: Option<String>,
    /// Draw on the next frame the section is shown (the studio's `--elevation` start option).
    draw_requested: bool,
    /// Close the solve options on the next frame (after a requested draw, so that the drawing
    /// shows below them).
    fold_options: bool,
}

impl Default for ElevationView {
    fn default() -> Self {
        Self {
            model: String::new(),
            irradiance: false,
            options: SolveOptions::default(),
            view: String::new(),
            object_edges: String::new(),
            export_path: String::new(),
            worker: Worker::new("elevation"),
            drawn: None,
            draw_requested: false,
            fold_options: false,
            message: None,
        }
    }
}

impl std::fmt::Debug for ElevationView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ElevationView")
            .field("model", &self.model)
            .field("irradiance", &self.irradiance)
            .field("busy", &self.worker.busy())
            .finish_non_exhaustive()
    }
}

/// The irradiance view's light: the solve options and the photo whose sun time places the sun
/// (empty: the first photo, as the CLI's `--view`).
#[derive(Debug, Clone, PartialEq)]
pub struct IrradianceRequest {
    /// Solve options.
    pub options: SolveOptions,
    /// Photo id, or empty.
    pub view: String,
}

/// Draws the elevation of `model` of `doc` (colours, or the irradiance of a solve with the
/// requested options), as `photomontage elevation` does with its default pixels per metre.
///
/// # Errors
/// The library's error as text.
pub fn draw_elevation(
    doc: &SiteDocument,
    model: &str,
    irradiance: Option<&IrradianceRequest>,
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<SiteElevation, String> {
    let lighting = irradiance.map(|r| ElevationLighting {
        params: r.options.elevation_transfer_params(),
        view: if r.view.is_empty() {
            doc.site
                .photos
                .first()
                .map(|p| p.id.clone())
                .unwrap_or_default()
        } else {
            r.view.clone()
        },
        cancel,
    });
    site_elevation(doc, model, &UnfoldParams::default(), lighting).map_err(|e| e.to_string())
}

/// Reads `NAME=METRES, NAME=METRES` (the CLI's repeated `--object-element-edge`).
///
/// # Errors
/// A sentence naming the entry that is not `NAME=METRES` with a positive finite size.
pub fn object_element_edges(text: &str) -> Result<std::collections::BTreeMap<String, f64>, String> {
    text.split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| {
            let (name, size) = t
                .rsplit_once('=')
                .ok_or_else(|| format!("object element edge `{t}` is not NAME=METRES"))?;
            match size.trim().parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok((name.trim().to_owned(), v)),
                _ => Err(format!(
                    "object element edge `{t}`: `{}` is not a positive number of metres",
                    size.trim()
                )),
            }
        })
        .collect()
}

impl ElevationView {
    fn poll(&mut self, ctx: &egui::Context) {
        match self.worker.poll() {
            Poll::Idle | Poll::Running(_) => {}
            Poll::Done(Ok(elevation)) => {
                let img = &elevation.image.image;
                let size = [img.width() as usize, img.height() as usize];
                let colour = egui::ColorImage::from_rgb(size, img.as_raw());
                let texture =
                    ctx.load_texture("unfolded elevation", colour, egui::TextureOptions::NEAREST);
                self.message = Some(format!(
                    "elevation ready: {} façades, {} × {} px",
                    elevation.facades.len(),
                    size[0],
                    size[1]
                ));
                self.drawn = Some((elevation, texture));
            }
            Poll::Done(Err(e)) | Poll::Failed(e) => {
                self.message = Some(format!("elevation failed: {e}"));
            }
            Poll::Cancelled => self.message = Some("elevation cancelled".into()),
        }
    }

    /// Asks for a drawing of the first visible model, with its irradiance when `irradiance`,
    /// the next time the section is shown.
    pub fn request_draw(&mut self, irradiance: bool) {
        self.irradiance = irradiance;
        self.draw_requested = true;
        self.fold_options = true;
    }

    /// Whether a drawing is running or asked for.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.draw_requested || self.worker.busy()
    }

    /// Starts the drawing on the worker, or says why the typed options are refused.
    fn start(&mut self, ctx: &egui::Context, doc: &SiteDocument) {
        let irradiance = if self.irradiance {
            match object_element_edges(&self.object_edges) {
                Ok(edges) => Some(IrradianceRequest {
                    options: SolveOptions {
                        object_element_edge_m: edges,
                        ..self.options.clone()
                    },
                    view: self.view.clone(),
                }),
                Err(e) => {
                    self.message = Some(format!("elevation failed: {e}"));
                    return;
                }
            }
        } else {
            None
        };
        let doc = doc.clone();
        let model = self.model.clone();
        self.message = Some("drawing the elevation…".into());
        self.worker.spawn(ctx, move |progress| {
            progress.set(None, "drawing the unfolded elevation");
            draw_elevation(&doc, &model, irradiance.as_ref(), progress.cancel_flag())
        });
    }

    /// The irradiance view's solve options, as the CLI names them.
    fn options_ui(&mut self, ui: &mut egui::Ui, doc: &SiteDocument) {
        let open = std::mem::take(&mut self.fold_options).then_some(false);
        egui::CollapsingHeader::new("solve options")
            .open(open)
            .default_open(true)
            .show(ui, |ui| {
                egui::Grid::new("elevation solve options").show(ui, |ui| {
                    ui.label("sun of photo");
                    let shown = if self.view.is_empty() {
                        "first photo".to_owned()
                    } else {
                        self.view.clone()
                    };
                    let combo = egui::ComboBox::from_id_salt("elevation view")
                        .selected_text(shown)
                        .show_ui(ui, |ui| {
                            ui.selectable_value(&mut self.view, String::new(), "first photo");
                            for p in &doc.site.photos {
                                ui.selectable_value(&mut self.view, p.id.clone(), p.id.as_str());
                            }
                        });
                    name_widget(ui, &combo.response, "elevation sun photo");
                    ui.end_row();
                    let o = &mut self.options;
                    for (label, value, min, speed) in [
                        ("patch edge (m)", &mut o.patch_edge_m, 1e-3, 0.05),
                        ("element edge (m)", &mut o.element_edge_m, 1e-3, 0.05),
                        ("BF tolerance", &mut o.bf_tolerance, 0.0, 1e-4),
                        ("sky tolerance", &mut o.sky_tolerance, 1e-3, 1e-3),
                        ("mean change", &mut o.mean_change, 0.0, 1e-4),
                        ("residual", &mut o.residual, 0.0, 1e-5),
                    ] {
                        ui.label(label);
                        let r = ui.add(
                            egui::DragValue::new(value)
                                .range(min..=1e6)
                                .speed(speed)
                                .max_decimals(6),
                        );
                        name_widget(ui, &r, &format!("elevation {label}"));
                        ui.end_row();
                    }
                    ui.label("form-factor samples per axis");
                    let r = ui.add(egui::DragValue::new(&mut o.samples_per_axis).range(1..=64));
                    name_widget(ui, &r, "elevation samples per axis");
                    ui.end_row();
                    ui.label("seed");
                    let r = ui.add(egui::DragValue::new(&mut o.seed));
                    name_widget(ui, &r, "elevation seed");
                    ui.end_row();
                    ui.label("object element edges");
                    let r = ui.add(
                        egui::TextEdit::singleline(&mut self.object_edges)
                            .hint_text("NAME=METRES, …")
                            .desired_width(200.0),
                    );
                    name_widget(ui, &r, "elevation object element edges");
                    ui.end_row();
                });
                let b = ui.button("Default solve options");
                name_widget(ui, &b, "Default solve options");
                if b.clicked() {
                    self.options = SolveOptions::default();
                    self.object_edges.clear();
                    self.view.clear();
                }
            });
    }

    fn export(&mut self, doc: &SiteDocument) {
        let Some((elevation, _)) = &self.drawn else {
            return;
        };
        let typed = self.export_path.trim();
        if typed.is_empty() {
            self.message = Some("type a PNG path to export to".into());
            return;
        }
        let path = doc.resolve(typed);
        let written = elevation
            .png_bytes()
            .map_err(|e| e.to_string())
            .and_then(|bytes| {
                photomontage::site::write_atomically(&path, &bytes).map_err(|e| e.to_string())
            });
        self.message = Some(match written {
            Ok(()) => format!("wrote {}", path.display()),
            Err(e) => format!("cannot write {}: {e}", path.display()),
        });
    }

    /// The section's widgets.
    pub fn ui(&mut self, ui: &mut egui::Ui, doc: &SiteDocument) {
        self.poll(ui.ctx());
        let models: Vec<String> = doc
            .site
            .models
            .iter()
            .filter(|m| m.visible)
            .map(|m| m.id.clone())
            .collect();
        if models.is_empty() {
            ui.label("No visible CAD model: import one to see its unfolded elevation.");
            return;
        }
        if !models.contains(&self.model) {
            self.model = models[0].clone();
        }
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("model")
                .selected_text(self.model.clone())
                .show_ui(ui, |ui| {
                    for m in &models {
                        ui.selectable_value(&mut self.model, m.clone(), m.as_str());
                    }
                });
            let r = ui.checkbox(&mut self.irradiance, "irradiance (radiosity)");
            name_widget(ui, &r, "elevation irradiance");
            let busy = self.worker.busy();
            let b = ui.add_enabled(!busy, egui::Button::new("Draw elevation"));
            name_widget(ui, &b, "Draw elevation");
            if b.clicked() || (std::mem::take(&mut self.draw_requested) && !busy) {
                self.start(ui.ctx(), doc);
            }
            if busy && ui.button("Cancel").clicked() {
                self.worker.cancel();
            }
        });
        if self.irradiance {
            self.options_ui(ui, doc);
        }
        if let Some(m) = &self.message {
            let r = ui.label(m);
            name_widget(ui, &r, &format!("elevation status: {m}"));
        }
        if self.drawn.is_some() {
            ui.horizontal(|ui| {
                let r = ui.add(
                    egui::TextEdit::singleline(&mut self.export_path)
                        .hint_text("elevation.png (relative to the site file)")
                        .desired_width(220.0),
                );
                name_widget(ui, &r, "elevation PNG path");
                let b = ui.button("Export PNG");
                name_widget(ui, &b, "Export elevation PNG");
                if b.clicked() {
                    self.export(doc);
                }
            });
        }
        if let Some((_, texture)) = &self.drawn {
            let size = texture.size_vec2();
            let width = ui.available_width().min(size.x).max(1.0);
            let r = ui.add(
                egui::Image::new(texture)
                    .fit_to_exact_size(egui::vec2(width, size.y * width / size.x.max(1.0))),
            );
            name_widget(ui, &r, "unfolded elevation image");
        }
    }
}
