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
//! # Known limitations
//! Edges are drawn as straight screen segments between projected vertices (lens distortion
//! bends the true image of a long edge slightly); edges with an end behind the camera are
//! skipped; triangulated faces show their diagonals. Large models are drawn edge by edge every
//! frame (fine for thousands of edges).

use eframe::egui::{self, Color32};
use photomontage::site::render::{site_camera, site_scene};
use photomontage::site::{CadModel, Placement, SiteDocument};
use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::commands::Command;

/// A model's edges in its own frame after unit and up-axis conversion (identity placement).
#[derive(Debug, Clone)]
struct LocalEdges {
    key: (String, String, String),
    edges_m: Vec<[[f64; 3]; 2]>,
}

/// Cache of imported model edges and the overlay switch.
#[derive(Debug, Default)]
pub struct ModelsPanel {
    /// Draw the wireframe overlay.
    pub show_wireframe: bool,
    /// Model file path typed by the user (the fallback of File → Import model…).
    pub model_path: String,
    cache: HashMap<String, Result<LocalEdges, String>>,
}

fn cache_key(m: &CadModel) -> (String, String, String) {
    (m.file.clone(), m.units.clone(), m.up_axis.clone())
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
        units: "m".into(),
        up_axis: if gltf { "y" } else { "z" }.into(),
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
        key: cache_key(model),
        edges_m,
    })
}

impl ModelsPanel {
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
        let stale = !matches!(self.cache.get(model_id), Some(Ok(e)) if e.key == cache_key(model));
        if stale {
            self.cache
                .insert(model_id.to_owned(), load_edges(doc, model));
        }
        let edges = match self.cache.get(model_id) {
            Some(Ok(e)) => e,
            Some(Err(e)) => return Err(e.clone()),
            None => return Err(format!("model {model_id} not loaded")),
        };
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
        let model = model_entry(doc, path);
        match load_edges(doc, &model) {
            Ok(edges) => {
                let text = format!(
                    "added model {} from {} (placed at the control points' centroid; move it \
                     in the Models tab)",
                    model.id,
                    path.display()
                );
                self.models.cache.insert(model.id.clone(), Ok(edges));
                self.models.show_wireframe = true;
                self.apply(Command::PutModel { model, at: None }, None);
                self.say(text, false);
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
        for m in &doc.site.models {
            ui.separator();
            ui.strong(format!("{} ({}, {})", m.id, m.file, m.units));
            if let Err(e) = self.models.wireframe_px(doc, &photo, &m.id)
                && self.models.show_wireframe
            {
                ui.colored_label(Color32::from_rgb(230, 160, 40), e);
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
