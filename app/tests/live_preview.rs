//! The Render tab's live preview, driven by labels on the courtyard sample with the box model:
//! with Live on, a sky-type change (Site & light tab) made mid-render cancels the running render
//! and starts a new one, and a material colour (Materials tab) another; when the preview has
//! caught up, its montage equals the library's `render_view` of the same site bit for bit (same
//! rays per pixel and seed) and the preview shows exactly the montage (no tile of a cancelled
//! render left). In the radiosity mode the studio's relit transfers match a fresh solve of the
//! edited site within the transfer tests' tolerance, the montage equals the library's render on
//! those solutions bit for bit, and each edit's instant image (replayed from records traced by
//! the first live render) equals the library's preview recorded under the edited site.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::radiosity::{RELIGHT_L1_REL_TOL, RELIGHT_MEAN_REL_TOL, Solution};
use photomontage::render::differential::radiosity_light::RadiosityLight;
use photomontage::render::preview::{PreviewImage, PreviewRecords};
use photomontage::render::{RenderedImage, render_view};
use photomontage::site::SiteDocument;
use photomontage::site::live_relight::TransferUpdate;
use photomontage::site::render::{prepare_view, site_scene};
use photomontage::site::render_photo::{RenderPlan, RenderRequest};
use photomontage::site::render_radiosity::site_radiosity_light;
use photomontage_studio::Studio;
use photomontage_studio::render_panel::{display_image, site_tone_map};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

const SPP: (u32, u32) = (4, 8);
const SEED: u64 = 7;

fn with_palette(site: &Path, radiosity: bool) {
    let mut text = std::fs::read_to_string(site).unwrap();
    text.push_str("\n[[palette]]\nname = \"Sienna\"\ncolour = \"#a0522d\"\n");
    if radiosity {
        // The relights are compared below with a fresh solve of the edited lighting. The
        // photo's reflectances are read under the lighting of the build and kept by relights,
        // while a fresh solve would read them under the edited sky, so this comparison runs with
        // the library's (the photo's path is compared in `site::live_relight_tests`).
        text.push_str("\n[render]\nradiosity = true\nphoto_reflectance = false\n");
    }
    std::fs::write(site, text).unwrap();
}

/// Opens the site, solves it, sets the quality and turns Live on (by its label).
fn live_studio(site: &Path) -> Harness<'static, Studio> {
    let mut h = harness(site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    {
        let q = &mut h.state_mut().render_panel_mut().quality;
        (q.spp_min, q.spp_max, q.seed) = (SPP.0, SPP.1, SEED);
    }
    h.get_by_label("Live preview").click();
    steps(&mut h);
    h
}

/// Steps until `done` holds (at most 300 s), without waiting for the UI to settle.
fn wait(h: &mut Harness<'static, Studio>, what: &str, done: impl Fn(&Studio) -> bool) {
    let start = std::time::Instant::now();
    while !done(h.state()) {
        h.step();
        std::thread::sleep(std::time::Duration::from_millis(20));
        assert!(start.elapsed().as_secs() < 300, "{what} did not finish");
    }
}

/// A few frames (a running render keeps repainting: `Harness::run` would not settle).
fn steps(h: &mut Harness<'static, Studio>) {
    for _ in 0..3 {
        h.step();
    }
}

fn caught_up(s: &Studio) -> bool {
    let p = s.render_panel();
    !p.busy() && p.live.shows(&s.document().unwrap().site) && p.montage().is_some()
}

/// Picks `model` in the Site & light tab's sky model list.
fn set_sky(h: &mut Harness<'static, Studio>, model: &str) {
    h.get_by_label("Site & light tab").click();
    steps(h);
    h.get_by_label("sky model").click();
    steps(h);
    h.get_by_label(model).click();
    steps(h);
}

/// Gives the brick material the palette's Sienna in the Materials tab.
fn set_brick_sienna(h: &mut Harness<'static, Studio>) {
    h.get_by_label("Materials tab").click();
    steps(h);
    h.get_by_label("Material brick").click();
    steps(h);
    h.get_by_label("Use Sienna").click();
    steps(h);
}

fn library_render(doc: &SiteDocument, radiosity: Option<Arc<RadiosityLight>>) -> RenderedImage {
    let mut job = prepare_view(doc, "P1").unwrap();
    job.settings.min_rays_per_pixel = SPP.0;
    job.settings.max_rays_per_pixel = SPP.1;
    job.settings.seed = SEED;
    job.lighting.radiosity = radiosity;
    let tracer = job.tracer().unwrap();
    render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false)).unwrap()
}

fn bits(im: &RenderedImage) -> Vec<u32> {
    im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The finished montage equals `library` bit for bit and the preview shows it, nothing else.
fn assert_montage_is(h: &Harness<'static, Studio>, library: &RenderedImage, label: &str) {
    let doc = h.state().document().unwrap();
    let panel = h.state().render_panel();
    let montage = &panel.montage().unwrap().image;
    assert!(library.changed_pixels > 1000, "{label}: the box is in view");
    assert!(bits(montage) == bits(library), "{label}: montage differs");
    assert!(
        panel.preview().unwrap().image().pixels
            == display_image(montage, &site_tone_map(doc)).pixels,
        "{label}: the preview shows something other than the montage"
    );
}

#[test]
fn live_preview_follows_sky_and_colour_and_equals_the_library() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    with_palette(&site, false);
    let mut h = live_studio(&site);
    // Live starts a render by itself, coarse pass first.
    assert!(
        h.state().render_panel().busy(),
        "{:?}",
        h.state().messages()
    );
    wait(&mut h, "first tiles", |s| {
        s.render_panel().progress().0 > 0 || !s.render_panel().busy()
    });
    assert!(
        h.state().render_panel().busy(),
        "the render ended before the edit"
    );
    // A sky type mid-render: the running render is cancelled and a new one starts.
    set_sky(&mut h, "cie_general:5");
    wait(&mut h, "live render after the sky", caught_up);
    assert!(h.state().render_panel().live.cancelled() >= 1);
    assert!(
        h.state()
            .messages()
            .iter()
            .all(|m| !m.is_error && !m.text.contains("cancelled")),
        "{:?}",
        h.state().messages()
    );
    let doc = h.state().document().unwrap().clone();
    assert_eq!(doc.site.lighting.sky_model.to_string(), "cie_general:5");
    assert_montage_is(&h, &library_render(&doc, None), "sky");
    h.get_by_label("Render").click();
    steps(&mut h);
    assert!(h.query_by_label_contains("frame ").is_some());

    set_brick_sienna(&mut h);
    wait(&mut h, "live render after the colour", caught_up);
    let doc = h.state().document().unwrap().clone();
    assert!(
        doc.site
            .materials
            .iter()
            .any(|m| m.material.name == "brick"),
        "the colour is a site material"
    );
    assert_montage_is(&h, &library_render(&doc, None), "colour");
    assert!(h.state().render_panel().live.last_frame().is_some());
}

fn assert_matches_fresh_solve(label: &str, relit: &Solution, fresh: &Solution) {
    // The transfer's documented relight tolerances (`radiosity::RELIGHT_*_REL_TOL`).
    let d = relit
        .relative_difference(fresh)
        .unwrap_or_else(|| panic!("{label}: same mesh and a lit scene"));
    assert!(d.l1_rel < RELIGHT_L1_REL_TOL, "{label}: L1 {}", d.l1_rel);
    assert!(
        d.mean_rel.abs() < RELIGHT_MEAN_REL_TOL,
        "{label}: mean {}",
        d.mean_rel
    );
}

#[test]
fn radiosity_mode_relights_the_kept_transfers() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    with_palette(&site, true);
    let mut h = live_studio(&site);
    wait(&mut h, "first live render", caught_up);
    let built = h
        .state()
        .render_panel()
        .live
        .last_relight()
        .unwrap()
        .clone();
    assert_eq!(built.update, TransferUpdate::Built);
    assert!(built.build.is_some(), "a build hands its report on");
    let first = h
        .state()
        .render_panel()
        .live
        .last_instant()
        .unwrap()
        .clone();
    assert!(
        first.recorded,
        "the first live render traces the instant image's records"
    );

    set_sky(&mut h, "cie_overcast");
    wait(&mut h, "live render after the sky", caught_up);
    set_brick_sienna(&mut h);
    wait(&mut h, "live render after the colour", caught_up);
    let relit = h
        .state()
        .render_panel()
        .live
        .last_relight()
        .unwrap()
        .clone();
    assert_eq!(relit.update, TransferUpdate::Relit);
    assert!(relit.build.is_none());
    // The colour edit's instant image: replayed from the first render's records, no ray.
    let live = &h.state().render_panel().live;
    let report = live.last_instant().unwrap().clone();
    assert!(!report.recorded && report.samples > 1000, "{report:?}");
    let instant = live.instant_image().unwrap().clone();
    h.get_by_label("Render").click();
    steps(&mut h);
    assert!(h.query_by_label_contains("radiosity update").is_some());
    assert!(h.query_by_label_contains("instant image").is_some());
    // The build's report stays shown after the relights (folded).
    let b = h.state().render_panel().live.last_build().unwrap().clone();
    assert_eq!(Some(&b), built.build.as_ref());
    assert!(
        h.query_by_label_contains(&format!(
            "Radiosity build: {} / {} elements",
            b.elements[0], b.elements[1]
        ))
        .is_some()
    );

    let doc = h.state().document().unwrap().clone();
    let transfers = h.state().render_panel().live.transfers();
    let light = transfers.lock().unwrap().as_ref().unwrap().light();
    let scene = site_scene(&doc).unwrap().scene;
    let (fresh, _) =
        site_radiosity_light(&doc, &scene, "P1", None, &AtomicBool::new(false)).unwrap();
    assert_matches_fresh_solve("with", &light.with_artificial, &fresh.with_artificial);
    assert_matches_fresh_solve(
        "without",
        &light.without_artificial,
        &fresh.without_artificial,
    );
    assert_instant_is_the_librarys(&doc, &light, &instant);
    assert_montage_is(&h, &library_render(&doc, Some(light)), "radiosity");
}

/// The studio's instant image after a sky and a colour edit, replayed from records traced
/// before both, equals the library's preview recorded now under the edited site and the same
/// relit solutions, bit for bit (`photomontage::render::preview`).
fn assert_instant_is_the_librarys(
    doc: &SiteDocument,
    light: &Arc<RadiosityLight>,
    instant: &PreviewImage,
) {
    let mut job = prepare_view(doc, "P1").unwrap();
    job.lighting.radiosity = Some(Arc::clone(light));
    let tracer = job.tracer().unwrap();
    let library =
        PreviewRecords::record(&tracer, instant.stride_px, &AtomicBool::new(false)).unwrap();
    let library = library
        .replay(&job.scene.scene, &job.lighting, &job.camera)
        .unwrap();
    let bits =
        |p: &PreviewImage| -> Vec<u32> { p.rgba.iter().flatten().map(|v| v.to_bits()).collect() };
    assert!(library.changed.iter().filter(|&&c| c).count() > 100);
    assert!(
        bits(&library) == bits(instant) && library.changed == instant.changed,
        "the instant image differs from the library's preview"
    );
}

/// In spectral mode the Render panel solves the radiosity once per spectral pass (the kept
/// transfers are RGB) and its montage equals the library's `RenderPlan` render of the same site
/// (the CLI's entry point) bit for bit.
#[test]
fn a_spectral_radiosity_render_is_the_librarys() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str("\n[render]\nradiosity = true\nspectral = true\n");
    std::fs::write(&site, text).unwrap();
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    {
        let q = &mut h.state_mut().render_panel_mut().quality;
        (q.spp_min, q.spp_max, q.seed) = (4, 4, SEED);
    }
    h.get_by_label("Start").click();
    steps(&mut h);
    wait(&mut h, "spectral radiosity render", |s| {
        !s.render_panel().busy() && s.render_panel().montage().is_some()
    });
    let doc = h.state().document().unwrap().clone();
    let request = RenderRequest {
        spp_min: Some(4),
        spp_max: Some(4),
        seed: Some(SEED),
        ..RenderRequest::view("P1")
    };
    let plan = RenderPlan::new(&doc, &request).unwrap();
    assert!(plan.spectral && plan.radiosity);
    let library = plan.render(&doc, &|_| {}, &AtomicBool::new(false)).unwrap();
    let report = library.radiosity.as_ref().expect("solved");
    assert!(
        report.notes.iter().any(|n| n.contains("3 passes")),
        "{report:?}"
    );
    let montage = &h.state().render_panel().montage().unwrap().image;
    assert!(library.image.changed_pixels > 1000, "the box is in view");
    assert!(
        bits(montage) == bits(&library.image),
        "the panel's spectral radiosity render differs from the library's"
    );
}
