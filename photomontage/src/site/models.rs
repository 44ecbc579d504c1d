//! Placing CAD models in a site, as the studio's Models panel does it: the `[[models]]` entry an
//! import adds ([`new_model_entry`]), the placement transform ([`world_from_model`]: scale, then
//! rotation about world Z, then translation — the importer's order, `scene::import`), and a
//! model's triangle edges for a wireframe overlay ([`model_edges`], [`wireframe_px`]: the AVR1
//! "wireline" check of a verified view, LVMF SPG 2012 Appendix C, drawn without hidden-line
//! removal; `verified::wireline` is the one with it).
//!
//! The edges are those of the model as the renderer imports it (`site::render::site_scene` on a
//! copy of the site holding only that model, at the identity placement), so units, up axis and
//! the importer's warnings are exactly the renderer's; placing them afterwards lets a placement
//! edit redraw without re-reading the file.
//!
//! # Known limitations
//! Every distinct triangle edge is kept, so triangulated faces show their diagonals (the
//! wireline's feature edges leave them out). Edges are projected end to end: lens distortion
//! bends the true image of a long edge slightly, and an edge with an end behind the camera is
//! dropped rather than clipped.

use std::collections::HashSet;
use std::path::Path;

use nalgebra::Point3;

use super::render::{SiteRenderError, SiteWarning, site_scene};
use super::{CadModel, ModelUnits, ModelUpAxis, Placement, SiteDocument};
use crate::camera::Camera;

/// World position of a model-frame point (metres, after the unit and up-axis conversion) under
/// `placement`: scale, rotation about world Z (counter-clockwise seen from above), translation.
#[must_use]
pub fn world_from_model(point_in_model_m: [f64; 3], placement: &Placement) -> [f64; 3] {
    let (sin, cos) = placement.rotation_z_deg.to_radians().sin_cos();
    let [x, y, z] = point_in_model_m.map(|c| c * placement.scale);
    let [tx, ty, tz] = placement.translation;
    [cos * x - sin * y + tx, sin * x + cos * y + ty, z + tz]
}

/// The `[[models]]` entry that importing the file `path` into `doc` adds: id from the file
/// name (characters other than letters, digits and `-` become `_`; `_2`, `_3`, … when taken),
/// path relative to the site file when it lies in the site's folder, units as given (`None`:
/// metres), up axis as given (`None`: Y for glTF/GLB, its convention, Z otherwise), placed at
/// the centroid of the control points so that it lands in the surveyed area, visible.
#[must_use]
pub fn new_model_entry(
    doc: &SiteDocument,
    path: &Path,
    units: Option<ModelUnits>,
    up_axis: Option<ModelUpAxis>,
) -> CadModel {
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
    for c in points {
        for k in 0..3 {
            centroid[k] += c.xyz[k] / points.len() as f64;
        }
    }
    CadModel {
        id,
        file: file.to_string_lossy().into_owned(),
        units: units.unwrap_or_default(),
        up_axis: up_axis.unwrap_or(if gltf { ModelUpAxis::Y } else { ModelUpAxis::Z }),
        placement: Placement {
            translation: centroid,
            ..Placement::default()
        },
        visible: true,
    }
}

/// The distinct edges of `triangles` (end points joined by their exact `f64` coordinates, either
/// direction), in the order first met; degenerate edges (both ends equal) are left out.
#[must_use]
pub fn unique_edges<'a>(
    triangles: impl IntoIterator<Item = &'a [Point3<f64>; 3]>,
) -> Vec<[[f64; 3]; 2]> {
    // +0.0 and −0.0 are the same coordinate.
    let key = |a: &[f64; 3]| a.map(|c| (c + 0.0).to_bits());
    let mut seen = HashSet::new();
    let mut edges = Vec::new();
    for t in triangles {
        let v = t.map(|p| [p.x, p.y, p.z]);
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            let (ka, kb) = (key(&a), key(&b));
            if ka == kb {
                continue;
            }
            let k = if ka < kb { (ka, kb) } else { (kb, ka) };
            if seen.insert(k) {
                edges.push([a, b]);
            }
        }
    }
    edges
}

/// A model's edges in its own frame (metres, units and up axis converted, identity placement)
/// and the importer's warnings about it.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelEdges {
    /// Distinct triangle edges ([`unique_edges`]).
    pub edges_in_model_m: Vec<[[f64; 3]; 2]>,
    /// The importer's warnings (`SiteWarning::ModelScale` for an absurd size among them).
    pub warnings: Vec<SiteWarning>,
}

/// Imports `model` as the renderer does and returns its edges at the identity placement (see
/// the module doc). The site's polygons and other models are not read.
///
/// # Errors
/// [`SiteRenderError`] when the model cannot be imported (unreadable file, unknown units, …).
pub fn model_edges(doc: &SiteDocument, model: &CadModel) -> Result<ModelEdges, SiteRenderError> {
    let mut one = doc.clone();
    one.site.polygons.clear();
    one.site.models = vec![CadModel {
        placement: Placement::default(),
        visible: true,
        ..model.clone()
    }];
    let scene = site_scene(&one)?;
    Ok(ModelEdges {
        edges_in_model_m: unique_edges(
            scene
                .scene
                .triangles()
                .iter()
                .map(|t| &t.vertices_in_world_m),
        ),
        warnings: scene.warnings,
    })
}

/// `edges` placed by `placement` and projected into `camera`'s image: pixel segments (the
/// library's pixel-centre convention). Edges with an end behind the camera are left out.
#[must_use]
pub fn wireframe_px(
    camera: &Camera,
    edges: &ModelEdges,
    placement: &Placement,
) -> Vec<[[f64; 2]; 2]> {
    edges
        .edges_in_model_m
        .iter()
        .filter_map(|[a, b]| {
            let pa = camera.project(&world_from_model(*a, placement).into())?;
            let pb = camera.project(&world_from_model(*b, placement).into())?;
            Some([[pa.x, pa.y], [pb.x, pb.y]])
        })
        .collect()
}

#[cfg(test)]
#[path = "models_tests.rs"]
mod tests;
