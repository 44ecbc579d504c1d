//! Frame time of the studio with a 24 MP photo on screen (issue 6 acceptance).
//!
//! Generates a 6000×4000 photo (a seeded pattern with detail at every scale, written as PNG),
//! opens it in the real [`Studio`] inside egui_kittest with its wgpu renderer, waits for the
//! worker to decode it, then runs frames while zooming (fit … 16:1 … fit, about moving points)
//! and panning. For each frame it times the studio's pass (layout, input, texture uploads:
//! `Harness::step`) and the GPU render with read-back (`Harness::render`), and prints the
//! median, 95th percentile and worst of each and of their sum.
//!
//! Then, with the Live preview in the radiosity mode (issue 17's "relight latency reported
//! with the frame time"): a temp copy of the courtyard sample with the box model and
//! `[render] radiosity = true`, solved, Live on, a manual sun stepped 1° in azimuth every
//! [`LIVE_STEP_EVERY`] frames (each step one undoable edit, as a slider drag gives), so that the
//! studio relights its transfers and re-renders on its worker while the frames are timed. It
//! prints the same statistics for those frames, the relight times the studio reported, and its
//! instant images' times (the replay, from the render job's start, and from the edit to the
//! frame that shows it).
//!
//! `cargo bench -p photomontage-studio --bench frame_time` (release profile; `live` as the only
//! argument runs the live part alone). On a machine without a GPU wgpu runs on lavapipe (CPU),
//! which makes the render column pessimistic.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use eframe::egui;
use egui_kittest::Harness;
use photomontage_studio::{Studio, StudioOptions};
use std::time::{Duration, Instant};

mod common;
use common::{FRAMES, HEIGHT_PX, WIDTH_PX, WINDOW, photo_site, stats};
/// The kittest helpers: the courtyard sample's temp copy, the box model, waiting for workers.
#[path = "../tests/common/mod.rs"]
mod test_common;

use photomontage_studio::commands::Command;
use photomontage_studio::light_commands::LightCommand;

/// Frames timed with the live preview.
const LIVE_FRAMES: usize = 200;
/// A sun step every this many frames (at 16 ms frames, about 6 steps per second: a slow drag).
const LIVE_STEP_EVERY: usize = 10;

fn main() {
    println!(
        "load average (1, 5, 15 min): {}",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
    if std::env::args().skip(1).any(|a| a == "live") {
        live_preview_frames();
        return;
    }
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
    live_preview_frames();
}

/// Whether the live preview shows the current site, finished.
fn caught_up(s: &Studio) -> bool {
    let p = s.render_panel();
    !p.busy() && p.live.shows(&s.document().expect("open").site) && p.montage().is_some()
}

/// Steps `h` until `done` holds (at most 600 s), without waiting for it to settle.
fn wait(h: &mut Harness<'static, Studio>, what: &str, done: impl Fn(&Studio) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
        assert!(start.elapsed().as_secs() < 600, "{what} did not finish");
    }
}

/// Sets the manual sun of the open site.
fn set_sun(h: &mut Harness<'static, Studio>, azimuth_deg: f64, elevation_deg: f64) {
    let mut lighting = h.state().document().expect("open").site.lighting.clone();
    lighting.sun_manual = Some(photomontage::site::SunManual {
        azimuth_deg,
        elevation_deg,
    });
    h.state_mut().apply(
        Command::Light(LightCommand::SetLighting(Box::new(lighting))),
        Some("bench sun".into()),
    );
}

/// The studio's frames while the Live preview relights its radiosity transfers.
fn live_preview_frames() {
    use egui_kittest::kittest::Queryable;
    let (_dir, site) = test_common::copy_sample();
    test_common::add_box_model(&site);
    let mut text = std::fs::read_to_string(&site).expect("site");
    text.push_str("\n[render]\nradiosity = true\n");
    std::fs::write(&site, text).expect("site");
    let studio = Studio::new(StudioOptions {
        site_path: site,
        state_path: None,
    });
    let mut h = Harness::builder()
        .with_size(egui::vec2(WINDOW[0], WINDOW[1]))
        .with_max_steps(400)
        .wgpu()
        .build_ui_state(|ui, s: &mut Studio| s.ui(ui), studio);
    wait(&mut h, "opening", Studio::is_idle);
    h.get_by_label("Solve").click();
    wait(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.step();
    {
        let q = &mut h.state_mut().render_panel_mut().quality;
        (q.spp_min, q.spp_max, q.seed) = (4, 8, 7);
    }
    h.get_by_label("Live preview").click();
    h.step();
    let t = Instant::now();
    wait(&mut h, "first live render (transfers built)", caught_up);
    println!(
        "live preview, radiosity mode: transfers built and first montage in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let sun =
        photomontage::site::sun_path::site_sun_angles(h.state().document().expect("open"), "P1")
            .expect("the sample's sun");
    let (mut azimuth_deg, elevation_deg) = (sun.azimuth_deg, sun.elevation_deg);
    set_sun(&mut h, azimuth_deg, elevation_deg);
    wait(&mut h, "live render of the manual sun", caught_up);

    let (mut step_t, mut render_t, mut total_t) = (Vec::new(), Vec::new(), Vec::new());
    let mut relights = Vec::new();
    let mut last = h.state().render_panel().live.last_relight().cloned();
    // The instant images (radiosity mode): their cost, and the time from the edit to the frame
    // that has one.
    let (mut instants, mut edit_to_instant, mut job_to_instant) =
        (Vec::new(), Vec::new(), Vec::new());
    let mut last_instant = h.state().render_panel().live.last_instant().cloned();
    let mut edit_at = Instant::now();
    for i in 0..LIVE_FRAMES {
        if i % LIVE_STEP_EVERY == 0 {
            azimuth_deg += 1.0;
            set_sun(&mut h, azimuth_deg, elevation_deg);
            edit_at = Instant::now();
        }
        let a = Instant::now();
        h.step();
        let b = Instant::now();
        h.render().expect("render");
        let c = Instant::now();
        step_t.push(b - a);
        render_t.push(c - b);
        total_t.push(c - a);
        let instant = h.state().render_panel().live.last_instant().cloned();
        if instant != last_instant {
            if let Some(r) = &instant {
                instants.push(Duration::from_secs_f64(r.seconds));
                job_to_instant.push(Duration::from_secs_f64(r.job_seconds));
                edit_to_instant.push(edit_at.elapsed());
            }
            last_instant = instant;
        }
        let now = h.state().render_panel().live.last_relight().cloned();
        if now != last {
            if let Some(r) = &now {
                relights.push((r.update, r.seconds));
            }
            last = now;
        }
    }
    println!(
        "{LIVE_FRAMES} frames with Live on (radiosity mode), a 1° sun step every \
         {LIVE_STEP_EVERY} frames ({} steps), window {}×{} points",
        LIVE_FRAMES / LIVE_STEP_EVERY,
        WINDOW[0],
        WINDOW[1]
    );
    stats("live: studio pass (step)", step_t);
    stats("live: render + read-back", render_t);
    stats("live: frame (sum)", total_t);
    if relights.is_empty() {
        println!("no relight finished during the timed frames");
    } else {
        let n = relights.len();
        let kinds: Vec<String> = relights.iter().map(|(k, _)| format!("{k:?}")).collect();
        println!("transfer updates seen: {}", kinds.join(" "));
        stats(
            &format!("live: update ({n} seen)"),
            relights
                .into_iter()
                .map(|(_, s)| Duration::from_secs_f64(s))
                .collect(),
        );
    }
    if instants.is_empty() {
        println!("no instant image during the timed frames");
    } else {
        let n = instants.len();
        stats(&format!("live: instant image ({n} seen)"), instants);
        stats(
            &format!("live: render job start to its instant image ({n})"),
            job_to_instant,
        );
        stats(
            &format!("live: edit to the frame showing its instant image ({n})"),
            edit_to_instant,
        );
    }
    println!(
        "load average (1, 5, 15 min): {}",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
}

const BASELINE_FRAMES: usize = 30;
