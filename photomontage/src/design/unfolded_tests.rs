// Exact comparisons: the values are copied, not computed.
#![allow(clippy::float_cmp)]

use super::*;
use crate::scene::{Material, ObjectKind, SceneObject};

/// A 10 m (x) × 6 m (y) × 8 m box with walls of `wall` and a roof, as one object.
fn box_scene(wall: [f64; 3]) -> (Scene, ObjectId) {
    let mut scene = Scene::new();
    let object = scene
        .add_object(SceneObject {
            name: "block".to_owned(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let wall_id = scene.add_material(Material::diffuse("wall", wall)).unwrap();
    let roof_id = scene
        .add_material(Material::diffuse("roof", [0.1; 3]))
        .unwrap();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let faces = [
        [p(0., 0., 0.), p(10., 0., 0.), p(10., 0., 8.), p(0., 0., 8.)],
        [
            p(10., 0., 0.),
            p(10., 6., 0.),
            p(10., 6., 8.),
            p(10., 0., 8.),
        ],
        [p(10., 6., 0.), p(0., 6., 0.), p(0., 6., 8.), p(10., 6., 8.)],
        [p(0., 6., 0.), p(0., 0., 0.), p(0., 0., 8.), p(0., 6., 8.)],
    ];
    for f in &faces {
        scene.add_polygon(f, wall_id, object).unwrap();
    }
    let roof = [p(0., 0., 8.), p(10., 0., 8.), p(10., 6., 8.), p(0., 6., 8.)];
    scene.add_polygon(&roof, roof_id, object).unwrap();
    (scene, object)
}

#[test]
fn box_facades_have_their_widths_in_pixels() {
    let (scene, object) = box_scene([0.3, 0.2, 0.1]);
    let params = UnfoldParams {
        px_per_m: 10.0,
        ..UnfoldParams::default()
    };
    let layout = unfold(&scene, object, &params).unwrap();
    let got: Vec<(String, u32, u32)> = layout
        .panels
        .iter()
        .map(|p| (p.compass().to_owned(), p.x0_px, p.width_px))
        .collect();
    // N, E, S, W: 10 m, 6 m, 10 m, 6 m at 10 px/m, GAP_PX apart after the margin.
    let want = [
        ("n", 20, 100),
        ("e", 136, 60),
        ("s", 212, 100),
        ("w", 328, 60),
    ];
    assert_eq!(got.len(), 4, "{got:?}");
    for ((c, x0, w), (wc, wx0, ww)) in got.iter().zip(want) {
        assert_eq!((c.as_str(), *x0, *w), (wc, wx0, ww), "{got:?}");
    }
    assert_eq!(layout.height_px, 80);
    assert_eq!(layout.z_range_m, [0.0, 8.0]);
    // The roof is not a façade: 4 panels of 2 triangles each.
    assert!(layout.panels.iter().all(|p| p.triangles.len() == 2));

    let drawn = draw(&scene, &layout, Shading::Colour);
    let want_px = crate::colour::designer::srgb8_from_linear([0.3, 0.2, 0.1]);
    for panel in &layout.panels {
        for (x, y) in [
            (panel.x0_px, layout.y0_px),
            (
                panel.x0_px + panel.width_px - 1,
                layout.y0_px + layout.height_px - 1,
            ),
            (
                panel.x0_px + panel.width_px / 2,
                layout.y0_px + layout.height_px / 2,
            ),
        ] {
            assert_eq!(
                drawn.image.get_pixel(x, y).0,
                want_px,
                "panel {} at ({x}, {y})",
                panel.compass()
            );
        }
        // The gap after each panel is background.
        let gap = drawn
            .image
            .get_pixel(panel.x0_px + panel.width_px, layout.y0_px + 5)
            .0;
        assert_eq!(gap, BACKGROUND);
    }
    assert!(drawn.max_irradiance_y.is_none());
}

#[test]
fn pixel_points_lie_on_their_facade() {
    let (scene, object) = box_scene([0.5; 3]);
    let layout = unfold(
        &scene,
        object,
        &UnfoldParams {
            px_per_m: 10.0,
            ..UnfoldParams::default()
        },
    )
    .unwrap();
    // South façade (third panel), viewer's right is east: pixel column 0 is x = 0.05 m.
    let south = &layout.panels[2];
    let (p, _) = point_at_pixel(&scene, &layout, south, south.x0_px, layout.y0_px).unwrap();
    assert!((p - Point3::new(0.05, 0.0, 7.95)).norm() < 1e-9, "{p}");
    assert!((south.azimuth_deg - 180.0).abs() < 1e-9);
}

#[test]
fn refusals() {
    let (scene, object) = box_scene([0.5; 3]);
    let bad = UnfoldParams {
        px_per_m: 0.0,
        ..UnfoldParams::default()
    };
    assert!(matches!(
        unfold(&scene, object, &bad),
        Err(UnfoldError::InvalidParameter { .. })
    ));
    assert!(matches!(
        unfold(&scene, ObjectId(9), &UnfoldParams::default()),
        Err(UnfoldError::NoObject { index: 9 })
    ));
    assert_eq!(ramp(0.0), [0, 0, 255]);
    assert_eq!(ramp(1.0), [255, 0, 0]);
    assert_eq!(ramp(0.5), [0, 255, 0]);
}
