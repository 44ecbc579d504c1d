//! Camera profiles in a site: a photo without `[photos.interior]` but with `profile = "…"`
//! starts its solve from the profile (here the courtyard generator's true interior,
//! `truth.json`: f 1500 px, k1 −0.04, k2 0.01), and a profile for another image size is refused
//! naming the photo and the profile.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::calibration::profile::CameraProfile;
use photomontage::camera::BrownConrady;
use photomontage::site::{SiteDocument, solve_site};
use photomontage_tests::sample_site;

fn profile(size: [u32; 2]) -> CameraProfile {
    CameraProfile {
        make: Some("Synthetic".into()),
        model: Some("courtyard generator".into()),
        image_size_px: size,
        fx_px: 1500.0,
        fy_px: 1500.0,
        principal_point_px: [799.5, 599.5],
        distortion: BrownConrady {
            k1: -0.04,
            k2: 0.01,
            ..BrownConrady::default()
        },
        rms_px: 0.0,
        board: None,
        square_mm: None,
        method: "truth.json".into(),
        source_images: Vec::new(),
    }
}

fn courtyard_with_profile(size: [u32; 2]) -> (tempfile::TempDir, SiteDocument) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lens.toml");
    std::fs::write(&path, profile(size).to_toml().unwrap()).unwrap();
    let back = CameraProfile::load(&path).unwrap();
    assert_eq!(
        back,
        profile(size),
        "the TOML reads back to the same profile"
    );
    let mut doc = SiteDocument::load(&sample_site("courtyard").join("site.toml")).unwrap();
    for p in &mut doc.site.photos {
        p.interior = None;
        p.profile = Some(path.display().to_string());
    }
    (dir, doc)
}

#[test]
fn a_photo_without_interior_starts_from_its_camera_profile() {
    let (_dir, doc) = courtyard_with_profile([1600, 1200]);
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    assert_eq!(solution.photos.len(), 3);
    for s in &solution.photos {
        assert_eq!(s.focal_source, "camera_profile");
        // The courtyard's photos were rendered with this interior: the solve fits well.
        assert!(s.rms_px < 1.0, "{}: {} px", s.id, s.rms_px);
    }
}

#[test]
fn a_profile_for_another_image_size_is_refused_naming_photo_and_profile() {
    let (_dir, doc) = courtyard_with_profile([640, 480]);
    let solution = solve_site(&doc);
    assert_eq!(solution.failures.len(), 3);
    let e = &solution.failures[0].error;
    assert!(
        e.contains("P1") && e.contains("lens.toml") && e.contains("[640, 480]"),
        "{e}"
    );
}
