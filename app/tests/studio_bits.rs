//! The design studio's smaller pieces (issue 17 items 1 and 3), driven by their labels: the
//! Perez sky's inputs in the Site & light tab, the sky map's marker of a manual sun, and text
//! typed but not applied surviving other edits and their undo (Site & light and Materials).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use chrono::Datelike;
use common::{copy_sample, harness};
use eframe::egui;
use egui_kittest::kittest::Queryable;
use photomontage::scene::Material;
use photomontage::site::{PerezInputs, SiteDocument, SiteMaterial, SkyModelName};
use photomontage_studio::Studio;
use photomontage_studio::commands::Command;
use photomontage_studio::light_commands::LightCommand;
use photomontage_studio::material_commands::MaterialCommand;
use std::path::Path;

type H = egui_kittest::Harness<'static, Studio>;

/// Tall enough for the whole Site & light tab without scrolling.
const TALL: [f32; 2] = [1400.0, 1700.0];
/// The marker's accessible rectangle is centred on the painted disc; both come from the same
/// f32 arithmetic, so only f32 rounding of screen points remains.
const MARKER_TOL_PT: f32 = 0.01;

/// Whether some widget's label contains `text` (several may: a legend and a caption).
fn has(h: &H, text: &str) -> bool {
    h.query_all_by_label_contains(text).next().is_some()
}

/// Steps until the Materials tab says "elevation ready", failing on "elevation failed" or
/// after `limit_s` seconds.
fn wait_for_elevation(h: &mut H, limit_s: u64) {
    let start = std::time::Instant::now();
    while !has(h, "elevation ready") {
        assert!(!has(h, "elevation failed"), "the elevation failed");
        assert!(
            start.elapsed().as_secs() < limit_s,
            "the elevation did not finish"
        );
        h.step();
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    h.run();
}

fn site_of(h: &H) -> photomontage::site::Site {
    h.state().document().unwrap().site.clone()
}

fn set_text(h: &mut H, label: &str, text: &str) {
    h.get_by_label(label).click();
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.run();
    h.get_by_label(label).type_text(text);
    h.run();
}

fn click(h: &mut H, label: &str) {
    h.get_by_label(label).click();
    h.run();
}

fn undo(h: &mut H) {
    h.key_press(egui::Key::Escape);
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.run();
}

fn value(h: &H, label: &str) -> String {
    h.get_by_label(label).value().unwrap_or_default()
}

fn open_light_tab(site: &Path) -> H {
    let mut h = harness(site, TALL);
    click(&mut h, "Site & light tab");
    h
}

#[test]
fn a_manual_sun_is_drawn_at_its_own_angles_on_the_sky_map() {
    let (_dir, site) = copy_sample();
    let mut h = open_light_tab(&site);
    // The sample's computed sun first.
    assert!(
        has(&h, "sun marker (computed)"),
        "the computed sun has its marker"
    );
    click(&mut h, "sun manual");
    set_text(&mut h, "manual azimuth", "200");
    set_text(&mut h, "manual elevation", "30");
    click(&mut h, "Set sun");
    h.run();
    let manual = site_of(&h).lighting.sun_manual.unwrap();
    assert_eq!((manual.azimuth_deg, manual.elevation_deg), (200.0, 30.0));
    assert!(!has(&h, "sun marker (computed)"));
    let marker = h.get_by_label("sun marker (manual) azimuth 200.000° elevation 30.000°");
    let map = h.get_by_label("sky map").rect();
    let [x, y] = photomontage::site::sun_path::sky_map_xy(200.0, 30.0);
    let radius = photomontage_studio::light_panel::sky_map::sky_map_radius();
    let want = egui::pos2(
        map.center().x + radius * x as f32,
        map.center().y - radius * y as f32,
    );
    let got = marker.rect().center();
    assert!(
        (got.x - want.x).abs() < MARKER_TOL_PT && (got.y - want.y).abs() < MARKER_TOL_PT,
        "marker at {got:?}, expected {want:?}"
    );
    assert!(has(&h, "sun set by hand"));
}

#[test]
fn a_manual_sun_is_drawn_without_a_location() {
    let (_dir, site) = copy_sample();
    let mut doc = SiteDocument::load(&site).unwrap();
    doc.site.location = None;
    doc.site.lighting.sun_manual = Some(photomontage::site::SunManual {
        azimuth_deg: 90.0,
        elevation_deg: 45.0,
    });
    doc.save().unwrap();
    let h = open_light_tab(&site);
    assert!(
        h.query_by_label("sun marker (manual) azimuth 90.000° elevation 45.000°")
            .is_some()
    );
}

#[test]
fn typed_light_text_survives_other_edits_and_their_undo() {
    let (_dir, site) = copy_sample();
    let original = SiteDocument::load(&site).unwrap().site;
    let mut h = open_light_tab(&site);
    // Typed, not applied.
    set_text(&mut h, "latitude", "12.5");
    set_text(&mut h, "lighting time", "2024-06-21T09:00:00+02:00");
    // Another field's edit, then its undo.
    set_text(&mut h, "exposure", "2");
    click(&mut h, "Set exposure");
    h.run();
    assert_eq!(site_of(&h).render.exposure, 2.0);
    assert_eq!(value(&h, "latitude"), "12.5");
    assert_eq!(value(&h, "lighting time"), "2024-06-21T09:00:00+02:00");
    undo(&mut h);
    assert_eq!(site_of(&h), original);
    assert_eq!(
        value(&h, "latitude"),
        "12.5",
        "not refilled by another field's undo"
    );
    assert_eq!(
        value(&h, "exposure"),
        original.render.exposure.to_string(),
        "the field's own undo refills it"
    );
    // Its own apply writes it, its own undo refills it.
    click(&mut h, "Apply location");
    h.run();
    assert_eq!(site_of(&h).location.unwrap().latitude_deg, 12.5);
    undo(&mut h);
    assert_eq!(site_of(&h), original);
    assert_eq!(value(&h, "latitude"), "47.3769");
    assert_eq!(value(&h, "lighting time"), "2024-06-21T09:00:00+02:00");
}

#[test]
fn typed_hex_survives_an_edit_of_another_material() {
    let (_dir, site) = copy_sample();
    let mut h = harness(&site, common::WINDOW);
    click(&mut h, "Materials tab");
    click(&mut h, "Material brick");
    set_text(&mut h, "Hex colour", "#123456");
    // Another material's edit (as a command of another panel would make) and its undo.
    let other = SiteMaterial::new(
        Material::diffuse("concrete", [0.3; 3]),
        Some("#959595".into()),
    );
    h.state_mut().apply(
        Command::Material(MaterialCommand::PutMaterial {
            material: Box::new(other),
            at: None,
        }),
        None,
    );
    h.run();
    assert_eq!(value(&h, "Hex colour"), "#123456");
    h.state_mut().undo();
    h.run();
    assert_eq!(value(&h, "Hex colour"), "#123456");
    // Its own apply, then its undo, refill it.
    click(&mut h, "Apply hex");
    h.run();
    let brick = |h: &H| {
        site_of(h)
            .materials
            .iter()
            .find(|m| m.material.name == "brick")
            .and_then(|m| m.colour.clone())
    };
    assert_eq!(brick(&h).as_deref(), Some("#123456"));
    h.state_mut().undo();
    h.run();
    assert_eq!(brick(&h), None);
    assert_ne!(value(&h, "Hex colour"), "#123456");
}

#[test]
fn a_ral_design_code_sets_a_material_colour() {
    let (_dir, site) = copy_sample();
    let mut h = harness(&site, common::WINDOW);
    click(&mut h, "Materials tab");
    click(&mut h, "Material brick");
    // The field starts at the code nearest the current colour.
    let shown = value(&h, "RAL Design code");
    assert!(
        shown.starts_with("RAL ") && photomontage::colour::designer::parse_colour(&shown).is_ok(),
        "{shown}"
    );
    let original = site_of(&h);
    // A RAL Classic code is refused, saying why; nothing changes.
    set_text(&mut h, "RAL Design code", "RAL 9010");
    click(&mut h, "Apply RAL Design");
    assert!(has(&h, "RAL Classic"));
    assert_eq!(site_of(&h), original);
    // The grey of lightness 50: Y = (66/116)³ in every channel, shown as its code.
    set_text(&mut h, "RAL Design code", "RAL 000 50 00");
    click(&mut h, "Apply RAL Design");
    h.run();
    let brick = |h: &H| {
        site_of(h)
            .materials
            .iter()
            .find(|m| m.material.name == "brick")
            .cloned()
            .unwrap()
    };
    assert_eq!(brick(&h).colour.as_deref(), Some("RAL 000 50 00"));
    let y = (66.0f64 / 116.0).powi(3);
    for c in brick(&h).material.diffuse_rgb {
        assert!(
            (c - y).abs() < 1e-12,
            "{:?}",
            brick(&h).material.diffuse_rgb
        );
    }
    assert!(has(&h, "RAL 000 50 00   LRV 18.4"));
    h.state_mut().undo();
    h.run();
    assert_eq!(site_of(&h), original);
    // A chip of a hue page: the page of 210° (the default), its chip RAL 210 50 15.
    click(&mut h, "RAL Design pages");
    click(&mut h, "RAL chip RAL 210 50 15");
    h.run();
    assert_eq!(brick(&h).colour.as_deref(), Some("RAL 210 50 15"));
    let expected = photomontage::colour::designer::parse_colour("RAL 210 50 15")
        .unwrap()
        .resolve()
        .linear_rgb;
    assert_eq!(brick(&h).material.diffuse_rgb, expected);
    assert_eq!(value(&h, "RAL Design code"), "RAL 210 50 15");
    // Another page: the greys.
    click(&mut h, "RAL Design hue page");
    click(&mut h, "RAL page 000");
    click(&mut h, "RAL chip RAL 000 70 00");
    h.run();
    assert_eq!(brick(&h).colour.as_deref(), Some("RAL 000 70 00"));
}

#[test]
fn the_perez_sky_is_set_by_clearness_and_brightness() {
    let (_dir, site) = copy_sample();
    let mut h = open_light_tab(&site);
    // A site file naming `perez` without its inputs does not load (`validate`): the sky is
    // chosen in the studio (the list's `SetLighting` command; `perez` is the 18th entry, below
    // the list's visible part), and the panel says what it still needs.
    let mut lighting = site_of(&h).lighting;
    lighting.sky_model = SkyModelName::Perez;
    h.state_mut().apply(
        Command::Light(LightCommand::SetLighting(Box::new(lighting))),
        None,
    );
    h.run();
    let original = site_of(&h);
    assert_eq!(original.lighting.sky_model, SkyModelName::Perez);
    assert!(
        has(&h, "needs clearness and brightness"),
        "a Perez sky without inputs says what it needs"
    );
    set_text(&mut h, "perez clearness", "0.5");
    set_text(&mut h, "perez brightness", "0.2");
    click(&mut h, "Set Perez sky");
    assert!(has(&h, "lighting.perez.clearness: 0.5 is below 1"));
    assert_eq!(site_of(&h), original);
    set_text(&mut h, "perez clearness", "4.7");
    click(&mut h, "Set Perez sky");
    h.run();
    let s = site_of(&h);
    assert_eq!(
        s.lighting.perez,
        Some(PerezInputs {
            clearness: Some(4.7),
            brightness: Some(0.2),
            ..PerezInputs::default()
        })
    );
    // The site renders with it: the one sky builder accepts it for the sample's sun.
    let doc = h.state().document().unwrap();
    let sun = photomontage::site::render::site_sun_dir(doc, "P1").unwrap();
    assert!(matches!(
        photomontage::site::render::site_sky_model(doc, "P1", &sun).unwrap(),
        photomontage::sky::SkyModel::Perez(_)
    ));
}

#[test]
fn a_click_on_the_planned_model_picks_its_material_and_the_sky_picks_none() {
    let (_dir, site) = copy_sample();
    common::add_box_model(&site);
    let mut h = harness(&site, common::WINDOW);
    click(&mut h, "Solve");
    common::step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    click(&mut h, "Materials tab");
    let doc = h.state().document().unwrap().clone();
    // The box's material in the scene the renderer builds.
    let scene = photomontage::site::render::site_scene(&doc).unwrap();
    let box_material = scene
        .scene
        .triangles()
        .iter()
        .find(|t| scene.object_sources[t.object.0 as usize].label() == "model:box")
        .map(|t| scene.scene.materials()[t.material.0 as usize].name.clone())
        .unwrap();
    let camera = photomontage::site::stored_camera(&doc.site, "P1").unwrap();
    // The middle of the box's south face (the box spans 2683014–016 E, 1247001–003 N,
    // 400–402 m), which faces camera P1 (common::BOX_MODEL).
    let on_box = [2_683_015.0, 1_247_001.0, 401.0];
    let px = camera.project(&on_box.into()).unwrap();

    // Without the mode a click picks nothing.
    common::click_photo_px(&mut h, [px.x, px.y]);
    assert!(!has(&h, "picked "));
    click(&mut h, "Pick from photo");
    assert!(has(&h, "click a surface on the photo"));
    common::click_photo_px(&mut h, [px.x, px.y]);
    assert!(
        has(&h, &format!("picked {box_material} on model:box")),
        "{:?}",
        h.state().messages()
    );
    // The tab's editor shows the picked material.
    assert!(h.query_by_label("Apply hex").is_some());
    // The sky: the top of the photo looks above everything of the courtyard.
    common::click_photo_px(&mut h, [800.0, 1.0]);
    assert!(has(&h, "no surface here"), "{:?}", h.state().messages());
    // Escape leaves the mode.
    h.key_press(egui::Key::Escape);
    h.run();
    assert!(!has(&h, "click a surface on the photo"));
}

#[test]
fn the_unfolded_elevation_is_drawn_on_the_worker_and_exported_as_the_cli_writes_it() {
    let (dir, site) = copy_sample();
    common::add_box_model(&site);
    let mut h = harness(&site, common::WINDOW);
    click(&mut h, "Materials tab");
    click(&mut h, "Unfolded elevation");
    click(&mut h, "Draw elevation");
    wait_for_elevation(&mut h, 120);
    assert!(h.query_by_label("unfolded elevation image").is_some());
    let out = dir.path().join("box-elevation.png");
    set_text(&mut h, "elevation PNG path", out.to_str().unwrap());
    click(&mut h, "Export elevation PNG");
    assert!(has(&h, &format!("wrote {}", out.display())));
    // What `photomontage elevation SITE --model box --out FILE.png` writes: the library's
    // drawing with the default pixels per metre, through the same encoder.
    let doc = SiteDocument::load(&site).unwrap();
    let cli = photomontage::site::elevation::site_elevation(
        &doc,
        "box",
        &photomontage::design::unfolded::UnfoldParams::default(),
        None,
    )
    .unwrap();
    let written = std::fs::read(&out).unwrap();
    assert_eq!(written, cli.png_bytes().unwrap());
    let decoded = image::load_from_memory(&written).unwrap().to_rgb8();
    assert_eq!(decoded, cli.image.image);
}

/// The sky at these (elevation, azimuth) degrees is compared.
const SKY_DIRECTIONS_DEG: [(f64, f64); 4] =
    [(5.0, 0.0), (30.0, 90.0), (60.0, 200.0), (85.0, 300.0)];
/// The studio and the library evaluate the same formula on the same inputs; only the order of
/// floating-point operations could differ.
const SAME_SKY_REL_TOL: f64 = 1e-12;

/// Relative luminance of the site's sky for photo P1 at [`SKY_DIRECTIONS_DEG`].
fn sky_luminances(doc: &SiteDocument, sky: &photomontage::sky::SkyModel) -> Vec<f64> {
    let sun = photomontage::site::render::site_sun_dir(doc, "P1").unwrap();
    SKY_DIRECTIONS_DEG
        .iter()
        .map(|&(el, az)| {
            let (el, az) = (el.to_radians(), az.to_radians());
            // The sun's vector type (the studio has no nalgebra of its own), set to the
            // direction: x east, y north, z up.
            let mut dir = sun;
            (dir.x, dir.y, dir.z) = (el.cos() * az.sin(), el.cos() * az.cos(), el.sin());
            sky.relative_luminance(&dir, &sun)
        })
        .collect()
}

#[test]
fn choosing_perez_in_the_list_fills_in_inputs_so_the_saved_site_loads() {
    let (_dir, site) = copy_sample();
    let mut h = open_light_tab(&site);
    let before = site_of(&h);
    assert_ne!(before.lighting.sky_model, SkyModelName::Perez);
    assert_eq!(before.lighting.perez, None);
    click(&mut h, "sky model");
    // `perez` is the list's 18th entry, below its visible part: scrolled to, then clicked.
    h.get_by_label("perez").scroll_to_me();
    h.run();
    click(&mut h, "perez");
    let chosen = site_of(&h);
    assert_eq!(chosen.lighting.sky_model, SkyModelName::Perez);
    assert_eq!(
        chosen.lighting.perez,
        Some(PerezInputs::gendaylit_example())
    );
    // The inputs are visible in their fields.
    assert_eq!(value(&h, "perez clearness"), "4.7065");
    assert_eq!(value(&h, "perez brightness"), "0.1243");
    click(&mut h, "Save");
    h.run();
    let saved = SiteDocument::load(&site).expect("the saved Perez site loads");
    assert_eq!(saved.site.lighting, chosen.lighting);
    // What the fix prevents: the same file without the inputs is refused, naming them.
    let mut without = saved.clone();
    without.site.lighting.perez = None;
    without.save().unwrap();
    let e = SiteDocument::load(&site).unwrap_err().to_string();
    assert!(e.contains("lighting.perez"), "{e}");
    // One undo restores the previous sky and (no) inputs.
    undo(&mut h);
    assert_eq!(site_of(&h).lighting, before.lighting);
}

#[test]
fn the_perez_irradiance_form_is_typed_in_the_studio() {
    let (_dir, site) = copy_sample();
    let mut h = open_light_tab(&site);
    click(&mut h, "sky model");
    h.get_by_label("perez").scroll_to_me();
    h.run();
    click(&mut h, "perez");
    let with_indices = site_of(&h);
    click(&mut h, "perez from irradiance");
    // A bad value: the library's message, nothing applied.
    set_text(&mut h, "perez direct normal", "-5");
    set_text(&mut h, "perez diffuse horizontal", "150");
    click(&mut h, "Set Perez sky");
    assert!(
        has(&h, "lighting.perez.direct_normal_w_m2: -5 W/m² is negative"),
        "{:?}",
        h.state().messages()
    );
    assert_eq!(site_of(&h), with_indices);
    set_text(&mut h, "perez direct normal", "600");
    click(&mut h, "Set Perez sky");
    h.run();
    let s = site_of(&h);
    assert_eq!(
        s.lighting.perez,
        Some(PerezInputs {
            direct_normal_w_m2: Some(600.0),
            diffuse_horizontal_w_m2: Some(150.0),
            ..PerezInputs::default()
        })
    );
    // The site's sky is the library's Perez sky for the same irradiance, sun and day.
    let doc = h.state().document().unwrap().clone();
    let sun = photomontage::site::render::site_sun_dir(&doc, "P1").unwrap();
    let studio_sky = photomontage::site::render::site_sky_model(&doc, "P1", &sun).unwrap();
    let day = photomontage::site::site_time::site_sun_time(&doc, "P1")
        .unwrap()
        .ordinal();
    let library_sky = photomontage::sky::SkyModel::Perez(
        photomontage::sky::perez::PerezSky::from_irradiance(600.0, 150.0, sun.z.acos(), day)
            .unwrap(),
    );
    for (got, want) in sky_luminances(&doc, &studio_sky)
        .into_iter()
        .zip(sky_luminances(&doc, &library_sky))
    {
        assert!(
            ((got - want) / want).abs() < SAME_SKY_REL_TOL,
            "{got} vs {want}"
        );
    }
    // Undo back to the indices, redo to the irradiance.
    undo(&mut h);
    assert_eq!(site_of(&h), with_indices);
    assert_eq!(value(&h, "perez clearness"), "4.7065");
    h.state_mut().redo();
    h.run();
    assert_eq!(site_of(&h), s);
    assert_eq!(value(&h, "perez direct normal"), "600");
}

#[test]
fn the_irradiance_elevation_takes_the_clis_solve_options() {
    let (dir, site) = copy_sample();
    common::add_box_model(&site);
    let mut h = harness(&site, TALL);
    click(&mut h, "Materials tab");
    click(&mut h, "Unfolded elevation");
    click(&mut h, "elevation irradiance");
    // Non-default options: 2 m elements (the CLI's `--element-edge-m 2`) and seed 3.
    h.get_by_label("elevation element edge (m)")
        .set_value_accesskit(2.0);
    h.run();
    h.get_by_label("elevation seed").set_value_accesskit(3.0);
    h.run();
    click(&mut h, "Draw elevation");
    wait_for_elevation(&mut h, 300);
    let out = dir.path().join("box-irradiance.png");
    set_text(&mut h, "elevation PNG path", out.to_str().unwrap());
    click(&mut h, "Export elevation PNG");
    let written = std::fs::read(&out).unwrap();
    // What `photomontage elevation SITE --model box --irradiance --element-edge-m 2 --seed 3
    // --out FILE.png` writes: the same options through the library's one mapping.
    let doc = SiteDocument::load(&site).unwrap();
    let options = photomontage::site::solve_options::SolveOptions {
        element_edge_m: 2.0,
        seed: 3,
        ..Default::default()
    };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let draw = |options: &photomontage::site::solve_options::SolveOptions| {
        photomontage::site::elevation::site_elevation(
            &doc,
            "box",
            &photomontage::design::unfolded::UnfoldParams::default(),
            Some(photomontage::site::elevation::ElevationLighting {
                params: options.elevation_transfer_params(),
                view: "P1".into(),
                cancel: &cancel,
            }),
        )
        .unwrap()
        .png_bytes()
        .unwrap()
    };
    assert_eq!(written, draw(&options), "the CLI's PNG, byte for byte");
    // The options matter: the defaults give another picture.
    assert_ne!(
        written,
        draw(&photomontage::site::solve_options::SolveOptions::default())
    );
}
