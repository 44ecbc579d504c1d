//! The scene of a site (Durisch 1992 §4.1 natural polygons and §5 CAD objects): the natural
//! scene of [`crate::fit::natural_scene::natural_scene`] (the one builder and rule set the
//! renderer, the fits, the picker, the radiosity CLI and the studio share) plus what only the
//! renderer needs: one artificial object per visible model, the library's definitions of CAD
//! materials, model scale checks, and a refusal of polygons without coordinates.
//!
//! # Known limitations
//! Polygons are single-sided triangles of their vertex points (no holes). CAD materials named in
//! the material library take the library's definition; the others keep their file's definition.

use nalgebra::Point3;
use serde::Serialize;

use super::render_error::{SiteRenderError, SiteWarning};
use super::{CadModel, SiteDocument};
pub use crate::fit::natural_scene::DEFAULT_POLYGON_ALBEDO;
use crate::fit::natural_scene::{NaturalSceneError, natural_scene};
use crate::scene::{ImportOptions, MaterialLibrary, ObjectKind, Placement, Scene};

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
/// The site's `[[materials]]` overlay the file's entries (see
/// [`super::site_materials::overlay_site_materials`]); clamping warnings are dropped here, and
/// kept by [`site_material_library_with_warnings`].
pub fn site_material_library(
    doc: &SiteDocument,
) -> Result<Option<MaterialLibrary>, SiteRenderError> {
    site_material_library_with_warnings(doc).map(|(lib, _)| lib)
}

/// [`site_material_library`] with the warnings of the site materials (clamped colours and
/// reflectances).
///
/// # Errors
/// An unreadable or invalid library file; an unparsable colour or invalid site material.
pub fn site_material_library_with_warnings(
    doc: &SiteDocument,
) -> Result<(Option<MaterialLibrary>, Vec<SiteWarning>), SiteRenderError> {
    let file_library = match &doc.site.lighting.material_library {
        None => None,
        Some(rel) => {
            let path = doc.resolve(rel);
            Some(MaterialLibrary::load(&path).map_err(|source| {
                SiteRenderError::MaterialLibrary {
                    path: path.display().to_string(),
                    source,
                }
            })?)
        }
    };
    super::site_materials::overlay_site_materials(file_library, &doc.site.materials)
}

/// Builds the scene of a site: one natural object per polygon (triangulated, material from the
/// library, image attribute = the polygon's photo) and one artificial object per visible model.
///
/// # Errors
/// An unknown vertex id, a polygon that cannot be triangulated, an unreadable material library
/// or CAD file (no faces, non-finite vertices, a size above 100 km), a bad unit or up axis.
pub fn site_scene(doc: &SiteDocument) -> Result<SiteScene, SiteRenderError> {
    let (library, material_warnings) = site_material_library_with_warnings(doc)?;
    let natural = natural_scene(&doc.site, library.as_ref()).map_err(|e| match e {
        NaturalSceneError::Polygon { polygon, source } => {
            SiteRenderError::Polygon { polygon, source }
        }
        NaturalSceneError::Scene(source) => SiteRenderError::Scene(source),
    })?;
    // The renderer needs every polygon: one left out for a vertex without coordinates is an
    // error here (the fits and the picker go on without it).
    if let Some(s) = natural.skipped.first() {
        return Err(SiteRenderError::UnknownPoint {
            polygon: s.polygon.clone(),
            point: s.point.clone(),
        });
    }
    let mut scene = natural.scene;
    let mut object_sources: Vec<ObjectSource> = natural
        .polygon_of_object
        .iter()
        .map(|&k| ObjectSource::Polygon(doc.site.polygons[k].id.clone()))
        .collect();
    let mut warnings: Vec<SiteWarning> = natural
        .missing_materials
        .into_iter()
        .map(|(material, polygons)| SiteWarning::MissingMaterial { material, polygons })
        .collect();
    warnings.extend(material_warnings);
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
    warnings.extend(super::site_materials::unmatched_site_materials(
        &doc.site.materials,
        scene.materials(),
    ));
    // A design variant's materials come last (`site::variants`).
    if let Some(overrides) = super::variants::applied_variant_materials(doc) {
        scene.apply_material_library(&overrides);
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
