//! The File menu on the courtyard sample: sites opened by the typed path (the fallback) and by
//! the menu's dialog (a substituted picker: kittest cannot drive a native dialog) land in the
//! recent list newest first, the list survives a restart through the UI state file, a site
//! whose file is gone is greyed out, a live one reopens from the menu; Save as, Import control
//! points and Import model go through the picker too (the model as one undoable edit).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{BOX_OBJ, WINDOW, copy_sample, harness_for, step_until};
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use photomontage_studio::files::{DialogPurpose, DialogRequest, FilePicker};
use photomontage_studio::{Studio, StudioOptions};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The centroid of ~2.7e6 m coordinates summed in two orders differs by a few ulps (≈ 5e-10 m
/// each); 1 µm is far above that and far below anything a placement is edited by.
const CENTROID_TOL_M: f64 = 1e-6;

/// A picker that answers every dialog with the next queued path and records the requests.
#[derive(Default)]
struct FakePicker {
    answers: Mutex<Vec<PathBuf>>,
    asked: Mutex<Vec<DialogPurpose>>,
}

impl FilePicker for FakePicker {
    fn pick(&self, request: &DialogRequest) -> Option<PathBuf> {
        self.asked.lock().unwrap().push(request.purpose);
        let mut a = self.answers.lock().unwrap();
        (!a.is_empty()).then(|| a.remove(0))
    }
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap()
}

fn open_menu_item(h: &mut Harness<'static, Studio>, item: &str) {
    h.get_by_label("File").click();
    h.run();
    h.get_by_label(item).click();
    h.run();
}

fn doc_path(h: &Harness<'static, Studio>) -> PathBuf {
    canonical(&h.state().document().expect("a site is open").path)
}

#[test]
fn recent_sites_typed_path_and_dialogs() {
    let (dir, site) = copy_sample();
    let second = dir.path().join("second.toml");
    let gone = dir.path().join("gone.toml");
    std::fs::copy(&site, &second).unwrap();
    std::fs::copy(&site, &gone).unwrap();
    let state = dir.path().join("config/state.toml");
    let options = |p: &Path| StudioOptions {
        site_path: p.to_path_buf(),
        state_path: Some(state.clone()),
    };

    let mut h = harness_for(Studio::new(options(&gone)), WINDOW);
    assert_eq!(doc_path(&h), canonical(&gone));

    // The typed path (fallback).
    h.get_by_label("site path").click();
    h.run();
    h.get_by_label("site path")
        .type_text(second.to_str().unwrap());
    h.run();
    h.get_by_label("Open").click();
    h.run();
    assert_eq!(doc_path(&h), canonical(&second));

    // The menu's dialog, answered by the fake picker.
    let picker = Arc::new(FakePicker::default());
    picker.answers.lock().unwrap().push(site.clone());
    h.state_mut().set_file_picker(picker.clone());
    open_menu_item(&mut h, "Open site…");
    step_until(&mut h, "open dialog", |s| s.is_idle());
    assert_eq!(doc_path(&h), canonical(&site));
    assert_eq!(*picker.asked.lock().unwrap(), vec![DialogPurpose::OpenSite]);

    let recent: Vec<PathBuf> = h
        .state()
        .recent_sites()
        .into_iter()
        .map(|e| e.path)
        .collect();
    assert_eq!(
        recent,
        vec![canonical(&site), canonical(&second), canonical(&gone)],
        "newest first"
    );
    let gone_canonical = canonical(&gone);
    std::fs::remove_file(&gone).unwrap();
    drop(h);

    // Restart: the list comes back from the state file; the missing site is greyed out.
    let mut h = harness_for(Studio::new(options(&second)), WINDOW);
    let entries = h.state().recent_sites();
    assert_eq!(entries.len(), 3);
    assert_eq!(entries[0].path, canonical(&second));
    assert_eq!(entries[1].path, canonical(&site));
    assert_eq!(entries[2].path, gone_canonical);
    assert!(entries[0].exists && entries[1].exists && !entries[2].exists);
    h.get_by_label("File").click();
    h.run();
    let gone_label = gone_canonical.display().to_string();
    assert!(
        h.get_by_label(&gone_label).accesskit_node().is_disabled(),
        "missing site greyed out"
    );
    let site_label = canonical(&site).display().to_string();
    let live = h.get_by_label(&site_label);
    assert!(!live.accesskit_node().is_disabled());
    live.click();
    h.run();
    assert_eq!(doc_path(&h), canonical(&site));

    // Save as through the dialog: a new file with the same site, now the open one and newest.
    let picker = Arc::new(FakePicker::default());
    let copy = dir.path().join("saved_as.toml");
    picker.answers.lock().unwrap().push(copy.clone());
    h.state_mut().set_file_picker(picker.clone());
    open_menu_item(&mut h, "Save as…");
    step_until(&mut h, "save-as dialog", |s| s.is_idle());
    assert_eq!(doc_path(&h), canonical(&copy));
    assert_eq!(h.state().recent_sites()[0].path, canonical(&copy));
    let reread = photomontage::site::SiteDocument::load(&copy).unwrap();
    assert_eq!(&reread.site, &h.state().document().unwrap().site);

    // Import control points through the dialog: the sample's own list, with an added point.
    let csv = dir.path().join("more_points.csv");
    let mut text = std::fs::read_to_string(dir.path().join("control_points.csv")).unwrap();
    text.push_str("NEW1,2683000.0,1247000.0,400.0\n");
    std::fs::write(&csv, text).unwrap();
    picker.answers.lock().unwrap().push(csv);
    open_menu_item(&mut h, "Import control points…");
    step_until(&mut h, "import dialog", |s| s.is_idle());
    let doc = h.state().document().unwrap();
    let new = doc
        .site
        .control_points
        .iter()
        .find(|c| c.id == "NEW1")
        .unwrap_or_else(|| panic!("NEW1 imported: {:?}", h.state().messages()));
    // Integers in metres parse exactly.
    assert_eq!(
        new.xyz.map(f64::to_bits),
        [2_683_000.0, 1_247_000.0, 400.0].map(f64::to_bits)
    );

    // Import model through the dialog: relative path, metres, Z up, at the control points'
    // centroid; one undoable edit.
    std::fs::write(dir.path().join("my box.obj"), BOX_OBJ).unwrap();
    picker
        .answers
        .lock()
        .unwrap()
        .push(dir.path().join("my box.obj"));
    open_menu_item(&mut h, "Import model…");
    step_until(&mut h, "model dialog", |s| s.is_idle());
    let site_now = &h.state().document().unwrap().site;
    let m = site_now
        .models
        .iter()
        .find(|m| m.id == "my_box")
        .unwrap_or_else(|| panic!("model added: {:?}", h.state().messages()));
    assert_eq!(m.file, "my box.obj");
    assert_eq!((m.units.as_str(), m.up_axis.as_str()), ("m", "z"));
    let n = site_now.control_points.len() as f64;
    for k in 0..3 {
        let mean = site_now
            .control_points
            .iter()
            .map(|c| c.xyz[k])
            .sum::<f64>()
            / n;
        assert!(
            (m.placement.translation[k] - mean).abs() < CENTROID_TOL_M,
            "axis {k}"
        );
    }
    h.get_by_label("Undo").click();
    h.run();
    assert!(h.state().document().unwrap().site.models.is_empty());
    // The typed-path fallback in the Models tab adds the same entry; a file that does not
    // import adds nothing and says why.
    h.get_by_label("Models").click();
    h.run();
    for (file, added) in [("missing.obj", false), ("my box.obj", true)] {
        h.get_by_label("model path").click();
        h.run();
        h.state_mut().models_panel_mut().model_path = dir.path().join(file).display().to_string();
        h.get_by_label("Add model").click();
        h.run();
        let models = &h.state().document().unwrap().site.models;
        assert_eq!(models.iter().any(|m| m.id == "my_box"), added, "{file}");
        if !added {
            assert!(models.is_empty());
            assert!(h.state().messages().last().unwrap().is_error);
        }
    }
    assert_eq!(
        *picker.asked.lock().unwrap(),
        vec![
            DialogPurpose::SaveSiteAs,
            DialogPurpose::ImportPoints,
            DialogPurpose::ImportModel
        ]
    );
}

#[test]
fn a_cancelled_dialog_changes_nothing() {
    let (dir, site) = copy_sample();
    let state = dir.path().join("state.toml");
    let mut h = harness_for(
        Studio::new(StudioOptions {
            site_path: site.clone(),
            state_path: Some(state),
        }),
        WINDOW,
    );
    let before = h.state().document().unwrap().clone();
    let picker = Arc::new(FakePicker::default());
    h.state_mut().set_file_picker(picker.clone());
    open_menu_item(&mut h, "Open site…");
    step_until(&mut h, "cancelled dialog", |s| s.is_idle());
    let after = h.state().document().unwrap();
    assert_eq!(after.path, before.path);
    assert_eq!(after.site, before.site);
    assert_eq!(*picker.asked.lock().unwrap(), vec![DialogPurpose::OpenSite]);
}
