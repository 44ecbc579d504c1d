//! The scene of a site (Durisch 1992 §4.1 natural polygons and §5 CAD objects): one natural
//! object per scene polygon and one artificial object per visible model, the one builder the
//! renderer, the fits and the studio share.
//!
//! # Known limitations
//! Polygons are single-sided triangles of their vertex points (no holes). CAD materials named in
//! the material library take the library's definition; the others keep their file's definition.

use std::collections::HashMap;

use nalgebra::Point3;
use serde::Serialize;

use super::render_error::{SiteRenderError, SiteWarning};
use super::{CadModel, SiteDocument};
use crate::scene::{
    ImportOptions, Material, MaterialLibrary, ObjectKind, Placement, Scene, SceneObject,
};

/// Diffuse reflectance of a polygon whose material is not in the library (or when the site has
/// no library): ρ_d = 0.5, mid-grey, [`Material::default`]. The name is kept so the warning and
/// the material list show what was meant.
pub const DEFAULT_POLYGON_ALBEDO: [f64; 3] = [0.5; 3];

/// A CAD model whose largest bounding-box side is above this gets a scale warning: 10 km, larger
/// than any single planned development (probably millimetres read as metres).
pub const SCALE_WARNING_MAX_EXTENT_M: f64 = 1e4;
/// A CAD model whose largest bounding-box side is below this gets a scale warning: 1 mm
/// (probably metres read as millimetres).
pub const SCALE_WARNING_MIN_EXTENT_M: f64 = 1e-3;

/// Which site entity a scene object came from (for the object-id output layer).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", content = "id", rename_all = "snake_case")]
pub enum ObjectSource {
    /// A scene polygon (natural), by id.
    Polygon(String),
    /// A CAD model (artificial), by id.
    Model(String),
}

impl ObjectSource {
    /// `polygon:ID` or `model:ID`.
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Self::Polygon(id) => format!("polygon:{id}"),
            Self::Model(id) => format!("model:{id}"),
        }
    }
}

/// The scene of a site.
#[derive(Debug, Clone)]
pub struct SiteScene {
    /// Natural polygons and artificial models.
    pub scene: Scene,
    /// For every scene object (by [`crate::scene::ObjectId`] index), where it came from.
    pub object_sources: Vec<ObjectSource>,
    /// Problems that did not stop the build.
    pub warnings: Vec<SiteWarning>,
}

fn point_table(doc: &SiteDocument) -> HashMap<&str, [f64; 3]> {
    let mut points: HashMap<&str, [f64; 3]> = doc
        .site
        .tie_points
        .iter()
        .map(|t| (t.id.as_str(), t.xyz))
        .collect();
    // Control points win over tie points of the same id.
    for c in &doc.site.control_points {
        points.insert(c.id.as_str(), c.xyz);
    }
    points
}

fn import_options(model: &CadModel) -> ImportOptions {
    ImportOptions {
        unit: Some(model.units.length_unit()),
        up_axis: Some(model.up_axis.up_axis()),
        placement: Placement {
            translation_in_world_m: model.placement.translation,
            rotation_about_z_deg: model.placement.rotation_z_deg,
            scale: model.placement.scale,
        },
        // Small models only warn (SCALE_WARNING_MIN_EXTENT_M); beyond the importer's 100 km the
        // unit is certainly wrong and it is an error.
        min_extent_m: 0.0,
        ..ImportOptions::default()
    }
}

/// The material library of the site, if it names one.
///
/// # Errors
/// [`SiteRenderError::MaterialLibrary`] when it cannot be read or is invalid.
pub fn site_material_library(
    doc: &SiteDocument,
) -> Result<Option<MaterialLibrary>, SiteRenderError> {
    let Some(rel) = &doc.site.lighting.material_library else {
        return Ok(None);
    };
    let path = doc.resolve(rel);
    MaterialLibrary::load(&path)
        .map(Some)
        .map_err(|source| SiteRenderError::MaterialLibrary {
            path: path.display().to_string(),
            source,
        })
}

/// Builds the scene of a site: one natural object per polygon (triangulated, material from the
/// library, image attribute = the polygon's photo) and one artificial object per visible model.
///
/// # Errors
/// An unknown vertex id, a polygon that cannot be triangulated, an unreadable material library
/// or CAD file (no faces, non-finite vertices, a size above 100 km), a bad unit or up axis.
pub fn site_scene(doc: &SiteDocument) -> Result<SiteScene, SiteRenderError> {
    let library = site_material_library(doc)?;
    let points = point_table(doc);
    let mut scene = Scene::new();
    let mut object_sources = Vec::new();
    let mut warnings = Vec::new();
    let mut missing: Vec<(String, Vec<String>)> = Vec::new();
    for poly in &doc.site.polygons {
        let vertices = poly
            .vertices
            .iter()
            .map(|v| {
                points
                    .get(v.as_str())
                    .map(|&xyz| Point3::from(xyz))
                    .ok_or_else(|| SiteRenderError::UnknownPoint {
                        polygon: poly.id.clone(),
                        point: v.clone(),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let material = match library.as_ref().and_then(|l| l.get(&poly.material)) {
            Some(m) => m.clone(),
            None => {
                match missing.iter_mut().find(|(m, _)| *m == poly.material) {
                    Some((_, polys)) => polys.push(poly.id.clone()),
                    None => missing.push((poly.material.clone(), vec![poly.id.clone()])),
                }
                Material::diffuse(&poly.material, DEFAULT_POLYGON_ALBEDO)
            }
        };
        let material = scene.add_material(material)?;
        let object = scene.add_object(SceneObject {
            name: poly.id.clone(),
            kind: ObjectKind::Natural,
            image_attribute: poly.image.clone(),
        })?;
        object_sources.push(ObjectSource::Polygon(poly.id.clone()));
        scene
            .add_polygon(&vertices, material, object)
            .map_err(|source| SiteRenderError::Polygon {
                polygon: poly.id.clone(),
                source,
            })?;
    }
    warnings.extend(
        missing
            .into_iter()
            .map(|(material, polygons)| SiteWarning::MissingMaterial { material, polygons }),
    );
    for model in doc.site.models.iter().filter(|m| m.visible) {
        let options = import_options(model);
        let path = doc.resolve(&model.file);
        let imported =
            crate::scene::load_model(&path, &options).map_err(|source| SiteRenderError::Model {
                model: model.id.clone(),
                path: path.display().to_string(),
                source,
            })?;
        warnings.extend(imported.warnings.iter().map(|w| SiteWarning::Import {
            model: model.id.clone(),
            message: import_warning_text(w),
        }));
        let mut extent = [Point3::origin(); 2];
        let mut first = true;
        for p in imported.triangles_in_world_m.iter().flatten() {
            if first {
                extent = [*p, *p];
                first = false;
            }
            extent = [extent[0].inf(p), extent[1].sup(p)];
        }
        let extent_m = (extent[1] - extent[0]).max();
        if !(SCALE_WARNING_MIN_EXTENT_M..=SCALE_WARNING_MAX_EXTENT_M).contains(&extent_m) {
            warnings.push(SiteWarning::ModelScale {
                model: model.id.clone(),
                extent_m,
            });
        }
        scene.add_model(&imported, &model.id, ObjectKind::Artificial)?;
        object_sources.push(ObjectSource::Model(model.id.clone()));
    }
    if let Some(lib) = &library {
        scene.apply_material_library(lib);
    }
    Ok(SiteScene {
        scene,
        object_sources,
        warnings,
    })
}

fn import_warning_text(w: &crate::scene::ImportWarning) -> String {
    use crate::scene::ImportWarning as W;
    match w {
        W::MissingMaterialLibrary { name, reason } => {
            format!("material library `{name}` not read ({reason}); default material used")
        }
        W::FacesWithoutMaterial { triangle_count } => {
            format!("{triangle_count} triangles without a material get the default (ρ_d = 0.5)")
        }
        W::UnitAssumed { unit } => format!("no unit in the file; {unit:?} assumed"),
        W::PolygonsSkipped { count } => {
            format!("{count} degenerate polygons skipped")
        }
        W::IgnoredEntities { kind, count } => format!("{count} {kind} entities ignored"),
    }
}
