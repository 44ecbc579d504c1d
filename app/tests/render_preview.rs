//! The Render panel on the courtyard sample (with a small OBJ box added as its planned model):
//! an unsolved photo gives a readable message; after Solve, a low-spp render on the worker
//! equals the library's `render_view` on the same site bit for bit; the A/B split moves the
//! montage's edge to the photo column it names; EXR and PNG exports read back to the montage.
//! The progressive preview: after any set of finished tiles it shows the final render inside
//! those tiles' rects and the photo elsewhere, and after the last tile the whole montage.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::kittest::Queryable;
use photomontage::colour::encode_srgb8;
use photomontage::render::TileProgress;
use photomontage::render::{DifferentialTracer, render_view};
use photomontage::site::render::prepare_view;
use photomontage_studio::render_panel::{Preview, display_image, display_photo, site_tone_map};
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

/// Screen positions are f32; the split line is compared to the transform of the same photo
/// column, so only f32 rounding separates them.
const SCREEN_TOL: f32 = 1e-3;

#[test]
fn render_preview_matches_the_library_and_exports() {
    let (dir, site) = copy_sample();
    add_box_model(&site);

    let mut h = harness(&site, WINDOW);
    h.get_by_label("Render").click();
    h.run();
    // Unsolved: a readable message, no render.
    h.get_by_label("Start").click();
    h.run();
    let last = h.state().messages().last().expect("a message").clone();
    assert!(
        last.is_error && last.text.contains("not solved"),
        "{last:?}"
    );
    assert!(!h.state().render_panel().busy());

    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    {
        let q = &mut h.state_mut().render_panel_mut().quality;
        q.spp_min = 4;
        q.spp_max = 4;
        q.seed = 7;
    }
    h.get_by_label("Start").click();
    h.step();
    assert!(
        h.state().render_panel().busy(),
        "{:?}",
        h.state().messages()
    );
    step_until(&mut h, "render", |s| {
        !s.render_panel().busy() && s.render_panel().montage().is_some()
    });
    let (done, total) = h.state().render_panel().progress();
    assert!(total > 0 && done == total, "{done}/{total} tiles reported");

    // The library, on the same (solved) site, same settings.
    let doc = h.state().document().unwrap().clone();
    let mut job = prepare_view(&doc, "P1").unwrap();
    job.settings.min_rays_per_pixel = 4;
    job.settings.max_rays_per_pixel = 4;
    job.settings.seed = 7;
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .unwrap();
    let tiles = Mutex::new(Vec::new());
    let library = render_view(
        &tracer,
        &job.settings,
        &|t| tiles.lock().unwrap().push(t),
        &AtomicBool::new(false),
    )
    .unwrap();
    let tiles = tiles.into_inner().unwrap();
    let montage = &h.state().render_panel().montage().unwrap().image;
    check_progressive_preview(&doc, &job.photo_linear, &library, &tiles);
    // The studio's own preview after its last tile is the montage's display image.
    let tone_map = site_tone_map(&doc);
    assert!(
        h.state().render_panel().preview().unwrap().image().pixels
            == display_image(montage, &tone_map).pixels,
        "preview after all tiles differs from the montage"
    );
    assert_eq!(montage.size_px, [1600, 1200]);
    assert!(library.changed_pixels > 1000, "the box is in view");
    let bits = |im: &photomontage::render::RenderedImage| -> Vec<u32> {
        im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
    };
    assert!(
        bits(montage) == bits(&library),
        "preview differs from render_view"
    );
    assert_eq!(montage.changed_pixels, library.changed_pixels);

    // A/B split: the montage edge follows the slider's photo column.
    h.state_mut().render_panel_mut().ab_split = 0.25;
    h.run();
    let t = h.state().view_transform().unwrap();
    let x = h.state().render_panel().split_screen_x(&t, 1600);
    let expect = t.screen_from_photo([400.0, 0.0]).x;
    assert!((x - expect).abs() < SCREEN_TOL, "{x} vs {expect}");

    // Export EXR (exact floats) and PNG (the site's tone map), read back.
    let tone_map = photomontage_studio::render_panel::site_tone_map(&doc);
    for name in ["montage.exr", "montage.png"] {
        let path = dir.path().join(name);
        h.state_mut().render_panel_mut().export_path = path.display().to_string();
        h.get_by_label("Export").click();
        h.run();
        assert!(path.exists(), "{:?}", h.state().messages());
        let back = image::open(&path).unwrap();
        let montage = &h.state().render_panel().montage().unwrap().image;
        if name.ends_with("exr") {
            let back = back.to_rgba32f();
            for (a, b) in back.pixels().zip(&montage.rgba) {
                assert_eq!(
                    a.0.map(f32::to_bits),
                    b.map(f32::to_bits),
                    "{:?} vs {b:?}",
                    a.0
                );
            }
        } else {
            let back = back.to_rgb8();
            for (a, b) in back.pixels().zip(&montage.rgba) {
                assert_eq!(a.0, encode_srgb8([b[0], b[1], b[2]], &tone_map));
            }
        }
    }
}

/// The preview after every other tile (in the order they finished) equals the final render's
/// display pixels inside those tiles and the photo's outside them.
fn check_progressive_preview(
    doc: &photomontage::site::SiteDocument,
    photo_linear: &image::Rgb32FImage,
    library: &photomontage::render::RenderedImage,
    tiles: &[TileProgress],
) {
    let tone_map = site_tone_map(doc);
    let size_px = library.size_px;
    let photo = display_photo(photo_linear, &tone_map);
    let finished = display_image(library, &tone_map);
    let mut preview = Preview::new("P1", size_px, photo.clone());
    let applied: Vec<&TileProgress> = tiles.iter().step_by(2).collect();
    for t in &applied {
        preview.apply_tile(t, &tone_map);
    }
    // Display step 1 (1600 px < 2048): display pixels are photo pixels.
    assert_eq!(preview.image().size, [1600, 1200]);
    let mut mask = vec![false; (size_px[0] * size_px[1]) as usize];
    for t in &applied {
        for y in t.origin_px[1]..t.origin_px[1] + t.size_px[1] {
            for x in t.origin_px[0]..t.origin_px[0] + t.size_px[0] {
                mask[(y * size_px[0] + x) as usize] = true;
            }
        }
    }
    let inside = |x: u32, y: u32| mask[(y * size_px[0] + x) as usize];
    let (mut changed_in, mut changed_out) = (0, 0);
    for y in 0..size_px[1] {
        for x in 0..size_px[0] {
            let k = (y * size_px[0] + x) as usize;
            let differs = finished.pixels[k] != photo.pixels[k];
            let want = if inside(x, y) {
                changed_in += usize::from(differs);
                finished.pixels[k]
            } else {
                changed_out += usize::from(differs);
                photo.pixels[k]
            };
            assert_eq!(preview.image().pixels[k], want, "pixel {x},{y}");
        }
    }
    // Both cases are exercised: the montage differs from the photo inside and outside.
    assert!(
        changed_in > 100 && changed_out > 100,
        "{changed_in} {changed_out}"
    );
}

/// Control marks: 6-px rings, one per observation on the photo (`photo_view::paint_marks`).
fn mark_rings(h: &egui_kittest::Harness<'static, photomontage_studio::Studio>) -> usize {
    h.output()
        .shapes
        .iter()
        .filter(|s| {
            matches!(&s.shape, eframe::egui::Shape::Circle(c)
                if (c.radius - 6.0).abs() < 1e-3 && c.fill == eframe::egui::Color32::TRANSPARENT)
        })
        .count()
}

/// Outlines of finished tiles: 1-px strokes in the outline colour (`RenderPanel::paint`).
fn tile_outlines(h: &egui_kittest::Harness<'static, photomontage_studio::Studio>) -> usize {
    let colour = eframe::egui::Color32::from_rgb(80, 200, 255);
    h.output()
        .shapes
        .iter()
        .filter(|s| matches!(&s.shape, eframe::egui::Shape::Rect(r) if r.stroke.color == colour))
        .count()
}

/// The Render tab's two overlay switches, driven by their labels: "show control marks" hides
/// and shows the observation marks, "show tile outlines" the finished tiles' outlines of a
/// running render (which goes on underneath).
#[test]
fn render_tab_hides_control_marks_and_tile_outlines() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    let on_p1 = h
        .state()
        .document()
        .unwrap()
        .site
        .observations
        .iter()
        .filter(|o| o.photo == "P1" && o.enabled)
        .count();
    assert!(on_p1 > 3, "the sample has marks on P1");
    assert!(mark_rings(&h) >= on_p1, "marks drawn on the Render tab");
    h.get_by_label("show control marks").click();
    h.run();
    assert_eq!(mark_rings(&h), 0, "marks hidden");
    h.get_by_label("show control marks").click();
    h.run();
    assert!(mark_rings(&h) >= on_p1, "marks shown again");

    // A slow render (many rays where the box is), to look at it while it runs.
    {
        let q = &mut h.state_mut().render_panel_mut().quality;
        q.spp_min = 16;
        q.spp_max = 16;
    }
    h.get_by_label("Start").click();
    // A running render asks for frames all the time: step, never `run`, until it ends.
    let start = std::time::Instant::now();
    loop {
        h.step();
        let (done, total) = h.state().render_panel().progress();
        if done >= 1 {
            assert!(done < total, "the render ran past the first tiles unseen");
            break;
        }
        assert!(start.elapsed().as_secs() < 300, "no tile finished");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    h.run_steps(2);
    assert!(h.state().render_panel().busy(), "still running");
    assert!(tile_outlines(&h) >= 1, "finished tiles outlined");
    h.get_by_label("show tile outlines").click();
    h.run_steps(2);
    assert!(h.state().render_panel().busy(), "the render goes on");
    assert_eq!(tile_outlines(&h), 0, "outlines hidden");
    h.get_by_label("show tile outlines").click();
    h.run_steps(2);
    assert!(tile_outlines(&h) >= 1, "outlines shown again");
    h.get_by_label("Cancel").click();
    let start = std::time::Instant::now();
    while h.state().render_panel().busy() {
        h.step();
        assert!(start.elapsed().as_secs() < 300, "the render did not stop");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}
