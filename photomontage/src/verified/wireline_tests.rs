use super::*;
use crate::bvh::BuildQuality;
use crate::camera::{Intrinsics, Pose};
use crate::scene::{Material, SceneObject};
use nalgebra::{Matrix3, Rotation3};

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

/// The faces of the box [x0, x1] × [y0, y1] × [0, h] as quads, outward, with or without bottom.
fn box_quads(x0: f64, x1: f64, y0: f64, y1: f64, h: f64, bottom: bool) -> Vec<[Point3<f64>; 4]> {
    let mut q = vec![
        [p(x0, y0, 0.0), p(x1, y0, 0.0), p(x1, y0, h), p(x0, y0, h)], // south
        [p(x1, y0, 0.0), p(x1, y1, 0.0), p(x1, y1, h), p(x1, y0, h)], // east
        [p(x1, y1, 0.0), p(x0, y1, 0.0), p(x0, y1, h), p(x1, y1, h)], // north
        [p(x0, y1, 0.0), p(x0, y0, 0.0), p(x0, y0, h), p(x0, y1, h)], // west
        [p(x0, y0, h), p(x1, y0, h), p(x1, y1, h), p(x0, y1, h)],     // roof
    ];
    if bottom {
        q.push([
            p(x0, y0, 0.0),
            p(x0, y1, 0.0),
            p(x1, y1, 0.0),
            p(x1, y0, 0.0),
        ]);
    }
    q
}

fn triangles(quads: &[[Point3<f64>; 4]]) -> Vec<[Point3<f64>; 3]> {
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

#[test]
fn a_box_has_twelve_feature_edges_and_no_diagonals() {
    for bottom in [true, false] {
        let edges = feature_edges(&triangles(&box_quads(0.0, 2.0, 0.0, 3.0, 4.0, bottom)));
        assert_eq!(edges.len(), 12, "bottom {bottom}");
        // No edge is a face diagonal: every edge runs along one axis.
        for e in &edges {
            let d = e.to_in_world_m - e.from_in_world_m;
            let axes = [d.x, d.y, d.z].iter().filter(|c| c.abs() > 0.0).count();
            assert_eq!(axes, 1, "{e:?}");
        }
    }
    // A flat quad: its four sides only.
    let quad = box_quads(0.0, 1.0, 0.0, 1.0, 1.0, false)[4];
    assert_eq!(feature_edges(&triangles(&[quad])).len(), 4);
}

/// A camera at (1, −10, 1) looking north at a 2 × 2 × 2 box at the origin, with a natural wall
/// 1 m high between them.
fn box_behind_a_wall() -> (Scene, Camera) {
    box_scene(true, None)
}

/// The box and camera of [`box_behind_a_wall`], with or without the wall, and with a natural
/// ground square at `ground_z` when given.
fn box_scene(wall: bool, ground_z: Option<f64>) -> (Scene, Camera) {
    let mut scene = Scene::new();
    let m = scene
        .add_material(Material::diffuse("grey", [0.5; 3]))
        .expect("material");
    let natural = scene
        .add_object(SceneObject {
            name: "wall".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .expect("object");
    if wall {
        scene
            .add_polygon(
                &[
                    p(-5.0, -3.0, 0.0),
                    p(5.0, -3.0, 0.0),
                    p(5.0, -3.0, 1.0),
                    p(-5.0, -3.0, 1.0),
                ],
                m,
                natural,
            )
            .expect("wall");
    }
    if let Some(z) = ground_z {
        scene
            .add_polygon(
                &[
                    p(-50.0, -50.0, z),
                    p(50.0, -50.0, z),
                    p(50.0, 50.0, z),
                    p(-50.0, 50.0, z),
                ],
                m,
                natural,
            )
            .expect("ground");
    }
    let building = scene
        .add_object(SceneObject {
            name: "building".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .expect("object");
    for quad in box_quads(0.0, 2.0, 0.0, 2.0, 2.0, false) {
        scene.add_polygon(&quad, m, building).expect("face");
    }
    let rotation = Rotation3::from_matrix_unchecked(Matrix3::new(
        1.0, 0.0, 0.0, //
        0.0, 0.0, 1.0, //
        0.0, -1.0, 0.0,
    ));
    let camera = Camera {
        intrinsics: Intrinsics::centred(500.0, [400, 300]),
        pose: Pose {
            rotation_world_from_camera: rotation,
            camera_center_in_world: p(1.0, -10.0, 1.0),
        },
    };
    (scene, camera)
}

#[test]
fn hidden_lines_behind_the_wall_and_the_box_itself() {
    let (scene, camera) = box_behind_a_wall();
    let tracer = SceneTracer::new(&scene, BuildQuality::default()).expect("tracer");
    let runs = wireline_runs(&scene, &tracer, &camera);
    let visible_at = |world: Point3<f64>| -> Option<bool> {
        let px = camera.project(&world)?;
        runs.iter()
            .flat_map(|r| r.points_px.iter().map(move |q| (q, r.visible)))
            .filter(|(q, _)| (*q - px).norm() < 0.3)
            .map(|(_, v)| v)
            .reduce(|a, b| a || b)
    };
    // The front top edge (y = 0, z = 2) is visible; the front bottom edge (z = 0) is behind the
    // 1 m wall (the ray from z = 1 to z = 0 crosses the wall plane y = −3 at z = 0.3).
    assert_eq!(visible_at(p(1.0, 0.0, 2.0)), Some(true));
    assert_eq!(visible_at(p(1.5, 0.0, 0.0)), Some(false));
    // The back edges (y = 2) are behind the box itself: the camera is below the roof, so the
    // front face hides the back top edge.
    assert_eq!(visible_at(p(1.0, 2.0, 0.0)), Some(false));
    assert_eq!(visible_at(p(0.5, 2.0, 2.0)), Some(false));
    // The front vertical edges are visible above the wall's sight line and hidden below it:
    // the ray to (0, 0, z) meets y = −3 at height 1 + (z − 1)·0.7, visible when that is > 1.
    assert_eq!(visible_at(p(0.0, 0.0, 1.5)), Some(true));
    assert_eq!(visible_at(p(0.0, 0.0, 0.5)), Some(false));
}

#[test]
fn a_base_sunk_within_the_survey_accuracy_stays_visible() {
    // The camera 1 m up, 10 m away: the ray to the box's front bottom edge meets a ground raised
    // by h at a grazing 5.7°, 10·h metres before the edge but only h behind the ground.
    let visible = |ground_z: f64| {
        let (scene, camera) = box_scene(false, Some(ground_z));
        let tracer = SceneTracer::new(&scene, BuildQuality::default()).expect("tracer");
        let px = camera.project(&p(1.0, 0.0, 0.0)).expect("in front");
        let runs = wireline_runs(&scene, &tracer, &camera);
        runs.iter()
            .flat_map(|r| r.points_px.iter().map(move |q| (q, r.visible)))
            .filter(|(q, _)| (*q - px).norm() < 0.3)
            .any(|(_, v)| v)
    };
    assert!(visible(0.0));
    assert!(
        visible(0.005),
        "5 mm of survey noise must not hide the base"
    );
    assert!(!visible(0.3), "30 cm of ground in front hides it");
}

#[test]
fn rasterised_runs_solid_and_dashed() {
    let solid = EdgeRun {
        points_px: vec![Point2::new(1.0, 1.0), Point2::new(9.0, 1.0)],
        visible: true,
    };
    let dashed = EdgeRun {
        points_px: vec![Point2::new(0.0, 5.0), Point2::new(19.0, 5.0)],
        visible: false,
    };
    let raster = rasterise(&[solid, dashed], [20, 8]);
    let at = |x: usize, y: usize| raster[y * 20 + x];
    assert!((1..=9).all(|x| at(x, 1) == LinePixel::Visible));
    assert!(at(0, 1) == LinePixel::None && at(10, 1) == LinePixel::None);
    // Dashes: on over arc length [0, 6), off over [6, 10), on again from 10.
    assert!((0..=5).all(|x| at(x, 5) == LinePixel::Hidden));
    assert!((7..=9).all(|x| at(x, 5) == LinePixel::None));
    assert!((11..=15).all(|x| at(x, 5) == LinePixel::Hidden));
    assert_eq!(
        raster.iter().filter(|p| **p != LinePixel::None).count(),
        9 + 6 + 6 + 2
    );
}
