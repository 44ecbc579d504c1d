//! The Variants tab on the courtyard sample with the small OBJ box as its planned model, driven
//! by its labels: a variant naming a removed model is refused with the library's message and
//! fixed by one undoable edit; two variants are made (the box recoloured red, the box hidden),
//! renamed (empty and taken names refused, nothing changed), rendered on the worker and each
//! checked bit for bit against the library's `render --variant` path (`variant_document` +
//! `RenderPlan`); the compare modes draw the variants' names; the comparison sheet exported
//! through the save dialog has one A3 page per variant whose text (poppler's `pdftotext`)
//! names it, and the PNG grid is the library's grid of the library's renders; every edit is
//! undone exactly and redone.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use std::path::PathBuf;
use std::process::Command as Process;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::site::render_photo::{RenderPlan, RenderRequest};
use photomontage::site::variant_renders::srgb_of;
use photomontage::site::variants::variant_document;
use photomontage::verified::comparison_sheet::{ComparisonCell, comparison_png};
use photomontage_studio::Studio;
use photomontage_studio::files::{DialogPurpose, DialogRequest, FilePicker};
use photomontage_studio::variants_panel::CompareMode;

/// A3 landscape in PDF points (420 × 297 mm at 72/25.4 pt per mm), as `pdfinfo` prints it.
const A3_PTS: &str = "1190.55 x 841.89 pts";
/// Rays per pixel and seed of the renders (low: the check is bit for bit, not of quality).
const SPP: u32 = 4;
const SEED: u64 = 7;

/// A variant naming a model the site does not have (as after the model was removed).
const GHOST: &str = "\n[[variants]]\nname = \"ghost\"\nvisible_models = [\"tower\"]\n";

/// Answers the save dialog with a fixed path.
struct FakePicker {
    answer: PathBuf,
    asked: Mutex<Vec<DialogPurpose>>,
}

impl FilePicker for FakePicker {
    fn pick(&self, request: &DialogRequest) -> Option<PathBuf> {
        self.asked.lock().unwrap().push(request.purpose);
        Some(self.answer.clone())
    }
}

/// Whether poppler-utils is installed; skipped with a notice outside CI, required in CI.
fn have_poppler() -> bool {
    let ok = Process::new("pdftotext").arg("-v").output().is_ok();
    if !ok {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "pdftotext (poppler-utils) is required in CI"
        );
        eprintln!("notice: pdftotext not installed; PDF read-back skipped");
    }
    ok
}

fn run_text(cmd: &mut Process) -> String {
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

fn click(h: &mut Harness<'static, Studio>, label: &str) {
    h.get_by_label(label).click();
    h.run();
    // Edits are applied after the frame of the click; one more frame shows them.
    h.step();
    h.run();
}

fn variant_names(h: &Harness<'static, Studio>) -> Vec<String> {
    let doc = h.state().document().unwrap();
    doc.site.variants.iter().map(|v| v.name.clone()).collect()
}

fn last_message(h: &Harness<'static, Studio>) -> photomontage_studio::Message {
    h.state().messages().last().expect("a message").clone()
}

fn shows(h: &Harness<'static, Studio>, text: &str) -> bool {
    h.query_all_by_label_contains(text).next().is_some()
}

fn rename(h: &mut Harness<'static, Studio>, to: &str) {
    h.state_mut().variants_panel_mut().name_field = to.to_owned();
    click(h, "Rename");
}

#[test]
fn variants_edited_rendered_compared_and_exported() {
    let (dir, site) = copy_sample();
    add_box_model(&site);
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str(GHOST);
    std::fs::write(&site, text).unwrap();

    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    let start = h.state().document().unwrap().site.clone();
    click(&mut h, "Variants tab");

    // A variant naming a removed model: rendering is refused naming it, nothing starts.
    click(&mut h, "Render all variants");
    let m = last_message(&h);
    assert!(
        m.is_error && m.text.contains("tower") && m.text.contains("ghost"),
        "{m:?}"
    );
    assert!(!h.state().variants_panel().busy());
    click(&mut h, "Variant ghost");
    assert!(shows(&h, "which the site does not have"));
    click(&mut h, "Drop missing models");
    let ghost = &h.state().document().unwrap().site.variants[0];
    assert_eq!(ghost.visible_models, Some(Vec::new()));
    click(&mut h, "Delete variant");
    assert!(variant_names(&h).is_empty());

    // Variant 1: the box, recoloured red.
    click(&mut h, "Add variant");
    assert_eq!(variant_names(&h), ["Variant 1"]);
    rename(&mut h, "Red box");
    assert_eq!(variant_names(&h), ["Red box"]);
    // The box's OBJ names no material: it gets the scene's "default".
    let material = "default";
    h.get_by_label("Material to override").click();
    h.run();
    click(&mut h, &format!("Pick material {material}"));
    click(&mut h, "Override material");
    h.get_by_label(&format!("Colour of {material}"));
    set_colour_text(&mut h, material, "#c02018");
    click(&mut h, &format!("Set colour of {material}"));
    let red_rgb = photomontage::colour::designer::linear_from_srgb8([0xc0, 0x20, 0x18]);
    let red = h.state().document().unwrap().site.variants[0].clone();
    assert_eq!(red.materials.len(), 1);
    assert_eq!(red.materials[0].diffuse_rgb, red_rgb);
    // The colour reaches the scene the renderer builds for the variant.
    let vdoc = variant_document(h.state().document().unwrap(), Some("Red box")).unwrap();
    let scene = photomontage::site::render::site_scene(&vdoc).unwrap();
    let m = scene
        .scene
        .materials()
        .iter()
        .find(|m| m.name == material)
        .unwrap();
    assert_eq!(m.diffuse_rgb, red_rgb);

    // Variant 2: the box hidden. Empty and taken names are refused with nothing changed.
    click(&mut h, "Add variant");
    click(&mut h, "Show box");
    let before_bad = h.state().document().unwrap().site.clone();
    rename(&mut h, "  ");
    assert!(shows(&h, "must not be empty"));
    rename(&mut h, "Red box");
    assert!(shows(&h, "exists already"));
    assert_eq!(h.state().document().unwrap().site, before_bad);
    rename(&mut h, "No box");
    assert_eq!(variant_names(&h), ["Red box", "No box"]);
    assert_eq!(
        h.state().document().unwrap().site.variants[1].visible_models,
        Some(Vec::new())
    );
    // Duplicate, then delete the copy.
    click(&mut h, "Duplicate");
    assert_eq!(variant_names(&h), ["Red box", "No box", "No box copy 1"]);
    click(&mut h, "Delete variant");
    let edited = h.state().document().unwrap().site.clone();
    assert_eq!(variant_names(&h), ["Red box", "No box"]);

    // Render both on the worker.
    set_quality(&mut h);
    // The spinner repaints while it runs: step, not run.
    h.get_by_label("Render all variants").click();
    h.step();
    assert!(
        h.state().variants_panel().busy(),
        "{:?}",
        h.state().messages()
    );
    step_until(&mut h, "variant renders", |s| {
        !s.variants_panel().busy() && s.variants_panel().renders().is_some()
    });
    let (done, total) = h.state().variants_panel().progress();
    assert!(total > 0 && done == total, "{done}/{total} tiles reported");

    // Each is the library's `render --variant` bit for bit.
    let doc = h.state().document().unwrap().clone();
    let request = RenderRequest {
        spp_min: Some(SPP),
        spp_max: Some(SPP),
        seed: Some(SEED),
        ..RenderRequest::view("P1")
    };
    let mut library = Vec::new();
    for name in ["Red box", "No box"] {
        let vdoc = variant_document(&doc, Some(name)).unwrap();
        let plan = RenderPlan::new(&vdoc, &request).unwrap();
        let photo = plan
            .render(&vdoc, &|_| {}, &AtomicBool::new(false))
            .unwrap();
        library.push((name, srgb_of(&photo, &plan), photo));
    }
    let bits = |im: &photomontage::render::RenderedImage| -> Vec<u32> {
        im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
    };
    {
        let renders = h.state().variants_panel().renders().unwrap();
        assert_eq!(renders.view, "P1");
        assert_eq!(renders.shown.len(), 2);
        for (shown, (name, _, photo)) in renders.shown.iter().zip(&library) {
            assert_eq!(shown.name(), *name);
            assert!(
                bits(&shown.render.photo.image) == bits(&photo.image),
                "variant {name}: the studio's render differs from the library's"
            );
        }
    }
    assert!(
        library[0].2.image.changed_pixels > 100,
        "the red box is drawn"
    );
    assert_eq!(library[1].2.image.changed_pixels, 0, "no box: the photo");

    // The compare modes, each drawing the variants' names.
    let labels =
        |h: &Harness<'static, Studio>| h.state().variants_panel().compare.drawn_labels.clone();
    click(&mut h, "A/B slider");
    assert_eq!(h.state().variants_panel().compare.mode, CompareMode::Slider);
    assert_eq!(labels(&h), ["Red box", "No box"]);
    h.get_by_label("A/B comparison");
    click(&mut h, "Side by side");
    assert_eq!(labels(&h), ["Red box", "No box"]);
    click(&mut h, "Grid");
    assert_eq!(labels(&h), ["Red box", "No box"]);
    h.get_by_label("Grid No box");
    click(&mut h, "Flicker");
    assert_eq!(labels(&h), ["Red box"]);
    click(&mut h, "Flip A/B");
    assert_eq!(labels(&h), ["No box"]);
    h.key_press(eframe::egui::Key::Space);
    h.run();
    assert_eq!(labels(&h), ["Red box"]);
    // Running, it alternates by itself at the fixed rate.
    click(&mut h, "Start flicker");
    let first = labels(&h);
    let mut flipped = false;
    for _ in 0..200 {
        h.step();
        if labels(&h) != first {
            flipped = true;
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(flipped, "the flicker never alternated");
    click(&mut h, "Pause flicker");

    // Export through the save dialog: the PDF, and the PNG grid beside it.
    let pdf = dir.path().join("variants.pdf");
    let picker = Arc::new(FakePicker {
        answer: pdf.clone(),
        asked: Mutex::new(Vec::new()),
    });
    h.state_mut().set_file_picker(picker.clone());
    click(&mut h, "Export comparison…");
    step_until(&mut h, "export", |s| s.is_idle());
    h.step();
    h.run();
    assert_eq!(
        *picker.asked.lock().unwrap(),
        [DialogPurpose::ExportComparison]
    );
    assert!(pdf.exists(), "{:?}", h.state().messages());
    let bytes = std::fs::read(&pdf).unwrap();
    assert!(bytes.starts_with(b"%PDF-"));
    let png_path = pdf.with_extension("png");
    let png = image::open(&png_path).unwrap().to_rgb8();
    let cells: Vec<ComparisonCell<'_>> = library
        .iter()
        .map(|(name, srgb, _)| ComparisonCell {
            name: (*name).to_owned(),
            image: srgb,
        })
        .collect();
    let want = comparison_png(&cells);
    assert_eq!(png.dimensions(), want.dimensions());
    assert!(
        png == want,
        "the PNG grid is not the library's grid of the library's renders"
    );
    if have_poppler() {
        let info = run_text(Process::new("pdfinfo").arg(&pdf));
        assert!(
            info.lines()
                .any(|l| l.starts_with("Pages:") && l.ends_with(" 2")),
            "{info}"
        );
        assert!(info.contains(A3_PTS), "{info}");
        for (page, name) in [(1, "Red box"), (2, "No box")] {
            let text = run_text(
                Process::new("pdftotext")
                    .args(["-f", &page.to_string(), "-l", &page.to_string()])
                    .arg(&pdf)
                    .arg("-"),
            );
            assert!(
                text.contains(&format!("Variant {name}")),
                "page {page}: {text}"
            );
            assert!(text.contains("view P1"), "page {page}: {text}");
        }
    }

    // Every edit undone exactly, then redone.
    let mut steps = 0;
    while h.state().document().unwrap().site != start {
        h.state_mut().undo();
        steps += 1;
        assert!(steps <= 30, "undo never reached the opened site");
    }
    let undo_steps = steps;
    // Drop missing, delete ghost, add, rename, override, colour, add, hide, rename,
    // duplicate, delete: one step each.
    assert_eq!(undo_steps, 11);
    for _ in 0..undo_steps {
        h.state_mut().redo();
    }
    assert_eq!(h.state().document().unwrap().site, edited);
}

fn set_colour_text(h: &mut Harness<'static, Studio>, material: &str, text: &str) {
    h.state_mut()
        .variants_panel_mut()
        .set_colour_text("Red box", material, text);
    h.run();
}

/// Two variants of the box, written into the site file.
const TWO_VARIANTS: &str = "\n[[variants]]\nname = \"With box\"\nvisible_models = [\"box\"]\n\n[[variants]]\nname = \"No box\"\nvisible_models = []\n";

/// Renders every variant of the solved sample at [`SPP`] and waits for them.
/// The variant renders' quality of these tests ([`SPP`] rays, seed [`SEED`]).
fn set_quality(h: &mut Harness<'static, Studio>) {
    let q = &mut h.state_mut().variants_panel_mut().quality;
    q.spp_min = SPP;
    q.spp_max = SPP;
    q.seed = SEED;
}

fn render_variants(h: &mut Harness<'static, Studio>) {
    h.get_by_label("Solve").click();
    step_until(h, "solve", |s| s.solution().is_some() && s.is_idle());
    click(h, "Variants tab");
    set_quality(h);
    h.get_by_label("Render all variants").click();
    h.step();
    step_until(h, "variant renders", |s| {
        !s.variants_panel().busy() && s.variants_panel().renders().is_some()
    });
    h.run();
}

#[test]
fn compare_settings_survive_a_killed_studio() {
    use photomontage_studio::StudioOptions;
    let (dir, site) = copy_sample();
    add_box_model(&site);
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str(TWO_VARIANTS);
    std::fs::write(&site, text).unwrap();
    let state = dir.path().join("config/state.toml");
    let studio = || {
        Studio::new(StudioOptions {
            site_path: site.clone(),
            state_path: Some(state.clone()),
        })
    };

    let mut h = common::harness_for(studio(), WINDOW);
    render_variants(&mut h);
    let compare = |h: &Harness<'static, Studio>| {
        let c = &h.state().variants_panel().compare;
        (c.mode, c.a, c.b, c.split, c.flicker_running)
    };
    assert_eq!(compare(&h), (CompareMode::Slider, 0, 1, 0.5, false));
    // A and B swapped in their lists, the split moved, then the flicker started.
    h.get_by_label("Variant A").click();
    h.run();
    click(&mut h, "Variant A No box");
    h.get_by_label("Variant B").click();
    h.run();
    click(&mut h, "Variant B With box");
    h.get_by_label("A/B split").set_value_accesskit(0.25);
    h.run();
    click(&mut h, "Flicker");
    click(&mut h, "Start flicker");
    let chosen = (CompareMode::Flicker, 1, 0, 0.25, true);
    assert_eq!(compare(&h), chosen);
    // Killed: dropped without `on_exit`, so only what was written while running counts.
    drop(h);
    let written = std::fs::read_to_string(&state).expect("the UI state was written");
    assert!(written.contains("flicker"), "{written}");

    // Reopened: the mode, split and flicker come back at once; A and B by name once the
    // variants are rendered again.
    let mut h = common::harness_for(studio(), WINDOW);
    let c = &h.state().variants_panel().compare;
    assert_eq!(
        (c.mode, c.split, c.flicker_running),
        (CompareMode::Flicker, 0.25, true)
    );
    render_variants(&mut h);
    assert_eq!(compare(&h), chosen);
    let names = |h: &Harness<'static, Studio>| {
        let r = h.state().variants_panel().renders().unwrap();
        let c = &h.state().variants_panel().compare;
        (
            r.shown[c.a].name().to_owned(),
            r.shown[c.b].name().to_owned(),
        )
    };
    assert_eq!(names(&h), ("No box".to_owned(), "With box".to_owned()));
    click(&mut h, "Pause flicker");
}
