//! Helpers shared by the studio's kittest tests: a temp copy of the courtyard sample, a harness
//! driving the real [`Studio`], and waiting for its workers.

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use eframe::egui;
use egui_kittest::Harness;
use photomontage_studio::{Studio, StudioOptions};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The courtyard sample in the repository.
pub fn sample_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/courtyard")
}

/// Copies the sample site (site file, control-point list, photos) into a fresh temp folder.
pub fn copy_sample() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = sample_dir();
    std::fs::create_dir(dir.path().join("photos")).expect("mkdir");
    for f in ["site.toml", "control_points.csv"] {
        std::fs::copy(src.join(f), dir.path().join(f)).expect("copy");
    }
    for e in std::fs::read_dir(src.join("photos")).expect("photos") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), dir.path().join("photos").join(e.file_name())).expect("copy");
    }
    let site = dir.path().join("site.toml");
    (dir, site)
}

/// Window size of the interaction tests: tall enough for the 24-row control-point table.
pub const WINDOW: [f32; 2] = [1400.0, 1000.0];

/// A harness running the real studio on `site`.
pub fn harness(site: &Path, size: [f32; 2]) -> Harness<'static, Studio> {
    let studio = Studio::new(StudioOptions {
        site_path: site.to_path_buf(),
        state_path: None,
    });
    harness_for(studio, size)
}

/// A harness running `studio` (made by the test, e.g. with a UI state file).
pub fn harness_for(studio: Studio, size: [f32; 2]) -> Harness<'static, Studio> {
    let mut h = Harness::builder()
        .with_size(egui::vec2(size[0], size[1]))
        .with_max_steps(400)
        .build_ui_state(|ui, s: &mut Studio| s.ui(ui), studio);
    wait_idle(&mut h);
    h
}

/// Steps until the studio's workers are done and the current photo is shown.
pub fn wait_idle(h: &mut Harness<'static, Studio>) {
    let start = Instant::now();
    loop {
        h.step();
        if h.state().is_idle() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "studio did not become idle"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    h.run();
}

/// A left click at a screen position (press and release without moving: a click).
pub fn click_at(h: &mut Harness<'static, Studio>, pos: egui::Pos2) {
    h.hover_at(pos);
    h.step();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.run();
}

/// Clicks the photo at a photo pixel position, through the view's transform.
pub fn click_photo_px(h: &mut Harness<'static, Studio>, p_px: [f64; 2]) {
    let pos = h
        .state()
        .photo_to_screen(p_px)
        .expect("the photo view has been drawn");
    click_at(h, pos);
}

/// A 2 m cube, corner at the origin (z up), as OBJ.
pub const BOX_OBJ: &str = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// The box stands 25 m in front of camera P1 (true centre 2683005, 1246978, 401.6, looking
/// towards azimuth ≈ 21°), so it covers about 120 px of the 1600 × 1200 photo.
pub const BOX_MODEL: &str = "\n[[models]]\nid = \"box\"\nfile = \"box.obj\"\nunits = \"m\"\n\
up_axis = \"z\"\n\n[models.placement]\ntranslation = [2683014.0, 1247001.0, 400.0]\n\
rotation_z_deg = 0.0\nscale = 1.0\n";

/// Adds the box model ([`BOX_OBJ`], [`BOX_MODEL`]) to the site file `site` (a temp copy).
pub fn add_box_model(site: &Path) {
    let dir = site.parent().expect("site dir");
    std::fs::write(dir.join("box.obj"), BOX_OBJ).expect("write box");
    let mut text = std::fs::read_to_string(site).expect("read site");
    text.push_str(BOX_MODEL);
    std::fs::write(site, text).expect("write site");
}

/// Steps until `done` holds (workers finish), at most 300 s.
pub fn step_until(h: &mut Harness<'static, Studio>, what: &str, done: impl Fn(&Studio) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "{what} did not finish"
        );
    }
    h.run();
}
