//! The differential renderer against Mitsuba 3 (issue 4 acceptance, "differential accuracy"):
//! the 1024-spp `without_box` render is the photo, the box is rendered into it and compared with
//! the 1024-spp `with_box` truth over the box pixels and the shadow pixels.
//!
//! The images are box-filtered 4 × 4 down to 320 × 180 (the camera's focal length and principal
//! point scaled to match) to keep the test within seconds in the dev profile.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage_tests::street::downscale;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use photomontage::colour::SampleSet;
use photomontage::peer_scene::{MAX_DEPTH, mitsuba_pair_scene};
use photomontage::render::{DifferentialTracer, RenderSettings, render_view, render_view_spectral};
use photomontage_tests::mitsuba_pair::pair_errors;
use photomontage_tests::shared_file;
use serde_json::Value;

/// Downscale factor of the test (`RENDER_MITSUBA_SCALE` overrides it, e.g. 1 for full size).
const DEFAULT_SCALE: u32 = 4;

fn scale() -> u32 {
    std::env::var("RENDER_MITSUBA_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&s| s > 0)
        .unwrap_or(DEFAULT_SCALE)
}

/// Box pixels: the acceptance goal (3 %); measured 2.0 %. Our model has sun, sky facets and
/// light reflected from the photographed ground (one gather over a Durisch m_h = 6 dome, and an
/// m_h = 2 gather for the box's light reaching the shadow); Mitsuba's paths have up to 3 bounces.
const BOX_MEAN_REL_TOL: f64 = 0.03;
/// Shadow pixels: the acceptance goal (3 %); measured 2.0 % (4.8 % without the nested
/// bounce that lights the box walls facing the shadow, 11 % without any bounce from the box).
const SHADOW_MEAN_REL_TOL: f64 = 0.03;

fn load(path: &Path) -> image::Rgb32FImage {
    photomontage::photo::load(path).unwrap().pixels
}

#[test]
fn box_and_shadow_match_mitsuba_1024spp() {
    let (Some(json), Some(photo_path), Some(truth_path)) = (
        shared_file("bench/data/mitsuba/scene.json"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_without_box.exr"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_with_box.exr"),
    ) else {
        return;
    };
    let spec: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let photo = downscale(&load(&photo_path), scale());
    let truth = downscale(&load(&truth_path), scale());

    // Scene, camera and lights: shared with the render-speed bench (`render_bench`).
    let (w, h) = (photo.width(), photo.height());
    let peer = mitsuba_pair_scene(&spec, [w, h]).unwrap();
    let (scene, camera, lighting) = (peer.scene, peer.camera, peer.lighting);
    let tracer = DifferentialTracer::new(&scene, &lighting, &camera, &photo, MAX_DEPTH).unwrap();
    // `RENDER_MITSUBA_SPECTRAL=durisch9|meyer4` measures the spectral mode instead.
    let spectral = match std::env::var("RENDER_MITSUBA_SPECTRAL").as_deref() {
        Ok("durisch9") => Some(SampleSet::Durisch9),
        Ok("meyer4") => Some(SampleSet::Meyer4),
        _ => None,
    };
    let (settings, cancel) = (RenderSettings::default(), AtomicBool::new(false));
    let out = match spectral {
        None => render_view(&tracer, &settings, &|_| {}, &cancel).unwrap(),
        Some(set) => render_view_spectral(&tracer, &settings, set, &|_| {}, &cancel).unwrap(),
    };

    if let Some(dir) = std::env::var_os("RENDER_MITSUBA_DUMP") {
        let dir = Path::new(&dir);
        out.write_png(
            &dir.join("ours.png"),
            &photomontage::colour::ToneMap::clamp(),
        )
        .unwrap();
        let t = photomontage::render::RenderedImage {
            size_px: [w, h],
            rgba: truth.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
            changed_pixels: 0,
            primary_rays: 0,
        };
        t.write_png(
            &dir.join("truth.png"),
            &photomontage::colour::ToneMap::clamp(),
        )
        .unwrap();
    }
    let e = pair_errors(&out.rgba, &truth, &photo);
    println!(
        "mitsuba {w}x{h} {spectral:?}: box pixels {} mean rel err {:.4}; shadow pixels {} mean rel err {:.4}; signed: box {:+.4}, shadow {:+.4}; RMSE {:.5}; changed pixels {}; rays/pixel {:.2}",
        e.box_pixels,
        e.box_mean_rel,
        e.shadow_pixels,
        e.shadow_mean_rel,
        e.box_bias,
        e.shadow_bias,
        e.rmse,
        out.changed_pixels,
        out.primary_rays as f64 / f64::from(w * h)
    );
    assert!(
        e.box_pixels > 1000 && e.shadow_pixels > 300,
        "masks: {} box, {} shadow",
        e.box_pixels,
        e.shadow_pixels
    );
    assert!(
        e.box_mean_rel <= BOX_MEAN_REL_TOL,
        "box mean relative error {}",
        e.box_mean_rel
    );
    assert!(
        e.shadow_mean_rel <= SHADOW_MEAN_REL_TOL,
        "shadow mean relative error {}",
        e.shadow_mean_rel
    );
}
