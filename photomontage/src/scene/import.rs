//! What every CAD importer shares: length units, the up-axis convention, the placement transform
//! from model to world coordinates, and the checks on the result (no faces, non-finite vertices,
//! absurd scale). This is the part of Durisch's CONVERT program (Durisch 1992 §5, Fig. 4) that is
//! independent of the file format.
//!
//! # Transform
//! A vertex `p_file` in file units becomes
//! `p_world = translation + R_z(rotation_about_z) · scale · A · (metres_per_unit · p_file)`,
//! where `A` is the identity for Z-up files and maps Y-up to Z-up by `(x, y, z) ↦ (x, −z, y)`
//! (a proper rotation, so handedness and face orientation are preserved; this is the convention
//! Blender uses when importing glTF).
//!
//! # Known limitations
//! Only uniform scale and rotation about the vertical axis are offered: enough to place a building
//! on a site plan, not to correct a tilted model. Degenerate (zero-area) faces are kept; they
//! cannot be hit by a ray and cost nothing but memory.

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use super::material::Material;

/// Smallest bounding-box side (largest of the three) accepted by default: 1 mm.
pub const DEFAULT_MIN_EXTENT_M: f64 = 1e-3;
/// Largest bounding-box side accepted by default: 100 km (a model larger than a city is almost
/// certainly in the wrong unit, e.g. millimetres read as metres).
pub const DEFAULT_MAX_EXTENT_M: f64 = 1e5;

/// Length unit of the coordinates in a CAD file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LengthUnit {
    /// Millimetres.
    Millimetre,
    /// Centimetres.
    Centimetre,
    /// Metres.
    Metre,
    /// International inch, 25.4 mm exactly.
    Inch,
    /// International foot, 0.3048 m exactly.
    Foot,
}

impl LengthUnit {
    /// Metres per one unit (exact by definition).
    #[must_use]
    pub fn metres_per_unit(self) -> f64 {
        match self {
            Self::Millimetre => 1e-3,
            Self::Centimetre => 1e-2,
            Self::Metre => 1.0,
            Self::Inch => 0.0254,
            Self::Foot => 0.3048,
        }
    }
}

/// Which model axis points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum UpAxis {
    /// +Y up (glTF 2.0 by specification; many OBJ exporters).
    Y,
    /// +Z up (the world frame of this crate; CAD, DXF, survey data).
    Z,
}

/// Placement of a model in the world: uniform scale, then rotation about the world Z axis,
/// then translation (world coordinates, metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Placement {
    /// Where the model origin goes, world coordinates in metres (may be large survey values).
    pub translation_in_world_m: [f64; 3],
    /// Counter-clockwise rotation about +Z seen from above, degrees.
    pub rotation_about_z_deg: f64,
    /// Uniform scale factor applied after the unit conversion.
    pub scale: f64,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            translation_in_world_m: [0.0; 3],
            rotation_about_z_deg: 0.0,
            scale: 1.0,
        }
    }
}

/// How a CAD file is read into world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ImportOptions {
    /// Unit of the file's coordinates. `None`: the file's own declaration where the format has one
    /// (DXF `$INSUNITS`, glTF metres by specification), otherwise metres.
    pub unit: Option<LengthUnit>,
    /// Up axis of the file. `None`: the format's convention (glTF: Y; OBJ and DXF: Z).
    pub up_axis: Option<UpAxis>,
    /// Placement in the world.
    pub placement: Placement,
    /// Smallest accepted largest bounding-box side after unit and scale, metres.
    pub min_extent_m: f64,
    /// Largest accepted largest bounding-box side after unit and scale, metres.
    pub max_extent_m: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            unit: None,
            up_axis: None,
            placement: Placement::default(),
            min_extent_m: DEFAULT_MIN_EXTENT_M,
            max_extent_m: DEFAULT_MAX_EXTENT_M,
        }
    }
}

/// Something worth telling the user that did not stop the import.
#[derive(Debug, Clone, PartialEq)]
pub enum ImportWarning {
    /// The material library named by the file could not be read; the default material is used.
    MissingMaterialLibrary {
        /// Library name as written in the file.
        name: String,
        /// Why it could not be read.
        reason: String,
    },
    /// Faces without a (known) material were given the default material.
    FacesWithoutMaterial {
        /// Number of triangles affected.
        triangle_count: usize,
    },
    /// The file declares no unit; this one was assumed.
    UnitAssumed {
        /// The unit used.
        unit: LengthUnit,
    },
    /// Polygons that could not be triangulated (no area, self-intersecting) were skipped.
    PolygonsSkipped {
        /// How many polygons.
        count: usize,
    },
    /// Entities of a kind that carries no surface were ignored.
    IgnoredEntities {
        /// Entity or primitive kind.
        kind: String,
        /// How many.
        count: usize,
    },
}

/// The checks every importer applies to its result.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelError {
    /// The file holds no surface faces at all.
    #[error("the model has no faces")]
    NoFaces,
    /// A vertex coordinate is NaN or infinite (index counted from 0 in file order).
    #[error("vertex {vertex_index} has a non-finite coordinate {coordinates:?}")]
    NonFiniteVertex {
        /// Vertex index in file order, from 0.
        vertex_index: usize,
        /// The offending coordinates as read.
        coordinates: [f64; 3],
    },
    /// The model's size after unit conversion and scale is implausible (probably the wrong unit).
    #[error(
        "the model's largest bounding-box side is {extent_m} m, outside the accepted range \
         [{min_m}, {max_m}] m: check the unit and scale"
    )]
    AbsurdScale {
        /// Largest side of the bounding box, metres.
        extent_m: f64,
        /// Accepted minimum, metres.
        min_m: f64,
        /// Accepted maximum, metres.
        max_m: f64,
    },
    /// The placement cannot be applied (non-finite or non-positive scale, non-finite values).
    #[error("invalid placement: {reason}")]
    InvalidPlacement {
        /// What is wrong.
        reason: String,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face_index} refers to vertex {vertex_index}, but there are {vertex_count}")]
    VertexIndexOutOfRange {
        /// Face index in file order, from 0.
        face_index: usize,
        /// The index it refers to (from 0).
        vertex_index: usize,
        /// Number of vertices available.
        vertex_count: usize,
    },
}

/// An imported model in world coordinates, ready to be added to a [`super::Scene`].
#[derive(Debug, Clone, Default)]
pub struct ImportedModel {
    /// Triangles in world coordinates, metres, counter-clockwise seen from the front.
    pub triangles_in_world_m: Vec<[Point3<f64>; 3]>,
    /// Per triangle, an index into `materials`.
    pub triangle_materials: Vec<u32>,
    /// Materials referenced by `triangle_materials`.
    pub materials: Vec<Material>,
    /// Non-fatal problems met on the way.
    pub warnings: Vec<ImportWarning>,
}

/// Collects triangles in file coordinates and turns them into an [`ImportedModel`].
#[derive(Debug)]
pub(crate) struct ModelBuilder {
    linear_world_from_file: Matrix3<f64>,
    translation_in_world_m: Vector3<f64>,
    min_extent_m: f64,
    max_extent_m: f64,
    /// Triangles after the linear part of the transform (no translation yet), to measure size.
    triangles_scaled: Vec<[Vector3<f64>; 3]>,
    triangle_materials: Vec<u32>,
    pub(crate) materials: Vec<Material>,
    pub(crate) warnings: Vec<ImportWarning>,
    default_material: Option<u32>,
    faces_without_material: usize,
    polygons_skipped: usize,
}

impl ModelBuilder {
    /// A builder for a file whose unit and up axis default to `file_unit` and `file_up`.
    pub(crate) fn new(
        options: &ImportOptions,
        file_unit: LengthUnit,
        file_up: UpAxis,
    ) -> Result<Self, ModelError> {
        let p = &options.placement;
        if !(p.scale.is_finite() && p.scale > 0.0) {
            return Err(ModelError::InvalidPlacement {
                reason: format!("scale must be finite and positive, got {}", p.scale),
            });
        }
        if !p.rotation_about_z_deg.is_finite()
            || p.translation_in_world_m.iter().any(|v| !v.is_finite())
        {
            return Err(ModelError::InvalidPlacement {
                reason: "rotation and translation must be finite".to_owned(),
            });
        }
        let unit = options.unit.unwrap_or(file_unit);
        let up = options.up_axis.unwrap_or(file_up);
        let axes = match up {
            UpAxis::Z => Matrix3::identity(),
            UpAxis::Y => Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
        };
        let rotation =
            Rotation3::from_axis_angle(&Vector3::z_axis(), p.rotation_about_z_deg.to_radians());
        let linear = rotation.matrix() * (p.scale * unit.metres_per_unit()) * axes;
        Ok(Self {
            linear_world_from_file: linear,
            translation_in_world_m: Vector3::from(p.translation_in_world_m),
            min_extent_m: options.min_extent_m,
            max_extent_m: options.max_extent_m,
            triangles_scaled: Vec::new(),
            triangle_materials: Vec::new(),
            materials: Vec::new(),
            warnings: Vec::new(),
            default_material: None,
            faces_without_material: 0,
            polygons_skipped: 0,
        })
    }

    /// Checks that every vertex is finite, reporting the first offender.
    pub(crate) fn check_finite<I: IntoIterator<Item = [f64; 3]>>(
        vertices: I,
    ) -> Result<(), ModelError> {
        for (vertex_index, v) in vertices.into_iter().enumerate() {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(ModelError::NonFiniteVertex {
                    vertex_index,
                    coordinates: v,
                });
            }
        }
        Ok(())
    }

    /// Index of the default material, added on first use.
    pub(crate) fn default_material(&mut self) -> u32 {
        if let Some(id) = self.default_material {
            return id;
        }
        let id = u32::try_from(self.materials.len()).unwrap_or(u32::MAX);
        self.materials.push(Material::default());
        self.default_material = Some(id);
        id
    }

    /// Adds a material, returning its index.
    pub(crate) fn add_material(&mut self, material: Material) -> u32 {
        let id = u32::try_from(self.materials.len()).unwrap_or(u32::MAX);
        self.materials.push(material);
        id
    }

    /// Adds a triangle in file coordinates. `material: None` uses the default material and
    /// counts the face for a [`ImportWarning::FacesWithoutMaterial`].
    pub(crate) fn push_triangle(&mut self, vertices_in_file: [[f64; 3]; 3], material: Option<u32>) {
        let material = match material {
            Some(m) => m,
            None => {
                self.faces_without_material += 1;
                self.default_material()
            }
        };
        let m = &self.linear_world_from_file;
        self.triangles_scaled
            .push(vertices_in_file.map(|v| m * Vector3::from(v)));
        self.triangle_materials.push(material);
    }

    /// Adds a planar polygon (file coordinates), triangulated by ear clipping. Degenerate
    /// polygons (collinear, fewer than 3 distinct vertices, self-intersecting) are skipped and
    /// counted in an [`ImportWarning::PolygonsSkipped`].
    pub(crate) fn push_polygon(&mut self, vertices_in_file: &[[f64; 3]], material: Option<u32>) {
        if vertices_in_file.len() == 3 {
            self.push_triangle(
                [
                    vertices_in_file[0],
                    vertices_in_file[1],
                    vertices_in_file[2],
                ],
                material,
            );
            return;
        }
        let points: Vec<Point3<f64>> = vertices_in_file.iter().map(|v| Point3::from(*v)).collect();
        match super::triangulate::triangulate_polygon(&points) {
            Ok(tris) => {
                for [a, b, c] in tris {
                    self.push_triangle(
                        [
                            vertices_in_file[a],
                            vertices_in_file[b],
                            vertices_in_file[c],
                        ],
                        material,
                    );
                }
            }
            Err(_) => self.polygons_skipped += 1,
        }
    }

    /// Applies the scale checks and the translation.
    pub(crate) fn finish(mut self) -> Result<ImportedModel, ModelError> {
        if self.triangles_scaled.is_empty() {
            return Err(ModelError::NoFaces);
        }
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for v in self.triangles_scaled.iter().flatten() {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        let extent_m = (hi - lo).max();
        if !(extent_m >= self.min_extent_m && extent_m <= self.max_extent_m) {
            return Err(ModelError::AbsurdScale {
                extent_m,
                min_m: self.min_extent_m,
                max_m: self.max_extent_m,
            });
        }
        if self.polygons_skipped > 0 {
            self.warnings.push(ImportWarning::PolygonsSkipped {
                count: self.polygons_skipped,
            });
        }
        if self.faces_without_material > 0 {
            self.warnings.push(ImportWarning::FacesWithoutMaterial {
                triangle_count: self.faces_without_material,
            });
        }
        let t = self.translation_in_world_m;
        Ok(ImportedModel {
            triangles_in_world_m: self
                .triangles_scaled
                .iter()
                .map(|tri| tri.map(|v| Point3::from(v + t)))
                .collect(),
            triangle_materials: self.triangle_materials,
            materials: self.materials,
            warnings: self.warnings,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Transforms are products of a few exact factors and one sine/cosine: 1e-12 m covers the
    /// rounding of values of order 1–10 m.
    const TRANSFORM_TOL_M: f64 = 1e-12;

    fn one_triangle(options: &ImportOptions, up: UpAxis) -> ImportedModel {
        let mut b = ModelBuilder::new(options, LengthUnit::Metre, up).unwrap();
        b.push_triangle([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], None);
        b.finish().unwrap()
    }

    #[test]
    fn units_are_exact_definitions() {
        assert!(
            (LengthUnit::Inch.metres_per_unit() * 12.0 - LengthUnit::Foot.metres_per_unit()).abs()
                < 1e-15
        );
        assert!(
            (LengthUnit::Millimetre.metres_per_unit() * 10.0
                - LengthUnit::Centimetre.metres_per_unit())
            .abs()
                < 1e-15
        );
    }

    #[test]
    fn y_up_maps_to_z_up_and_keeps_orientation() {
        // A triangle in the file's XY plane, facing +Z (towards the viewer in Y-up = "forward"),
        // becomes a triangle in the world XZ plane facing −Y.
        let m = one_triangle(&ImportOptions::default(), UpAxis::Y);
        let [a, b, c] = m.triangles_in_world_m[0];
        assert!(
            (c - Point3::new(0.0, 0.0, 1.0)).norm() < TRANSFORM_TOL_M,
            "file +Y is world +Z"
        );
        let n = (b - a).cross(&(c - a));
        assert!(
            (n - Vector3::new(0.0, -1.0, 0.0)).norm() < TRANSFORM_TOL_M,
            "file +Z is world −Y"
        );
        assert!(
            m.warnings
                .contains(&ImportWarning::FacesWithoutMaterial { triangle_count: 1 })
        );
    }

    #[test]
    fn placement_scales_rotates_then_translates() {
        let options = ImportOptions {
            unit: Some(LengthUnit::Foot),
            placement: Placement {
                translation_in_world_m: [600_000.0, 200_000.0, 400.0],
                rotation_about_z_deg: 90.0,
                scale: 2.0,
            },
            ..ImportOptions::default()
        };
        let m = one_triangle(&options, UpAxis::Z);
        // file (1,0,0) ft -> 0.6096 m along x -> rotated 90° -> along +y.
        let b = m.triangles_in_world_m[0][1];
        let expected = Point3::new(600_000.0, 200_000.0 + 0.6096, 400.0);
        assert!((b - expected).norm() < 1e-9, "{b} vs {expected}");
    }

    #[test]
    fn absurd_scale_and_bad_placement_are_errors() {
        let options = ImportOptions {
            unit: Some(LengthUnit::Millimetre),
            ..ImportOptions::default()
        };
        let mut b = ModelBuilder::new(&options, LengthUnit::Metre, UpAxis::Z).unwrap();
        b.push_triangle([[0.0; 3], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0]], None);
        assert!(matches!(b.finish(), Err(ModelError::AbsurdScale { .. })));
        let mut b =
            ModelBuilder::new(&ImportOptions::default(), LengthUnit::Metre, UpAxis::Z).unwrap();
        b.push_triangle([[0.0; 3], [2e5, 0.0, 0.0], [0.0, 1.0, 0.0]], None);
        assert!(
            matches!(b.finish(), Err(ModelError::AbsurdScale { extent_m, .. }) if (extent_m - 2e5).abs() < 1e-6)
        );
        let bad = ImportOptions {
            placement: Placement {
                scale: 0.0,
                ..Placement::default()
            },
            ..ImportOptions::default()
        };
        assert!(matches!(
            ModelBuilder::new(&bad, LengthUnit::Metre, UpAxis::Z),
            Err(ModelError::InvalidPlacement { .. })
        ));
        let b = ModelBuilder::new(&ImportOptions::default(), LengthUnit::Metre, UpAxis::Z).unwrap();
        assert_eq!(b.finish().unwrap_err(), ModelError::NoFaces);
    }

    #[test]
    fn degenerate_polygons_are_skipped_with_a_warning() {
        let mut b =
            ModelBuilder::new(&ImportOptions::default(), LengthUnit::Metre, UpAxis::Z).unwrap();
        b.push_polygon(
            &[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
            None,
        );
        b.push_polygon(
            &[[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            None,
        );
        let m = b.finish().unwrap();
        assert_eq!(m.triangles_in_world_m.len(), 2);
        assert!(
            m.warnings
                .contains(&ImportWarning::PolygonsSkipped { count: 1 }),
            "{:?}",
            m.warnings
        );
    }

    #[test]
    fn non_finite_vertex_is_reported_with_its_index() {
        let v = [[0.0, 0.0, 0.0], [1.0, f64::NAN, 0.0]];
        let err = ModelBuilder::check_finite(v).unwrap_err();
        assert!(matches!(
            err,
            ModelError::NonFiniteVertex {
                vertex_index: 1,
                ..
            }
        ));
    }
}
