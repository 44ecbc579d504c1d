//! Planar views at a standard focal length on the `street` sample site (true cameras): the view's
//! camera keeps the photo's pose and has the requested 35 mm equivalent; bad input is refused by
//! name. (The 0.1 px placement of world points is checked in the library's own tests with a
//! distorted synthetic photo.)
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::verified::geometry::{camera_angles, fields_of_view_deg, focal_35mm_equiv_mm};
use photomontage::verified::planar_view::planar_view;
use photomontage_tests::truth::site_with_true_cameras;

/// Closed forms: round-off only.
const EXACT_TOL: f64 = 1e-9;

#[test]
fn fifty_mm_view_of_the_street() {
    let doc = site_with_true_cameras("street");
    let view = planar_view(&doc, "V1", 50.0, None).unwrap();
    let cam = &view.camera;
    let f35 = focal_35mm_equiv_mm(cam.intrinsics.focal_px, cam.intrinsics.image_size_px).unwrap();
    assert!((f35 - 50.0).abs() < EXACT_TOL, "{f35}");
    // 1280 × 960 at 50 mm: f = 50 · 1600 / 43.2666 = 1849.0 px, HFoV 2·atan(640/1849.0).
    let [hfov, _] = fields_of_view_deg(&cam.intrinsics);
    let want = 2.0
        * (640.0 / (50.0 * 1600.0 / 43.266_615_305_567_87_f64))
            .atan()
            .to_degrees();
    assert!((hfov - want).abs() < EXACT_TOL);
    // The photo (about 29.7 mm) covers the whole 50 mm view; the pose is the photo's.
    assert!((view.coverage - 1.0).abs() < EXACT_TOL);
    let source = photomontage::site::render::site_camera(&doc, "V1").unwrap();
    let (a, b) = (camera_angles(&source).unwrap(), camera_angles(cam).unwrap());
    assert!((a.bearing_grid_deg - b.bearing_grid_deg).abs() < EXACT_TOL);
    assert!((a.pitch_deg - b.pitch_deg).abs() < EXACT_TOL);
    // A 20 mm view is wider than the photo: about (20/29.7)² of it is covered.
    let wide = planar_view(&doc, "V1", 20.0, Some([640, 480])).unwrap();
    assert!(
        wide.coverage < 0.5 && wide.coverage > 0.4,
        "{}",
        wide.coverage
    );
}

#[test]
fn bad_input_is_refused_by_name() {
    let doc = site_with_true_cameras("street");
    let err = planar_view(&doc, "V2", f64::NAN, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("V2") && err.contains("35 mm"), "{err}");
    let err = planar_view(&doc, "V2", 50.0, Some([0, 10]))
        .unwrap_err()
        .to_string();
    assert!(err.contains("V2"), "{err}");
    let unsolved = photomontage::site::SiteDocument::load(
        &photomontage_tests::sample_site("street").join("site.toml"),
    )
    .unwrap();
    let err = planar_view(&unsolved, "V3", 50.0, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("V3") && err.contains("not solved"), "{err}");
}

#[test]
fn cylindrical_view_refuses_photos_from_different_points() {
    use photomontage::verified::cylindrical_view::{
        CylindricalError, CylindricalOptions, site_cylindrical_view,
    };
    // The street's views stand metres apart; V3 (9 m up) is farthest from their mean centre.
    let doc = site_with_true_cameras("street");
    let err = site_cylindrical_view(&doc, &["V1", "V2", "V3"], &CylindricalOptions::default())
        .unwrap_err();
    assert!(
        matches!(&err, CylindricalError::NotOnePoint { photo, .. } if photo == "V3"),
        "{err}"
    );
    let unsolved = photomontage::site::SiteDocument::load(
        &photomontage_tests::sample_site("street").join("site.toml"),
    )
    .unwrap();
    let err = site_cylindrical_view(&unsolved, &["V1"], &CylindricalOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("V1") && err.contains("not solved"), "{err}");
}

/// The montage rendered into a 50 mm view agrees with the generator's truth image (the street
/// with the building, rendered by Mitsuba) re-projected into the same view, over the building's
/// interior pixels: the tolerance of street_render.rs (4.5 % mean relative error of the building)
/// plus 1 % for the truth's resampling.
const BUILDING_MEAN_REL_TOL: f64 = 0.055;

#[test]
fn the_montage_renders_into_a_planar_view_as_into_a_photo() {
    use photomontage::render::{DifferentialTracer, render_view};
    use photomontage::verified::planar_view::{planar_view_job, reproject};
    let doc = site_with_true_cameras("street");
    let size = [320, 240];
    let (view, job) = planar_view_job(&doc, "V1", 50.0, Some(size)).unwrap();
    assert_eq!(job.camera, view.camera);
    assert_eq!([job.photo_linear.width(), job.photo_linear.height()], size);
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .unwrap();
    let montage = render_view(
        &tracer,
        &job.settings,
        &|_| {},
        &std::sync::atomic::AtomicBool::new(false),
    )
    .unwrap();
    // The truth, re-projected from the photo's camera into the view.
    let truth = photomontage_tests::street::load_linear(
        &photomontage_tests::sample_site("street").join("truth/V1.png"),
    );
    let source = photomontage::site::render::site_camera(&doc, "V1").unwrap();
    let truth_view = reproject(&source, &truth, &view.camera);
    let [w, h] = size.map(|v| v as usize);
    let (mut err, mut n) = (0.0, 0);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            // Interior of the building: it and its four neighbours fully covered.
            if [i, i - 1, i + 1, i - w, i + w]
                .iter()
                .all(|&j| montage.rgba[j][3] >= 1.0)
            {
                let (o, t) = (montage.rgba[i], truth_view.rgba[i]);
                err += (0..3)
                    .map(|k| (f64::from(o[k]) - f64::from(t[k])).abs() / f64::from(t[k]).max(1e-3))
                    .sum::<f64>()
                    / 3.0;
                n += 1;
            }
        }
    }
    let mre = err / f64::from(n);
    println!(
        "50 mm view: {n} building pixels, mean relative error vs the re-projected truth {mre:.4}"
    );
    assert!(n > 1000, "the building is in the 50 mm view");
    assert!(mre < BUILDING_MEAN_REL_TOL, "{mre}");
}
