//! The Models panel on the courtyard sample with a 2 m box model: the wireframe overlay is the
//! box's corners projected by the solved camera (`Camera::project`, the known answer);
//! changing the translation through the command path moves every projected corner to the
//! projection of the moved corner; undo restores the original wireframe.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::kittest::Queryable;
use photomontage::site::render::site_camera;
use photomontage_studio::commands::Command;

/// The overlay and the reference call the same projection on the same f64 corners; only the
/// order of the placement arithmetic could differ (rotation 0, scale 1: none), so agreement is
/// to rounding of world coordinates of ~2.7e6 m seen at 1500 px/25 m.
const PROJECTION_TOL_PX: f64 = 1e-6;

fn corners(translation: [f64; 3]) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for dz in [0.0, 2.0] {
        for (dx, dy) in [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)] {
            out.push([
                translation[0] + dx,
                translation[1] + dy,
                translation[2] + dz,
            ]);
        }
    }
    out
}

/// Checks that the segment ends are exactly the projected corners (each end is some corner,
/// every corner is some end) and returns the number of segments.
fn check_wireframe(segments: &[[[f64; 2]; 2]], expected_px: &[[f64; 2]]) -> usize {
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < PROJECTION_TOL_PX;
    for s in segments {
        for end in s {
            assert!(
                expected_px.iter().any(|e| near(*end, *e)),
                "{end:?} is no projected corner"
            );
        }
    }
    for e in expected_px {
        assert!(
            segments.iter().flatten().any(|end| near(*end, *e)),
            "corner {e:?} missing"
        );
    }
    segments.len()
}

#[test]
fn moving_a_model_moves_its_wireframe_by_the_camera_projection_and_undo_restores_it() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);
    // Unsolved photo: a readable error, no wireframe.
    let err = h.state_mut().model_wireframe_px("P1", "box").unwrap_err();
    assert!(!err.is_empty());
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Models").click();
    h.run();
    h.get_by_label("wireframe overlay").click();
    h.run();

    let doc = h.state().document().unwrap().clone();
    let camera = site_camera(&doc, "P1").unwrap();
    let project = |t: [f64; 3]| -> Vec<[f64; 2]> {
        corners(t)
            .into_iter()
            .map(|c| {
                let p = camera.project(&c.into()).expect("in front");
                [p.x, p.y]
            })
            .collect()
    };
    let t0 = [2683014.0, 1247001.0, 400.0];
    let before = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    // 12 cube edges + 6 face diagonals (the OBJ quads are triangulated).
    assert_eq!(check_wireframe(&before, &project(t0)), 18);

    let mut placement = doc.site.models[0].placement.clone();
    let t1 = [t0[0] + 1.5, t0[1] - 0.5, t0[2] + 0.25];
    placement.translation = t1;
    h.state_mut().apply(
        Command::SetModelPlacement {
            model: "box".into(),
            placement,
        },
        None,
    );
    h.run();
    let after = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    assert_eq!(check_wireframe(&after, &project(t1)), 18);
    assert!(
        after
            .iter()
            .zip(&before)
            .any(|(a, b)| a[0][0].to_bits() != b[0][0].to_bits())
    );

    h.get_by_label("Undo").click();
    h.run();
    let undone = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    let bits = |w: &[[[f64; 2]; 2]]| -> Vec<u64> {
        w.iter().flatten().flatten().map(|v| v.to_bits()).collect()
    };
    assert_eq!(bits(&undone), bits(&before));
    let restored = h.state().document().unwrap().site.models[0]
        .placement
        .translation;
    assert_eq!(restored.map(f64::to_bits), t0.map(f64::to_bits));
}
