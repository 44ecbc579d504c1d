//! The Render panel's verified-view controls: the Sheet button (the verified-view PDF,
//! `photomontage::verified::sheet`, of the finished view — the photo, or a planar or cylindrical
//! view with its own geometry — at the AVR level it was made with, on the paper chosen in the
//! panel, A3 by default) and the Report button (the view geometry report of the
//! current photo, `photomontage::verified::view_geometry`, shown as the sheet's table).

use std::path::Path;

use eframe::egui;
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::encode_srgb8;
use photomontage::site::SiteDocument;
use photomontage::verified::reprojected_geometry::with_paper;
use photomontage::verified::sheet::{SheetFormat, sheet_for_geometry, sheet_for_view, write_sheet};
use photomontage::verified::sheet_content::geometry_rows;
use photomontage::verified::{ViewGeometryOptions, view_geometry};

use crate::render_panel::{RenderPanel, RenderPanelError, site_tone_map};

impl RenderPanel {
    /// Writes the sheet of the finished view to `path` (through a temporary file and a rename).
    ///
    /// # Errors
    /// `NothingToExport` or the sheet's error (unsolved view, write failure, …).
    pub fn export_sheet(
        &self,
        doc: &SiteDocument,
        path: &Path,
        tone_map: &ToneMap,
    ) -> Result<(), RenderPanelError> {
        let m = self.montage().ok_or(RenderPanelError::NothingToExport)?;
        let [w, h] = m.image.size_px;
        let rgb = image::RgbImage::from_fn(w, h, |x, y| {
            let p = m.image.rgba[(y * w + x) as usize];
            image::Rgb(encode_srgb8([p[0], p[1], p[2]], tone_map))
        });
        let paper = self.view_choice.paper;
        let pdf = match &m.geometry {
            // A re-projected view: its own geometry, on the chosen paper.
            Some(g) => {
                sheet_for_geometry(doc, &with_paper(g, paper), &rgb, m.avr, SheetFormat::Pdf)
            }
            None => sheet_for_view(
                doc,
                &m.photo_id,
                &rgb,
                m.avr,
                &ViewGeometryOptions {
                    paper,
                    ground_level_m: None,
                },
            ),
        }
        .map_err(Box::new)?;
        write_sheet(path, &pdf).map_err(Box::new)?;
        Ok(())
    }

    /// The view geometry report's table (label, value rows as on the sheet), when the report
    /// is of `photo_id`.
    pub(crate) fn report_ui(&self, ui: &mut egui::Ui, photo_id: &str) {
        if let Some(report) = self.report.as_ref().filter(|r| r.photo_id == photo_id) {
            egui::Grid::new("view geometry")
                .striped(true)
                .show(ui, |ui| {
                    for (label, value) in geometry_rows(report) {
                        ui.label(label);
                        ui.label(value);
                        ui.end_row();
                    }
                });
        }
    }
}

impl crate::Studio {
    /// Computes the view geometry report of the current photo (shown in the Render panel).
    pub fn make_report(&mut self) {
        let (Some(doc), Some(id)) = (self.doc.as_ref(), self.current_photo.clone()) else {
            self.say("open a site with a photo first", true);
            return;
        };
        match view_geometry(doc, &id, &ViewGeometryOptions::default()) {
            Ok(report) => {
                self.render.report = Some(report);
                self.say(format!("view geometry of {id}"), false);
            }
            Err(e) => {
                self.render.report = None;
                self.say(e.to_string(), true);
            }
        }
    }

    /// Writes the verified-view sheet of the finished view to the path typed in the panel.
    pub fn export_sheet(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let path = std::path::PathBuf::from(self.render.sheet_path.trim());
        if path.extension().and_then(|e| e.to_str()) != Some("pdf") {
            self.say("type a sheet path ending in .pdf first", true);
            return;
        }
        match self.render.export_sheet(doc, &path, &site_tone_map(doc)) {
            Ok(()) => self.say(format!("wrote the sheet {}", path.display()), false),
            Err(e) => self.say(e.to_string(), true),
        }
    }
}
