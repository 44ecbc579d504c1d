//! glTF 2.0 import (`.gltf` with embedded or external buffers, `.glb`) via the `gltf` crate:
//! meshes of the default scene under their node transforms, triangle primitives (lists, strips,
//! fans), and each material's base colour (→ diffuse), metallic/roughness (→ GGX specular with
//! F0 = lerp(0.04, base colour, metallic), Burley 2012) and emissive factor. Durisch 1992 §5
//! "CONVERT" for today's interchange format (Khronos glTF 2.0 specification, §3.4 coordinate
//! system: metres, +Y up, so the default up axis here is Y).
//!
//! # Known limitations
//! Textures, morph targets, skins and extensions (KHR_materials_*) are ignored. Only the default
//! scene (or the first) is read. Node hierarchies deeper than [`MAX_NODE_DEPTH`] are cut.

use std::collections::HashMap;
use std::path::Path;

use gltf::mesh::Mode;
use nalgebra::{Matrix4, Point3};

use super::import::{
    ImportOptions, ImportWarning, ImportedModel, LengthUnit, ModelBuilder, ModelError, UpAxis,
};
use super::material::{Material, Specular};

/// Node nesting depth at which traversal stops (guards against malicious recursion).
pub const MAX_NODE_DEPTH: usize = 64;

/// Errors reading a glTF file.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The file or its buffers could not be read or parsed.
    #[error("cannot read glTF {path}: {reason}")]
    Load {
        /// File path.
        path: String,
        /// The gltf crate's description.
        reason: String,
    },
    /// The geometry failed a model check.
    #[error("glTF {path}: {source}")]
    Model {
        /// File path.
        path: String,
        /// The failed check.
        source: ModelError,
    },
}

fn material_from_gltf(m: &gltf::Material<'_>) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _a] = pbr
        .base_color_factor()
        .map(|c| f64::from(c).clamp(0.0, 1.0));
    let metallic = f64::from(pbr.metallic_factor()).clamp(0.0, 1.0);
    let name = m.name().map_or_else(
        || format!("gltf_material_{}", m.index().unwrap_or(0)),
        str::to_owned,
    );
    let base = [r, g, b];
    let mut out = Material::diffuse(&name, base.map(|c| c * (1.0 - metallic)));
    out.specular = Some(Specular {
        roughness: f64::from(pbr.roughness_factor()).clamp(1e-3, 1.0),
        f0: 0.04 * (1.0 - metallic) + metallic * (r + g + b) / 3.0,
    });
    let e = m.emissive_factor().map(f64::from);
    if e.iter().all(|v| v.is_finite() && *v >= 0.0) && e.iter().sum::<f64>() > 0.0 {
        out.emission_rgb_w_m2_sr = Some(e);
    }
    out
}

struct Walker<'a> {
    buffers: &'a [gltf::buffer::Data],
    builder: ModelBuilder,
    materials: HashMap<usize, u32>,
    vertices_seen: usize,
    ignored_primitives: usize,
}

impl Walker<'_> {
    fn node(
        &mut self,
        node: &gltf::Node<'_>,
        parent: &Matrix4<f64>,
        depth: usize,
    ) -> Result<(), ModelError> {
        if depth >= MAX_NODE_DEPTH {
            return Ok(());
        }
        let local = Matrix4::from_fn(|r, c| f64::from(node.transform().matrix()[c][r]));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                self.primitive(&prim, &world)?;
            }
        }
        for child in node.children() {
            self.node(&child, &world, depth + 1)?;
        }
        Ok(())
    }

    fn primitive(
        &mut self,
        prim: &gltf::Primitive<'_>,
        world: &Matrix4<f64>,
    ) -> Result<(), ModelError> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.ignored_primitives += 1;
            return Ok(());
        }
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            return Ok(());
        };
        // Accessor counts are untrusted: never collect more items than the buffers can hold
        // (a position takes at least 12 bytes, an index at least 1), whatever the count claims.
        let buffer_bytes: usize = self.buffers.iter().map(|b| b.0.len()).sum();
        let positions: Vec<[f64; 3]> = positions
            .take(buffer_bytes / 12)
            .map(|p| p.map(f64::from))
            .collect();
        ModelBuilder::check_finite(positions.iter().copied()).map_err(|e| match e {
            ModelError::NonFiniteVertex {
                vertex_index,
                coordinates,
            } => ModelError::NonFiniteVertex {
                vertex_index: vertex_index + self.vertices_seen,
                coordinates,
            },
            other => other,
        })?;
        self.vertices_seen += positions.len();
        let transformed: Vec<[f64; 3]> = positions
            .iter()
            .map(|p| {
                let q = world.transform_point(&Point3::from(*p));
                [q.x, q.y, q.z]
            })
            .collect();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(ix) => ix.into_u32().take(buffer_bytes).collect(),
            None => (0..u32::try_from(positions.len()).unwrap_or(u32::MAX)).collect(),
        };
        let material = match prim.material().index() {
            Some(i) => Some(match self.materials.get(&i) {
                Some(&id) => id,
                None => {
                    let id = self
                        .builder
                        .add_material(material_from_gltf(&prim.material()));
                    self.materials.insert(i, id);
                    id
                }
            }),
            None => None,
        };
        // A negative-determinant transform mirrors the mesh: swap two vertices to keep the front.
        let mirrored = world.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
        let n = indices.len();
        let triangles: Box<dyn Iterator<Item = [usize; 3]>> = match mode {
            Mode::TriangleStrip => Box::new((0..n.saturating_sub(2)).map(|i| {
                if i % 2 == 0 {
                    [i, i + 1, i + 2]
                } else {
                    [i + 1, i, i + 2]
                }
            })),
            Mode::TriangleFan => Box::new((1..n.saturating_sub(1)).map(|i| [0, i, i + 1])),
            _ => Box::new((0..n / 3).map(|i| [3 * i, 3 * i + 1, 3 * i + 2])),
        };
        for (face_index, corners) in triangles.enumerate() {
            let mut tri = [[0.0; 3]; 3];
            for (k, &c) in corners.iter().enumerate() {
                let v = indices[c] as usize;
                tri[k] = *transformed
                    .get(v)
                    .ok_or(ModelError::VertexIndexOutOfRange {
                        face_index,
                        vertex_index: v,
                        vertex_count: transformed.len(),
                    })?;
            }
            if mirrored {
                tri.swap(1, 2);
            }
            self.builder.push_triangle(tri, material);
        }
        Ok(())
    }
}

/// Reads a glTF 2.0 file into world coordinates.
///
/// # Errors
/// [`GltfError::Load`] for unreadable, malformed or truncated files and missing buffers,
/// [`GltfError::Model`] for no faces, non-finite vertices, bad indices, absurd scale.
pub fn load_gltf(path: &Path, options: &ImportOptions) -> Result<ImportedModel, GltfError> {
    let path_str = path.display().to_string();
    let load_err = |e: gltf::Error| GltfError::Load {
        path: path_str.clone(),
        reason: e.to_string(),
    };
    let model_err = |source| GltfError::Model {
        path: path_str.clone(),
        source,
    };
    let file = gltf::Gltf::open(path).map_err(load_err)?;
    let buffers =
        gltf::import_buffers(&file.document, path.parent(), file.blob.clone()).map_err(load_err)?;
    let builder = ModelBuilder::new(options, LengthUnit::Metre, UpAxis::Y).map_err(model_err)?;
    let mut walker = Walker {
        buffers: &buffers,
        builder,
        materials: HashMap::new(),
        vertices_seen: 0,
        ignored_primitives: 0,
    };
    if let Some(scene) = file
        .document
        .default_scene()
        .or_else(|| file.document.scenes().next())
    {
        for node in scene.nodes() {
            walker
                .node(&node, &Matrix4::identity(), 0)
                .map_err(model_err)?;
        }
    }
    if walker.ignored_primitives > 0 {
        walker
            .builder
            .warnings
            .push(ImportWarning::IgnoredEntities {
                kind: "point/line primitive".to_owned(),
                count: walker.ignored_primitives,
            });
    }
    walker.builder.finish().map_err(model_err)
}
