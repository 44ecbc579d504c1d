//! The Fit tab on the `street` sample site (Mitsuba-rendered, known geometry; generate.py):
//! samples picked by clicking the photo get the material of the scene polygon the clicked point
//! lies on (a point of building B's south façade → `plaster_facade`, of the street → `paving`),
//! clicks on an unsolved photo or on the sky add nothing and say why, Shift-drag adds a horizon
//! rectangle, every edit undoes and redoes; the fit run from the tab shows the numbers of
//! `fit_site`'s report for the same site (the CLI's call), formatted as the CLI prints them;
//! Apply writes exactly what `apply_fit` writes, and Undo restores the previous lighting.
//!
//! The fit samples are those of `tests/tests/street_fit.rs` (paving from V3, plaster of B's
//! sunlit south and shaded west façades between the window rows), fewer of them, with
//! `[fit_settings]` interreflection and ambient switched off in the tab (eq. 9 without E_r, as
//! in the paper, and k_u = 0 as the generator has none; fast).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, click_photo_px, harness, step_until};
use eframe::egui;
use egui_kittest::SnapshotOptions;
use egui_kittest::kittest::Queryable;
use photomontage::fit::site::{SiteFitOptions, apply_fit, fit_site};
use photomontage::site::{Sample, SamplePurpose, SiteDocument, stored_camera};
use std::path::{Path, PathBuf};

/// Site frame origin of generate.py's local coordinates (truth.json `origin`).
const ORIGIN: [f64; 3] = [2_683_400.0, 1_247_600.0, 408.0];
/// A click lands where it was aimed up to the f32 screen coordinates (≈ 1e-4 points at 1000
/// points, i.e. ≈ 2e-4 photo px at the fitted zoom ≈ 0.5): 0.01 px is far above that and far
/// below any pixel.
const CLICK_TOL_PX: f64 = 0.01;
/// Median window of the fit samples (pixels), as street_fit.rs.
const WINDOW_PX: u32 = 7;

/// The street sample in the repository.
fn street_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/street")
}

/// Copies the street site (site file, library, model, photos) into a fresh temp folder.
fn copy_street() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = street_dir();
    std::fs::create_dir(dir.path().join("photos")).expect("mkdir");
    for f in [
        "site.toml",
        "materials.toml",
        "control_points.csv",
        "planned_building.obj",
        "planned_building.mtl",
    ] {
        std::fs::copy(src.join(f), dir.path().join(f)).expect("copy");
    }
    for e in std::fs::read_dir(src.join("photos")).expect("photos") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), dir.path().join("photos").join(e.file_name())).expect("copy");
    }
    let site = dir.path().join("site.toml");
    (dir, site)
}

fn local(p: [f64; 3]) -> [f64; 3] {
    [ORIGIN[0] + p[0], ORIGIN[1] + p[1], ORIGIN[2] + p[2]]
}

fn world_sample(id: &str, photo: &str, material: &str, local_m: [f64; 3]) -> Sample {
    Sample {
        id: format!("{photo}_{id}"),
        photo: photo.into(),
        material: material.into(),
        purpose: SamplePurpose::Daylight,
        point: Some(local(local_m)),
        x_px: None,
        y_px: None,
        window_px: WINDOW_PX,
        enabled: true,
    }
}

/// Paving seen from V3 (sunlit street and the street in B's shadow) and B's plaster (sunlit
/// south façade y = 5 m, shaded west façade x = 8 m) from V1 and V3: street_fit.rs's points.
fn fit_samples() -> Vec<Sample> {
    let mut out = Vec::new();
    for (i, p) in [[0.0, -20.0], [-2.0, -15.0], [-3.0, -10.0], [2.0, -8.0]]
        .iter()
        .enumerate()
    {
        out.push(world_sample(
            &format!("sun{i}"),
            "V3",
            "paving",
            [p[0], p[1], 0.0],
        ));
    }
    for (i, p) in [[2.0, 12.0], [0.0, 15.0], [4.0, 18.0], [5.6, -12.0]]
        .iter()
        .enumerate()
    {
        out.push(world_sample(
            &format!("shade{i}"),
            "V3",
            "paving",
            [p[0], p[1], 0.0],
        ));
    }
    for photo in ["V1", "V3"] {
        for z in [3.5, 6.9] {
            for x in [10.0, 16.0] {
                out.push(world_sample(
                    &format!("Bs{z}_{x}"),
                    photo,
                    "plaster_facade",
                    [x, 5.0, z],
                ));
            }
            for y in [8.0, 16.0] {
                out.push(world_sample(
                    &format!("Bw{z}_{y}"),
                    photo,
                    "plaster_facade",
                    [8.0, y, z],
                ));
            }
        }
    }
    out
}

type H = egui_kittest::Harness<'static, photomontage_studio::Studio>;

fn solve(h: &mut H) {
    h.get_by_label("Solve").click();
    step_until(h, "solve", |s| s.solution().is_some() && s.is_idle());
    // A solve shows the Results tab: back to the Fit tab.
    h.get_by_label("Fit tab").click();
    h.run();
}

fn samples(h: &H) -> Vec<Sample> {
    h.state().document().unwrap().site.samples.clone()
}

fn last_message(h: &H) -> photomontage_studio::Message {
    h.state().messages().last().unwrap().clone()
}

fn projected(h: &H, photo: &str, local_m: [f64; 3]) -> [f64; 2] {
    let camera = stored_camera(&h.state().document().unwrap().site, photo).unwrap();
    let p = camera.project(&local(local_m).into()).unwrap();
    [p.x, p.y]
}

fn has_label(h: &H, text: &str) -> bool {
    h.query_all_by_label(text).next().is_some()
}

#[test]
fn samples_picked_on_the_photo_get_the_material_of_the_polygon_under_the_click() {
    let (_dir, site) = copy_street();
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Fit tab").click();
    h.run();
    assert_eq!(h.state().current_photo(), Some("V1"));

    // No samples: the fit's NothingToFit appears as a readable message.
    h.get_by_label("Run fit").click();
    step_until(&mut h, "fit", |s| s.is_idle());
    assert!(
        h.query_all_by_label_contains("no enabled samples")
            .next()
            .is_some(),
        "{:?}",
        h.state().messages()
    );
    // Unsolved photo: nothing added, a message says why.
    click_photo_px(&mut h, [640.0, 700.0]);
    let m = last_message(&h);
    assert!(m.is_error && m.text.contains("not solved"), "{m:?}");
    assert!(samples(&h).is_empty());

    solve(&mut h);
    // B's south façade (y = 5 m, x 8–22 m, 11 m high; generate.py): a point between the window
    // rows, polygon B_south, material `plaster_facade`.
    let facade = projected(&h, "V1", [13.0, 5.0, 3.5]);
    click_photo_px(&mut h, facade);
    let s = samples(&h);
    assert_eq!(s.len(), 1, "{:?}", h.state().messages());
    assert_eq!(s[0].id, "S1");
    assert_eq!(s[0].photo, "V1");
    assert_eq!(s[0].material, "plaster_facade");
    assert_eq!(s[0].purpose, SamplePurpose::Daylight);
    assert!((s[0].x_px.unwrap() - facade[0]).abs() < CLICK_TOL_PX);
    assert!((s[0].y_px.unwrap() - facade[1]).abs() < CLICK_TOL_PX);
    assert!(last_message(&h).text.contains("B_south"));

    // The street (z = 0, polygon `ground`, material `paving`), as an atmosphere sample.
    h.get_by_label("pick purpose atmosphere").click();
    h.run();
    let street = projected(&h, "V1", [-2.0, -15.0, 0.0]);
    click_photo_px(&mut h, street);
    let s = samples(&h);
    assert_eq!(s.len(), 2, "{:?}", h.state().messages());
    assert_eq!(s[1].id, "S2");
    assert_eq!(s[1].material, "paving");
    assert_eq!(s[1].purpose, SamplePurpose::Atmosphere);

    // The sky above the buildings: no polygon, nothing added.
    click_photo_px(&mut h, [640.0, 3.0]);
    let m = last_message(&h);
    assert!(m.is_error && m.text.contains("no scene polygon"), "{m:?}");
    assert_eq!(samples(&h).len(), 2);

    // Undo / redo of a pick.
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(samples(&h).len(), 1);
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(samples(&h).len(), 2);

    // The table: disable, switch purpose, delete; undo puts S1 back first.
    h.get_by_label("use sample S1").click();
    h.run();
    assert!(!samples(&h)[0].enabled);
    h.get_by_label("purpose S2").click();
    h.run();
    assert_eq!(samples(&h)[1].purpose, SamplePurpose::Daylight);
    h.get_by_label("delete sample S1").click();
    h.run();
    assert_eq!(samples(&h).len(), 1);
    h.get_by_label("Undo").click();
    h.run();
    let s = samples(&h);
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].id, "S1");
    assert!(!s[0].enabled);

    // Shift-drag: a horizon rectangle from pixel (100, 20) to (300, 60).
    let a = h.state().photo_to_screen([100.0, 20.0]).unwrap();
    let b = h.state().photo_to_screen([300.0, 60.0]).unwrap();
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::SHIFT));
    h.hover_at(a);
    h.step();
    h.event(egui::Event::PointerButton {
        pos: a,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.step();
    for k in 1..=4 {
        let t = k as f32 / 4.0;
        h.hover_at(a + (b - a) * t);
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: b,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.run();
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.run();
    let horizons = h.state().document().unwrap().site.horizon_samples.clone();
    assert_eq!(horizons.len(), 1, "{:?}", h.state().messages());
    assert_eq!(horizons[0].id, "H1");
    assert_eq!(horizons[0].photo, "V1");
    assert_eq!(horizons[0].origin_px, [100, 20]);
    assert_eq!(horizons[0].size_px, [201, 41]);
    assert_eq!(samples(&h).len(), 2, "a drag adds no sample");
    h.get_by_label("Undo").click();
    h.run();
    assert!(
        h.state()
            .document()
            .unwrap()
            .site
            .horizon_samples
            .is_empty()
    );
}

/// Snapshot comparison as the studio's other snapshots (app/tests/studio.rs): egui_kittest's
/// default per-pixel threshold 0.6, at most 10 pixels above it (antialiased glyph edges).
fn snapshot_options() -> SnapshotOptions {
    SnapshotOptions::new().threshold(0.6).max_failed_pixels(10)
}

/// Masks the message lines naming the temp folder (they differ per run).
fn mask_temp_paths(h: &mut H) {
    let rects: Vec<_> = h
        .query_all_by_label_contains("tmp")
        .map(|n| {
            let r = n.rect();
            egui::Rect::from_x_y_ranges(0.0..=f32::MAX, r.min.y - 2.0..=r.max.y + 2.0)
        })
        .collect();
    for r in rects {
        h.mask(r);
    }
}

fn rgb(v: [f64; 3]) -> String {
    format!("{:.5} {:.5} {:.5}", v[0], v[1], v[2])
}

fn sigma(s: [Option<f64>; 3]) -> String {
    let parts: Vec<String> = s
        .iter()
        .map(|x| x.map_or_else(|| "—".to_owned(), |x| format!("{x:.5}")))
        .collect();
    format!("± {}", parts.join(" "))
}

#[test]
fn fit_run_in_the_studio_shows_the_reports_numbers_and_applies_them_undoably() {
    let (_dir, site) = copy_street();
    let mut doc = SiteDocument::load(&site).unwrap();
    doc.site.samples = fit_samples();
    doc.save().unwrap();
    let mut h = harness(&site, WINDOW);
    solve(&mut h);

    // [fit_settings] interreflection off through the tab: one undoable edit.
    assert!(
        h.state()
            .document()
            .unwrap()
            .site
            .fit_settings
            .interreflection
    );
    h.get_by_label("interreflection").click();
    h.run();
    let settings = |h: &H| h.state().document().unwrap().site.fit_settings;
    assert!(!settings(&h).interreflection);
    h.get_by_label("Undo").click();
    h.run();
    assert!(settings(&h).interreflection);
    h.get_by_label("Redo").click();
    h.run();
    assert!(!settings(&h).interreflection && settings(&h).ambient);
    // k_u = 0 too: the generator has no ambient term (street_fit.rs's acceptance case).
    h.get_by_label("fit ambient").click();
    h.run();
    assert!(!settings(&h).ambient);

    h.get_by_label("Run fit").click();
    step_until(&mut h, "fit", |s| s.fit_report().is_some() && s.is_idle());
    let before = h.state().document().unwrap().clone();
    // The CLI's call on the same site.
    let expected = fit_site(&before, &SiteFitOptions::default(), None).unwrap();
    let shown = h.state().fit_report().unwrap().clone();
    assert_eq!(shown, expected, "the studio's report is fit_site's");
    let k_s = expected.sun_weight.expect("daylight fitted");
    assert!(!expected.weights_relative);
    for (value, s) in [
        (k_s, expected.sun_weight_sigma),
        (
            expected.ambient_weight.unwrap(),
            expected.ambient_weight_sigma,
        ),
        (expected.sky_weight.unwrap(), expected.sky_weight_sigma),
    ] {
        assert!(has_label(&h, &rgb(value)), "{} not shown", rgb(value));
        let s = sigma(s.unwrap());
        assert!(has_label(&h, &s), "{s} not shown");
    }
    assert!(has_label(&h, &rgb(expected.horizon_colour)));
    assert!(
        has_label(&h, "weights absolute (materials' ρ_d from the library)"),
        "absolute flag"
    );
    // The residual table: every row's residual, flagged rows marked.
    for r in &expected.residuals {
        assert!(
            has_label(&h, &rgb(r.residual_rgb)),
            "residual of {} not shown",
            r.sample
        );
    }
    let flagged = expected.residuals.iter().filter(|r| r.flagged).count();
    assert_eq!(h.query_all_by_label("OUTLIER").count(), flagged);
    for w in &expected.warnings {
        assert!(has_label(&h, &format!("warning: {w}")), "warning {w}");
    }
    eprintln!(
        "studio fit: k_s {k_s:?}, k_h {:?}, k_u {:?}, {} residuals, {flagged} flagged",
        expected.sky_weight,
        expected.ambient_weight,
        expected.residuals.len()
    );

    h.remove_cursor();
    h.run();
    mask_temp_paths(&mut h);
    h.snapshot_options("studio_fit", &snapshot_options());

    // Apply: exactly apply_fit's write-back, one undoable edit.
    h.get_by_label("Apply fit").click();
    h.run();
    let after = h.state().document().unwrap().site.clone();
    let stamp = after.fit.as_ref().expect("[fit] record").fitted_at.clone();
    let mut want = before.site.clone();
    apply_fit(&mut want, &expected, &stamp);
    assert_eq!(after, want);
    // Bit-exact: apply_fit copies the report's values.
    let bits = |v: [f64; 3]| v.map(f64::to_bits);
    assert_eq!(bits(after.lighting.sun_weight), bits(k_s));
    assert_ne!(
        bits(before.site.lighting.sun_weight),
        bits(k_s),
        "the fit changed k_s"
    );
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(h.state().document().unwrap().site, before.site);
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(h.state().document().unwrap().site, want);
    // Saved, the site file carries the fitted lighting (what a later render reads).
    h.get_by_label("Save").click();
    h.run();
    let saved = SiteDocument::load(Path::new(&site)).unwrap();
    assert_eq!(saved.site.lighting, want.lighting);
}
