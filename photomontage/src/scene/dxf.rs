//! DXF import via the `dxf` crate: `3DFACE` entities and `POLYLINE` polyface meshes and polygon
//! (M×N) meshes. This is Durisch 1992 §5's CONVERT program ("converts data from the widely used
//! DXF format (Autodesk, 1988)"). Each layer becomes a material named after it (mid-grey until a
//! material library assigns it). The unit comes from the header's `$INSUNITS` unless the options
//! give one; a unitless drawing is read as metres with a warning. Up axis Z.
//!
//! Face rules (AutoCAD DXF Reference, POLYLINE/VERTEX group codes 70, 71–74): polyline flag 64 is
//! a polyface mesh whose vertices with flag 64 are positions and whose vertices with flag 128 only
//! are faces (1-based indices, negative = invisible edge, 0 = unused corner); flag 16 is an M×N
//! polygon mesh, row-major, flags 1 and 32 closing it in M and N. A 3DFACE whose fourth corner
//! equals its third is a triangle.
//!
//! # Known limitations
//! Blocks (`INSERT`), `MESH` (subdivision) entities, `SOLID`/`3DSOLID` (ACIS) and extrusion
//! thickness are not converted; they are counted in an [`ImportWarning::IgnoredEntities`]
//! warning. Smooth-surface fitting of polygon meshes is ignored (the control mesh is used).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use dxf::entities::{EntityType, Polyline};
use dxf::enums::Units;

use super::import::{
    ImportOptions, ImportWarning, ImportedModel, LengthUnit, ModelBuilder, ModelError, UpAxis,
};
use super::material::Material;

/// Errors reading a DXF file.
#[derive(Debug, thiserror::Error)]
pub enum DxfError {
    /// The file could not be read or parsed.
    #[error("cannot read DXF {path}: {reason}")]
    Load {
        /// File path.
        path: String,
        /// The dxf crate's description.
        reason: String,
    },
    /// `$INSUNITS` names a unit this importer does not know; pass one in the options.
    #[error("DXF {path}: unsupported drawing unit {unit}; set the unit explicitly")]
    UnsupportedUnit {
        /// File path.
        path: String,
        /// The unit as named by the dxf crate.
        unit: String,
    },
    /// The geometry failed a model check.
    #[error("DXF {path}: {source}")]
    Model {
        /// File path.
        path: String,
        /// The failed check.
        source: ModelError,
    },
}

fn point(p: &dxf::Point) -> [f64; 3] {
    [p.x, p.y, p.z]
}

struct Converter {
    builder: ModelBuilder,
    layers: HashMap<String, u32>,
    ignored: BTreeMap<String, usize>,
    vertex_counter: usize,
    face_counter: usize,
}

impl Converter {
    fn layer_material(&mut self, layer: &str) -> u32 {
        if let Some(&id) = self.layers.get(layer) {
            return id;
        }
        let id = self
            .builder
            .add_material(Material::diffuse(layer, [0.5; 3]));
        self.layers.insert(layer.to_owned(), id);
        id
    }

    fn check(&mut self, vertices: &[[f64; 3]]) -> Result<(), ModelError> {
        let base = self.vertex_counter;
        self.vertex_counter += vertices.len();
        ModelBuilder::check_finite(vertices.iter().copied()).map_err(|e| match e {
            ModelError::NonFiniteVertex {
                vertex_index,
                coordinates,
            } => ModelError::NonFiniteVertex {
                vertex_index: base + vertex_index,
                coordinates,
            },
            other => other,
        })
    }

    fn face3d(&mut self, f: &dxf::entities::Face3D, material: u32) -> Result<(), ModelError> {
        let c = [
            point(&f.first_corner),
            point(&f.second_corner),
            point(&f.third_corner),
            point(&f.fourth_corner),
        ];
        self.check(&c)?;
        self.face_counter += 1;
        // DXF writes a triangle as a 3DFACE whose fourth corner repeats the third exactly.
        #[allow(clippy::float_cmp)]
        let is_triangle = c[3] == c[2];
        if is_triangle {
            self.builder
                .push_triangle([c[0], c[1], c[2]], Some(material));
        } else {
            self.builder.push_polygon(&c, Some(material));
        }
        Ok(())
    }

    fn polyface(&mut self, p: &Polyline, material: u32) -> Result<(), ModelError> {
        let positions: Vec<[f64; 3]> = p
            .vertices()
            .filter(|v| v.flags & 64 != 0)
            .map(|v| point(&v.location))
            .collect();
        self.check(&positions)?;
        for v in p
            .vertices()
            .filter(|v| v.flags & 128 != 0 && v.flags & 64 == 0)
        {
            let face_index = self.face_counter;
            self.face_counter += 1;
            let ids = [
                v.polyface_mesh_vertex_index1,
                v.polyface_mesh_vertex_index2,
                v.polyface_mesh_vertex_index3,
                v.polyface_mesh_vertex_index4,
            ];
            let mut corners = Vec::with_capacity(4);
            for id in ids
                .iter()
                .map(|i| i.unsigned_abs() as usize)
                .filter(|&i| i != 0)
            {
                let corner = positions
                    .get(id - 1)
                    .ok_or(ModelError::VertexIndexOutOfRange {
                        face_index,
                        vertex_index: id - 1,
                        vertex_count: positions.len(),
                    })?;
                if corners.last() != Some(corner) {
                    corners.push(*corner);
                }
            }
            if corners.len() >= 3 {
                self.builder.push_polygon(&corners, Some(material));
            }
        }
        Ok(())
    }

    fn polygon_mesh(&mut self, p: &Polyline, material: u32) -> Result<(), ModelError> {
        let vertices: Vec<[f64; 3]> = p.vertices().map(|v| point(&v.location)).collect();
        self.check(&vertices)?;
        let (m, n) = (
            usize::try_from(p.polygon_mesh_m_vertex_count).unwrap_or(0),
            usize::try_from(p.polygon_mesh_n_vertex_count).unwrap_or(0),
        );
        if m < 2 || n < 2 || m.checked_mul(n) != Some(vertices.len()) {
            return Err(ModelError::VertexIndexOutOfRange {
                face_index: self.face_counter,
                vertex_index: m.saturating_mul(n).saturating_sub(1),
                vertex_count: vertices.len(),
            });
        }
        let closed_m = p.flags & 1 != 0;
        let closed_n = p.flags & 32 != 0;
        let rows = if closed_m { m } else { m - 1 };
        let cols = if closed_n { n } else { n - 1 };
        for i in 0..rows {
            for j in 0..cols {
                let at = |a: usize, b: usize| vertices[(a % m) * n + (b % n)];
                let quad = [at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)];
                self.face_counter += 1;
                self.builder.push_polygon(&quad, Some(material));
            }
        }
        Ok(())
    }
}

fn variant_name(e: &EntityType) -> String {
    let debug = format!("{e:?}");
    debug
        .split(['(', ' ', '{'])
        .next()
        .unwrap_or("unknown")
        .to_owned()
}

/// Reads a DXF file's surface entities into world coordinates.
///
/// # Errors
/// [`DxfError::Load`] for unreadable, malformed or truncated files, [`DxfError::UnsupportedUnit`],
/// [`DxfError::Model`] for no faces, non-finite vertices, bad indices, absurd scale.
pub fn load_dxf(path: &Path, options: &ImportOptions) -> Result<ImportedModel, DxfError> {
    let path_str = path.display().to_string();
    let model_err = |source| DxfError::Model {
        path: path_str.clone(),
        source,
    };
    let drawing = dxf::Drawing::load_file(path).map_err(|e| DxfError::Load {
        path: path_str.clone(),
        reason: e.to_string(),
    })?;
    let mut warnings = Vec::new();
    let file_unit = match drawing.header.default_drawing_units {
        Units::Millimeters => LengthUnit::Millimetre,
        Units::Centimeters => LengthUnit::Centimetre,
        Units::Meters => LengthUnit::Metre,
        Units::Inches => LengthUnit::Inch,
        Units::Feet => LengthUnit::Foot,
        Units::Unitless => {
            if options.unit.is_none() {
                warnings.push(ImportWarning::UnitAssumed {
                    unit: LengthUnit::Metre,
                });
            }
            LengthUnit::Metre
        }
        other => {
            if options.unit.is_none() {
                return Err(DxfError::UnsupportedUnit {
                    path: path_str,
                    unit: format!("{other:?}"),
                });
            }
            LengthUnit::Metre
        }
    };
    let mut conv = Converter {
        builder: ModelBuilder::new(options, file_unit, UpAxis::Z).map_err(model_err)?,
        layers: HashMap::new(),
        ignored: BTreeMap::new(),
        vertex_counter: 0,
        face_counter: 0,
    };
    conv.builder.warnings.extend(warnings);
    for entity in drawing.entities() {
        let layer = &entity.common.layer;
        match &entity.specific {
            EntityType::Face3D(f) => {
                let m = conv.layer_material(layer);
                conv.face3d(f, m)
            }
            EntityType::Polyline(p) if p.flags & 64 != 0 => {
                let m = conv.layer_material(layer);
                conv.polyface(p, m)
            }
            EntityType::Polyline(p) if p.flags & 16 != 0 => {
                let m = conv.layer_material(layer);
                conv.polygon_mesh(p, m)
            }
            other => {
                *conv.ignored.entry(variant_name(other)).or_default() += 1;
                Ok(())
            }
        }
        .map_err(model_err)?;
    }
    for (kind, count) in std::mem::take(&mut conv.ignored) {
        conv.builder
            .warnings
            .push(ImportWarning::IgnoredEntities { kind, count });
    }
    conv.builder.finish().map_err(model_err)
}
