//! File → New site… and calibrating the courtyard sample from scratch, all in the studio:
//! a new site from the sample's three photos (chosen in the multi-select dialog, a substituted
//! picker: kittest cannot drive a native dialog), the interior orientation entered in each
//! photo's camera settings as a user would (the sample's PNGs carry no EXIF, so the library's
//! stated fallback is used and announced), the surveyor's control-point file imported, every
//! observation placed by clicking the pixel the sample's site file holds, Solve — and every
//! camera compared with the CLI's (`solve_site`, what `photomontage solve` runs) on the
//! sample's own site file. Also: the typed-path fallback and the readable errors (site file
//! exists, the same photo twice, an unreadable image).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, click_photo_px, copy_sample, harness, step_until, wait_idle};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::site::{SiteDocument, solve_site};
use photomontage_studio::Studio;
use photomontage_studio::files::{DialogPurpose, DialogRequest, FilePicker};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// Clicks go photo px → f32 screen points → photo px: within 1.2e-4 points, i.e. 3e-4 px at
/// the fitted zoom (~0.4); 1e-3 px leaves a margin (as the studio test's `CLICK_TOL_PX`).
const CLICK_TOL_PX: f64 = 1e-3;
/// Camera centres from the studio vs the CLI: the clicked observations differ by < 0.002 σ from
/// the file's, which moves a camera by that fraction of its own σ (1–3 cm here): 0.1 mm is
/// generous and far below anything visible (the same bound as `tests/studio.rs`).
const CAMERA_CENTRE_TOL_M: f64 = 1e-4;
/// See [`CAMERA_CENTRE_TOL_M`]; ‖R₁ − R₂‖_F/√2 ≈ the rotation angle between them.
const CAMERA_ROTATION_TOL_RAD: f64 = 1e-5;
/// The click error reaches the self-calibrated focal length with a gain of a few
/// (1e-4 … 5e-4 px measured in `tests/studio.rs`); σ_f is a few px.
const FOCAL_TOL_PX: f64 = 2e-3;
/// k1 is estimated too. A change Δk1 moves a pixel at normalised radius r by Δk1·r³·f; at the
/// image corner r = 1000 px / 1450 px ≈ 0.69, so f·r³ ≈ 476 px and 4e-6 is 2e-3 px there, the
/// same bound as [`FOCAL_TOL_PX`] (measured: up to 1.1e-6, k1 being the weakest parameter).
const K1_TOL: f64 = 4e-6;

/// A picker answering each dialog with the next queued list of paths.
#[derive(Default)]
struct FakePicker {
    answers: Mutex<Vec<Vec<PathBuf>>>,
    asked: Mutex<Vec<DialogPurpose>>,
}

impl FilePicker for FakePicker {
    fn pick(&self, request: &DialogRequest) -> Option<PathBuf> {
        self.pick_many(request)?.into_iter().next()
    }

    fn pick_many(&self, request: &DialogRequest) -> Option<Vec<PathBuf>> {
        self.asked.lock().unwrap().push(request.purpose);
        let mut a = self.answers.lock().unwrap();
        (!a.is_empty()).then(|| a.remove(0))
    }
}

fn open_new_site_window(h: &mut Harness<'static, Studio>) {
    h.get_by_label("File").click();
    h.run();
    h.get_by_label("New site…").click();
    h.run();
}

fn canonical(p: &std::path::Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap()
}

#[test]
fn a_new_site_from_the_sample_photos_calibrates_to_the_cli_cameras() {
    let (dir, sample_site) = copy_sample();
    let original = SiteDocument::load(&sample_site).expect("sample loads");
    let photos: Vec<PathBuf> = original
        .site
        .photos
        .iter()
        .map(|p| original.resolve(&p.file))
        .collect();
    let new_path = dir.path().join("from_scratch.toml");
    let mut h = harness(&sample_site, WINDOW);

    // File → New site…: photos from the multi-select dialog, the file from the save dialog.
    let picker = Arc::new(FakePicker::default());
    picker.answers.lock().unwrap().push(photos.clone());
    picker.answers.lock().unwrap().push(vec![new_path.clone()]);
    h.state_mut().set_file_picker(picker.clone());
    open_new_site_window(&mut h);
    h.get_by_label("Choose photos…").click();
    h.run();
    step_until(&mut h, "photo dialog", Studio::is_idle);
    assert_eq!(h.state_mut().new_site_dialog_mut().photos, photos);
    h.get_by_label("Choose file…").click();
    h.run();
    step_until(&mut h, "file dialog", Studio::is_idle);
    h.get_by_label("Create site").click();
    h.run();
    wait_idle(&mut h);
    assert_eq!(
        *picker.asked.lock().unwrap(),
        vec![DialogPurpose::NewSitePhotos, DialogPurpose::NewSiteFile]
    );

    // The new site is open, saved, in the recent list; one entry per photo, ids from the file
    // names, paths relative to the site file, the size read from the file.
    let doc = h.state().document().expect("new site open").clone();
    assert_eq!(canonical(&doc.path), canonical(&new_path));
    assert_eq!(SiteDocument::load(&new_path).expect("saved").site, doc.site);
    assert_eq!(h.state().recent_sites()[0].path, canonical(&new_path));
    assert_eq!(doc.site.photos.len(), 3);
    for (p, o) in doc.site.photos.iter().zip(&original.site.photos) {
        assert_eq!((&p.id, &p.file), (&o.id, &o.file));
        let i = p.interior.as_ref().expect("an interior");
        assert_eq!(i.image_size_px, Some([1600, 1200]));
        // No EXIF in the PNGs: the stated fallback, the diagonal (exactly 2000 px), estimated.
        assert!((i.focal_px - 2000.0).abs() < 1e-9, "{}", i.focal_px);
        assert!(p.self_calibration.focal);
        let warned = h.state().messages().iter().any(|m| {
            m.text.contains(&format!("photo `{}`", p.id)) && m.text.contains("no focal length")
        });
        assert!(warned, "the fallback is announced for {}", p.id);
    }

    // Enter the interior a user would (the sample's: focal 1450 px, principal point at the
    // centre, no distortion; the solve estimates focal and k1) in each photo's camera settings.
    for p in &original.site.photos {
        h.get_by_label(&format!("photo {}", p.id)).click();
        wait_idle(&mut h);
        h.get_by_label("Camera settings").click();
        h.run();
        let want = p.interior.as_ref().expect("sample interior");
        h.get_by_label("focal px")
            .set_value_accesskit(want.focal_px);
        h.run();
        let flags = p.self_calibration;
        let now = h
            .state()
            .document()
            .unwrap()
            .site
            .photos
            .iter()
            .find(|q| q.id == p.id)
            .unwrap()
            .self_calibration;
        for (label, want, have) in [
            ("estimate focal length", flags.focal, now.focal),
            (
                "estimate principal point",
                flags.principal_point,
                now.principal_point,
            ),
            ("estimate k1", flags.k1, now.k1),
            ("estimate k2", flags.k2, now.k2),
        ] {
            if want != have {
                h.get_by_label(label).click();
                h.run();
            }
        }
        let set = h
            .state()
            .document()
            .unwrap()
            .site
            .photos
            .iter()
            .find(|q| q.id == p.id)
            .unwrap()
            .clone();
        assert_eq!(set.interior.as_ref(), Some(want), "{}", p.id);
        assert_eq!(set.self_calibration, p.self_calibration, "{}", p.id);
        h.get_by_label("Close camera settings").click();
        h.run();
    }
    // The settings are edits like any other: undo takes the last one back, redo reapplies it.
    let before_undo = h.state().document().unwrap().site.clone();
    h.get_by_label("Undo").click();
    h.run();
    assert_ne!(h.state().document().unwrap().site, before_undo);
    h.get_by_label("Redo").click();
    h.run();
    assert_eq!(h.state().document().unwrap().site, before_undo);

    // Import the surveyor's control-point file by typing its path.
    let csv = dir.path().join("control_points.csv");
    h.get_by_label("import path").click();
    h.run();
    h.get_by_label("import path")
        .type_text(csv.to_str().expect("utf-8 path"));
    h.run();
    h.get_by_label("Import").click();
    h.run();
    assert_eq!(
        h.state().document().unwrap().site.control_points,
        original.site.control_points
    );

    // Place every observation of the sample file by clicking its pixel.
    for photo in &original.site.photos {
        h.get_by_label(&format!("photo {}", photo.id)).click();
        wait_idle(&mut h);
        for o in original
            .site
            .observations
            .iter()
            .filter(|o| o.photo == photo.id)
        {
            if original.site.control_points.iter().any(|c| c.id == o.point) {
                h.get_by_label(&o.point).click();
            } else {
                h.get_by_label("point id")
                    .set_text_value_accesskit(&o.point);
                h.run();
                h.get_by_label("Pick id").click();
            }
            h.run();
            assert_eq!(h.state().selected_point(), Some(o.point.as_str()));
            // Zoom in on the spot as a user does: A3 and A4 on P2 are 1 px apart, and a click
            // on a mark selects it instead of placing.
            *h.state_mut().viewport_mut() = photomontage_studio::viewport::Viewport {
                zoom: 16.0,
                centre_px: [o.x_px, o.y_px],
                fitted: false,
            };
            h.run();
            click_photo_px(&mut h, [o.x_px, o.y_px]);
        }
    }
    let placed = &h.state().document().unwrap().site.observations;
    assert_eq!(placed.len(), original.site.observations.len());
    for (p, o) in placed.iter().zip(&original.site.observations) {
        assert_eq!((&p.photo, &p.point), (&o.photo, &o.point));
        assert!((p.x_px - o.x_px).abs() < CLICK_TOL_PX && (p.y_px - o.y_px).abs() < CLICK_TOL_PX);
    }

    // Solve in the studio; the CLI solves the sample's own file.
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    let studio = h.state().solution().expect("solved").clone();
    let cli = solve_site(&original);
    assert!(cli.failures.is_empty() && studio.failures.is_empty());
    assert_eq!(studio.photos.len(), cli.photos.len());
    for c in &cli.photos {
        let s = studio.photos.iter().find(|s| s.id == c.id).expect("solved");
        let dc =
            (s.camera.pose.camera_center_in_world - c.camera.pose.camera_center_in_world).norm();
        let dr = (s.camera.pose.rotation_world_from_camera.matrix()
            - c.camera.pose.rotation_world_from_camera.matrix())
        .norm()
            / std::f64::consts::SQRT_2;
        let df = (s.camera.intrinsics.focal_px - c.camera.intrinsics.focal_px).abs();
        let dk1 = (s.camera.intrinsics.distortion.k1 - c.camera.intrinsics.distortion.k1).abs();
        eprintln!(
            "{}: Δcentre {dc:.3e} m, Δrotation {dr:.3e} rad, Δfocal {df:.3e} px, Δk1 {dk1:.3e}",
            c.id
        );
        assert!(dc < CAMERA_CENTRE_TOL_M, "{}: centre {dc} m", c.id);
        assert!(dr < CAMERA_ROTATION_TOL_RAD, "{}: rotation {dr} rad", c.id);
        assert!(df < FOCAL_TOL_PX, "{}: focal {df} px", c.id);
        assert!(dk1 < K1_TOL, "{}: k1 {dk1}", c.id);
        assert_eq!(s.outliers, c.outliers, "{}", c.id);
        assert_eq!(s.solved_by, c.solved_by);
    }
    // Saved from the studio, the cameras are in the new site file.
    h.get_by_label("Save").click();
    h.run();
    let saved = SiteDocument::load(&new_path).expect("saved");
    assert!(saved.site.photos.iter().all(|p| p.exterior.is_some()));
}

#[test]
fn typed_paths_and_readable_errors_change_nothing() {
    let (dir, sample_site) = copy_sample();
    let mut h = harness(&sample_site, WINDOW);
    let before = h.state().document().unwrap().clone();
    open_new_site_window(&mut h);

    let type_into = |h: &mut Harness<'static, Studio>, label: &str, text: &str| {
        h.get_by_label(label).click();
        h.run();
        h.get_by_label(label).type_text(text);
        h.run();
    };
    let p1 = dir.path().join("photos/P1.png");
    type_into(&mut h, "new site photo path", p1.to_str().unwrap());
    h.get_by_label("Add photo").click();
    h.run();
    assert_eq!(h.state_mut().new_site_dialog_mut().photos, vec![p1.clone()]);

    // The site file exists: refused, readable, nothing overwritten.
    type_into(&mut h, "new site file", sample_site.to_str().unwrap());
    let sample_text = std::fs::read(&sample_site).unwrap();
    h.get_by_label("Create site").click();
    h.run();
    assert!(
        h.query_all_by_label_contains("already exists")
            .next()
            .is_some(),
        "error shown"
    );
    assert!(h.state().messages().last().unwrap().is_error);
    assert_eq!(std::fs::read(&sample_site).unwrap(), sample_text);
    assert_eq!(h.state().document().unwrap().path, before.path);

    // The same photo twice (spelled differently): refused.
    let new_path = dir.path().join("new.toml");
    h.state_mut().new_site_dialog_mut().site_path = new_path.display().to_string();
    let again = dir.path().join("photos/../photos/P1.png");
    type_into(&mut h, "new site photo path", again.to_str().unwrap());
    h.get_by_label("Add photo").click();
    h.run();
    h.get_by_label("Create site").click();
    h.run();
    assert!(
        h.query_all_by_label_contains("is chosen twice")
            .next()
            .is_some(),
        "error shown"
    );
    assert!(!new_path.exists());

    // An unreadable image: refused, named.
    h.get_by_label(&format!("remove photo {}", again.display()))
        .click();
    h.run();
    let bad = dir.path().join("photos/broken.jpg");
    std::fs::write(&bad, b"\xff\xd8\xff\xe0 not a jpeg").unwrap();
    type_into(&mut h, "new site photo path", bad.to_str().unwrap());
    h.get_by_label("Add photo").click();
    h.run();
    h.get_by_label("Create site").click();
    h.run();
    assert!(
        h.query_all_by_label_contains("broken.jpg").next().is_some(),
        "error shown"
    );
    assert!(!new_path.exists());
    assert_eq!(h.state().document().unwrap().site, before.site);

    // Without the broken one it works, by typed paths alone.
    h.get_by_label(&format!("remove photo {}", bad.display()))
        .click();
    h.run();
    h.get_by_label("Create site").click();
    h.run();
    wait_idle(&mut h);
    let doc = h.state().document().unwrap();
    assert_eq!(canonical(&doc.path), canonical(&new_path));
    assert_eq!(doc.site.photos.len(), 1);
    assert_eq!(doc.site.photos[0].file, "photos/P1.png");
}

#[test]
fn a_photo_without_interior_gets_one_entered_by_hand_undoably() {
    let (_dir, sample_site) = copy_sample();
    let mut doc = SiteDocument::load(&sample_site).unwrap();
    doc.site.photos[0].interior = None;
    doc.save().unwrap();
    let mut h = harness(&sample_site, WINDOW);
    h.get_by_label("Camera settings").click();
    h.run();
    h.get_by_label("Enter by hand").click();
    h.run();
    let p1 = |h: &Harness<'static, Studio>| h.state().document().unwrap().site.photos[0].clone();
    let i = p1(&h).interior.expect("entered");
    // The fallback start: the diagonal of 1600 × 1200, exactly 2000 px; size from the file.
    assert_eq!(i.image_size_px, Some([1600, 1200]));
    assert!((i.focal_px - 2000.0).abs() < 1e-9);
    // Principal point off the centre, then a distortion coefficient: each one undo step.
    h.get_by_label("principal point at centre").click();
    h.run();
    assert_eq!(
        p1(&h).interior.unwrap().principal_point_px,
        Some([800.0, 600.0])
    );
    h.get_by_label("distortion k2").set_value_accesskit(-0.01);
    h.run();
    assert_eq!(
        p1(&h).interior.unwrap().distortion.k2.to_bits(),
        (-0.01f64).to_bits()
    );
    h.get_by_label("Close camera settings").click();
    h.run();
    assert!(h.query_by_label("Close camera settings").is_none());
    for _ in 0..3 {
        h.get_by_label("Undo").click();
        h.run();
    }
    assert_eq!(p1(&h).interior, None);
    assert_eq!(h.state().document().unwrap().site, doc.site);
}
