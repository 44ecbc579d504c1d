//! The scene: natural polygons approximating the photographed surroundings and artificial CAD
//! objects (the planned building), as triangles with materials (Durisch 1992 §4.1 "natural
//! environment description", §5 "artificial environment description" and its CONVERT program).
//!
//! Coordinates are world coordinates in `f64` metres (survey eastings of 10⁵–10⁶ m lose
//! millimetres in `f32`). For tracing, [`tracer::SceneTracer`] subtracts an `f64` local origin and
//! traces `f32` triangles relative to it.
//!
//! Every triangle carries a material id, an object id and, through its object, the flag that
//! drives the differential renderer: [`ObjectKind::Natural`] (in the photo) or
//! [`ObjectKind::Artificial`] (planned).
//!
//! # Known limitations
//! No instancing: repeated CAD blocks are stored once per copy. Natural polygons carry one image
//! attribute (the photo they are textured from) per object, not per polygon.

pub mod dxf;
pub mod gltf;
mod gltf_accessors;
pub mod import;
pub mod material;
pub mod obj;
pub mod tracer;
pub mod triangulate;

use std::path::Path;

use nalgebra::Point3;
use serde::{Deserialize, Serialize};

pub use import::{
    ImportOptions, ImportWarning, ImportedModel, LengthUnit, ModelError, Placement, UpAxis,
};
pub use material::{Material, MaterialLibrary};
pub use tracer::{SceneHit, SceneTracer};
pub use triangulate::TriangulateError;

/// Whether geometry is part of the photographed reality or of the planned project.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ObjectKind {
    /// Existing surroundings, seen in the photos (Durisch's "natural object").
    Natural,
    /// Planned CAD geometry (Durisch's "artificial object").
    Artificial,
}

/// Index of a material in [`Scene::materials`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct MaterialId(pub u32);

/// Index of an object in [`Scene::objects`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ObjectId(pub u32);

/// A triangle in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneTriangle {
    /// Vertices, world frame, metres, counter-clockwise seen from the front.
    pub vertices_in_world_m: [Point3<f64>; 3],
    /// Its material.
    pub material: MaterialId,
    /// Its object.
    pub object: ObjectId,
}

/// A named group of triangles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneObject {
    /// Name (file name, layer or polygon group).
    pub name: String,
    /// Natural or artificial.
    pub kind: ObjectKind,
    /// For natural objects: the id of the photo whose pixels give their colour when they are seen
    /// in reflections (Durisch's image attribute, §4.1).
    pub image_attribute: Option<String>,
}

/// Errors building a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file extension names no supported format.
    #[error("unsupported CAD format '{extension}' (supported: obj, gltf, glb, dxf)")]
    UnsupportedFormat {
        /// The extension found.
        extension: String,
    },
    /// OBJ import failed.
    #[error(transparent)]
    Obj(#[from] obj::ObjError),
    /// glTF import failed.
    #[error(transparent)]
    Gltf(#[from] gltf::GltfError),
    /// DXF import failed.
    #[error(transparent)]
    Dxf(#[from] dxf::DxfError),
    /// A scene polygon could not be triangulated.
    #[error("polygon of object {object}: {source}")]
    Polygon {
        /// Object name.
        object: String,
        /// Why.
        source: TriangulateError,
    },
    /// An id does not refer to an existing object or material.
    #[error("unknown {what} id {id}")]
    UnknownId {
        /// "object" or "material".
        what: &'static str,
        /// The id.
        id: u32,
    },
    /// More than 2³² objects, materials or triangles.
    #[error("too many {what} for 32-bit ids")]
    TooMany {
        /// What overflowed.
        what: &'static str,
    },
    /// Building the acceleration structure failed.
    #[error(transparent)]
    Bvh(#[from] crate::bvh::BvhError),
}

fn id_from_len(len: usize, what: &'static str) -> Result<u32, SceneError> {
    u32::try_from(len).map_err(|_| SceneError::TooMany { what })
}

/// Triangles, objects and materials in world coordinates.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    triangles: Vec<SceneTriangle>,
    objects: Vec<SceneObject>,
    materials: Vec<Material>,
}

impl Scene {
    /// An empty scene.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// All triangles.
    #[must_use]
    pub fn triangles(&self) -> &[SceneTriangle] {
        &self.triangles
    }

    /// All objects; [`ObjectId`] indexes this.
    #[must_use]
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// All materials; [`MaterialId`] indexes this.
    #[must_use]
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The objects of `kind` alone (every material, object names and triangle order kept): the
    /// photographed state ([`ObjectKind::Natural`]) or the planned objects.
    ///
    /// # Errors
    /// Id overflow (not reachable from a valid scene).
    pub fn part_of_kind(&self, kind: ObjectKind) -> Result<Scene, SceneError> {
        let mut out = Scene::new();
        for m in &self.materials {
            out.add_material(m.clone())?;
        }
        let mut ids = Vec::with_capacity(self.objects.len());
        for o in &self.objects {
            ids.push(if o.kind == kind {
                Some(out.add_object(o.clone())?)
            } else {
                None
            });
        }
        for t in &self.triangles {
            if let Some(Some(id)) = ids.get(t.object.0 as usize) {
                out.add_polygon(&t.vertices_in_world_m, t.material, *id)?;
            }
        }
        Ok(out)
    }

    /// Adds an object and returns its id.
    ///
    /// # Errors
    /// [`SceneError::TooMany`] past 2³² objects.
    pub fn add_object(&mut self, object: SceneObject) -> Result<ObjectId, SceneError> {
        let id = id_from_len(self.objects.len(), "objects")?;
        self.objects.push(object);
        Ok(ObjectId(id))
    }

    /// Adds a material, or returns the id of an equal one already present.
    ///
    /// # Errors
    /// [`SceneError::TooMany`] past 2³² materials.
    pub fn add_material(&mut self, material: Material) -> Result<MaterialId, SceneError> {
        if let Some(i) = self.materials.iter().position(|m| *m == material) {
            return Ok(MaterialId(id_from_len(i, "materials")?));
        }
        let id = id_from_len(self.materials.len(), "materials")?;
        self.materials.push(material);
        Ok(MaterialId(id))
    }

    /// Adds an imported model as one object of the given kind.
    ///
    /// # Errors
    /// [`SceneError::TooMany`] on id overflow.
    pub fn add_model(
        &mut self,
        model: &ImportedModel,
        name: &str,
        kind: ObjectKind,
    ) -> Result<ObjectId, SceneError> {
        let object = self.add_object(SceneObject {
            name: name.to_owned(),
            kind,
            image_attribute: None,
        })?;
        let ids = model
            .materials
            .iter()
            .map(|m| self.add_material(m.clone()))
            .collect::<Result<Vec<_>, _>>()?;
        let default = self.add_material(Material::default())?;
        for (tri, &m) in model
            .triangles_in_world_m
            .iter()
            .zip(&model.triangle_materials)
        {
            self.triangles.push(SceneTriangle {
                vertices_in_world_m: *tri,
                material: ids.get(m as usize).copied().unwrap_or(default),
                object,
            });
        }
        id_from_len(self.triangles.len(), "triangles")?;
        Ok(object)
    }

    /// Adds a planar polygon (convex or concave, world coordinates) to an existing object,
    /// triangulated in its plane; returns the number of triangles added.
    ///
    /// # Errors
    /// Unknown ids, or [`SceneError::Polygon`] when the polygon cannot be triangulated.
    pub fn add_polygon(
        &mut self,
        polygon_in_world_m: &[Point3<f64>],
        material: MaterialId,
        object: ObjectId,
    ) -> Result<usize, SceneError> {
        let Some(obj) = self.objects.get(object.0 as usize) else {
            return Err(SceneError::UnknownId {
                what: "object",
                id: object.0,
            });
        };
        if material.0 as usize >= self.materials.len() {
            return Err(SceneError::UnknownId {
                what: "material",
                id: material.0,
            });
        }
        let tris = triangulate::triangulate_polygon(polygon_in_world_m).map_err(|source| {
            SceneError::Polygon {
                object: obj.name.clone(),
                source,
            }
        })?;
        for [a, b, c] in &tris {
            self.triangles.push(SceneTriangle {
                vertices_in_world_m: [
                    polygon_in_world_m[*a],
                    polygon_in_world_m[*b],
                    polygon_in_world_m[*c],
                ],
                material,
                object,
            });
        }
        Ok(tris.len())
    }

    /// Imports a CAD file (by extension: `.obj`, `.gltf`/`.glb`, `.dxf`) as one object.
    ///
    /// # Errors
    /// The format's import error, or [`SceneError::UnsupportedFormat`].
    pub fn import_file(
        &mut self,
        path: &Path,
        options: &ImportOptions,
        kind: ObjectKind,
    ) -> Result<(ObjectId, Vec<ImportWarning>), SceneError> {
        let model = load_model(path, options)?;
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let id = self.add_model(&model, &name, kind)?;
        Ok((id, model.warnings))
    }

    /// Gives every triangle of every object of `kind` the material `material` (e.g. a neutral
    /// massing material for the planned objects); returns how many triangles changed.
    ///
    /// # Errors
    /// [`SceneError::UnknownId`] when `material` is not in the scene.
    pub fn set_material_of_kind(
        &mut self,
        kind: ObjectKind,
        material: MaterialId,
    ) -> Result<usize, SceneError> {
        if self.materials.len() <= material.0 as usize {
            return Err(SceneError::UnknownId {
                what: "material",
                id: material.0,
            });
        }
        let mut changed = 0;
        for t in &mut self.triangles {
            if self.objects.get(t.object.0 as usize).map(|o| o.kind) == Some(kind) {
                t.material = material;
                changed += 1;
            }
        }
        Ok(changed)
    }

    /// Replaces every material by `f` of it, in place (ids and triangles kept), e.g. the
    /// reflectances of one spectral pass; the name is kept whatever `f` returns.
    pub fn map_materials(&mut self, f: &dyn Fn(&Material) -> Material) {
        for m in &mut self.materials {
            let mut mapped = f(m);
            mapped.name = std::mem::take(&mut m.name);
            *m = mapped;
        }
    }

    /// Replaces every scene material whose name appears in the library by the library's
    /// definition; returns how many were replaced.
    pub fn apply_material_library(&mut self, library: &MaterialLibrary) -> usize {
        let mut replaced = 0;
        for m in &mut self.materials {
            if let Some(lib) = library.get(&m.name) {
                *m = lib.clone();
                replaced += 1;
            }
        }
        replaced
    }

    /// Axis-aligned bounding box (min, max) of all triangles, world frame; `None` when empty.
    #[must_use]
    pub fn bounding_box_in_world_m(&self) -> Option<[Point3<f64>; 2]> {
        let mut it = self
            .triangles
            .iter()
            .flat_map(|t| t.vertices_in_world_m.iter());
        let first = *it.next()?;
        Some(it.fold([first, first], |[lo, hi], p| [lo.inf(p), hi.sup(p)]))
    }
}

/// Reads a CAD file by extension into world coordinates.
///
/// # Errors
/// The format's import error, or [`SceneError::UnsupportedFormat`].
pub fn load_model(path: &Path, options: &ImportOptions) -> Result<ImportedModel, SceneError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "obj" => Ok(obj::load_obj(path, options)?),
        "gltf" | "glb" => Ok(gltf::load_gltf(path, options)?),
        "dxf" => Ok(dxf::load_dxf(path, options)?),
        _ => Err(SceneError::UnsupportedFormat { extension }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_and_models_share_materials_and_keep_kinds() {
        let mut scene = Scene::new();
        let ground = scene
            .add_object(SceneObject {
                name: "ground".into(),
                kind: ObjectKind::Natural,
                image_attribute: Some("IMG_1".into()),
            })
            .unwrap();
        let grass = scene
            .add_material(Material::diffuse("grass", [0.1, 0.3, 0.1]))
            .unwrap();
        let l_shape: Vec<Point3<f64>> = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, 10.0),
            (10.0, 10.0),
            (10.0, 20.0),
            (0.0, 20.0),
        ]
        .iter()
        .map(|&(x, y)| Point3::new(600_000.0 + x, 200_000.0 + y, 400.0))
        .collect();
        assert_eq!(scene.add_polygon(&l_shape, grass, ground).unwrap(), 4);
        let model = ImportedModel {
            triangles_in_world_m: vec![[
                Point3::new(600_005.0, 200_005.0, 400.0),
                Point3::new(600_006.0, 200_005.0, 400.0),
                Point3::new(600_005.0, 200_005.0, 410.0),
            ]],
            triangle_materials: vec![0],
            materials: vec![Material::diffuse("grass", [0.1, 0.3, 0.1])],
            warnings: vec![],
        };
        let building = scene
            .add_model(&model, "building", ObjectKind::Artificial)
            .unwrap();
        assert_eq!(scene.materials().len(), 2, "grass shared, plus the default");
        assert_eq!(scene.triangles()[4].material, grass);
        assert_eq!(
            scene.objects()[building.0 as usize].kind,
            ObjectKind::Artificial
        );
        let [lo, hi] = scene.bounding_box_in_world_m().unwrap();
        assert_eq!(lo, Point3::new(600_000.0, 200_000.0, 400.0));
        assert_eq!(hi, Point3::new(600_020.0, 200_020.0, 410.0));
        assert!(matches!(
            scene.add_polygon(&l_shape, MaterialId(99), ground),
            Err(SceneError::UnknownId {
                what: "material",
                ..
            })
        ));
        assert!(matches!(
            scene.add_polygon(&l_shape[..2], grass, ground),
            Err(SceneError::Polygon {
                source: TriangulateError::TooFewVertices { count: 2 },
                ..
            })
        ));
    }
}
