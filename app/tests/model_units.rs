//! Model units and up axis in the Models panel, on the courtyard sample with a 2 m box: choosing
//! feet scales the wireframe to the projection of the box's corners × 0.3048 (exact by
//! definition); choosing Y up maps the corners by (x, y, z) ↦ (x, −z, y) (the importer's
//! documented convention); both are undoable. A model drawn in millimetres but added as metres
//! (20 km across) shows the importer's scale warning; added in millimetres it does not, and
//! switching it to metres afterwards brings the warning back, undo takes it away.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::site::render::site_camera;
use photomontage_studio::Studio;

/// The overlay and the reference call the same projection on corners computed from the same
/// f64 values; only rounding of ~2.7e6 m world coordinates differs (as `tests/models.rs`).
const PROJECTION_TOL_PX: f64 = 1e-6;

/// The box's corner offsets in the world for a corner map applied to {0, 2}³.
fn corners(t: [f64; 3], map: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for z in [0.0, 2.0] {
        for (x, y) in [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)] {
            let [dx, dy, dz] = map([x, y, z]);
            out.push([t[0] + dx, t[1] + dy, t[2] + dz]);
        }
    }
    out
}

/// Every segment end is a projected corner and every projected corner is a segment end.
fn assert_wireframe(segments: &[[[f64; 2]; 2]], expected_px: &[[f64; 2]]) {
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < PROJECTION_TOL_PX;
    assert_eq!(segments.len(), 18, "12 edges and 6 face diagonals");
    for end in segments.iter().flatten() {
        assert!(
            expected_px.iter().any(|e| near(*end, *e)),
            "{end:?} is no projected corner"
        );
    }
    for e in expected_px {
        assert!(
            segments.iter().flatten().any(|end| near(*end, *e)),
            "corner {e:?} missing"
        );
    }
}

fn choose(h: &mut Harness<'static, Studio>, combo: &str, option: &str) {
    h.get_by_label(combo).click();
    h.run();
    h.get_by_label(option).click();
    h.run();
}

fn model(h: &Harness<'static, Studio>, id: &str) -> photomontage::site::CadModel {
    h.state()
        .document()
        .unwrap()
        .site
        .models
        .iter()
        .find(|m| m.id == id)
        .unwrap()
        .clone()
}

fn scale_warning_shown(h: &Harness<'static, Studio>, id: &str) -> bool {
    // The panel's label (the message area says "warning: …" and keeps old messages).
    h.query_all_by_label_contains(&format!("importer: model `{id}` is"))
        .next()
        .is_some()
}

#[test]
fn units_and_up_axis_change_the_wireframe_exactly_and_undo() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Models").click();
    h.run();
    h.get_by_label("wireframe overlay").click();
    h.run();
    let doc = h.state().document().unwrap().clone();
    let camera = site_camera(&doc, "P1").unwrap();
    let project = |c: Vec<[f64; 3]>| -> Vec<[f64; 2]> {
        c.into_iter()
            .map(|c| {
                let p = camera.project(&c.into()).expect("in front");
                [p.x, p.y]
            })
            .collect()
    };
    let t0 = [2683014.0, 1247001.0, 400.0];
    let before = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    assert_wireframe(&before, &project(corners(t0, |p| p)));

    choose(&mut h, "box units", "ft (0.3048 m)");
    assert_eq!(model(&h, "box").units.as_str(), "ft");
    let feet = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    assert_wireframe(&feet, &project(corners(t0, |p| p.map(|c| c * 0.3048))));
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(model(&h, "box").units.as_str(), "m");
    let undone = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    assert_wireframe(&undone, &project(corners(t0, |p| p)));

    choose(&mut h, "box up axis", "Y up (glTF)");
    assert_eq!(model(&h, "box").up_axis.as_str(), "y");
    let y_up = h.state_mut().model_wireframe_px("P1", "box").unwrap();
    assert_wireframe(&y_up, &project(corners(t0, |[x, y, z]| [x, -z, y])));
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(model(&h, "box").up_axis.as_str(), "z");
}

#[test]
fn the_importers_scale_warning_follows_the_chosen_unit() {
    let (dir, site) = copy_sample();
    // A 20 m building drawn in millimetres: 20 000 units across.
    let obj: String = common::BOX_OBJ
        .lines()
        .map(|l| {
            if l.starts_with("v ") {
                format!("{}\n", l.replace('2', "20000"))
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let big = dir.path().join("big.obj");
    std::fs::write(&big, obj).unwrap();
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Models").click();
    h.run();
    let add = |h: &mut Harness<'static, Studio>| {
        h.state_mut().models_panel_mut().model_path = big.display().to_string();
        h.get_by_label("Add model").click();
        h.run();
    };

    // Added as metres: 20 km across, the importer's warning in the messages and the panel.
    add(&mut h);
    assert_eq!(model(&h, "big").units.as_str(), "m");
    let last = h.state().messages().last().unwrap().clone();
    assert!(
        last.is_error && last.text.contains("20000.0000 m across"),
        "{last:?}"
    );
    assert!(scale_warning_shown(&h, "big"));
    h.get_by_label("Undo").click();
    h.run();
    assert!(h.state().document().unwrap().site.models.is_empty());

    // Added in millimetres (chosen before adding): 20 m, no warning.
    choose(&mut h, "new model units", "mm (0.001 m)");
    add(&mut h);
    assert_eq!(model(&h, "big").units.as_str(), "mm");
    assert!(!scale_warning_shown(&h, "big"));
    assert!(!h.state().messages().last().unwrap().is_error);

    // Switched to metres afterwards: the warning is back; undo removes it again.
    choose(&mut h, "big units", "m (1 m)");
    assert_eq!(model(&h, "big").units.as_str(), "m");
    assert!(scale_warning_shown(&h, "big"));
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(model(&h, "big").units.as_str(), "mm");
    assert!(!scale_warning_shown(&h, "big"));
}
