//! The studio's Models panel: the site's `[[models]]` with numeric placement (translation,
//! rotation about Z, scale) edited through the one command path
//! ([`crate::commands::Command::SetModelPlacement`], so undo/redo and autosave see it), and a
//! wireframe overlay of each visible model's triangle edges projected with the current photo's
//! solved camera (`photomontage::camera::Camera::project`): the AVR1 "wireline" check of a
//! verified view (Landscape Institute TGN 06/19, AVR levels).
//!
//! The model's edges come from the library (`photomontage::site::models`: imported by the
//! renderer's own importer at the identity placement, placed exactly as the importer places it,
//! projected with the photo's camera); this panel caches them per model file, units and up axis.
//!
//! **Import model** (typed path or File → Import model…) adds the `[[models]]` entry of
//! `photomontage::site::models::new_model_entry` (id from the file name, path relative to the
//! site file, placed at the control points' centroid) as one undoable edit
//! ([`crate::commands::Command::PutModel`]) after importing it once to check that it reads.
//!
//! Each model's length unit and up axis (the importer's `LengthUnit` and `UpAxis`, written as
//! `units` and `up_axis`) are chosen when adding it (the "added in" combo boxes) and edited
//! afterwards with combo boxes (one undoable [`crate::commands::Command::PutModel`] each); the
//! wireframe follows, and the importer's scale warning (`site::render::SiteWarning::ModelScale`,
//! a model under 1 mm or over 10 km across after the conversion) is shown under the model.
//!
//! # Known limitations
//! Edges are drawn as straight screen segments between projected vertices (lens distortion
//! bends the true image of a long edge slightly); edges with an end behind the camera are
//! skipped; triangulated faces show their diagonals. Large models are drawn edge by edge every
//! frame (fine for thousands of edges).

use eframe::egui::{self, Color32};
use photomontage::scene::{LengthUnit, UpAxis};
use photomontage::site::models::{ModelEdges, model_edges, new_model_entry, wireframe_px};
use photomontage::site::render::{SiteWarning, site_camera};
use photomontage::site::{CadModel, SiteDocument};
use std::collections::HashMap;

use crate::commands::Command;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// The length units the importer reads (`photomontage::scene::LengthUnit`), with the site file
/// spelling of `[[models]] units`.
pub const UNITS: [(&str, LengthUnit); 5] = [
    ("m", LengthUnit::Metre),
    ("cm", LengthUnit::Centimetre),
    ("mm", LengthUnit::Millimetre),
    ("in", LengthUnit::Inch),
    ("ft", LengthUnit::Foot),
];

/// The up axes the importer knows (`photomontage::scene::UpAxis`), with the site file spelling of
/// `[[models]] up_axis`.
pub const UP_AXES: [(&str, UpAxis); 2] = [("z", UpAxis::Z), ("y", UpAxis::Y)];

fn unit_label(unit: &str) -> String {
    UNITS.iter().find(|(u, _)| *u == unit).map_or_else(
        || format!("{unit} (unknown)"),
        |(u, l)| format!("{u} ({} m)", l.metres_per_unit()),
    )
}

fn axis_label(axis: &str) -> String {
    match UP_AXES.iter().find(|(a, _)| a.eq_ignore_ascii_case(axis)) {
        Some((a, UpAxis::Z)) => format!("{} up (CAD, DXF)", a.to_uppercase()),
        Some((a, UpAxis::Y)) => format!("{} up (glTF)", a.to_uppercase()),
        None => format!("{axis} (unknown)"),
    }
}

/// A combo box choosing one of `options` (site file spellings) for `value`; true when changed.
fn choice_ui(
    ui: &mut egui::Ui,
    name: &str,
    value: &mut String,
    options: &[&str],
    label: fn(&str) -> String,
) -> bool {
    let before = value.clone();
    let r = egui::ComboBox::from_id_salt(name)
        .selected_text(label(value))
        .show_ui(ui, |ui| {
            for o in options {
                ui.selectable_value(value, (*o).to_owned(), label(o));
            }
        });
    name_widget(ui, &r.response, name);
    *value != before
}

/// Cache of imported model edges and the overlay switch.
#[derive(Debug, Default)]
pub struct ModelsPanel {
    /// Draw the wireframe overlay.
    pub show_wireframe: bool,
    /// Model file path typed by the user (the fallback of File → Import model…).
    pub model_path: String,
    /// Units of the next model added (site spelling, [`UNITS`]); `None`: metres.
    pub new_units: Option<String>,
    /// Up axis of the next model added ([`UP_AXES`]); `None`: the format's convention (Y for
    /// glTF, Z otherwise).
    pub new_up_axis: Option<String>,
    /// Per model id: the (file, units, up axis) it was imported with and the result (errors are
    /// cached too, so a broken file is not re-read every frame).
    cache: HashMap<String, (CacheKey, Result<ModelEdges, String>)>,
}

/// What a model's import depends on: its file, units and up axis.
type CacheKey = (String, String, String);

fn cache_key(m: &CadModel) -> CacheKey {
    (m.file.clone(), m.units.to_string(), m.up_axis.to_string())
}

impl ModelsPanel {
    /// The model's edges, imported again when its file, units or up axis changed.
    fn edges(&mut self, doc: &SiteDocument, model: &CadModel) -> &Result<ModelEdges, String> {
        let key = cache_key(model);
        let stale = self.cache.get(&model.id).is_none_or(|(k, _)| *k != key);
        if stale {
            let loaded = model_edges(doc, model).map_err(|e| e.to_string());
            self.cache.insert(model.id.clone(), (key.clone(), loaded));
        }
        &self
            .cache
            .entry(model.id.clone())
            .or_insert_with(|| (key, Err("not loaded".into())))
            .1
    }

    /// The importer's warnings for model `model_id` as the site has it now (e.g. "model `x` is
    /// 12000 m across: check its units"), importing it if needed.
    ///
    /// # Errors
    /// A readable message when the model is unknown or cannot be imported.
    pub fn model_warnings(
        &mut self,
        doc: &SiteDocument,
        model_id: &str,
    ) -> Result<Vec<SiteWarning>, String> {
        let model = doc
            .site
            .models
            .iter()
            .find(|m| m.id == model_id)
            .ok_or_else(|| format!("no model {model_id}"))?;
        self.edges(doc, model)
            .as_ref()
            .map(|e| e.warnings.clone())
            .map_err(Clone::clone)
    }

    /// The projected wireframe (pixel segments) of model `model_id` in photo `photo_id`.
    ///
    /// # Errors
    /// A readable message when the model is unknown or cannot be imported, or the photo is not
    /// solved.
    pub fn wireframe_px(
        &mut self,
        doc: &SiteDocument,
        photo_id: &str,
        model_id: &str,
    ) -> Result<Vec<[[f64; 2]; 2]>, String> {
        let model = doc
            .site
            .models
            .iter()
            .find(|m| m.id == model_id)
            .ok_or_else(|| format!("no model {model_id}"))?;
        let camera = site_camera(doc, photo_id).map_err(|e| e.to_string())?;
        let edges = self.edges(doc, model).as_ref().map_err(Clone::clone)?;
        Ok(wireframe_px(&camera, edges, &model.placement))
    }
}

impl crate::Studio {
    /// The Models panel (wireframe cache and switch).
    pub fn models_panel_mut(&mut self) -> &mut ModelsPanel {
        &mut self.models
    }

    /// The projected wireframe of a model in a photo (what the overlay draws).
    ///
    /// # Errors
    /// As [`ModelsPanel::wireframe_px`]; also when no site is open.
    pub fn model_wireframe_px(
        &mut self,
        photo_id: &str,
        model_id: &str,
    ) -> Result<Vec<[[f64; 2]; 2]>, String> {
        let doc = self.doc.as_ref().ok_or("no site open")?;
        self.models.wireframe_px(doc, photo_id, model_id)
    }

    /// Adds the CAD model file `path` to the site (one undoable edit) after checking that it
    /// imports; errors become messages and change nothing.
    pub fn import_model(&mut self, path: &std::path::Path) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let model = new_model_entry(
            doc,
            path,
            self.models
                .new_units
                .as_deref()
                .and_then(|u| u.parse().ok()),
            self.models
                .new_up_axis
                .as_deref()
                .and_then(|a| a.parse().ok()),
        );
        match model_edges(doc, &model).map_err(|e| e.to_string()) {
            Ok(edges) => {
                let text = format!(
                    "added model {} from {} in {}, {} (placed at the control points' \
                     centroid; move it in the Models tab)",
                    model.id,
                    path.display(),
                    unit_label(model.units.as_str()),
                    axis_label(model.up_axis.as_str())
                );
                let warnings = edges.warnings.clone();
                self.models
                    .cache
                    .insert(model.id.clone(), (cache_key(&model), Ok(edges)));
                self.models.show_wireframe = true;
                self.apply(Command::PutModel { model, at: None }, None);
                self.say(text, false);
                for w in warnings {
                    // The scale warning is red: the model is almost certainly in the wrong unit.
                    let absurd = matches!(w, SiteWarning::ModelScale { .. });
                    self.say(format!("warning: {w}"), absurd);
                }
            }
            Err(e) => self.say(format!("cannot import {}: {e}", path.display()), true),
        }
    }

    pub(crate) fn paint_wireframes(
        &mut self,
        painter: &egui::Painter,
        t: &crate::viewport::ViewTransform,
        photo_id: &str,
    ) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        if !self.models.show_wireframe {
            return;
        }
        let stroke = egui::Stroke::new(1.5, Color32::from_rgb(0, 255, 120));
        for m in doc.site.models.iter().filter(|m| m.visible) {
            if let Ok(segments) = self.models.wireframe_px(doc, photo_id, &m.id) {
                for [a, b] in segments {
                    painter.line_segment([t.screen_from_photo(a), t.screen_from_photo(b)], stroke);
                }
            }
        }
    }
}

impl Panel for ModelsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        let r = ui.checkbox(&mut self.show_wireframe, "wireframe overlay");
        name_widget(ui, &r, "wireframe overlay");
        let mut add = false;
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.model_path)
                    .hint_text("model file (.obj, .gltf, .glb, .dxf)")
                    .desired_width(260.0),
            );
            name_widget(ui, &r, "model path");
            add = ui.button("Add model").clicked();
        });
        ui.horizontal(|ui| {
            ui.label("added in");
            let mut units = self.new_units.clone().unwrap_or_else(|| "m".into());
            let names: Vec<&str> = UNITS.iter().map(|(u, _)| *u).collect();
            if choice_ui(ui, "new model units", &mut units, &names, unit_label) {
                self.new_units = Some(units);
            }
            let mut axis = self.new_up_axis.clone().unwrap_or_else(|| "auto".into());
            let axes = ["auto", "z", "y"];
            let label = |a: &str| {
                if a == "auto" {
                    "up axis of the format".to_string()
                } else {
                    axis_label(a)
                }
            };
            if choice_ui(ui, "new model up axis", &mut axis, &axes, label) {
                self.new_up_axis = (axis != "auto").then_some(axis);
            }
        });
        if add && !self.model_path.trim().is_empty() {
            let path = std::path::PathBuf::from(self.model_path.trim());
            actions.push(Action::ImportModel(path));
        }
        let Some(doc) = ctx.doc else {
            return actions;
        };
        if doc.site.models.is_empty() {
            ui.label("the site has no [[models]]");
            return actions;
        }
        let photo = ctx.current_photo.unwrap_or_default();
        let mut commands = Vec::new();
        let warn = crate::widgets::WARNING;
        for m in &doc.site.models {
            ui.separator();
            ui.strong(format!("{} ({})", m.id, m.file));
            ui.horizontal(|ui| {
                let mut changed = m.clone();
                let names: Vec<&str> = UNITS.iter().map(|(u, _)| *u).collect();
                let mut units = m.units.to_string();
                let a = choice_ui(
                    ui,
                    &format!("{} units", m.id),
                    &mut units,
                    &names,
                    unit_label,
                );
                let axes: Vec<&str> = UP_AXES.iter().map(|(a, _)| *a).collect();
                let mut axis = m.up_axis.to_string();
                let b = choice_ui(
                    ui,
                    &format!("{} up axis", m.id),
                    &mut axis,
                    &axes,
                    axis_label,
                );
                changed.units = units.parse().unwrap_or(m.units);
                changed.up_axis = axis.parse().unwrap_or(m.up_axis);
                if a || b {
                    commands.push((
                        Command::PutModel {
                            model: changed,
                            at: None,
                        },
                        None,
                    ));
                }
            });
            match self.model_warnings(doc, &m.id) {
                Ok(warnings) => {
                    for w in warnings {
                        ui.colored_label(warn, format!("importer: {w}"));
                    }
                }
                Err(e) => {
                    ui.colored_label(warn, e);
                }
            }
            if let Err(e) = self.wireframe_px(doc, photo, &m.id)
                && self.show_wireframe
            {
                ui.colored_label(warn, e);
            }
            let mut p = m.placement.clone();
            let mut changed = false;
            ui.horizontal(|ui| {
                for (k, axis) in ["E", "N", "H"].iter().enumerate() {
                    ui.label(*axis);
                    let r = ui.add(egui::DragValue::new(&mut p.translation[k]).speed(0.05));
                    name_widget(ui, &r, &format!("{} {axis}", m.id));
                    changed |= r.changed();
                }
            });
            ui.horizontal(|ui| {
                ui.label("rotation Z °");
                let r = ui.add(egui::DragValue::new(&mut p.rotation_z_deg).speed(0.1));
                name_widget(ui, &r, &format!("{} rotation", m.id));
                changed |= r.changed();
                ui.label("scale");
                let r = ui.add(
                    egui::DragValue::new(&mut p.scale)
                        .speed(0.001)
                        .range(1e-6..=1e6),
                );
                name_widget(ui, &r, &format!("{} scale", m.id));
                changed |= r.changed();
            });
            if changed {
                commands.push((
                    Command::SetModelPlacement {
                        model: m.id.clone(),
                        placement: p,
                    },
                    Some(format!("placement {}", m.id)),
                ));
            }
        }
        actions.extend(
            commands
                .into_iter()
                .map(|(command, merge_key)| Action::Edit {
                    command: Box::new(command),
                    merge_key,
                }),
        );
        actions
    }
}
