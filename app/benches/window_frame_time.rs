//! Frame time of the studio in a real window with a 24 MP photo on screen (issue 6 acceptance).
//!
//! The companion of `frame_time.rs` (kittest + wgpu with read-back): this one opens the real
//! eframe window with its own glow (OpenGL) renderer, exactly as `photomontage-studio` runs,
//! on a generated 6000×4000 PNG, waits for the worker to decode and tile it, then zooms from
//! fit to 16:1 and back about a wandering point with a small pan every frame, repainting
//! continuously with vsync off. A frame is the interval between the starts of two successive
//! passes: the studio's pass, egui's tessellation, the GL paint and the buffer swap. It prints
//! the median, 95th percentile and worst of the frame and of the studio pass alone.
//!
//! Needs a display: `xvfb-run -a cargo bench -p photomontage-studio --bench window_frame_time`
//! (under Xvfb, Mesa's llvmpipe rasterises on the CPU). With the argument `baseline` the window
//! shows one label instead of the studio: the renderer's own cost for the same window.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use eframe::egui;
use photomontage_studio::{Studio, StudioOptions, window};
use std::time::{Duration, Instant};

mod common;
use common::{FRAMES, WINDOW, photo_site, stats};

/// Frames run after decoding and before timing (shader compilation, first uploads).
const WARM_UP_FRAMES: usize = 10;

struct Bench {
    studio: Studio,
    /// One label instead of the studio: the renderer's own cost for the same window.
    baseline: bool,
    warm_up: usize,
    frame: usize,
    fit_zoom: Option<f64>,
    last_start: Option<Instant>,
    frame_t: Vec<Duration>,
    pass_t: Vec<Duration>,
}

impl eframe::App for Bench {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let start = Instant::now();
        let ctx = ui.ctx().clone();
        ctx.request_repaint();
        let ready =
            self.baseline || self.studio.is_idle() && self.studio.view_transform().is_some();
        let timing = ready && self.warm_up >= WARM_UP_FRAMES;
        if timing {
            if let Some(last) = self.last_start {
                self.frame_t.push(start - last);
            }
            self.last_start = Some(start);
            if let Some(t) = self.studio.view_transform() {
                let rect = t.rect;
                let fit = *self.fit_zoom.get_or_insert(t.zoom);
                let per_frame = (16.0 / fit).powf(2.0 / FRAMES as f64);
                let i = self.frame;
                let phase = i as f32 / FRAMES as f32 * std::f32::consts::TAU;
                let anchor =
                    rect.center() + egui::vec2(phase.cos(), phase.sin()) * rect.size() * 0.3;
                let v = self.studio.viewport_mut();
                let factor = if i < FRAMES / 2 {
                    per_frame
                } else {
                    1.0 / per_frame
                };
                v.zoom_about(rect, anchor, factor);
                v.pan(egui::vec2(3.0 * phase.sin(), 2.0 * phase.cos()));
            }
            self.frame += 1;
        } else if ready {
            self.warm_up += 1;
        }
        let a = Instant::now();
        if self.baseline {
            ui.label("baseline");
        } else {
            self.studio.ui(ui);
        }
        if timing {
            self.pass_t.push(a.elapsed());
        }
        if self.frame > FRAMES {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

fn main() {
    let dir = tempfile::tempdir().expect("tempdir");
    let site_path = photo_site(dir.path(), "window frame-time bench");
    let mut studio = Studio::new(StudioOptions {
        site_path,
        state_path: None,
    });
    studio.set_host_clears_to_panel_fill(true);
    let baseline = std::env::args().any(|a| a == "baseline");
    let bench = Bench {
        studio,
        baseline,
        warm_up: 0,
        frame: 0,
        fit_zoom: None,
        last_start: None,
        frame_t: Vec::new(),
        pass_t: Vec::new(),
    };
    let results = std::sync::Arc::new(std::sync::Mutex::new(None));
    let out = std::sync::Arc::clone(&results);
    // The studio's own window options (dithering off), with vsync off so that frames are not
    // paced by the (virtual) display.
    let mut native = window::native_options(WINDOW, "photomontage studio frame time");
    native.glow_options.vsync = false;
    eframe::run_native(
        "photomontage studio frame time",
        native,
        Box::new(move |_cc| Ok(Box::new(Recorder { bench, out }))),
    )
    .expect("window");
    let (frame_t, pass_t) = results.lock().expect("lock").take().expect("frames ran");
    println!(
        "{} frames, window {}×{} points, {}, glow renderer",
        frame_t.len(),
        WINDOW[0],
        WINDOW[1],
        if baseline {
            "one label (baseline)"
        } else {
            "24 MP photo, zoom fit → 16 → fit"
        }
    );
    stats("frame (start to start)", frame_t);
    stats("studio pass", pass_t);
}

type Timings = (Vec<Duration>, Vec<Duration>);

/// Hands the timings out of the event loop when the window closes.
struct Recorder {
    bench: Bench,
    out: std::sync::Arc<std::sync::Mutex<Option<Timings>>>,
}

impl eframe::App for Recorder {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.bench.ui(ui, frame);
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        window::clear_colour(visuals)
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        if let Ok(mut o) = self.out.lock() {
            *o = Some((
                std::mem::take(&mut self.bench.frame_t),
                std::mem::take(&mut self.bench.pass_t),
            ));
        }
    }
}
