//! The Materials tab's RAL Design page: one hue page of the RAL Design System's grid
//! (`photomontage::colour::ral_design`, computed from the codes, no swatch table), drawn as a
//! fan page (lightest row on top, chroma growing to the right), each chip a button that gives
//! its code to the material editor.
//!
//! # Known limitations
//! The page shows the nominal grid inside the sRGB gamut; a physical fan holds a subset of it
//! and its chips may deviate from their nominal coordinates (docs/methodology.md, "Colour
//! systems").

use eframe::egui;
use photomontage::colour::designer::{ColourSpec, srgb8_from_linear};
use photomontage::colour::ral_design::{HUE_PAGES_DEG, RalDesign};

use crate::widgets::name_widget;

/// Side of a chip, points.
const CHIP_PT: f32 = 18.0;

/// The page shown.
#[derive(Debug, Clone, Copy)]
pub struct RalDesignPage {
    /// Hue of the page, degrees (one of [`HUE_PAGES_DEG`]).
    pub hue_deg: u16,
}

impl Default for RalDesignPage {
    fn default() -> Self {
        Self { hue_deg: 210 }
    }
}

impl RalDesignPage {
    /// Draws the page chooser and the page; the code text of a clicked chip.
    pub fn ui(&mut self, ui: &mut egui::Ui) -> Option<String> {
        let mut chosen = None;
        let r = egui::ComboBox::from_label("hue page")
            .selected_text(page_name(self.hue_deg))
            .show_ui(ui, |ui| {
                for hue in HUE_PAGES_DEG {
                    let r = ui.selectable_value(&mut self.hue_deg, hue, page_name(hue));
                    name_widget(ui, &r, &format!("RAL page {hue:03}"));
                }
            });
        name_widget(ui, &r.response, "RAL Design hue page");
        let page = RalDesign::page(self.hue_deg);
        let mut rows: Vec<Vec<RalDesign>> = Vec::new();
        for code in page {
            match rows.last_mut() {
                Some(row) if row[0].lightness == code.lightness => row.push(code),
                _ => rows.push(vec![code]),
            }
        }
        for row in rows {
            ui.horizontal(|ui| {
                ui.add_sized(
                    [28.0, CHIP_PT],
                    egui::Label::new(format!("L {}", row[0].lightness)),
                );
                for code in row {
                    let rgb = srgb8_from_linear(ColourSpec::RalDesign(code).resolve().linear_rgb);
                    let (rect, r) =
                        ui.allocate_exact_size(egui::vec2(CHIP_PT, CHIP_PT), egui::Sense::click());
                    ui.painter().rect_filled(
                        rect,
                        2.0,
                        egui::Color32::from_rgb(rgb[0], rgb[1], rgb[2]),
                    );
                    let r = r.on_hover_text(format!("{code} (C {})", code.chroma));
                    name_widget(ui, &r, &format!("RAL chip {code}"));
                    if r.clicked() {
                        chosen = Some(code.to_string());
                    }
                }
            });
        }
        chosen
    }
}

fn page_name(hue_deg: u16) -> String {
    if hue_deg == 0 {
        "000 greys".to_owned()
    } else {
        format!("{hue_deg:03}")
    }
}
