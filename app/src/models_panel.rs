//! The studio's Models panel: the site's `[[models]]` with numeric placement (translation,
//! rotation about Z, scale) edited through the one command path
//! ([`crate::commands::Command::SetModelPlacement`], so undo/redo and autosave see it), and a
//! wireframe overlay of each visible model's triangle edges projected with the current photo's
//! solved camera (`photomontage::camera::Camera::project`): the AVR1 "wireline" check of a
//! verified view (Landscape Institute TGN 06/19, AVR levels).
//!
//! The model is loaded through the renderer's own importer (`site::render::site_scene` on a
//! copy of the site holding only that model at the identity placement), cached per model file,
//! and placed here exactly as the importer places it: scale, then rotation about world Z, then
//! translation.
//!
//! **Import model** (typed path or File → Import model…) adds a `[[models]]` entry as one
//! undoable edit ([`crate::commands::Command::PutModel`]) after importing it once to check that it
//! reads: id from the file name, path relative to the site file when it lies in the site's
//! folder, units metres, up axis Y for glTF (its convention) and Z otherwise, placed at the
//! centroid of the control points so that it lands in the surveyed area.
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
use photomontage::site::render::{SiteWarning, site_camera, site_scene};
use photomontage::site::{CadModel, ModelUnits, ModelUpAxis, Placement, SiteDocument};
use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::commands::Command;

/// A model's edges in its own frame after unit and up-axis conversion (identity placement).
#[derive(Debug, Clone)]
struct LocalEdges {
    edges_m: Vec<[[f64; 3]; 2]>,
    /// The importer's warnings for the model (an absurd extent after the unit conversion,
    /// `SiteWarning::ModelScale`, among them).
    warnings: Vec<SiteWarning>,
}

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
    crate::points::name_widget(ui, &r.response, name);
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
    cache: HashMap<String, (CacheKey, Result<LocalEdges, String>)>,
}

/// What a model's import depends on: its file, units and up axis.
type CacheKey = (String, String, String);

fn cache_key(m: &CadModel) -> CacheKey {
    (m.file.clone(), m.units.to_string(), m.up_axis.to_string())
}

/// World position of a model-frame point under `placement` (scale, rotation about Z,
/// translation: the importer's order).
#[must_use]
pub fn place(p_m: [f64; 3], placement: &Placement) -> [f64; 3] {
    let (sin, cos) = placement.rotation_z_deg.to_radians().sin_cos();
    let [x, y, z] = p_m.map(|c| c * placement.scale);
    let [tx, ty, tz] = placement.translation;
    [cos * x - sin * y + tx, sin * x + cos * y + ty, z + tz]
}

/// The `[[models]]` entry that importing the file `path` into `doc` adds (see the module doc),
/// with units and up axis as chosen (`None`: metres, the format's convention).
#[must_use]
pub fn model_entry_as(
    doc: &SiteDocument,
    path: &Path,
    units: Option<&str>,
    up_axis: Option<&str>,
) -> CadModel {
    let mut m = model_entry(doc, path);
    if let Some(u) = units.and_then(|u| u.parse().ok()) {
        m.units = u;
    }
    if let Some(a) = up_axis.and_then(|a| a.parse().ok()) {
        m.up_axis = a;
    }
    m
}

/// The `[[models]]` entry that importing the file `path` into `doc` adds (see the module doc).
#[must_use]
pub fn model_entry(doc: &SiteDocument, path: &Path) -> CadModel {
    let stem: String = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = if stem.is_empty() {
        "model".into()
    } else {
        stem
    };
    let taken = |id: &str| doc.site.models.iter().any(|m| m.id == id);
    let id = (1..)
        .map(|n| {
            if n == 1 {
                stem.clone()
            } else {
                format!("{stem}_{n}")
            }
        })
        .find(|id| !taken(id))
        .unwrap_or(stem);
    let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let file = std::fs::canonicalize(doc.base_dir())
        .ok()
        .and_then(|base| absolute.strip_prefix(base).ok().map(Path::to_path_buf))
        .unwrap_or(absolute);
    let gltf = path.extension().is_some_and(|e| {
        let e = e.to_string_lossy().to_ascii_lowercase();
        e == "gltf" || e == "glb"
    });
    let points = &doc.site.control_points;
    let mut centroid = [0.0; 3];
    if !points.is_empty() {
        for c in points {
            for k in 0..3 {
                centroid[k] += c.xyz[k] / points.len() as f64;
            }
        }
    }
    CadModel {
        id,
        file: file.to_string_lossy().into_owned(),
        units: ModelUnits::Metre,
        up_axis: if gltf { ModelUpAxis::Y } else { ModelUpAxis::Z },
        placement: Placement {
            translation: centroid,
            ..Placement::default()
        },
        visible: true,
    }
}

fn load_edges(doc: &SiteDocument, model: &CadModel) -> Result<LocalEdges, String> {
    let mut one = doc.clone();
    one.site.polygons.clear();
    let mut m = model.clone();
    m.placement = Placement::default();
    m.visible = true;
    one.site.models = vec![m];
    let scene = site_scene(&one).map_err(|e| e.to_string())?;
    let key_of = |a: &[f64; 3]| a.map(f64::to_bits);
    let mut seen = HashSet::new();
    let mut edges_m = Vec::new();
    for t in scene.scene.triangles() {
        let v = t.vertices_in_world_m.map(|p| [p.x, p.y, p.z]);
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            let (ka, kb) = (key_of(&a), key_of(&b));
            let k = if ka < kb { (ka, kb) } else { (kb, ka) };
            if seen.insert(k) {
                edges_m.push([a, b]);
            }
        }
    }
    Ok(LocalEdges {
        edges_m,
        warnings: scene.warnings,
    })
}

impl ModelsPanel {
    /// The model's edges, imported again when its file, units or up axis changed.
    fn edges(&mut self, doc: &SiteDocument, model: &CadModel) -> &Result<LocalEdges, String> {
        let key = cache_key(model);
        let stale = self.cache.get(&model.id).is_none_or(|(k, _)| *k != key);
        if stale {
            let loaded = load_edges(doc, model);
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
        Ok(edges
            .edges_m
            .iter()
            .filter_map(|[a, b]| {
                let pa = camera.project(&place(*a, &model.placement).into())?;
                let pb = camera.project(&place(*b, &model.placement).into())?;
                Some([[pa.x, pa.y], [pb.x, pb.y]])
            })
            .collect())
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
    pub fn import_model(&mut self, path: &Path) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let model = model_entry_as(
            doc,
            path,
            self.models.new_units.as_deref(),
            self.models.new_up_axis.as_deref(),
        );
        match load_edges(doc, &model) {
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

    pub(crate) fn models_tab_ui(&mut self, ui: &mut egui::Ui) {
        let r = ui.checkbox(&mut self.models.show_wireframe, "wireframe overlay");
        crate::points::name_widget(ui, &r, "wireframe overlay");
        let mut add = false;
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.models.model_path)
                    .hint_text("model file (.obj, .gltf, .glb, .dxf)")
                    .desired_width(260.0),
            );
            crate::points::name_widget(ui, &r, "model path");
            add = ui.button("Add model").clicked();
        });
        ui.horizontal(|ui| {
            ui.label("added in");
            let mut units = self.models.new_units.clone().unwrap_or_else(|| "m".into());
            let names: Vec<&str> = UNITS.iter().map(|(u, _)| *u).collect();
            if choice_ui(ui, "new model units", &mut units, &names, unit_label) {
                self.models.new_units = Some(units);
            }
            let mut axis = self
                .models
                .new_up_axis
                .clone()
                .unwrap_or_else(|| "auto".into());
            let axes = ["auto", "z", "y"];
            let label = |a: &str| {
                if a == "auto" {
                    "up axis of the format".to_string()
                } else {
                    axis_label(a)
                }
            };
            if choice_ui(ui, "new model up axis", &mut axis, &axes, label) {
                self.models.new_up_axis = (axis != "auto").then_some(axis);
            }
        });
        if add && !self.models.model_path.trim().is_empty() {
            let path = std::path::PathBuf::from(self.models.model_path.trim());
            self.import_model(&path);
        }
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        if doc.site.models.is_empty() {
            ui.label("the site has no [[models]]");
            return;
        }
        let photo = self.current_photo.clone().unwrap_or_default();
        let mut commands = Vec::new();
        let warn = Color32::from_rgb(230, 160, 40);
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
            match self.models.model_warnings(doc, &m.id) {
                Ok(warnings) => {
                    for w in warnings {
                        ui.colored_label(warn, format!("importer: {w}"));
                    }
                }
                Err(e) => {
                    ui.colored_label(warn, e);
                }
            }
            if let Err(e) = self.models.wireframe_px(doc, &photo, &m.id)
                && self.models.show_wireframe
            {
                ui.colored_label(warn, e);
            }
            let mut p = m.placement.clone();
            let mut changed = false;
            ui.horizontal(|ui| {
                for (k, axis) in ["E", "N", "H"].iter().enumerate() {
                    ui.label(*axis);
                    let r = ui.add(egui::DragValue::new(&mut p.translation[k]).speed(0.05));
                    crate::points::name_widget(ui, &r, &format!("{} {axis}", m.id));
                    changed |= r.changed();
                }
            });
            ui.horizontal(|ui| {
                ui.label("rotation Z °");
                let r = ui.add(egui::DragValue::new(&mut p.rotation_z_deg).speed(0.1));
                crate::points::name_widget(ui, &r, &format!("{} rotation", m.id));
                changed |= r.changed();
                ui.label("scale");
                let r = ui.add(
                    egui::DragValue::new(&mut p.scale)
                        .speed(0.001)
                        .range(1e-6..=1e6),
                );
                crate::points::name_widget(ui, &r, &format!("{} scale", m.id));
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
        self.pending.extend(commands);
    }
}
