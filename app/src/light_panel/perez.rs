//! The Perez sky's inputs in the Site & light tab: clearness ε and brightness Δ, typed and
//! checked with the site file's own rules (`photomontage::site::PerezInputs::form`, the errors
//! the renderer gives) before they are written to `[lighting.perez]`.
//!
//! # Known limitations
//! The irradiance form (direct normal and diffuse horizontal irradiance) is shown when the site
//! file uses it, but is typed in the file.

use eframe::egui;
use photomontage::site::{Lighting, PerezInputs};

use super::{ERROR_COLOUR, LightPanel};
use crate::light_inputs::finite;
use crate::widgets::name_widget;

/// Draws the ε/Δ fields and their Set button; a valid Set writes them into `lighting` (the
/// caller turns the change into one undoable edit).
pub fn perez_ui(panel: &mut LightPanel, ui: &mut egui::Ui, lighting: &mut Lighting) {
    let stored = lighting.perez.clone().unwrap_or_default();
    if let (Some(direct), Some(diffuse)) =
        (stored.direct_normal_w_m2, stored.diffuse_horizontal_w_m2)
    {
        ui.label(format!(
            "Perez sky from irradiance: direct normal {direct} W/m², diffuse horizontal \
             {diffuse} W/m² (edit in the site file, or set ε and Δ below)"
        ));
    }
    if let Err(e) = stored.form() {
        let text = format!("Perez sky: {e}");
        let r = ui.colored_label(ERROR_COLOUR, &text);
        name_widget(ui, &r, &format!("perez status: {text}"));
    }
    ui.horizontal(|ui| {
        for (label, caption, text) in [
            ("perez clearness", "clearness ε", &mut panel.perez_clearness),
            (
                "perez brightness",
                "brightness Δ",
                &mut panel.perez_brightness,
            ),
        ] {
            ui.label(caption);
            let r = ui.add(egui::TextEdit::singleline(text).desired_width(70.0));
            name_widget(ui, &r, label);
        }
        let b = ui.button("Set Perez sky");
        name_widget(ui, &b, "Set Perez sky");
        if b.clicked() {
            let typed = finite(&panel.perez_clearness, "clearness")
                .and_then(|c| finite(&panel.perez_brightness, "brightness").map(|b| (c, b)));
            let inputs = typed.and_then(|(clearness, brightness)| {
                let inputs = PerezInputs {
                    clearness: Some(clearness),
                    brightness: Some(brightness),
                    ..PerezInputs::default()
                };
                inputs.form().map(|_| inputs).map_err(|e| e.to_string())
            });
            match inputs {
                Ok(inputs) => lighting.perez = Some(inputs),
                Err(e) => panel.error = Some(e),
            }
        }
    });
}
