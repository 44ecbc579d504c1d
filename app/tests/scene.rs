//! The Scene panel on the courtyard sample: intersecting tie point T1 (observed in all three
//! photos) after Solve lands within a stated bound of its seeded true position (truth.json) as
//! one undoable edit; a polygon built by picking four control points in order becomes a natural
//! scene object of two triangles on exactly those points; undo removes it. The same polygon
//! picked by clicking the control points' projected pixels on the photo, closed with Enter,
//! undone and redone.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, click_photo_px, copy_sample, harness, sample_dir, step_until};
use eframe::egui;
use egui_kittest::kittest::Queryable;
use photomontage::site::render::{ObjectSource, site_scene};
use photomontage::site::stored_camera;

/// T1 lies ≈ 40 m from the cameras; σ 0.5 px at f 1500 px is ≈ 0.013 m across each ray, the
/// 20–40° intersection angles make depth ≈ 2–3× worse, and the solved cameras carry their own
/// error (not propagated by the intersection): 0.1 m is ≈ 3× that expected error.
const TIE_TOL_M: f64 = 0.1;

fn truth_point(id: &str) -> [f64; 3] {
    let text = std::fs::read_to_string(sample_dir().join("truth.json")).unwrap();
    // truth.json: `"points": { ..., "T1": [x, y, z], ... }` (the file's own layout).
    let points = &text[text.find("\"points\"").unwrap()..];
    let at = points.find(&format!("\"{id}\"")).unwrap();
    let list = &points[at..];
    let list = &list[list.find('[').unwrap() + 1..list.find(']').unwrap()];
    let v: Vec<f64> = list.split(',').map(|x| x.trim().parse().unwrap()).collect();
    [v[0], v[1], v[2]]
}

#[test]
fn intersect_a_tie_point_and_build_a_polygon_through_the_command_path() {
    let (_dir, site) = copy_sample();
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Scene").click();
    h.run();

    let before = h.state().document().unwrap().site.tie_points.clone();
    h.get_by_label("intersect T1").click();
    h.run();
    let ties = &h.state().document().unwrap().site.tie_points;
    let t1 = ties.iter().find(|t| t.id == "T1").expect("T1 stored");
    let truth = truth_point("T1");
    let err: Vec<f64> = (0..3).map(|k| (t1.xyz[k] - truth[k]).abs()).collect();
    eprintln!("T1 error {err:?} m, sigma {:?} m", t1.sigma_m);
    assert!(err.iter().all(|e| *e < TIE_TOL_M), "T1 error {err:?} m");
    assert!(
        t1.sigma_m.iter().all(|s| *s > 0.0 && *s < TIE_TOL_M),
        "{:?}",
        t1.sigma_m
    );
    let last = h.state().messages().last().unwrap();
    assert!(
        !last.is_error && last.text.contains("intersected"),
        "{last:?}"
    );
    h.get_by_label("Undo").click();
    h.run();
    assert!(h.state().document().unwrap().site.tie_points == before);

    // A wall from four control points, picked in order.
    h.get_by_label("polygon id").click();
    h.run();
    h.get_by_label("polygon id").type_text("wall");
    h.run();
    h.state_mut().scene_panel_mut().material = "default".into();
    for v in ["A1", "A2", "A4", "A3"] {
        h.get_by_label(&format!("vertex {v}")).click();
        h.run();
    }
    h.get_by_label("Create polygon").click();
    h.run();
    let doc = h.state().document().unwrap().clone();
    let wall = doc
        .site
        .polygons
        .iter()
        .find(|p| p.id == "wall")
        .expect("wall");
    assert_eq!(wall.vertices, ["A1", "A2", "A4", "A3"]);
    assert_eq!(wall.material, "default");
    let scene = site_scene(&doc).unwrap();
    let obj = scene
        .object_sources
        .iter()
        .position(|s| *s == ObjectSource::Polygon("wall".into()))
        .expect("wall in the scene");
    let tris: Vec<_> = scene
        .scene
        .triangles()
        .iter()
        .filter(|t| t.object.0 as usize == obj)
        .collect();
    assert_eq!(tris.len(), 2);
    let corners: Vec<[f64; 3]> = ["A1", "A2", "A4", "A3"]
        .iter()
        .map(|id| {
            doc.site
                .control_points
                .iter()
                .find(|c| c.id == *id)
                .unwrap()
                .xyz
        })
        .collect();
    for t in &tris {
        for v in t.vertices_in_world_m {
            let v = [v.x, v.y, v.z].map(f64::to_bits);
            assert!(corners.iter().any(|c| c.map(f64::to_bits) == v), "{v:?}");
        }
    }
    h.get_by_label("Undo").click();
    h.run();
    assert!(
        h.state()
            .document()
            .unwrap()
            .site
            .polygons
            .iter()
            .all(|p| p.id != "wall")
    );
}

#[test]
fn polygon_vertices_picked_by_clicking_the_photo() {
    let (_dir, site) = copy_sample();
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Scene").click();
    h.run();
    assert_eq!(h.state().current_photo(), Some("P1"));
    h.state_mut().scene_panel_mut().polygon_id = "wall".into();
    h.state_mut().scene_panel_mut().material = "default".into();

    // The projected pixels of the four corners, with the solved camera of P1.
    let doc = h.state().document().unwrap().clone();
    let camera = stored_camera(&doc.site, "P1").expect("P1 solved");
    let order = ["A1", "A2", "A4", "A3"];
    for id in order {
        let c = doc.site.control_points.iter().find(|c| c.id == id).unwrap();
        let p = camera.project(&c.xyz.into()).expect("in front of P1");
        // A click 2 px (photo) off the projected point: within the pick radius at the fitted
        // zoom (< 1 screen point), nearest wins.
        click_photo_px(&mut h, [p.x + 2.0, p.y - 1.0]);
    }
    assert_eq!(h.state_mut().scene_panel_mut().vertices, order);
    // A click far from every point picks nothing.
    click_photo_px(&mut h, [5.0, 5.0]);
    assert_eq!(h.state_mut().scene_panel_mut().vertices.len(), 4);
    assert!(
        h.state()
            .document()
            .unwrap()
            .site
            .polygons
            .iter()
            .all(|p| p.id != "wall"),
        "picking is not an edit"
    );

    h.key_press(egui::Key::Enter);
    h.run();
    let wall = |h: &egui_kittest::Harness<'static, photomontage_studio::Studio>| {
        h.state()
            .document()
            .unwrap()
            .site
            .polygons
            .iter()
            .find(|p| p.id == "wall")
            .cloned()
    };
    let made = wall(&h).unwrap_or_else(|| panic!("wall closed: {:?}", h.state().messages()));
    assert_eq!(made.vertices, order);
    assert!(h.state_mut().scene_panel_mut().vertices.is_empty());
    h.get_by_label("Undo").click();
    h.run();
    assert!(wall(&h).is_none(), "undo removes the polygon");
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(wall(&h).unwrap().vertices, order, "redo restores it");
}
