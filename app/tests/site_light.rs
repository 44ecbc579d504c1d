//! The Site & light tab driven by its labels (issue 17 items 1 and 2): a typed location, time
//! zone and local lighting time show the sun angles `photomontage sun` prints for the same
//! place and instant (the library call the CLI makes, and NREL's published SPA example); the
//! edits survive a kill (autosave) and undo restores the site; bad input (unknown zone,
//! latitude out of range, non-finite number, unreadable photometric file) shows a message in
//! the panel and changes nothing; a drag of the time slider is one undo step; a luminaire is
//! added, placed by a click on the photo, dimmed, and saved as expected; the radiosity switches
//! are undoable edits of the render settings.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{click_photo_px, copy_sample, harness, step_until};
use eframe::egui;
use egui_kittest::kittest::{NodeT, Queryable};
use photomontage::site::{SiteDocument, stored_camera};
use photomontage::sun::{SpaParams, solar_position};
use photomontage_studio::{Studio, StudioOptions};
use std::path::{Path, PathBuf};

type H = egui_kittest::Harness<'static, Studio>;

/// Tall enough for the whole tab without scrolling.
const TALL: [f32; 2] = [1400.0, 1700.0];
/// The panel prints angles with 6 decimals: half a unit of the last digit.
const PRINT_TOL_DEG: f64 = 5e-7;
/// NREL's example (Reda & Andreas 2004, Table A5.1) uses ΔT = 67 s, 820 mbar and 11 °C; the
/// CLI's defaults are ΔT = 69 s, 1013.25 mbar, 12 °C. Refraction does not move the azimuth;
/// 2 s of ΔT turn the hour angle by 2 s × 15°/h = 0.0083°, so 0.02° bounds the azimuth.
const NREL_AZIMUTH_TOL_DEG: f64 = 0.02;
/// A click lands where it was aimed within 0.01 px (the bound of the Fit tab's test,
/// app/tests/fit.rs): the placed luminaire's foot must project there.
const CLICK_TOL_PX: f64 = 0.01;
/// The street's ground polygon runs through surveyed points G1–G4 at 407.982–408.006 m: its
/// plane is within 2 cm of 408 m wherever a click lands near the camera.
const GROUND_TOL_M: f64 = 0.02;

fn site_of(h: &H) -> photomontage::site::Site {
    h.state().document().unwrap().site.clone()
}

fn has_label_containing(h: &H, text: &str) -> bool {
    h.query_all_by_label_contains(text).next().is_some()
}

/// Replaces the text of the field labelled `label` with `text`.
fn set_text(h: &mut H, label: &str, text: &str) {
    h.get_by_label(label).click();
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.run();
    h.get_by_label(label).type_text(text);
    h.run();
}

/// Undoes the last edit with Ctrl+Z (after Escape takes the focus from any text field, whose
/// own undo would take the key otherwise).
fn undo(h: &mut H) {
    h.key_press(egui::Key::Escape);
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.run();
}

fn click(h: &mut H, label: &str) {
    h.get_by_label(label).click();
    h.run();
}

/// The number in the label that starts with `prefix` (e.g. "sun azimuth 123.456789°").
fn shown_angle(h: &H, prefix: &str) -> f64 {
    let node = h.get_by_label_contains(prefix);
    let n = node.accesskit_node();
    let label = n.label().or_else(|| n.value()).unwrap_or_default();
    label
        .trim_start_matches(prefix)
        .trim()
        .trim_end_matches('°')
        .parse()
        .unwrap_or_else(|e| panic!("`{label}`: {e}"))
}

fn open_tab(site: &Path) -> H {
    let mut h = harness(site, TALL);
    click(&mut h, "Site & light tab");
    h
}

#[test]
#[allow(clippy::float_cmp)] // the typed values are stored exactly
fn typed_location_zone_and_local_time_show_the_sun_of_photomontage_sun() {
    let (_dir, site) = copy_sample();
    let original = SiteDocument::load(&site).unwrap().site;
    let mut h = open_tab(&site);

    // NREL SPA example site (Golden, Colorado), its zone, and 12:30:30 MST = 13:30:30 MDT.
    set_text(&mut h, "latitude", "39.742476");
    set_text(&mut h, "longitude", "-105.1786");
    set_text(&mut h, "elevation", "1830.14");
    set_text(&mut h, "time zone", "America/Denver");
    click(&mut h, "Apply location");
    set_text(&mut h, "lighting time", "2003-10-17 13:30:30");
    click(&mut h, "Set lighting time");

    let s = site_of(&h);
    let loc = s.location.clone().unwrap();
    assert_eq!(loc.latitude_deg, 39.742476);
    assert_eq!(loc.longitude_deg, -105.1786);
    assert_eq!(loc.elevation_m, 1830.14);
    assert_eq!(loc.time_zone.as_deref(), Some("America/Denver"));
    assert_eq!(loc.crs, original.location.as_ref().unwrap().crs, "CRS kept");
    assert_eq!(
        s.lighting.time.as_deref(),
        Some("2003-10-17T13:30:30-06:00"),
        "local time stored with the zone's offset (daylight saving time)"
    );

    // What `photomontage sun --lat 39.742476 --lon -105.1786 --elevation-m 1830.14
    // --time 2003-10-17T13:30:30-06:00` computes (its defaults for the rest).
    let time = chrono::DateTime::parse_from_rfc3339("2003-10-17T13:30:30-06:00").unwrap();
    let cli = solar_position(
        &time,
        &SpaParams {
            elevation_m: 1830.14,
            ..SpaParams::at(39.742476, -105.1786)
        },
    )
    .unwrap();
    let az = shown_angle(&h, "sun azimuth");
    let el = shown_angle(&h, "sun elevation");
    assert!(
        (az - cli.azimuth_deg).abs() <= PRINT_TOL_DEG,
        "{az} vs {cli:?}"
    );
    assert!(
        (el - cli.elevation_deg).abs() <= PRINT_TOL_DEG,
        "{el} vs {cli:?}"
    );
    assert!(
        (az - 194.340241).abs() < NREL_AZIMUTH_TOL_DEG,
        "NREL's published azimuth 194.340241°, shown {az}"
    );
    assert!(has_label_containing(
        &h,
        "sun computed for 2003-10-17T13:30:30-06:00"
    ));
    assert!(h.query_by_label("sky map").is_some());

    // Kill and reopen: the autosave sidecar carries the edits, the site file has none.
    h.state_mut().autosave_now();
    let reopened = Studio::new(StudioOptions {
        site_path: site.clone(),
        state_path: None,
    });
    assert!(
        reopened
            .messages()
            .iter()
            .any(|m| m.text.contains("restored")),
        "{:?}",
        reopened.messages()
    );
    assert_eq!(reopened.document().unwrap().site, s);
    assert_eq!(SiteDocument::load(&site).unwrap().site, original);

    // Undo twice: the original site, and the panel shows its sun again.
    undo(&mut h);
    undo(&mut h);
    assert_eq!(site_of(&h), original);
    let zurich = chrono::DateTime::parse_from_rfc3339("2024-06-21T15:00:00+02:00").unwrap();
    let back = solar_position(
        &zurich,
        &SpaParams {
            elevation_m: 400.0,
            ..SpaParams::at(47.3769, 8.5417)
        },
    )
    .unwrap();
    assert!((shown_angle(&h, "sun azimuth") - back.azimuth_deg).abs() <= PRINT_TOL_DEG);
    assert_eq!(
        h.get_by_label("latitude").value().as_deref(),
        Some("47.3769")
    );
}

#[test]
fn bad_input_shows_a_message_in_the_panel_and_changes_nothing() {
    let (dir, site) = copy_sample();
    let original = SiteDocument::load(&site).unwrap().site;
    let mut h = open_tab(&site);

    set_text(&mut h, "time zone", "Europe/Zurch");
    click(&mut h, "Apply location");
    assert!(
        has_label_containing(&h, "did you mean `Europe/Zurich`"),
        "{:?}",
        h.state().messages()
    );
    assert_eq!(site_of(&h), original);
    // The typed text stays for the user to correct.
    assert_eq!(
        h.get_by_label("time zone").value().as_deref(),
        Some("Europe/Zurch")
    );
    set_text(&mut h, "time zone", "Europe/Zurich");
    set_text(&mut h, "latitude", "95");
    click(&mut h, "Apply location");
    assert!(has_label_containing(&h, "latitude 95 is outside −90…90°"));
    set_text(&mut h, "latitude", "NaN");
    click(&mut h, "Apply location");
    assert!(has_label_containing(
        &h,
        "latitude: `NaN` is not a finite number"
    ));
    set_text(&mut h, "exposure", "inf");
    click(&mut h, "Set exposure");
    assert!(has_label_containing(
        &h,
        "exposure: `inf` is not a finite number"
    ));
    set_text(&mut h, "lighting time", "2024-03-31 02:30");
    click(&mut h, "Set lighting time");
    assert!(
        has_label_containing(&h, "is not RFC 3339"),
        "no zone in the site: a local time is refused, naming the field"
    );
    assert_eq!(site_of(&h), original);

    // Photometric files: missing, and not IES/LDT.
    set_text(&mut h, "luminaire file", "missing.ies");
    click(&mut h, "Add luminaire");
    assert!(has_label_containing(&h, "missing.ies"));
    std::fs::write(
        dir.path().join("bad.ies"),
        "this is not a photometric file\n",
    )
    .unwrap();
    set_text(&mut h, "luminaire file", "bad.ies");
    click(&mut h, "Add luminaire");
    assert!(has_label_containing(&h, "luminaire file"));
    assert!(has_label_containing(&h, "bad.ies"));
    assert!(!has_label_containing(&h, "click the photo to place"));
    assert_eq!(site_of(&h), original);
    assert!(!h.state().autosave_pending(), "nothing was edited");
}

/// Presses at `from`, moves to `to` in steps, releases: one drag.
fn drag(h: &mut H, from: egui::Pos2, to: egui::Pos2) {
    h.hover_at(from);
    h.run();
    h.event(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    h.step();
    for i in 1..=8 {
        let p = from + (to - from) * (i as f32 / 8.0);
        h.event(egui::Event::PointerMoved(p));
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: to,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    h.run();
}

#[test]
fn a_drag_of_the_time_slider_is_one_undo_step_and_moves_the_sun() {
    let (_dir, site) = copy_sample();
    let original = SiteDocument::load(&site).unwrap().site;
    let mut h = open_tab(&site);
    let rect = h.get_by_label("time slider").rect();
    let y = rect.center().y;
    drag(
        &mut h,
        egui::pos2(rect.left() + 20.0, y),
        egui::pos2(rect.left() + 60.0, y),
    );
    let s = site_of(&h);
    let time = s.lighting.time.clone().unwrap();
    assert_ne!(
        Some(time.clone()),
        original.lighting.time,
        "the drag changed the time"
    );
    assert!(time.starts_with("2024-06-21T"), "same date: {time}");
    assert!(
        time.ends_with(":00+02:00"),
        "whole minutes at the same offset: {time}"
    );
    // The sun shown is the SPA at the new time.
    let t = chrono::DateTime::parse_from_rfc3339(&time).unwrap();
    let spa = solar_position(
        &t,
        &SpaParams {
            elevation_m: 400.0,
            ..SpaParams::at(47.3769, 8.5417)
        },
    )
    .unwrap();
    assert!((shown_angle(&h, "sun azimuth") - spa.azimuth_deg).abs() <= PRINT_TOL_DEG);
    // One undo restores the time before the drag, and nothing is left to undo.
    undo(&mut h);
    assert_eq!(site_of(&h), original);
    undo(&mut h);
    assert!(
        h.state()
            .messages()
            .last()
            .is_some_and(|m| m.text.contains("nothing to undo")),
        "{:?}",
        h.state().messages()
    );
}

/// Site frame origin of the street site's local coordinates (truth.json `origin`).
const STREET_ORIGIN: [f64; 3] = [2_683_400.0, 1_247_600.0, 408.0];

fn copy_street() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/street");
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
    std::fs::copy(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../photomontage/tests/fixtures/downlight.ies"),
        dir.path().join("downlight.ies"),
    )
    .expect("copy ies");
    let site = dir.path().join("site.toml");
    (dir, site)
}

#[test]
#[allow(clippy::float_cmp)] // a typed scale is stored exactly
fn a_luminaire_is_added_placed_by_a_click_dimmed_and_saved() {
    let (_dir, site) = copy_street();
    let mut h = harness(&site, TALL);
    click(&mut h, "Solve");
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    click(&mut h, "Site & light tab");
    let solved = site_of(&h);

    set_text(&mut h, "luminaire file", "downlight.ies");
    click(&mut h, "Add luminaire");
    assert!(has_label_containing(
        &h,
        "click the photo to place downlight.ies"
    ));
    // The street (z = 0, polygon `ground`) 15 m in front of V1; 4 m mounting height.
    let ground = [
        STREET_ORIGIN[0] - 2.0,
        STREET_ORIGIN[1] - 15.0,
        STREET_ORIGIN[2],
    ];
    let camera = stored_camera(&solved, "V1").unwrap();
    let px = camera.project(&ground.into()).unwrap();
    click_photo_px(&mut h, [px.x, px.y]);
    let s = site_of(&h);
    assert_eq!(s.luminaires.len(), 1, "{:?}", h.state().messages());
    let l = &s.luminaires[0];
    assert_eq!(l.id, "L1");
    assert_eq!(l.file, "downlight.ies");
    assert!(l.enabled);
    // Its foot, 4 m below it, is the ground point under the click.
    let foot = [l.position_m[0], l.position_m[1], l.position_m[2] - 4.0];
    let foot_px = camera.project(&foot.into()).unwrap();
    assert!(
        (foot_px.x - px.x).hypot(foot_px.y - px.y) < CLICK_TOL_PX,
        "{:?} vs {:?}",
        foot_px,
        px
    );
    assert!((foot[2] - ground[2]).abs() < GROUND_TOL_M, "{foot:?}");
    assert!(
        h.query_by_label("polar plot L1").is_some(),
        "polar diagram shown"
    );
    assert!(has_label_containing(&h, "outer circle 1000 cd"));

    // Dim it by typing a scale, aim it by typing a tilt.
    set_text(&mut h, "scale L1", "0.0005");
    h.key_press(egui::Key::Enter);
    h.run();
    set_text(&mut h, "tilt L1", "20");
    h.key_press(egui::Key::Enter);
    h.run();
    let s = site_of(&h);
    assert_eq!(s.luminaires[0].scale, 0.0005, "{:?}", s.luminaires);
    assert_eq!(s.luminaires[0].tilt_deg, 20.0);

    // Saved file.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.run();
    let saved = SiteDocument::load(&site).unwrap().site;
    assert_eq!(saved.luminaires, s.luminaires);
    let text = std::fs::read_to_string(&site).unwrap();
    assert!(text.contains("[[luminaires]]") && text.contains("file = \"downlight.ies\""));

    // Undo the tilt, the dimming and the addition.
    for _ in 0..3 {
        undo(&mut h);
    }
    assert_eq!(site_of(&h).luminaires, solved.luminaires);
    assert_eq!(site_of(&h), solved);
}

/// The radiosity switches of the tab set `[render] radiosity` and `[render] photo_reflectance`
/// (what `photomontage render` reads) as undoable edits; the photo's reflectance can only be
/// switched while the radiosity mode is on.
#[test]
fn the_radiosity_switches_are_undoable_edits_of_the_render_settings() {
    let (_dir, site) = copy_sample();
    let original = SiteDocument::load(&site).unwrap().site;
    let mut h = open_tab(&site);
    let (radiosity, photo) = (original.render.radiosity, original.render.photo_reflectance);
    if radiosity {
        click(&mut h, "radiosity");
        assert!(!site_of(&h).render.radiosity, "switched off");
    }
    // Off: the photo's reflectance is greyed out, a click changes nothing.
    let before = site_of(&h);
    click(&mut h, "reflectance from the photo");
    assert_eq!(
        site_of(&h),
        before,
        "disabled while the radiosity mode is off"
    );
    click(&mut h, "radiosity");
    let s = site_of(&h);
    assert!(s.render.radiosity);
    assert_eq!(
        s.render.photo_reflectance, photo,
        "unchanged by the mode switch"
    );
    click(&mut h, "reflectance from the photo");
    let s = site_of(&h);
    assert!(s.render.radiosity);
    assert_eq!(s.render.photo_reflectance, !photo);
    assert!(h.state().autosave_pending(), "an edit to save");
    // Every switch is one undo step.
    for _ in 0..if radiosity { 3 } else { 2 } {
        undo(&mut h);
    }
    assert_eq!(site_of(&h), original);
}
