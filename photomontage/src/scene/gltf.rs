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
use crate::bounded_read::{MAX_MODEL_FILE_BYTES, check_regular_file, read_bounded};

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
    /// The file or a buffer file it names is not a regular file under the size cap.
    #[error("glTF {path}: {source}")]
    Referenced {
        /// The glTF file.
        path: String,
        /// Which file and why (boxed: keeps the error enums small).
        source: Box<crate::bounded_read::BoundedReadError>,
    },
    /// A buffer holds fewer bytes than its `byteLength` says.
    #[error(
        "glTF {path}: buffers[{buffer}] ({origin}) holds {actual} bytes but its byteLength is {expected}"
    )]
    ShortBuffer {
        /// The glTF file.
        path: String,
        /// Index of the buffer.
        buffer: usize,
        /// Where its bytes come from (a file, a data URI, the GLB binary chunk); boxed to keep
        /// the error enums small.
        origin: Box<str>,
        /// `byteLength`.
        expected: usize,
        /// Bytes present.
        actual: usize,
    },
    /// A node is its own ancestor.
    #[error("glTF {path}: nodes[{node}]{} is its own ancestor (a cycle in the node hierarchy)", name.as_ref().map(|n| format!(" `{n}`")).unwrap_or_default())]
    NodeCycle {
        /// The glTF file.
        path: String,
        /// Index of a node on the cycle.
        node: usize,
        /// Its name, when it has one.
        name: Option<String>,
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

/// Refuses a node hierarchy with a cycle (the glTF crate would follow it until the depth cap,
/// compounding transforms into a 10¹⁰ m bounding box), by depth-first search over all nodes.
/// Size of the GLB file header (magic, version, total length), glTF 2.0 §4.4.2.
const GLB_HEADER_BYTES: u32 = 12;

/// Parses and validates glTF or GLB bytes. gltf-json 1.4's validation indexes `accessors` with
/// a primitive's `POSITION` index before checking it (a panic on an index past the end; found
/// by the `gltf` fuzz target), so the file is parsed without validation, the `POSITION` indices
/// are checked here, and only then is the crate's validation run; then the accessors the
/// importer reads are checked against what the crate's readers assume (`gltf_accessors`).
fn parse_validated(bytes: &[u8]) -> Result<gltf::Gltf, String> {
    // gltf 1.4's `Glb::from_slice` subtracts the 12-byte header from the declared length
    // unchecked (an overflow panic with overflow checks on; found by the `gltf` fuzz target).
    if let Some(declared) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .and_then(|b| <[u8; 4]>::try_from(b).ok())
        .map(u32::from_le_bytes)
        && declared < GLB_HEADER_BYTES
    {
        return Err(format!(
            "GLB header declares a total length of {declared} bytes, less than the {GLB_HEADER_BYTES}-byte header itself"
        ));
    }
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| e.to_string())?;
    let json = document.into_json();
    super::gltf_accessors::check_position_indices(&json)?;
    let document = gltf::Document::from_json(json).map_err(|e| e.to_string())?;
    super::gltf_accessors::check_primitive_accessors(document.as_json())?;
    Ok(gltf::Gltf { document, blob })
}

fn check_node_cycles(document: &gltf::Document, path: &str) -> Result<(), GltfError> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        OnPath,
        Done,
    }
    let nodes: Vec<gltf::Node<'_>> = document.nodes().collect();
    let mut marks = vec![Mark::New; nodes.len()];
    for root in 0..nodes.len() {
        if marks[root] != Mark::New {
            continue;
        }
        // Explicit stack of (node, next child position): no recursion on untrusted depth.
        let mut stack = vec![(root, 0usize)];
        marks[root] = Mark::OnPath;
        while let Some(&mut (node, ref mut next)) = stack.last_mut() {
            let child = nodes[node].children().nth(*next).map(|c| c.index());
            *next += 1;
            match child {
                None => {
                    marks[node] = Mark::Done;
                    stack.pop();
                }
                Some(c) if marks.get(c) == Some(&Mark::OnPath) => {
                    return Err(GltfError::NodeCycle {
                        path: path.to_owned(),
                        node: c,
                        name: nodes[c].name().map(str::to_owned),
                    });
                }
                Some(c) if marks.get(c) == Some(&Mark::New) => {
                    marks[c] = Mark::OnPath;
                    stack.push((c, 0));
                }
                Some(_) => {}
            }
        }
    }
    Ok(())
}

/// `%XX` decoding of a relative URI; `None` when the result is not UTF-8 (the glTF crate would
/// panic on it).
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && let Some(v) = uri
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            out.push(v);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Checks every buffer before it is read: external files must be regular files under the cap,
/// and every source must hold at least `byteLength` bytes (the glTF crate pads short buffers to
/// a multiple of 4 and so accepts up to 3 missing bytes).
fn check_buffers(file: &gltf::Gltf, base: Option<&Path>, path: &str) -> Result<(), GltfError> {
    for buffer in file.document.buffers() {
        let (actual, origin) = match buffer.source() {
            gltf::buffer::Source::Bin => (
                file.blob.as_ref().map_or(0, Vec::len),
                "the GLB binary chunk".to_owned(),
            ),
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let payload = uri.split_once(',').map_or("", |(_, p)| p);
                let digits = payload.trim_end_matches('=').len();
                (digits * 3 / 4, "its data URI".to_owned())
            }
            gltf::buffer::Source::Uri(uri) if !uri.contains(':') => {
                let relative = percent_decode(uri).ok_or_else(|| GltfError::Load {
                    path: path.to_owned(),
                    reason: format!(
                        "buffers[{}].uri `{uri}` is not UTF-8 after %-decoding",
                        buffer.index()
                    ),
                })?;
                let file_path = base.unwrap_or(Path::new("")).join(relative);
                check_regular_file(&file_path, MAX_MODEL_FILE_BYTES).map_err(|source| {
                    GltfError::Referenced {
                        path: path.to_owned(),
                        source: Box::new(source),
                    }
                })?;
                let len = std::fs::metadata(&file_path).map_or(0, |m| m.len());
                (
                    usize::try_from(len).unwrap_or(usize::MAX),
                    file_path.display().to_string(),
                )
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("file:") => {
                let file_path = Path::new(
                    uri.strip_prefix("file://")
                        .or_else(|| uri.strip_prefix("file:"))
                        .unwrap_or(uri),
                );
                check_regular_file(file_path, MAX_MODEL_FILE_BYTES).map_err(|source| {
                    GltfError::Referenced {
                        path: path.to_owned(),
                        source: Box::new(source),
                    }
                })?;
                continue;
            }
            // Other schemes: the glTF crate reports them.
            gltf::buffer::Source::Uri(_) => continue,
        };
        if actual < buffer.length() {
            return Err(GltfError::ShortBuffer {
                path: path.to_owned(),
                buffer: buffer.index(),
                origin: origin.into_boxed_str(),
                expected: buffer.length(),
                actual,
            });
        }
    }
    Ok(())
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
    let referenced = |source| GltfError::Referenced {
        path: path_str.clone(),
        source: Box::new(source),
    };
    let bytes = read_bounded(path, MAX_MODEL_FILE_BYTES).map_err(referenced)?;
    let file = parse_validated(&bytes).map_err(|reason| GltfError::Load {
        path: path_str.clone(),
        reason,
    })?;
    check_node_cycles(&file.document, &path_str)?;
    check_buffers(&file, path.parent(), &path_str)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = include_str!("../../tests/fixtures/quad_nodes.gltf");

    /// Writes the quad fixture, edited by `edit`, as `model.gltf` in `dir`.
    fn write_edited(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> std::path::PathBuf {
        let mut json: serde_json::Value = serde_json::from_str(QUAD).unwrap();
        edit(&mut json);
        let path = dir.join("model.gltf");
        std::fs::write(&path, serde_json::to_string(&json).unwrap()).unwrap();
        path
    }

    #[test]
    fn node_cycle_is_an_error_naming_the_node() {
        // child → parent makes parent its own ancestor; this was once a 4.7e10 m model.
        let dir = tempfile::tempdir().unwrap();
        let path = write_edited(dir.path(), |j| {
            j["nodes"][1]["children"] = serde_json::json!([0])
        });
        let err = load_gltf(&path, &ImportOptions::default()).unwrap_err();
        assert!(
            matches!(&err, GltfError::NodeCycle { node: 0, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("nodes[0] `parent`"), "{err}");
    }

    #[test]
    fn buffer_short_of_its_byte_length_is_refused() {
        // 58 bytes for a byteLength of 60: the glTF crate pads to 60 and accepted it.
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("short.bin"), [0u8; 58]).unwrap();
        let path = write_edited(dir.path(), |j| j["buffers"][0]["uri"] = "short.bin".into());
        let err = load_gltf(&path, &ImportOptions::default()).unwrap_err();
        assert!(
            matches!(
                &err,
                GltfError::ShortBuffer {
                    buffer: 0,
                    expected: 60,
                    actual: 58,
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("short.bin"), "{err}");
    }

    #[test]
    fn buffer_naming_a_device_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        for uri in ["/dev/zero", "file:///dev/zero"] {
            let path = write_edited(dir.path(), |j| j["buffers"][0]["uri"] = uri.into());
            let err = load_gltf(&path, &ImportOptions::default()).unwrap_err();
            assert!(matches!(&err, GltfError::Referenced { .. }), "{uri}: {err}");
            assert!(err.to_string().contains("/dev/zero"), "{err}");
        }
    }

    #[test]
    fn the_fixture_still_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = write_edited(dir.path(), |_| {});
        assert!(load_gltf(&path, &ImportOptions::default()).is_ok());
    }
}
