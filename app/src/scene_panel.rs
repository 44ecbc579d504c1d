//! The studio's Scene panel (Durisch 1992 §4.1, scene geometry): spatial intersection of a
//! point observed in two or more solved photos (`photomontage::photogrammetry::intersect`,
//! least-squares rays with σ XYZ) stored as a tie point, and scene polygons built by picking
//! their vertex points in order (from the list here or by clicking them on the photo,
//! [`crate::scene_pick`]) with a material from the site's library. Both edits go through
//! the one command path ([`crate::commands::Command::SetTiePoints`],
//! [`crate::commands::Command::PutPolygon`]).
//!
//! # Known limitations
//! The intersection takes the stored cameras as error-free (as the library does); the bundle
//! adjustment of a Solve re-estimates tie points jointly and replaces these values. The vertices
//! picked so far are view state, not an edit: only closing the polygon is undoable.

use eframe::egui::{self, Color32};
use photomontage::camera::Camera;
use photomontage::photogrammetry::{ImageObservation, Intersection, intersect};
use photomontage::site::render::site_material_library;
use photomontage::site::{Observation, Polygon, Site, SiteDocument, TiePoint, stored_camera};

use crate::commands::Command;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// The (camera, observation) ray of `o`, when its photo is solved.
fn observation_ray(site: &Site, o: &Observation) -> Option<(Camera, ImageObservation)> {
    let camera = stored_camera(site, &o.photo)?;
    Some((
        camera,
        ImageObservation {
            point_id: o.point.clone(),
            pixel: [o.x_px, o.y_px].into(),
            sigma_px: o.sigma_px,
        },
    ))
}

/// Material offered when the site names no material library.
pub const DEFAULT_MATERIAL: &str = "default";

/// Intersects `point` from its observations in the solved photos of `site`.
///
/// # Errors
/// A readable message: fewer than two solved photos observe it, or the intersection failed.
pub fn intersect_point(site: &Site, point: &str) -> Result<Intersection, String> {
    let rays: Vec<(Camera, ImageObservation)> = site
        .observations
        .iter()
        .filter(|o| o.point == point)
        .filter_map(|o| observation_ray(site, o))
        .collect();
    if rays.len() < 2 {
        return Err(format!(
            "{point} is observed in {} solved photo(s); intersection needs 2 or more",
            rays.len()
        ));
    }
    intersect(&rays).map_err(|e| format!("intersecting {point}: {e}"))
}

/// State of the Scene panel: the polygon being built.
#[derive(Debug, Default)]
pub struct ScenePanel {
    /// Id of the polygon being built.
    pub polygon_id: String,
    /// Vertex point ids picked so far, in order.
    pub vertices: Vec<String>,
    /// Material chosen.
    pub material: String,
    /// Photo whose pixels colour the polygon (image attribute); the current photo when empty.
    pub image: Option<String>,
}

/// Materials to offer: the site library's, or [`DEFAULT_MATERIAL`] and those the polygons use.
#[must_use]
pub fn material_choices(doc: &SiteDocument) -> Vec<String> {
    let mut names: Vec<String> = match site_material_library(doc) {
        Ok(Some(lib)) => lib.materials.iter().map(|m| m.name.clone()).collect(),
        _ => vec![DEFAULT_MATERIAL.to_owned()],
    };
    for p in &doc.site.polygons {
        if !names.contains(&p.material) {
            names.push(p.material.clone());
        }
    }
    names
}

impl crate::Studio {
    /// The Scene panel (polygon under construction).
    pub fn scene_panel_mut(&mut self) -> &mut ScenePanel {
        &mut self.scene
    }

    /// Intersects `point` from the solved photos and stores it as a tie point with its σ
    /// (one undoable edit). Errors become messages.
    pub fn intersect_tie_point(&mut self, point: &str) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        if doc.site.control_points.iter().any(|c| c.id == point) {
            self.say(
                format!("{point} is a control point; intersect tie points only"),
                true,
            );
            return;
        }
        match intersect_point(&doc.site, point) {
            Ok(x) => {
                let mut ties = doc.site.tie_points.clone();
                let tie = TiePoint {
                    id: point.to_owned(),
                    xyz: x.point_in_world.coords.into(),
                    sigma_m: x.sigma_m,
                };
                match ties.iter_mut().find(|t| t.id == point) {
                    Some(t) => *t = tie,
                    None => ties.push(tie),
                }
                let s = x.sigma_m;
                let text = format!(
                    "{point}: intersected, σ {:.3} {:.3} {:.3} m, angle {:.1}°, RMS {:.2} px",
                    s[0], s[1], s[2], x.max_intersection_angle_deg, x.rms_px
                );
                self.apply(Command::SetTiePoints(ties), None);
                self.say(text, false);
                for w in x.warnings {
                    self.say(format!("{point}: {w}"), false);
                }
            }
            Err(e) => self.say(e, true),
        }
    }

    /// Creates the polygon of the picked vertices (one undoable edit) and clears the picks.
    pub fn create_polygon(&mut self) {
        let id = self.scene.polygon_id.trim().to_owned();
        if id.is_empty() || self.scene.vertices.len() < 3 {
            self.say("a polygon needs an id and at least 3 vertices", true);
            return;
        }
        let material = if self.scene.material.is_empty() {
            DEFAULT_MATERIAL.to_owned()
        } else {
            self.scene.material.clone()
        };
        let polygon = Polygon {
            id: id.clone(),
            vertices: std::mem::take(&mut self.scene.vertices),
            material,
            image: self
                .scene
                .image
                .clone()
                .or_else(|| self.current_photo.clone()),
        };
        self.apply(Command::PutPolygon { polygon, at: None }, None);
        self.say(format!("polygon {id} created"), false);
    }
}

impl Panel for ScenePanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let Some(doc) = ctx.doc else {
            return Vec::new();
        };
        let ties: Vec<String> = {
            let mut t: Vec<String> = doc
                .site
                .observations
                .iter()
                .map(|o| o.point.clone())
                .filter(|p| !doc.site.control_points.iter().any(|c| c.id == *p))
                .collect();
            t.sort_unstable();
            t.dedup();
            t
        };
        let points: Vec<String> = doc
            .site
            .control_points
            .iter()
            .map(|c| c.id.clone())
            .chain(doc.site.tie_points.iter().map(|t| t.id.clone()))
            .collect();
        let materials = material_choices(doc);
        ui.strong("Intersect a tie point (observed in 2 or more solved photos)");
        let mut intersect_id = None;
        ui.horizontal_wrapped(|ui| {
            for t in &ties {
                let r = ui.button(t);
                name_widget(ui, &r, &format!("intersect {t}"));
                if r.clicked() {
                    intersect_id = Some(t.clone());
                }
            }
        });
        ui.separator();
        ui.strong("Build a polygon: pick its vertices in order");
        ui.label("click the points on the photo (or in this list); Enter closes the polygon");
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.polygon_id)
                    .hint_text("polygon id")
                    .desired_width(120.0),
            );
            name_widget(ui, &r, "polygon id");
            let selected = if self.material.is_empty() {
                "material".to_owned()
            } else {
                self.material.clone()
            };
            egui::ComboBox::from_label("material")
                .selected_text(selected)
                .show_ui(ui, |ui| {
                    for m in &materials {
                        ui.selectable_value(&mut self.material, m.clone(), m);
                    }
                });
        });
        ui.horizontal_wrapped(|ui| {
            for p in &points {
                let r = ui.small_button(p);
                name_widget(ui, &r, &format!("vertex {p}"));
                if r.clicked() {
                    self.vertices.push(p.clone());
                }
            }
        });
        ui.label(format!("vertices: {}", self.vertices.join(", ")));
        let mut create = false;
        ui.horizontal(|ui| {
            if ui.button("Remove last vertex").clicked() {
                self.vertices.pop();
            }
            create = ui.button("Create polygon").clicked();
        });
        ui.separator();
        for p in &doc.site.polygons {
            ui.colored_label(
                Color32::LIGHT_GRAY,
                format!("{}: {} ({})", p.id, p.vertices.join(" "), p.material),
            );
        }
        let mut actions: Vec<Action> = intersect_id
            .map(Action::IntersectTiePoint)
            .into_iter()
            .collect();
        if create {
            actions.push(Action::CreatePolygon);
        }
        actions
    }
}
