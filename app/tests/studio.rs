//! The studio driven by AccessKit labels with egui_kittest (headless wgpu, lavapipe on CI):
//! placing, undo/redo, solving on the worker and the residual table against the library's
//! `solve_site` (what `photomontage solve` prints); calibrating the sample site from scratch;
//! image snapshots of the main screens.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, click_photo_px, copy_sample, harness, wait_idle};
use egui_kittest::SnapshotOptions;
use egui_kittest::kittest::Queryable;
use photomontage::site::{SiteDocument, solve_site};
use std::time::{Duration, Instant};

/// A click goes photo px → f32 screen points → photo px. f32 has 24 bits, so at ~1400 points
/// the round trip is within 1.2e-4 points = 1.2e-4/zoom px; at the fitted zoom (~0.4) that is
/// 3e-4 px. 1e-3 px leaves a margin and is 500× below the observations' σ of 0.5 px.
const CLICK_TOL_PX: f64 = 1e-3;

/// Cameras from the studio vs the CLI's: the clicked observations differ from the file's by
/// < [`CLICK_TOL_PX`], i.e. < 0.002 σ; a camera moves by that fraction of its own σ (the solve
/// is linear near the optimum), and the centre σ here is ≈ 1–3 cm, so 0.1 mm in the centre and
/// 1e-5 rad in rotation are generous yet far below anything a user would see.
const CAMERA_CENTRE_TOL_M: f64 = 1e-4;
/// See [`CAMERA_CENTRE_TOL_M`].
const CAMERA_ROTATION_TOL_RAD: f64 = 1e-5;
/// Focal length: the click error (≤ 3e-4 px per observation) reaches the focal length with a
/// gain of a few (measured 1.2e-4 … 5.0e-4 px on the three photos); σ_f is a few px.
const FOCAL_TOL_PX: f64 = 2e-3;

fn wait_for_solution(h: &mut egui_kittest::Harness<'static, photomontage_studio::Studio>) {
    let start = Instant::now();
    while h.state().solution().is_none() || !h.state().is_idle() {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "solve did not finish"
        );
    }
    h.run();
}

#[test]
fn place_undo_redo_solve_and_the_residual_table_shows_the_cli_numbers() {
    let (_dir, site_path) = copy_sample();
    let original = SiteDocument::load(&site_path).expect("sample loads");
    let mut h = harness(&site_path, WINDOW);
    assert_eq!(h.state().current_photo(), Some("P1"));

    // Switch to P2 and take one of its observations off, then place it again by clicking.
    h.get_by_label("photo P2").click();
    wait_idle(&mut h);
    assert_eq!(h.state().current_photo(), Some("P2"));
    let target = original
        .site
        .observations
        .iter()
        .find(|o| o.photo == "P2")
        .expect("P2 has observations")
        .clone();
    h.get_by_label(&target.point).click();
    h.run();
    assert_eq!(h.state().selected_point(), Some(target.point.as_str()));
    h.key_press(eframe::egui::Key::Delete);
    h.run();
    let count = |h: &egui_kittest::Harness<'static, photomontage_studio::Studio>| {
        h.state()
            .document()
            .expect("open")
            .site
            .observations
            .iter()
            .filter(|o| o.photo == "P2" && o.point == target.point)
            .count()
    };
    assert_eq!(count(&h), 0, "Delete removed the observation");

    click_photo_px(&mut h, [target.x_px, target.y_px]);
    let placed = |h: &egui_kittest::Harness<'static, photomontage_studio::Studio>| {
        h.state()
            .document()
            .expect("open")
            .site
            .observations
            .iter()
            .find(|o| o.photo == "P2" && o.point == target.point)
            .cloned()
    };
    let p = placed(&h).expect("placed by clicking");
    assert!(
        (p.x_px - target.x_px).abs() < CLICK_TOL_PX,
        "{} vs {}",
        p.x_px,
        target.x_px
    );
    assert!(
        (p.y_px - target.y_px).abs() < CLICK_TOL_PX,
        "{} vs {}",
        p.y_px,
        target.y_px
    );

    // Undo the placement, undo the deletion: the site is the original, bit for bit.
    h.get_by_label("Undo").click();
    h.run();
    assert!(placed(&h).is_none(), "undo removed the placed observation");
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(h.state().document().expect("open").site, original.site);
    // Redo both: deleted, then placed again at the clicked position.
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(count(&h), 0);
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(placed(&h), Some(p.clone()));

    // Save (atomic) and solve on the worker.
    h.get_by_label("Save").click();
    h.run();
    h.get_by_label("Solve").click();
    wait_for_solution(&mut h);

    // What the CLI computes for the same file.
    let saved = SiteDocument::load(&site_path).expect("saved site loads");
    let cli = solve_site(&saved);
    assert!(cli.failures.is_empty(), "{:?}", cli.failures);
    let studio = h.state().solution().expect("solved").clone();
    assert_eq!(studio.photos.len(), cli.photos.len());
    for (s, c) in studio.photos.iter().zip(&cli.photos) {
        assert_eq!(s.id, c.id);
        assert_eq!(s.residuals.len(), c.residuals.len());
        for (rs, rc) in s.residuals.iter().zip(&c.residuals) {
            assert_eq!(rs.point_id, rc.point_id);
            assert_eq!(
                photomontage_studio::solve::row_cells(rs),
                photomontage_studio::solve::row_cells(rc)
            );
        }
    }
    // The table on screen shows the CLI's numbers, with the CLI's rounding.
    let p2 = cli.photos.iter().find(|p| p.id == "P2").expect("P2 solved");
    h.get_by_label_contains(&format!("P2: bundle · RMS {:.3} px", p2.rms_px));
    for r in &p2.residuals {
        for cell in photomontage_studio::solve::row_cells(r) {
            assert!(
                h.query_all_by_label(&cell).next().is_some(),
                "residual cell {cell} of {} shown",
                r.point_id
            );
        }
    }
    // The mislabelled observation of the sample is flagged in the table.
    let outliers: Vec<&str> = cli
        .photos
        .iter()
        .flat_map(|p| p.outliers.iter().map(String::as_str))
        .collect();
    assert_eq!(
        outliers.len(),
        1,
        "the sample has one mislabelled observation"
    );
    if p2.outliers.is_empty() {
        assert!(h.query_by_label("OUTLIER").is_none());
    } else {
        assert!(h.query_all_by_label("OUTLIER").next().is_some());
    }
    // The solve landed in the site through the command path: undo takes it back out.
    assert!(
        h.state().document().expect("open").site.photos[1]
            .exterior
            .is_some()
    );
    h.get_by_label("Undo").click();
    h.run();
    assert!(
        h.state().document().expect("open").site.photos[1]
            .exterior
            .is_none()
    );
}

#[test]
fn calibrating_the_sample_in_the_studio_matches_the_cli_cameras() {
    let (dir, site_path) = copy_sample();
    let original = SiteDocument::load(&site_path).expect("sample loads");
    // Start from the site without control points, observations (and the polygons that refer
    // to the points).
    let mut bare = original.site.clone();
    bare.control_points.clear();
    bare.observations.clear();
    bare.polygons.clear();
    bare.save(&site_path).expect("save bare site");
    let mut h = harness(&site_path, WINDOW);

    // Import the surveyor's list by typing its path.
    let csv = dir.path().join("control_points.csv");
    h.get_by_label("import path").click();
    h.run();
    h.get_by_label("import path")
        .type_text(csv.to_str().expect("utf-8 path"));
    h.run();
    h.get_by_label("Import").click();
    h.run();
    let imported = &h.state().document().expect("open").site.control_points;
    assert_eq!(imported, &original.site.control_points);

    // Place every observation of the original file as a user would: pick the photo, pick the
    // point, click its pixel.
    for photo in &original.site.photos {
        h.get_by_label(&format!("photo {}", photo.id)).click();
        wait_idle(&mut h);
        for o in original
            .site
            .observations
            .iter()
            .filter(|o| o.photo == photo.id)
        {
            let surveyed = original.site.control_points.iter().any(|c| c.id == o.point);
            if surveyed {
                h.get_by_label(&o.point).click();
            } else {
                // A tie point: type its id and pick it.
                h.get_by_label("point id")
                    .set_text_value_accesskit(&o.point);
                h.run();
                h.get_by_label("Pick id").click();
            }
            h.run();
            assert_eq!(h.state().selected_point(), Some(o.point.as_str()));
            // Zoom in on the spot, as a user does: at the fitted zoom some marks lie within the
            // grab radius of each other (A3 and A4 on P2 are 1 px apart), and a click on a mark
            // selects it instead of placing.
            *h.state_mut().viewport_mut() = photomontage_studio::viewport::Viewport {
                zoom: 16.0,
                centre_px: [o.x_px, o.y_px],
                fitted: false,
            };
            h.run();
            click_photo_px(&mut h, [o.x_px, o.y_px]);
        }
    }
    let placed = &h.state().document().expect("open").site.observations;
    let missing: Vec<_> = original
        .site
        .observations
        .iter()
        .filter(|o| {
            !placed
                .iter()
                .any(|p| p.photo == o.photo && p.point == o.point)
        })
        .map(|o| format!("{} {}", o.photo, o.point))
        .collect();
    assert!(missing.is_empty(), "not placed: {missing:?}");
    assert_eq!(placed.len(), original.site.observations.len());
    for (p, o) in placed.iter().zip(&original.site.observations) {
        assert_eq!((&p.photo, &p.point), (&o.photo, &o.point));
        assert!((p.x_px - o.x_px).abs() < CLICK_TOL_PX && (p.y_px - o.y_px).abs() < CLICK_TOL_PX);
        assert!((p.sigma_px - o.sigma_px).abs() < 1e-12 && p.enabled == o.enabled);
    }

    h.get_by_label("Solve").click();
    wait_for_solution(&mut h);
    let studio = h.state().solution().expect("solved").clone();
    let cli = solve_site(&original);
    assert_eq!(studio.photos.len(), 3);
    for c in &cli.photos {
        let s = studio
            .photos
            .iter()
            .find(|s| s.id == c.id)
            .expect("same photos solved");
        let dc =
            (s.camera.pose.camera_center_in_world - c.camera.pose.camera_center_in_world).norm();
        // ‖R₁ − R₂‖_F = 2√2·sin(θ/2) ≈ √2·θ; `angle_to` takes acos of a value that rounds
        // past 1 for nearly equal rotations (NaN).
        let dr = (s.camera.pose.rotation_world_from_camera.matrix()
            - c.camera.pose.rotation_world_from_camera.matrix())
        .norm()
            / std::f64::consts::SQRT_2;
        let df = (s.camera.intrinsics.focal_px - c.camera.intrinsics.focal_px).abs();
        eprintln!(
            "{}: Δcentre {dc:.3e} m, Δrotation {dr:.3e} rad, Δfocal {df:.3e} px",
            c.id
        );
        assert!(
            dc < CAMERA_CENTRE_TOL_M,
            "{}: centre differs by {dc} m",
            c.id
        );
        assert!(
            dr < CAMERA_ROTATION_TOL_RAD,
            "{}: rotation differs by {dr} rad",
            c.id
        );
        assert!(df < FOCAL_TOL_PX, "{}: focal differs by {df} px", c.id);
        assert_eq!(s.outliers, c.outliers);
    }
    // The cameras were written into the site (saved from the studio).
    h.get_by_label("Save").click();
    h.run();
    let saved = SiteDocument::load(&site_path).expect("saved");
    assert!(saved.site.photos.iter().all(|p| p.exterior.is_some()));
}

/// Snapshot comparison: egui_kittest's per-pixel colour threshold 0.6 (its default, "enough
/// for most egui tests to pass across different wgpu backends") and at most
/// [`SNAPSHOT_MAX_FAILED_PIXELS`] pixels above it.
const SNAPSHOT_THRESHOLD: f32 = 0.6;
/// A handful of antialiased glyph edges may differ between lavapipe/llvmpipe builds; a moved
/// mark, table row or photo tile changes hundreds of pixels, so 10 still catches real changes.
const SNAPSHOT_MAX_FAILED_PIXELS: usize = 10;

fn snapshot_options() -> SnapshotOptions {
    SnapshotOptions::new()
        .threshold(SNAPSHOT_THRESHOLD)
        .max_failed_pixels(SNAPSHOT_MAX_FAILED_PIXELS)
}

#[test]
fn snapshots_of_the_main_screens() {
    let (_dir, site_path) = copy_sample();
    let mut h = harness(&site_path, [1100.0, 660.0]);
    h.remove_cursor();
    h.run();
    mask_messages(&mut h);
    h.snapshot_options("studio_points", &snapshot_options());
    h.get_by_label("Solve").click();
    wait_for_solution(&mut h);
    h.remove_cursor();
    h.run();
    mask_messages(&mut h);
    h.snapshot_options("studio_solved", &snapshot_options());
}

/// The message area names the temp folder, which differs per run: mask it (after the last
/// step, as `Harness::mask` paints over the current frame).
fn mask_messages(h: &mut egui_kittest::Harness<'static, photomontage_studio::Studio>) {
    let rects: Vec<_> = h
        .query_all_by_label_contains("tmp")
        // Full width: the path's width in a proportional font varies with its letters.
        .map(|n| {
            let r = n.rect();
            eframe::egui::Rect::from_x_y_ranges(0.0..=f32::MAX, r.min.y - 2.0..=r.max.y + 2.0)
        })
        .collect();
    for r in rects {
        h.mask(r);
    }
}

/// The same shapes drawn over the same background: only blending order could differ, which it
/// does not for opaque fills; one 8-bit level allows for rounding in the rasteriser.
const CLEAR_PICTURE_TOL: u8 = 1;

/// Shapes that fill a rectangle with exactly the panel colour.
fn panel_fills(h: &egui_kittest::Harness<'static, photomontage_studio::Studio>) -> usize {
    let fill = h.ctx.global_style().visuals.panel_fill;
    h.output()
        .shapes
        .iter()
        .filter(|s| matches!(&s.shape, eframe::egui::Shape::Rect(r) if r.fill == fill))
        .count()
}

/// The real window clears to the panel colour and the panels then skip their own fill
/// (`Studio::set_host_clears_to_panel_fill`): the picture must be the one the panels paint
/// themselves. kittest draws every UI inside a frame filled with the panel colour, which plays
/// the window's clear here, so the two frames must be the same picture while the one with the
/// flag paints fewer panel-coloured rectangles.
#[test]
fn clearing_to_the_panel_colour_gives_the_same_picture() {
    let (_dir, site_path) = copy_sample();
    let mut h = harness(&site_path, [1100.0, 660.0]);
    h.remove_cursor();
    h.run();
    let painted = h.render().expect("render");
    let fills_painted = panel_fills(&h);
    h.state_mut().set_host_clears_to_panel_fill(true);
    // A state change requests no repaint by itself: step explicitly.
    h.step();
    h.run();
    let cleared = h.render().expect("render");
    let fills_cleared = panel_fills(&h);
    assert!(
        fills_cleared + 4 <= fills_painted,
        "the four side panels must stop filling: {fills_painted} → {fills_cleared} panel fills"
    );
    assert_eq!(painted.dimensions(), cleared.dimensions());
    let worst = painted
        .pixels()
        .zip(cleared.pixels())
        .flat_map(|(a, b)| (0..4).map(move |k| a[k].abs_diff(b[k])))
        .max()
        .unwrap_or(0);
    assert!(
        worst <= CLEAR_PICTURE_TOL,
        "the frames differ by {worst} levels"
    );
}
