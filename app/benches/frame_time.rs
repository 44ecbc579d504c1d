//! Frame time of the studio with a 24 MP photo on screen (issue 6 acceptance).
//!
//! Generates a 6000×4000 photo (a seeded pattern with detail at every scale, written as PNG),
//! opens it in the real [`Studio`] inside egui_kittest with its wgpu renderer, waits for the
//! worker to decode it, then runs frames while zooming (fit … 16:1 … fit, about moving points)
//! and panning. For each frame it times the studio's pass (layout, input, texture uploads:
//! `Harness::step`) and the GPU render with read-back (`Harness::render`), and prints the
//! median, 95th percentile and worst of each and of their sum.
//!
//! `cargo bench -p photomontage-studio --bench frame_time` (release profile). On a machine
//! without a GPU wgpu runs on lavapipe (CPU), which makes the render column pessimistic.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use eframe::egui;
use egui_kittest::Harness;
use photomontage_studio::{Studio, StudioOptions};
use std::time::{Duration, Instant};

mod common;
use common::{FRAMES, HEIGHT_PX, WIDTH_PX, WINDOW, photo_site, stats};

fn main() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t = Instant::now();
    let site_path = photo_site(dir.path(), "frame-time bench");
    println!(
        "generated {WIDTH_PX}×{HEIGHT_PX} PNG in {:.1} s",
        t.elapsed().as_secs_f64()
    );

    let studio = Studio::new(StudioOptions {
        site_path,
        state_path: None,
    });
    let mut h = Harness::builder()
        .with_size(egui::vec2(WINDOW[0], WINDOW[1]))
        .wgpu()
        .build_ui_state(|ui, s: &mut Studio| s.ui(ui), studio);
    let t = Instant::now();
    let mut frames_while_decoding = Vec::new();
    while !h.state().is_idle() {
        let f = Instant::now();
        h.step();
        h.render().expect("render");
        frames_while_decoding.push(f.elapsed());
        std::thread::sleep(Duration::from_millis(5));
    }
    println!(
        "decoded and tiled on the worker in {:.2} s ({} frames meanwhile)",
        t.elapsed().as_secs_f64(),
        frames_while_decoding.len()
    );
    if !frames_while_decoding.is_empty() {
        stats("frame while decoding", frames_while_decoding);
    }

    let rect = h.state().view_transform().expect("photo view drawn").rect;
    let (mut step_t, mut render_t, mut total_t) = (Vec::new(), Vec::new(), Vec::new());
    // Zoom in from fit to 16:1 over the first half, back out over the second, about a point
    // that wanders over the view, with a small pan every frame.
    let fit = h.state().view_transform().expect("drawn").zoom;
    let per_frame = (16.0 / fit).powf(2.0 / FRAMES as f64);
    for i in 0..FRAMES {
        let phase = i as f32 / FRAMES as f32 * std::f32::consts::TAU;
        let anchor = rect.center() + egui::vec2(phase.cos(), phase.sin()) * rect.size() * 0.3;
        {
            let v = h.state_mut().viewport_mut();
            let factor = if i < FRAMES / 2 {
                per_frame
            } else {
                1.0 / per_frame
            };
            v.zoom_about(rect, anchor, factor);
            v.pan(egui::vec2(3.0 * phase.sin(), 2.0 * phase.cos()));
        }
        let a = Instant::now();
        h.step();
        let b = Instant::now();
        h.render().expect("render");
        let c = Instant::now();
        step_t.push(b - a);
        render_t.push(c - b);
        total_t.push(c - a);
    }
    println!(
        "{FRAMES} frames, window {}×{} points, zoom fit ({fit:.3}) → 16 → fit",
        WINDOW[0], WINDOW[1]
    );
    stats("studio pass (step)", step_t);
    stats("render + read-back", render_t);
    stats("frame (sum)", total_t);

    // Baseline: the same renderer and window with one label and no photo, to separate the
    // renderer's own cost (lavapipe rasterising and reading back the window) from the photo's.
    let mut base = Harness::builder()
        .with_size(egui::vec2(WINDOW[0], WINDOW[1]))
        .wgpu()
        .build_ui(|ui| {
            ui.label("baseline");
        });
    let mut base_t = Vec::new();
    for _ in 0..BASELINE_FRAMES {
        base.step();
        let a = Instant::now();
        base.render().expect("render");
        base_t.push(a.elapsed());
    }
    stats("baseline render + read-back", base_t);
}

const BASELINE_FRAMES: usize = 30;
