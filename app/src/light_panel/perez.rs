//! The Perez sky's inputs in the Site & light tab, in either of the site file's two forms:
//! clearness ε and brightness Δ, or direct normal and diffuse horizontal irradiance (W/m²).
//! Typed values are checked with the site file's own rules (`photomontage::site::PerezInputs::form`)
//! and, for the irradiance form, with the one sky builder
//! (`photomontage::site::render::site_sky_model`: the day of the year must come from the sun
//! time) before they are written to `[lighting.perez]`; a refusal shows the library's message
//! and writes nothing.
//!
//! Choosing `perez` in the sky list for a site without valid inputs fills in
//! [`PerezInputs::gendaylit_example`] in the same undoable edit (`sky_ui` in the parent module),
//! so a saved site always loads.
//!
//! # Known limitations
//! The irradiance form is checked against the current photo's sun time only; another photo
//! without a time is refused when it is rendered, with the same message.

use eframe::egui;
use photomontage::site::render::{site_sky_model, site_sun_dir};
use photomontage::site::{Lighting, PerezInputs, SiteDocument};

use super::{ERROR_COLOUR, LightPanel};
use crate::light_inputs::finite;
use crate::widgets::name_widget;

/// The inputs to use when `lighting` is switched to the Perez sky: its own when they are a
/// valid form, else [`PerezInputs::gendaylit_example`].
#[must_use]
pub fn inputs_for_new_perez_sky(lighting: &Lighting) -> PerezInputs {
    match &lighting.perez {
        Some(p) if p.form().is_ok() => p.clone(),
        _ => PerezInputs::gendaylit_example(),
    }
}

/// The inputs typed in the panel, in the chosen form, checked.
///
/// # Errors
/// A sentence for the panel: a field that is no finite number, or the library's message.
fn typed_inputs(panel: &LightPanel) -> Result<PerezInputs, String> {
    let inputs = if panel.perez_irradiance_form {
        PerezInputs {
            direct_normal_w_m2: Some(finite(&panel.perez_direct_normal, "direct normal")?),
            diffuse_horizontal_w_m2: Some(finite(
                &panel.perez_diffuse_horizontal,
                "diffuse horizontal",
            )?),
            ..PerezInputs::default()
        }
    } else {
        PerezInputs {
            clearness: Some(finite(&panel.perez_clearness, "clearness")?),
            brightness: Some(finite(&panel.perez_brightness, "brightness")?),
            ..PerezInputs::default()
        }
    };
    inputs.form().map_err(|e| e.to_string())?;
    Ok(inputs)
}

/// Refuses inputs the sky builder cannot use for the current photo for a reason that lies in
/// `[lighting.perez]` (the irradiance form without a sun time); a sun below the horizon or a
/// site without a location is not the inputs' fault and is left to the render.
fn check_with_sky_builder(
    doc: &SiteDocument,
    photo: Option<&str>,
    lighting: &Lighting,
) -> Result<(), String> {
    let Some(photo) = photo else { return Ok(()) };
    let mut candidate = doc.clone();
    candidate.site.lighting = lighting.clone();
    let Ok(sun) = site_sun_dir(&candidate, photo) else {
        return Ok(());
    };
    match site_sky_model(&candidate, photo, &sun) {
        Err(photomontage::site::render::SiteRenderError::Request { field, reason })
            if field.starts_with("lighting.perez") =>
        {
            Err(format!("{field}: {reason}"))
        }
        _ => Ok(()),
    }
}

/// Draws the form choice, its two fields and the Set button; a valid Set writes the inputs
/// into `lighting` (the caller turns the change into one undoable edit).
pub fn perez_ui(
    panel: &mut LightPanel,
    ui: &mut egui::Ui,
    doc: &SiteDocument,
    photo: Option<&str>,
    lighting: &mut Lighting,
) {
    let stored = lighting.perez.clone().unwrap_or_default();
    if let Err(e) = stored.form() {
        let text = format!("Perez sky: {e}");
        let r = ui.colored_label(ERROR_COLOUR, &text);
        name_widget(ui, &r, &format!("perez status: {text}"));
    }
    ui.horizontal(|ui| {
        let r = ui.radio_value(
            &mut panel.perez_irradiance_form,
            false,
            "clearness ε, brightness Δ",
        );
        name_widget(ui, &r, "perez from indices");
        let r = ui.radio_value(&mut panel.perez_irradiance_form, true, "irradiance (W/m²)");
        name_widget(ui, &r, "perez from irradiance");
    });
    ui.horizontal(|ui| {
        let fields = if panel.perez_irradiance_form {
            [
                (
                    "perez direct normal",
                    "direct normal",
                    &mut panel.perez_direct_normal,
                ),
                (
                    "perez diffuse horizontal",
                    "diffuse horizontal",
                    &mut panel.perez_diffuse_horizontal,
                ),
            ]
        } else {
            [
                ("perez clearness", "clearness ε", &mut panel.perez_clearness),
                (
                    "perez brightness",
                    "brightness Δ",
                    &mut panel.perez_brightness,
                ),
            ]
        };
        for (label, caption, text) in fields {
            ui.label(caption);
            let r = ui.add(egui::TextEdit::singleline(text).desired_width(70.0));
            name_widget(ui, &r, label);
        }
        let b = ui.button("Set Perez sky");
        name_widget(ui, &b, "Set Perez sky");
        if b.clicked() {
            let checked = typed_inputs(panel).and_then(|inputs| {
                let mut candidate = lighting.clone();
                candidate.perez = Some(inputs);
                check_with_sky_builder(doc, photo, &candidate).map(|()| candidate)
            });
            match checked {
                Ok(candidate) => *lighting = candidate,
                Err(e) => panel.error = Some(e),
            }
        }
    });
}
