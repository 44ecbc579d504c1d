//! Importer tests on the small hand-written fixtures in `tests/fixtures/` (OBJ+MTL, glTF with
//! embedded base64 buffers, DXF), including broken files and their exact errors.
//!
//! Expected values are worked out by hand from the fixture text (see the comments there).

use std::path::{Path, PathBuf};

use nalgebra::{Point3, Vector3};
use photomontage::bvh::BuildQuality;
use photomontage::scene::{
    ImportOptions, ImportWarning, ImportedModel, LengthUnit, ModelError, ObjectKind, Scene,
    SceneTracer,
    dxf::{DxfError, load_dxf},
    gltf::{GltfError, load_gltf},
    obj::{ObjError, load_obj},
};

/// Fixture coordinates are small integers scaled by exact unit factors (1e-3, powers of two):
/// results agree to rounding of a few operations.
const COORD_TOL_M: f64 = 1e-9;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn normal(tri: &[Point3<f64>; 3]) -> Vector3<f64> {
    (tri[1] - tri[0]).cross(&(tri[2] - tri[0]))
}

fn total_area(m: &ImportedModel, material: u32) -> f64 {
    m.triangles_in_world_m
        .iter()
        .zip(&m.triangle_materials)
        .filter(|(_, mm)| **mm == material)
        .map(|(t, _)| normal(t).norm() / 2.0)
        .sum()
}

fn close(a: &Point3<f64>, b: [f64; 3]) -> bool {
    (a - Point3::from(b)).norm() < COORD_TOL_M
}

#[test]
fn obj_with_concave_face_and_mtl() {
    let m = load_obj(&fixture("house.obj"), &ImportOptions::default()).unwrap();
    // L floor (area 3) → 4 triangles, wall quad → 2, triangle → 1.
    assert_eq!(m.triangles_in_world_m.len(), 7);
    let names: Vec<&str> = m.materials.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["floor", "glass_pane", "default"]);
    assert!((total_area(&m, 0) - 3.0).abs() < COORD_TOL_M);
    assert!(
        m.triangles_in_world_m[..4]
            .iter()
            .all(|t| normal(t).z > 0.0),
        "floor faces up"
    );
    assert!(
        m.triangles_in_world_m[4..6]
            .iter()
            .all(|t| normal(t).y < 0.0),
        "wall faces −y"
    );
    let kd = m.materials[0].diffuse_rgb;
    assert!(
        kd.iter()
            .zip([0.6, 0.5, 0.4])
            .all(|(a, b)| (a - b).abs() < 1e-12),
        "{kd:?}"
    );
    let glass = m.materials[1].glass.unwrap();
    assert!((glass.ior - 1.52).abs() < 1e-12 && (glass.transmittance_rgb[0] - 0.8).abs() < 1e-12);
    // Ns 900 → roughness (2/902)^¼.
    let s = m.materials[1].specular.unwrap();
    assert!(
        (s.roughness - (2.0f64 / 902.0).powf(0.25)).abs() < 1e-12 && (s.f0 - 0.04).abs() < 1e-12
    );
    assert_eq!(
        m.warnings,
        vec![ImportWarning::FacesWithoutMaterial { triangle_count: 1 }]
    );
}

#[test]
fn obj_units_axes_and_placement() {
    let options = ImportOptions {
        unit: Some(LengthUnit::Centimetre),
        up_axis: Some(photomontage::scene::UpAxis::Y),
        placement: photomontage::scene::Placement {
            translation_in_world_m: [600_000.0, 200_000.0, 400.0],
            rotation_about_z_deg: 180.0,
            scale: 1.0,
        },
        ..ImportOptions::default()
    };
    let m = load_obj(&fixture("house.obj"), &options).unwrap();
    // File vertex 8 (2, 0, 3) cm, Y up → (0.02, −0.03, 0) m, rotated 180° → (−0.02, 0.03, 0).
    let expected = [600_000.0 - 0.02, 200_000.03, 400.0];
    assert!(
        m.triangles_in_world_m
            .iter()
            .flatten()
            .any(|p| close(p, expected))
    );
}

#[test]
fn obj_broken_files_give_exact_errors() {
    let o = ImportOptions::default();
    assert!(matches!(
        load_obj(&fixture("no_faces.obj"), &o),
        Err(ObjError::Model {
            source: ModelError::NoFaces,
            ..
        })
    ));
    match load_obj(&fixture("nan_vertex.obj"), &o) {
        Err(ObjError::Model {
            source:
                ModelError::NonFiniteVertex {
                    vertex_index: 1,
                    coordinates,
                },
            ..
        }) => {
            assert!(coordinates[0].is_nan());
        }
        other => panic!("{other:?}"),
    }
    match load_obj(&fixture("truncated.obj"), &o) {
        Err(ObjError::Load { reason, .. }) => assert_eq!(reason, "position parse error"),
        other => panic!("{other:?}"),
    }
    match load_obj(&fixture("out_of_range.obj"), &o) {
        Err(ObjError::Load { reason, .. }) => assert_eq!(reason, "face vertex index out of bounds"),
        other => panic!("{other:?}"),
    }
    match load_obj(&fixture("absent.obj"), &o) {
        Err(ObjError::Load { reason, .. }) => assert!(reason.contains("No such file"), "{reason}"),
        other => panic!("{other:?}"),
    }
    // A missing MTL is a warning, not an error; the face gets the default material.
    let m = load_obj(&fixture("missing_mtl.obj"), &o).unwrap();
    assert_eq!(m.materials.len(), 1);
    assert_eq!(m.materials[0].name, "default");
    assert!(
        matches!(&m.warnings[0], ImportWarning::MissingMaterialLibrary { name, .. } if name == "does_not_exist.mtl")
    );
    assert_eq!(
        m.warnings[1],
        ImportWarning::FacesWithoutMaterial { triangle_count: 1 }
    );
    // Millimetres make the 1-unit triangle 1 mm: accepted (the limit is inclusive); 0.1 mm is not.
    let mm = ImportOptions {
        unit: Some(LengthUnit::Millimetre),
        ..o
    };
    assert!(load_obj(&fixture("missing_mtl.obj"), &mm).is_ok());
    let tiny = ImportOptions {
        placement: photomontage::scene::Placement {
            scale: 0.1,
            ..Default::default()
        },
        ..mm
    };
    assert!(matches!(
        load_obj(&fixture("missing_mtl.obj"), &tiny),
        Err(ObjError::Model {
            source: ModelError::AbsurdScale { .. },
            ..
        })
    ));
}

#[test]
fn gltf_node_transforms_materials_and_axes() {
    let m = load_gltf(&fixture("quad_nodes.gltf"), &ImportOptions::default()).unwrap();
    assert_eq!(m.triangles_in_world_m.len(), 2);
    // Quad (0..1)² in glTF XY, child scale 2, parent translation (10,0,0), then Y-up → Z-up.
    let [a, b, c] = m.triangles_in_world_m[0];
    assert!(
        close(&a, [10.0, 0.0, 0.0]) && close(&b, [12.0, 0.0, 0.0]) && close(&c, [12.0, 0.0, 2.0]),
        "{a} {b} {c}"
    );
    assert!(
        normal(&m.triangles_in_world_m[0]).y < 0.0,
        "glTF +Z front → world −Y"
    );
    let mat = &m.materials[0];
    assert_eq!(mat.name, "red_metal");
    assert!(
        mat.diffuse_rgb.iter().all(|c| c.abs() < 1e-12),
        "fully metallic: no diffuse"
    );
    let s = mat.specular.unwrap();
    assert!((s.roughness - 0.25).abs() < 1e-7 && (s.f0 - (0.8 + 0.1 + 0.1) / 3.0).abs() < 1e-7);
    assert!(m.warnings.is_empty());
}

#[test]
fn gltf_broken_files_give_exact_errors() {
    let o = ImportOptions::default();
    assert!(matches!(
        load_gltf(&fixture("no_faces.gltf"), &o),
        Err(GltfError::Model {
            source: ModelError::NoFaces,
            ..
        })
    ));
    assert!(matches!(
        load_gltf(&fixture("nan_vertex.gltf"), &o),
        Err(GltfError::Model {
            source: ModelError::NonFiniteVertex {
                vertex_index: 1,
                ..
            },
            ..
        })
    ));
    match load_gltf(&fixture("truncated.gltf"), &o) {
        Err(GltfError::Load { reason, .. }) => assert!(reason.contains("EOF"), "{reason}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn dxf_3dface_polyface_and_polygon_mesh_in_millimetres() {
    let m = load_dxf(&fixture("model_mm.dxf"), &ImportOptions::default()).unwrap();
    // 3DFACE triangle 1 + 3DFACE quad 2 + polyface tetrahedron 4 + 2×3 polygon mesh 4.
    assert_eq!(m.triangles_in_world_m.len(), 11);
    let names: Vec<&str> = m.materials.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["roof", "walls", "terrain"]);
    assert_eq!(
        m.warnings,
        vec![ImportWarning::IgnoredEntities {
            kind: "Line".into(),
            count: 1
        }]
    );
    assert!(
        close(&m.triangles_in_world_m[0][1], [1.0, 0.0, 3.0]),
        "$INSUNITS 4 = millimetres"
    );
    // The tetrahedron is closed with outward faces: the divergence theorem gives its volume,
    // 1/6 m³ for unit legs.
    let volume: f64 = m
        .triangles_in_world_m
        .iter()
        .zip(&m.triangle_materials)
        .filter(|(_, mm)| **mm == 1)
        .map(|(t, _)| t[0].coords.dot(&t[1].coords.cross(&t[2].coords)) / 6.0)
        .sum();
    assert!((volume - 1.0 / 6.0).abs() < COORD_TOL_M, "{volume}");
    assert!(
        (total_area(&m, 2) - 2.0).abs() < COORD_TOL_M,
        "polygon mesh 2 m × 1 m"
    );
}

#[test]
fn dxf_broken_files_give_exact_errors() {
    let o = ImportOptions::default();
    assert!(matches!(
        load_dxf(&fixture("no_faces.dxf"), &o),
        Err(DxfError::Model {
            source: ModelError::NoFaces,
            ..
        })
    ));
    assert!(matches!(
        load_dxf(&fixture("nan_vertex.dxf"), &o),
        Err(DxfError::Model {
            source: ModelError::NonFiniteVertex {
                vertex_index: 1,
                ..
            },
            ..
        })
    ));
    assert!(matches!(
        load_dxf(&fixture("truncated.dxf"), &o),
        Err(DxfError::Load { .. })
    ));
}

#[test]
fn imported_model_is_traced_with_its_materials() {
    let mut scene = Scene::new();
    let options = ImportOptions {
        placement: photomontage::scene::Placement {
            translation_in_world_m: [600_000.0, 200_000.0, 400.0],
            ..Default::default()
        },
        ..ImportOptions::default()
    };
    let (id, warnings) = scene
        .import_file(&fixture("house.obj"), &options, ObjectKind::Artificial)
        .unwrap();
    assert_eq!(warnings.len(), 1);
    let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
    // Straight down onto the L floor's concave corner region (1.5, 0.5) and onto the notch (1.5, 1.5).
    let down = Vector3::new(0.0, 0.0, -1.0);
    let ray = tracer.ray_from_world(
        &Point3::new(600_001.5, 200_000.5, 410.0),
        &down,
        0.0,
        f32::INFINITY,
    );
    let hit = tracer.closest_hit(&ray).unwrap();
    assert_eq!(hit.object, id);
    assert_eq!(scene.materials()[hit.material.0 as usize].name, "floor");
    assert!((f64::from(hit.hit.t) - 10.0).abs() < 1e-4);
    let notch = tracer.ray_from_world(
        &Point3::new(600_001.5, 200_001.5, 410.0),
        &down,
        0.0,
        f32::INFINITY,
    );
    assert!(
        tracer.closest_hit(&notch).is_none(),
        "the concave notch is not covered"
    );
}
