//! Wavefront OBJ + MTL import (via `tobj`), Durisch 1992 §5 "CONVERT" for a format architects'
//! tools export today.
//!
//! Faces keep file order: triangle `i` of a triangle-only file is the `i`-th `f` line, as in the
//! Embree benchmark's convention. Polygons with more than three vertices are triangulated by ear
//! clipping in their plane ([`super::triangulate`]), so concave faces come out right (tobj's own
//! triangulation is a fan). Materials: `Kd` → diffuse, `Ks`/`Ns` → GGX specular
//! (roughness = (2/(Ns+2))^¼, the Blinn–Phong to Beckmann/GGX correspondence α² = 2/(Ns+2)),
//! `Ni` with `d` < 1 → glass, `Ke` → emission. A missing MTL file or unknown `usemtl` gives a
//! warning and the default material. Default unit metres, default up axis Z.
//!
//! # Known limitations
//! Texture maps, normals and texture coordinates are ignored. tobj reports parse errors without a
//! line number. Point and line elements are ignored.

use std::path::Path;

use crate::bounded_read::{BoundedReadError, MAX_MODEL_FILE_BYTES, read_bounded};

use super::import::{
    ImportOptions, ImportWarning, ImportedModel, LengthUnit, ModelBuilder, ModelError, UpAxis,
};
use super::material::{Glass, Material, Specular};

/// Largest MTL library read (real ones are kilobytes).
pub const MAX_MTL_FILE_BYTES: u64 = 64 << 20;

/// Errors reading an OBJ file.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// tobj could not read or parse the file.
    #[error("cannot read OBJ {path}: {reason}")]
    Load {
        /// File path.
        path: String,
        /// tobj's description.
        reason: String,
    },
    /// The OBJ or an MTL library it names is not a regular file under the size cap.
    #[error("OBJ {path}: {source}")]
    Referenced {
        /// The OBJ file.
        path: String,
        /// Which file and why (boxed: keeps the error enums small).
        source: Box<crate::bounded_read::BoundedReadError>,
    },
    /// The geometry failed a model check.
    #[error("OBJ {path}: {source}")]
    Model {
        /// File path.
        path: String,
        /// The failed check.
        source: ModelError,
    },
}

fn material_from_mtl(m: &tobj::Material) -> Material {
    let mut out = Material::diffuse(
        &m.name,
        m.diffuse.unwrap_or([0.5; 3]).map(|c| c.clamp(0.0, 1.0)),
    );
    if let Some(ks) = m.specular {
        let f0 = (ks[0] + ks[1] + ks[2]) / 3.0;
        if f0 > 0.0 {
            let ns = m.shininess.unwrap_or(0.0).max(0.0);
            let roughness = (2.0 / (ns + 2.0)).powf(0.25).clamp(1e-3, 1.0);
            out.specular = Some(Specular {
                roughness,
                f0: f0.clamp(0.0, 1.0),
            });
        }
    }
    if let Some(d) = m.dissolve
        && d < 1.0
    {
        out.glass = Some(Glass {
            ior: m.optical_density.unwrap_or(1.5).max(1.0),
            transmittance_rgb: [(1.0 - d).clamp(0.0, 1.0); 3],
        });
    }
    if let Some(ke) = m.unknown_param.get("Ke") {
        let v: Vec<f64> = ke
            .split_whitespace()
            .filter_map(|s| s.parse().ok())
            .collect();
        if let [r, g, b] = v[..]
            && [r, g, b].iter().all(|x| x.is_finite() && *x >= 0.0)
            && r + g + b > 0.0
        {
            out.emission_rgb_w_m2_sr = Some([r, g, b]);
        }
    }
    out
}

/// The first MTL colour statement (`Ka`, `Kd`, `Ks`, `Ke`) with fewer than three values, as
/// `line N: ...`. tobj 4.0 panics on those (an `unwrap` in its `parse_float3`; found by the
/// `obj_mtl` fuzz target), so the library is checked before tobj reads it. Lines split as tobj
/// splits them (`\n`, an optional `\r` dropped).
fn short_colour_line(mtl: &[u8]) -> Option<String> {
    String::from_utf8_lossy(mtl)
        .lines()
        .enumerate()
        .find_map(|(index, line)| {
            let mut words = line.split_whitespace();
            let keyword = words.next()?;
            let values = words.count();
            (matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke") && values < 3).then(|| {
                format!(
                    "line {}: `{keyword}` needs 3 numbers (r g b), found {values}",
                    index + 1
                )
            })
        })
}

/// Reads an OBJ file (and its MTL libraries) into world coordinates.
///
/// # Errors
/// [`ObjError::Load`] for unreadable or malformed files (including face indices out of range),
/// [`ObjError::Model`] for no faces, non-finite vertices, absurd scale or bad placement.
pub fn load_obj(path: &Path, options: &ImportOptions) -> Result<ImportedModel, ObjError> {
    let path_str = path.display().to_string();
    let model_err = |source| ObjError::Model {
        path: path_str.clone(),
        source,
    };
    let load_options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let referenced = |source| ObjError::Referenced {
        path: path_str.clone(),
        source: Box::new(source),
    };
    let obj_bytes = read_bounded(path, MAX_MODEL_FILE_BYTES).map_err(|e| match e {
        BoundedReadError::Io { source, .. } => ObjError::Load {
            path: path_str.clone(),
            reason: source.to_string(),
        },
        other => referenced(other),
    })?;
    // MTL libraries go through the same check; tobj's loader can only say "failed", so the
    // reason waits here.
    let mtl_refusal = std::cell::RefCell::new(None);
    let mtl_malformed: std::cell::RefCell<Option<String>> = std::cell::RefCell::new(None);
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let loaded =
        tobj::load_obj_buf(
            &mut obj_bytes.as_slice(),
            &load_options,
            |mtl_path| match read_bounded(&folder.join(mtl_path), MAX_MTL_FILE_BYTES) {
                Ok(bytes) => match short_colour_line(&bytes) {
                    Some(reason) => {
                        mtl_malformed
                            .borrow_mut()
                            .get_or_insert_with(|| format!("{}: {reason}", mtl_path.display()));
                        Err(tobj::LoadError::MaterialParseError)
                    }
                    None => tobj::load_mtl_buf(&mut bytes.as_slice()),
                },
                Err(BoundedReadError::Io { .. }) => Err(tobj::LoadError::OpenFileFailed),
                Err(e) => {
                    mtl_refusal.borrow_mut().get_or_insert(e);
                    Err(tobj::LoadError::OpenFileFailed)
                }
            },
        );
    if let Some(e) = mtl_refusal.into_inner() {
        return Err(referenced(e));
    }
    let (models, materials) = loaded.map_err(|e| ObjError::Load {
        path: path_str.clone(),
        reason: e.to_string(),
    })?;
    let mut builder =
        ModelBuilder::new(options, LengthUnit::Metre, UpAxis::Z).map_err(model_err)?;
    let material_ids: Vec<u32> = match materials {
        Ok(mats) => mats
            .iter()
            .map(|m| builder.add_material(material_from_mtl(m)))
            .collect(),
        Err(e) => {
            builder
                .warnings
                .push(ImportWarning::MissingMaterialLibrary {
                    name: mtllib_names(&obj_bytes).join(", "),
                    reason: mtl_malformed.take().unwrap_or_else(|| e.to_string()),
                });
            Vec::new()
        }
    };
    // tobj keeps only the vertices that faces use, so the reported index counts those.
    ModelBuilder::check_finite(
        models
            .iter()
            .flat_map(|m| m.mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
    )
    .map_err(model_err)?;
    for model in &models {
        let mesh = &model.mesh;
        let material = mesh.material_id.and_then(|i| material_ids.get(i).copied());
        let vertex = |i: u32| -> [f64; 3] {
            let i = i as usize * 3;
            [
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            ]
        };
        if mesh.face_arities.is_empty() {
            for tri in mesh.indices.chunks_exact(3) {
                builder.push_triangle([vertex(tri[0]), vertex(tri[1]), vertex(tri[2])], material);
            }
        } else {
            let mut start = 0usize;
            for &arity in &mesh.face_arities {
                let end = start + arity as usize;
                let Some(face) = mesh.indices.get(start..end) else {
                    break;
                };
                let poly: Vec<[f64; 3]> = face.iter().map(|&i| vertex(i)).collect();
                if poly.len() >= 3 {
                    builder.push_polygon(&poly, material);
                }
                start = end;
            }
        }
    }
    builder.finish().map_err(model_err)
}

/// The `mtllib` names an OBJ file mentions (for the warning text only).
fn mtllib_names(obj_bytes: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(obj_bytes)
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mtllib "))
        .map(|s| s.trim().to_owned())
        .take(16)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn mtllib_naming_a_device_file_is_refused() {
        // `mtllib /dev/zero` once read until the allocation of 8 GB aborted.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(&path, format!("mtllib /dev/zero\n{TRIANGLE}")).unwrap();
        let err = load_obj(&path, &ImportOptions::default()).unwrap_err();
        assert!(
            matches!(
                &err,
                ObjError::Referenced {
                    source,
                    ..
                } if matches!(**source, BoundedReadError::NotRegularFile { .. })
            ),
            "{err}"
        );
        assert!(err.to_string().contains("/dev/zero"), "{err}");
    }

    #[test]
    fn missing_mtllib_stays_a_warning_and_a_real_one_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(&path, format!("mtllib gone.mtl\n{TRIANGLE}")).unwrap();
        let model = load_obj(&path, &ImportOptions::default()).unwrap();
        assert!(
            model
                .warnings
                .iter()
                .any(|w| matches!(w, ImportWarning::MissingMaterialLibrary { name, .. } if name == "gone.mtl"))
        );
        std::fs::write(dir.path().join("ok.mtl"), "newmtl red\nKd 0.8 0.1 0.1\n").unwrap();
        std::fs::write(&path, format!("mtllib ok.mtl\nusemtl red\n{TRIANGLE}")).unwrap();
        let model = load_obj(&path, &ImportOptions::default()).unwrap();
        assert!(
            model.materials.iter().any(|m| m.name == "red"),
            "{:?}",
            model.materials
        );
    }

    #[test]
    fn obj_that_is_a_device_is_refused() {
        assert!(matches!(
            load_obj(Path::new("/dev/zero"), &ImportOptions::default()),
            Err(ObjError::Referenced { .. })
        ));
    }
}
