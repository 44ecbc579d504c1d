//! The Materials tab's "Unfolded elevation" (Tonn & Donath; issue 17 item 3): one visible CAD
//! model's façades side by side, with their current colours or with the irradiance of a
//! radiosity solve, drawn by the library's `photomontage::site::elevation::site_elevation` (the
//! function `photomontage elevation` calls) on the studio's worker, shown as an image and
//! exported as the same PNG bytes the CLI writes (`SiteElevation::png_bytes`).
//!
//! # Known limitations
//! The irradiance view solves with the library's default transfer parameters
//! (`TransferParams::default()`, the sun of the first photo), not with the CLI's solve options
//! (`--patch-edge-m`, `--element-edge-m`, …), so its pixels equal the CLI's only where those
//! options give the same parameters; the colour view's pixels are the CLI's. The picture is not
//! redrawn by itself when the site changes: press Draw again.

use eframe::egui;
use photomontage::design::unfolded::UnfoldParams;
use photomontage::radiosity::TransferParams;
use photomontage::site::SiteDocument;
use photomontage::site::elevation::{ElevationLighting, SiteElevation, site_elevation};

use crate::widgets::name_widget;
use crate::worker::{Poll, Worker};

/// The elevation's state: the chosen model and view, the job, the last picture.
pub struct ElevationView {
    model: String,
    irradiance: bool,
    export_path: String,
    worker: Worker<Result<SiteElevation, String>>,
    drawn: Option<(SiteElevation, egui::TextureHandle)>,
    message: Option<String>,
}

impl Default for ElevationView {
    fn default() -> Self {
        Self {
            model: String::new(),
            irradiance: false,
            export_path: String::new(),
            worker: Worker::new("elevation"),
            drawn: None,
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

/// Draws the elevation of `model` of `doc` (colours, or irradiance when `irradiance`), as the
/// CLI does with its default pixels per metre.
///
/// # Errors
/// The library's error as text.
pub fn draw_elevation(
    doc: &SiteDocument,
    model: &str,
    irradiance: bool,
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<SiteElevation, String> {
    let lighting = irradiance.then(|| ElevationLighting {
        params: TransferParams::default(),
        view: doc
            .site
            .photos
            .first()
            .map(|p| p.id.clone())
            .unwrap_or_default(),
        cancel,
    });
    site_elevation(doc, model, &UnfoldParams::default(), lighting).map_err(|e| e.to_string())
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
            if b.clicked() {
                let doc = doc.clone();
                let model = self.model.clone();
                let irradiance = self.irradiance;
                self.message = Some("drawing the elevation…".into());
                self.worker.spawn(ui.ctx(), move |progress| {
                    progress.set(None, "drawing the unfolded elevation");
                    draw_elevation(&doc, &model, irradiance, progress.cancel_flag())
                });
            }
            if busy && ui.button("Cancel").clicked() {
                self.worker.cancel();
            }
        });
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
