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
