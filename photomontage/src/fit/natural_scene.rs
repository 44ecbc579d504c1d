//! The natural scene of a site (Durisch 1992 §4.1: the scene polygons approximating the
//! photographed surroundings), built by one function with one rule set for every caller: the
//! renderer ([`crate::site::site_scene::site_scene`] adds the CAD models to it), the fits and
//! the photo picker ([`super::pick`]), the radiosity CLI and the studio (through `site_scene`).
//!
//! Rules: one natural object per polygon, named by the polygon id, image attribute = the
//! polygon's photo; vertices from the control points, else the tie points (a control point wins
//! over a tie point of the same id); the polygon's material from the site's material library,
//! else a diffuse material of that name with ρ_d = [`DEFAULT_POLYGON_ALBEDO`] (reported in
//! [`NaturalScene::missing_materials`]); a polygon with a vertex that has no coordinates is left
//! out and reported in [`NaturalScene::skipped`] (the fits and the picker work on half-solved
//! sites; the renderer refuses such a site); a polygon that cannot be triangulated is an error.
//!
//! # Known limitations
//! Polygons are single-sided triangle fans of their vertex points (no holes), as
//! [`Scene::add_polygon`] triangulates them.

use std::collections::HashMap;

use nalgebra::Point3;

use crate::scene::{Material, MaterialLibrary, ObjectKind, Scene, SceneError, SceneObject};
use crate::site::Site;

/// Diffuse reflectance of a polygon whose material is not in the library (or when the site has
/// no library): ρ_d = 0.5, mid-grey, [`Material::default`]. The name is kept so the warning and
/// the material list show what was meant.
pub const DEFAULT_POLYGON_ALBEDO: [f64; 3] = [0.5; 3];

/// What can stop the natural scene from being built.
#[derive(Debug, thiserror::Error)]
pub enum NaturalSceneError {
    /// A polygon could not be added (degenerate, too few vertices).
    #[error("polygon `{polygon}`: {source}")]
    Polygon {
        /// The polygon's id.
        polygon: String,
        /// Why.
        source: SceneError,
    },
    /// The scene refused an object or material (too many).
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
}

/// A polygon left out because one of its vertices has no coordinates.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedPolygon {
    /// The polygon's id.
    pub polygon: String,
    /// The first vertex id without coordinates.
    pub point: String,
}

/// The natural scene and how it maps back to the site.
#[derive(Debug, Clone)]
pub struct NaturalScene {
    /// One natural object per polygon that could be built, in site order.
    pub scene: Scene,
    /// For every scene triangle, the index of its polygon in `site.polygons`.
    pub polygon_of_triangle: Vec<usize>,
    /// For every scene object, the index of its polygon in `site.polygons`.
    pub polygon_of_object: Vec<usize>,
    /// Polygons left out (a vertex without coordinates), in site order.
    pub skipped: Vec<SkippedPolygon>,
    /// Materials not in the library and the polygons naming them (first-seen order).
    pub missing_materials: Vec<(String, Vec<String>)>,
}

impl NaturalScene {
    /// The skipped polygons as sentences (the fits' and the picker's warnings).
    #[must_use]
    pub fn skipped_warnings(&self) -> Vec<String> {
        self.skipped
            .iter()
            .map(|s| {
                format!(
                    "polygon `{}` skipped: vertex `{}` has no coordinates yet (run `solve`)",
                    s.polygon, s.point
                )
            })
            .collect()
    }
}

/// Builds the natural scene of `site` by the rules of the module doc.
///
/// # Errors
/// [`NaturalSceneError::Polygon`] naming a polygon that cannot be triangulated.
pub fn natural_scene(
    site: &Site,
    library: Option<&MaterialLibrary>,
) -> Result<NaturalScene, NaturalSceneError> {
    let mut coords: HashMap<&str, [f64; 3]> = site
        .tie_points
        .iter()
        .map(|t| (t.id.as_str(), t.xyz))
        .collect();
    // Control points win over tie points of the same id.
    for c in &site.control_points {
        coords.insert(c.id.as_str(), c.xyz);
    }
    let mut out = NaturalScene {
        scene: Scene::new(),
        polygon_of_triangle: Vec::new(),
        polygon_of_object: Vec::new(),
        skipped: Vec::new(),
        missing_materials: Vec::new(),
    };
    for (index, poly) in site.polygons.iter().enumerate() {
        let vertices: Result<Vec<_>, &String> = poly
            .vertices
            .iter()
            .map(|v| coords.get(v.as_str()).map(|&p| Point3::from(p)).ok_or(v))
            .collect();
        let vertices = match vertices {
            Ok(v) => v,
            Err(point) => {
                out.skipped.push(SkippedPolygon {
                    polygon: poly.id.clone(),
                    point: point.clone(),
                });
                continue;
            }
        };
        let material = if let Some(m) = library.and_then(|l| l.get(&poly.material)) {
            m.clone()
        } else {
            match out
                .missing_materials
                .iter_mut()
                .find(|(m, _)| *m == poly.material)
            {
                Some((_, polys)) => polys.push(poly.id.clone()),
                None => out
                    .missing_materials
                    .push((poly.material.clone(), vec![poly.id.clone()])),
            }
            Material::diffuse(&poly.material, DEFAULT_POLYGON_ALBEDO)
        };
        let material = out.scene.add_material(material)?;
        let object = out.scene.add_object(SceneObject {
            name: poly.id.clone(),
            kind: ObjectKind::Natural,
            image_attribute: poly.image.clone(),
        })?;
        let added = out
            .scene
            .add_polygon(&vertices, material, object)
            .map_err(|source| NaturalSceneError::Polygon {
                polygon: poly.id.clone(),
                source,
            })?;
        out.polygon_of_object.push(index);
        out.polygon_of_triangle
            .extend(std::iter::repeat_n(index, added));
    }
    Ok(out)
}
