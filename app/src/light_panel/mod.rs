//! The Site & light side tab (issue 17 item 1): the site's location (typed, or from the control
//! points' CRS with `photomontage::site::control_location`), its IANA time zone (checked, with
//! the "did you mean" hint of `photomontage::time_zone`), the current photo's capture time, the
//! lighting time, the sun (computed or manual), the sky model and the sun/ambient/sky weights,
//! the exposure, the atmosphere and the ground, a sky map with date and time sliders
//! ([`crate::light_panel::sky_map`]) and the luminaires ([`crate::light_panel::luminaires`]).
//!
//! Every change is one undoable `Command::Light` ([`crate::light_commands`]) of the same site
//! fields the CLI reads; nothing studio-only is written to the site file. Typed values are
//! checked before anything is written, and text typed but not applied survives other edits and
//! their undo (each field refills only when its own site value changes): a bad value (unknown zone, latitude out of range, a
//! non-finite number, an unreadable photometric file) shows a message in the panel and leaves
//! the site and the typed text as they were. The sun angles shown are those the renderer uses
//! (`photomontage::site::sun_path::site_sun_angles`: the SPA with the inputs of
//! `photomontage sun`).
//!
//! # Known limitations
//! Local times typed without an offset
//! are stored resolved to RFC 3339 with the offset in force (what `validate` asks of
//! `lighting.time`). Luminaire files are typed paths (no file dialog).

pub mod luminaires;
pub mod perez;
pub mod sky_map;

use std::collections::HashMap;

use eframe::egui::{self, Color32};
use photomontage::site::sun_path::{SunSource, site_sun_angles};
use photomontage::site::{SiteDocument, SkyModelName, SunManual, site_time::site_time_zone};

use crate::commands::Command;
use crate::light_commands::LightCommand;
use crate::light_inputs::{finite, from_control, sky_models, typed_location, typed_time};
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// Colour of the panel's error message.
const ERROR_COLOUR: Color32 = Color32::from_rgb(230, 80, 60);

/// The Site & light tab's own state: the text being typed and the last message.
#[derive(Default)]
pub struct LightPanel {
    /// Keep the render settings (exposure, the radiosity switches) scrolled into view (the
    /// screenshot option `--light-render-settings`).
    pub scroll_to_render: bool,
    /// Per text field, the site value it was last filled from: a field is refilled only when
    /// its own value in the site changes (its apply, or an undo of it), so text typed but not
    /// applied survives every other edit.
    filled_from: HashMap<&'static str, String>,
    /// Latitude text, degrees north.
    pub latitude: String,
    /// Longitude text, degrees east.
    pub longitude: String,
    /// Elevation text, metres.
    pub elevation: String,
    /// IANA time zone name (empty: none).
    pub time_zone: String,
    /// CRS name for "From control points".
    pub crs: String,
    /// Lighting time text (empty: the photo's time).
    pub lighting_time: String,
    /// Capture time of the current photo (empty: EXIF).
    pub taken_at: String,
    /// Manual sun azimuth text.
    pub sun_azimuth: String,
    /// Manual sun elevation text.
    pub sun_elevation: String,
    /// Exposure text.
    pub exposure: String,
    /// Perez sky clearness ε text.
    pub perez_clearness: String,
    /// Perez sky brightness Δ text.
    pub perez_brightness: String,
    /// Perez direct normal irradiance text, W/m².
    pub perez_direct_normal: String,
    /// Perez diffuse horizontal irradiance text, W/m².
    pub perez_diffuse_horizontal: String,
    /// Whether the Perez fields show the irradiance form (else ε and Δ); follows the site's
    /// form whenever `[lighting.perez]` changes.
    pub perez_irradiance_form: bool,
    /// The last refusal, shown in red until the next successful edit.
    pub error: Option<String>,
    /// Sky map and sliders.
    pub sky_map: crate::light_panel::sky_map::SkyMapState,
    /// Luminaires.
    pub luminaires: crate::light_panel::luminaires::LuminairesState,
    /// Counts drags/typing sessions so that each is one undo step.
    gesture: u64,
}

/// Sets `field` to `value` when the site value `source` differs from the one it was last
/// filled from (or it was never filled).
fn refill_field(
    filled: &mut HashMap<&'static str, String>,
    key: &'static str,
    source: String,
    value: String,
    field: &mut String,
) {
    if filled.get(key) != Some(&source) {
        *field = value;
        filled.insert(key, source);
    }
}

pub(crate) fn edit(c: LightCommand, key: Option<String>) -> Action {
    Action::Edit {
        command: Box::new(Command::Light(c)),
        merge_key: key,
    }
}

impl LightPanel {
    fn refill(&mut self, doc: &SiteDocument, photo: Option<&str>) {
        let site = &doc.site;
        let taken_at = photo
            .and_then(|id| site.photos.iter().find(|p| p.id == id))
            .and_then(|p| p.taken_at.clone());
        let loc = site.location.as_ref();
        let manual = site.lighting.sun_manual.as_ref();
        let perez = site.lighting.perez.as_ref();
        let text = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
        let filled = &mut self.filled_from;
        for (key, source, field) in [
            (
                "latitude",
                text(loc.map(|l| l.latitude_deg)),
                &mut self.latitude,
            ),
            (
                "longitude",
                text(loc.map(|l| l.longitude_deg)),
                &mut self.longitude,
            ),
            (
                "elevation",
                text(loc.map(|l| l.elevation_m)),
                &mut self.elevation,
            ),
            (
                "time zone",
                loc.and_then(|l| l.time_zone.clone()).unwrap_or_default(),
                &mut self.time_zone,
            ),
            (
                "lighting time",
                site.lighting.time.clone().unwrap_or_default(),
                &mut self.lighting_time,
            ),
            (
                "manual azimuth",
                text(manual.map(|m| m.azimuth_deg)),
                &mut self.sun_azimuth,
            ),
            (
                "manual elevation",
                text(manual.map(|m| m.elevation_deg)),
                &mut self.sun_elevation,
            ),
            (
                "exposure",
                site.render.exposure.to_string(),
                &mut self.exposure,
            ),
            (
                "perez clearness",
                text(perez.and_then(|p| p.clearness)),
                &mut self.perez_clearness,
            ),
            (
                "perez brightness",
                text(perez.and_then(|p| p.brightness)),
                &mut self.perez_brightness,
            ),
            (
                "perez direct normal",
                text(perez.and_then(|p| p.direct_normal_w_m2)),
                &mut self.perez_direct_normal,
            ),
            (
                "perez diffuse horizontal",
                text(perez.and_then(|p| p.diffuse_horizontal_w_m2)),
                &mut self.perez_diffuse_horizontal,
            ),
        ] {
            refill_field(filled, key, source.clone(), source, field);
        }
        // The capture time belongs to the current photo: a change of photo refills it too.
        let perez_source = format!("{perez:?}");
        if filled.get("perez form") != Some(&perez_source) {
            self.perez_irradiance_form = perez.is_some_and(|p| p.direct_normal_w_m2.is_some());
            filled.insert("perez form", perez_source);
        }
        let taken_at = taken_at.unwrap_or_default();
        let source = format!("{photo:?} {taken_at}");
        refill_field(filled, "capture time", source, taken_at, &mut self.taken_at);
        if let Some(crs) = loc.and_then(|l| l.crs.clone()) {
            refill_field(filled, "control CRS", crs.clone(), crs, &mut self.crs);
        }
    }

    /// A key that is the same for every change of one drag or typing session of `field`.
    pub(crate) fn gesture_key(&mut self, field: &str, response: &egui::Response) -> String {
        if response.drag_started() || response.gained_focus() {
            self.gesture += 1;
        }
        format!("light:{field}:{}", self.gesture)
    }

    fn refuse(&mut self, why: String) {
        self.error = Some(why);
    }

    fn location_ui(&mut self, ui: &mut egui::Ui, doc: &SiteDocument, out: &mut Vec<Action>) {
        ui.strong("Location");
        egui::Grid::new("light location").show(ui, |ui| {
            for (label, caption, text, hint) in [
                (
                    "latitude",
                    "latitude (°N)",
                    &mut self.latitude,
                    "degrees north",
                ),
                (
                    "longitude",
                    "longitude (°E)",
                    &mut self.longitude,
                    "degrees east",
                ),
                ("elevation", "elevation (m)", &mut self.elevation, "metres"),
                (
                    "time zone",
                    "time zone (IANA)",
                    &mut self.time_zone,
                    "e.g. Europe/Zurich",
                ),
            ] {
                ui.label(caption);
                let r = ui.add(
                    egui::TextEdit::singleline(text)
                        .hint_text(hint)
                        .min_size(egui::vec2(200.0, 0.0)),
                );
                name_widget(ui, &r, label);
                ui.end_row();
            }
        });
        ui.horizontal(|ui| {
            if ui.button("Apply location").clicked() {
                match typed_location(
                    &self.latitude,
                    &self.longitude,
                    &self.elevation,
                    &self.time_zone,
                    doc.site.location.as_ref(),
                ) {
                    Ok(loc) if Some(&loc) == doc.site.location.as_ref() => self.error = None,
                    Ok(loc) => {
                        self.error = None;
                        out.push(edit(LightCommand::SetLocation(Some(Box::new(loc))), None));
                    }
                    Err(e) => self.refuse(e),
                }
            }
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.crs)
                    .hint_text("CRS, e.g. EPSG:2056")
                    .desired_width(110.0),
            );
            name_widget(ui, &r, "control CRS");
            if ui.button("From control points").clicked() {
                match from_control(doc, &self.crs) {
                    Ok(loc) => {
                        self.error = None;
                        out.push(edit(LightCommand::SetLocation(Some(Box::new(loc))), None));
                    }
                    Err(e) => self.refuse(e),
                }
            }
        });
    }

    fn times_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        photo: Option<&str>,
        out: &mut Vec<Action>,
    ) {
        ui.strong("Time");
        let zone = site_time_zone(&doc.site).ok().flatten();
        egui::Grid::new("light times").show(ui, |ui| {
            ui.label("lighting time:");
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.lighting_time)
                    .hint_text("empty: the photo's time")
                    .min_size(egui::vec2(200.0, 0.0)),
            );
            name_widget(ui, &r, "lighting time");
            if ui.button("Set lighting time").clicked() {
                match typed_time(&self.lighting_time, zone.as_ref(), "lighting time") {
                    Ok(time) => {
                        self.error = None;
                        let mut lighting = doc.site.lighting.clone();
                        lighting.time = time;
                        if lighting != doc.site.lighting {
                            out.push(edit(LightCommand::SetLighting(Box::new(lighting)), None));
                        }
                    }
                    Err(e) => self.refuse(e),
                }
            }
            ui.end_row();
            if let Some(photo) = photo {
                ui.label(format!("capture time of {photo}"));
                let r = ui.add(
                    egui::TextEdit::singleline(&mut self.taken_at)
                        .hint_text("empty: EXIF time")
                        .min_size(egui::vec2(200.0, 0.0)),
                );
                name_widget(ui, &r, "capture time");
                if ui.button("Set capture time").clicked() {
                    match typed_time(&self.taken_at, zone.as_ref(), "capture time") {
                        Ok(taken_at) => {
                            self.error = None;
                            out.push(edit(
                                LightCommand::SetTakenAt {
                                    photo: photo.to_owned(),
                                    taken_at,
                                },
                                None,
                            ));
                        }
                        Err(e) => self.refuse(e),
                    }
                }
                ui.end_row();
            }
        });
    }

    fn sun_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        photo: Option<&str>,
        out: &mut Vec<Action>,
    ) {
        ui.strong("Sun");
        let lighting = &doc.site.lighting;
        let mut manual = lighting.sun_manual.is_some();
        ui.horizontal(|ui| {
            let r = ui.radio_value(&mut manual, false, "computed (SPA)");
            name_widget(ui, &r, "sun computed");
            let r2 = ui.radio_value(&mut manual, true, "manual");
            name_widget(ui, &r2, "sun manual");
            if r.changed() || r2.changed() {
                let mut l = lighting.clone();
                l.sun_manual = manual.then(|| SunManual {
                    azimuth_deg: finite(&self.sun_azimuth, "").unwrap_or(180.0),
                    elevation_deg: finite(&self.sun_elevation, "").unwrap_or(45.0),
                });
                out.push(edit(LightCommand::SetLighting(Box::new(l)), None));
            }
        });
        if manual {
            ui.horizontal(|ui| {
                for (label, caption, text) in [
                    ("manual azimuth", "azimuth (°)", &mut self.sun_azimuth),
                    ("manual elevation", "elevation (°)", &mut self.sun_elevation),
                ] {
                    ui.label(caption);
                    let r = ui.add(egui::TextEdit::singleline(text).desired_width(70.0));
                    name_widget(ui, &r, label);
                }
                if ui.button("Set sun").clicked() {
                    let az = finite(&self.sun_azimuth, "manual azimuth");
                    let el = finite(&self.sun_elevation, "manual elevation");
                    match (az, el) {
                        (Ok(a), Ok(e)) if (-90.0..=90.0).contains(&e) => {
                            self.error = None;
                            let mut l = lighting.clone();
                            l.sun_manual = Some(SunManual {
                                azimuth_deg: a.rem_euclid(360.0),
                                elevation_deg: e,
                            });
                            out.push(edit(LightCommand::SetLighting(Box::new(l)), None));
                        }
                        (Ok(_), Ok(e)) => {
                            self.refuse(format!("manual elevation {e} is outside −90…90°"));
                        }
                        (Err(e), _) | (_, Err(e)) => self.refuse(e),
                    }
                }
            });
        }
        match photo.map(|p| site_sun_angles(doc, p)) {
            Some(Ok(sun)) => {
                ui.label(format!("sun azimuth {:.6}°", sun.azimuth_deg));
                ui.label(format!("sun elevation {:.6}°", sun.elevation_deg));
                ui.label(match &sun.source {
                    SunSource::Manual => "sun set by hand".to_owned(),
                    SunSource::Computed(t) => format!("sun computed for {}", t.to_rfc3339()),
                });
            }
            Some(Err(e)) => {
                ui.colored_label(ERROR_COLOUR, format!("no sun: {e}"));
            }
            None => {
                ui.label("no photo: no sun time");
            }
        }
    }

    fn sky_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        photo: Option<&str>,
        out: &mut Vec<Action>,
    ) {
        ui.strong("Sky and weights");
        let lighting = &doc.site.lighting;
        let mut l = lighting.clone();
        let mut key = None;
        egui::ComboBox::from_label("sky model")
            .selected_text(l.sky_model.to_string())
            .show_ui(ui, |ui| {
                for m in sky_models() {
                    let text = m.to_string();
                    ui.selectable_value(&mut l.sky_model, m, text);
                }
            });
        if l.sky_model == SkyModelName::Perez && lighting.sky_model != SkyModelName::Perez {
            // Chosen now: valid inputs go with it, in the same edit, so a saved site loads.
            l.perez = Some(crate::light_panel::perez::inputs_for_new_perez_sky(&l));
        }
        if l.sky_model == SkyModelName::Perez {
            crate::light_panel::perez::perez_ui(self, ui, doc, photo, &mut l);
        }
        egui::Grid::new("light weights").show(ui, |ui| {
            for (label, values, max) in [
                ("sun weight", &mut l.sun_weight, 1e6),
                ("ambient weight", &mut l.ambient_weight, 1e6),
                ("sky weight", &mut l.sky_weight, 1e6),
                ("extinction per m", &mut l.atmosphere.extinction_per_m, 1.0),
                ("horizon colour", &mut l.atmosphere.horizon_colour, 1e6),
            ] {
                ui.label(label);
                for (c, v) in ["R", "G", "B"].iter().zip(values.iter_mut()) {
                    let r = ui.add(
                        egui::DragValue::new(v)
                            .range(0.0..=max)
                            .speed(if max < 10.0 { 1e-4 } else { 0.01 })
                            .max_decimals(6),
                    );
                    let name = format!("{label} {c}");
                    name_widget(ui, &r, &name);
                    if r.changed() {
                        key = Some(self.gesture_key(&name, &r));
                    }
                }
                ui.end_row();
            }
        });
        ui.horizontal(|ui| {
            let mut modelled = l.ground_modelled;
            egui::ComboBox::from_label("ground")
                .selected_text(match modelled {
                    None => "modelled if a polygon faces up",
                    Some(true) => "modelled",
                    Some(false) => "uniform albedo",
                })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut modelled, None, "modelled if a polygon faces up");
                    ui.selectable_value(&mut modelled, Some(true), "modelled");
                    ui.selectable_value(&mut modelled, Some(false), "uniform albedo");
                });
            l.ground_modelled = modelled;
        });
        ui.horizontal(|ui| {
            ui.label("ground albedo");
            let mut albedo = l.ground_albedo.unwrap_or([0.2; 3]);
            let mut changed = false;
            for (c, v) in ["R", "G", "B"].iter().zip(albedo.iter_mut()) {
                let r = ui.add(egui::DragValue::new(v).range(0.0..=1.0).speed(0.005));
                let name = format!("ground albedo {c}");
                name_widget(ui, &r, &name);
                if r.changed() {
                    changed = true;
                    key = Some(self.gesture_key(&name, &r));
                }
            }
            if changed {
                l.ground_albedo = Some(albedo);
            }
        });
        if &l != lighting {
            self.error = None;
            out.push(edit(LightCommand::SetLighting(Box::new(l)), key));
        }
        ui.horizontal(|ui| {
            ui.label("exposure:");
            let r = ui.add(egui::TextEdit::singleline(&mut self.exposure).desired_width(80.0));
            name_widget(ui, &r, "exposure");
            if ui.button("Set exposure").clicked() {
                match finite(&self.exposure, "exposure") {
                    Ok(e) if e > 0.0 => {
                        self.error = None;
                        if e.to_bits() != doc.site.render.exposure.to_bits() {
                            out.push(edit(LightCommand::SetExposure(e), None));
                        }
                    }
                    Ok(e) => self.refuse(format!("exposure {e} must be positive")),
                    Err(e) => self.refuse(e),
                }
            }
        });
        let render = &doc.site.render;
        let (mut radiosity, mut photo_reflectance) = (render.radiosity, render.photo_reflectance);
        ui.horizontal(|ui| {
            let r = ui
                .checkbox(&mut radiosity, "radiosity")
                .on_hover_text("sky and interreflected light from radiosity solutions of the site with and without the planned objects (CLI: render --radiosity)");
            name_widget(ui, &r, "radiosity");
            let r = ui
                .add_enabled(
                    radiosity,
                    egui::Checkbox::new(&mut photo_reflectance, "reflectance from the photo"),
                )
                .on_hover_text("the photographed surfaces take their diffuse reflectance from the photo's pixels where it sees them, else from the material library");
            name_widget(ui, &r, "reflectance from the photo");
            if self.scroll_to_render {
                r.scroll_to_me(Some(egui::Align::Center));
            }
        });
        if (radiosity, photo_reflectance) != (render.radiosity, render.photo_reflectance) {
            out.push(edit(
                LightCommand::SetRadiosity {
                    radiosity,
                    photo_reflectance,
                },
                None,
            ));
        }
    }
}

impl Panel for LightPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut out = Vec::new();
        let Some(doc) = ctx.doc else {
            ui.label("no site open");
            return out;
        };
        self.refill(doc, ctx.current_photo);
        egui::ScrollArea::vertical().show(ui, |ui| {
            if let Some(e) = &self.error {
                let r = ui.colored_label(ERROR_COLOUR, e.clone());
                name_widget(ui, &r, &format!("light error: {e}"));
            }
            self.location_ui(ui, doc, &mut out);
            ui.separator();
            self.times_ui(ui, doc, ctx.current_photo, &mut out);
            ui.separator();
            self.sun_ui(ui, doc, ctx.current_photo, &mut out);
            ui.separator();
            crate::light_panel::sky_map::sky_map_ui(self, ui, doc, ctx.current_photo, &mut out);
            ui.separator();
            self.sky_ui(ui, doc, ctx.current_photo, &mut out);
            ui.separator();
            crate::light_panel::luminaires::luminaires_ui(self, ui, doc, &mut out);
        });
        out
    }
}
