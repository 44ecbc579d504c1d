#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::*;
use crate::camera::{Intrinsics, Pose};
use crate::site::{ControlPoint, Site};
use nalgebra::{Matrix3, Rotation3};
use std::path::PathBuf;

/// Placement and projection are a few f64 operations on values near 1–10: agreement to 1e-12
/// (a few ulps of the largest term) is exact arithmetic up to rounding.
const EXACT: f64 = 1e-12;

/// A 2 m cube, corner at the origin, as OBJ quads (6 faces → 12 triangles).
const BOX_OBJ: &str = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

fn doc_in(dir: &Path) -> SiteDocument {
    SiteDocument {
        path: dir.join("site.toml"),
        site: Site::default(),
    }
}

fn longest_m(edges: &ModelEdges) -> f64 {
    edges
        .edges_in_model_m
        .iter()
        .map(|[a, b]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= EXACT)
}

#[test]
fn placement_scales_then_rotates_about_z_then_translates() {
    let placement = Placement {
        translation: [100.0, 200.0, 5.0],
        rotation_z_deg: 90.0,
        scale: 2.0,
    };
    // (1, 0, 3) → scaled (2, 0, 6) → rotated 90° CCW (0, 2, 6) → translated.
    assert!(close(
        world_from_model([1.0, 0.0, 3.0], &placement),
        [100.0, 202.0, 11.0]
    ));
    // (0, 1, 0) → (0, 2, 0) → (−2, 0, 0).
    assert!(close(
        world_from_model([0.0, 1.0, 0.0], &placement),
        [98.0, 200.0, 5.0]
    ));
    assert!(close(
        world_from_model([1.5, -2.0, 3.0], &Placement::default()),
        [1.5, -2.0, 3.0]
    ));
}

#[test]
fn unique_edges_of_a_quad_and_a_cube() {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    // A quad as two triangles: 4 sides and the shared diagonal (once, though met twice and in
    // both directions); a degenerate triangle adds nothing new.
    let quad = [
        [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0)],
        [p(0.0, 0.0, 0.0), p(1.0, 1.0, 0.0), p(0.0, 1.0, 0.0)],
        [p(0.0, 0.0, 0.0), p(0.0, 0.0, 0.0), p(-0.0, 1.0, 0.0)],
    ];
    let edges = unique_edges(&quad);
    assert_eq!(edges.len(), 5, "{edges:?}");
    assert_eq!(
        edges[0],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        "first met first"
    );
    // A cube: 12 edges and one diagonal per face (Euler: E = V + F − 2 = 8 + 12 − 2 = 18).
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("box.obj"), BOX_OBJ).unwrap();
    let doc = doc_in(dir.path());
    let model = new_model_entry(
        &doc,
        &dir.path().join("box.obj"),
        Some(ModelUnits::Centimetre),
        None,
    );
    let edges = model_edges(&doc, &model).unwrap();
    assert_eq!(edges.edges_in_model_m.len(), 18);
    // In metres: a side of 2 units in centimetres is 0.02 m; the longest edge is the face
    // diagonal.
    let longest = longest_m(&edges);
    assert!((longest - 0.02 * 2f64.sqrt()).abs() <= EXACT, "{longest}");
    // 2 cm across lies inside the importer's 1 mm … 10 km range: no scale warning (the
    // importer's note about the missing material is passed on).
    assert!(
        !edges
            .warnings
            .iter()
            .any(|w| matches!(w, SiteWarning::ModelScale { .. })),
        "{:?}",
        edges.warnings
    );
    // In inches the same 18 edges, the face diagonal 2 × 0.0254 × √2 m.
    let inches = CadModel {
        units: ModelUnits::Inch,
        ..model.clone()
    };
    let edges = model_edges(&doc, &inches).unwrap();
    assert_eq!(edges.edges_in_model_m.len(), 18);
    assert!((longest_m(&edges) - 2.0 * 0.0254 * 2f64.sqrt()).abs() <= EXACT);
    // A file that is not there is the importer's error.
    let missing = CadModel {
        file: "nope.obj".into(),
        ..model
    };
    assert!(model_edges(&doc, &missing).is_err());
}

#[test]
fn a_new_entry_takes_a_free_id_a_relative_path_and_the_control_point_centroid() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("cad")).unwrap();
    let obj = dir.path().join("cad/tower block.obj");
    std::fs::write(&obj, BOX_OBJ).unwrap();
    let mut doc = doc_in(dir.path());
    for (id, xyz) in [("A", [0.0, 0.0, 0.0]), ("B", [4.0, 2.0, 10.0])] {
        doc.site.control_points.push(ControlPoint {
            id: id.into(),
            xyz,
            sigma_m: [0.01; 3],
            crs: None,
            enabled: true,
        });
    }
    let m = new_model_entry(&doc, &obj, None, None);
    assert_eq!(m.id, "tower_block");
    assert_eq!(PathBuf::from(&m.file), PathBuf::from("cad/tower block.obj"));
    assert_eq!((m.units.as_str(), m.up_axis.as_str()), ("m", "z"));
    assert!(close(m.placement.translation, [2.0, 1.0, 5.0]));
    assert!(m.visible);
    // The id is taken now: the next import of the same file gets `_2`; glTF is Y up.
    doc.site.models.push(m);
    let again = new_model_entry(
        &doc,
        &obj,
        Some(ModelUnits::Millimetre),
        Some(ModelUpAxis::Y),
    );
    assert_eq!(again.id, "tower_block_2");
    assert_eq!((again.units.as_str(), again.up_axis.as_str()), ("mm", "y"));
    let gltf = new_model_entry(&doc, Path::new("/elsewhere/x.GLB"), None, None);
    assert_eq!(gltf.up_axis, ModelUpAxis::Y);
    assert_eq!(
        gltf.file, "/elsewhere/x.GLB",
        "outside the site folder: kept as given"
    );
}

#[test]
fn wireframe_projects_placed_edges_with_the_pinhole_model() {
    // Camera at (1, −10, 1) looking north (+Y), image x east, y down; f = 500 px, 400 × 300.
    let camera = Camera {
        intrinsics: Intrinsics::centred(500.0, [400, 300]),
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::new(
                1.0, 0.0, 0.0, //
                0.0, 0.0, 1.0, //
                0.0, -1.0, 0.0,
            )),
            camera_center_in_world: Point3::new(1.0, -10.0, 1.0),
        },
    };
    let edges = ModelEdges {
        edges_in_model_m: vec![
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            // Ends 20 m south of the model origin: behind the camera.
            [[0.0, 0.0, 0.0], [0.0, -20.0, 0.0]],
        ],
        warnings: Vec::new(),
    };
    // Model origin placed on the optical axis, 10 m ahead.
    let placement = Placement {
        translation: [1.0, 0.0, 1.0],
        rotation_z_deg: 0.0,
        scale: 1.0,
    };
    let segments = wireframe_px(&camera, &edges, &placement);
    assert_eq!(
        segments.len(),
        1,
        "the edge reaching behind the camera is dropped"
    );
    let [a, b] = segments[0];
    // The origin is at the principal point ((w − 1)/2, (h − 1)/2); 1 m east at 10 m is
    // f · 1/10 = 50 px right.
    assert!(
        (a[0] - 199.5).abs() <= EXACT && (a[1] - 149.5).abs() <= EXACT,
        "{a:?}"
    );
    assert!(
        (b[0] - 249.5).abs() <= EXACT && (b[1] - 149.5).abs() <= EXACT,
        "{b:?}"
    );
    // Scaled by 2 and turned 90° CCW, the unit edge points north (away): its end is 2 m
    // further, still on the axis.
    let turned = Placement {
        rotation_z_deg: 90.0,
        scale: 2.0,
        ..placement
    };
    let [a, b] = wireframe_px(&camera, &edges, &turned)[0];
    assert!(
        (a[0] - b[0]).abs() <= 1e-9 && (a[1] - b[1]).abs() <= 1e-9,
        "{a:?} {b:?}"
    );
}
