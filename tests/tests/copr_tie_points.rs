//! COPR kite photos solved with tie points (issue 15, feature `opencv`): every photo sees at
//! most three control points (IMG_0031: gcp00, gcp01, gcp04, two of them on one pixel;
//! IMG_0046 and IMG_0052: gcp03, gcp04), so none can be resected alone (`copr.rs`). SIFT tie
//! points found by `match` let `solve` place them: relative orientation of the best pair, the
//! third photo resected from intersected tie points, absolute orientation on gcp03/gcp04
//! (intersected) and gcp01 (one ray), then the bundle adjustment with control and tie points.
//!
//! What the data allow to check: every photo solved; the mislabelled pair still named, and the
//! adjusted cameras say which label is wrong; the camera centres above the GCPs' plane (h = 0)
//! at the height the GCPs' image scale implies; the tie points on the ground at the GCPs' height.
#![cfg(feature = "opencv")]

use photomontage::photogrammetry::control_io::parse_odm_gcp_list;
use photomontage::site::{ControlPoint, Observation, Photo, Site, SiteDocument, solve_site};
use photomontage::site::tie_matching::match_site;

/// Hand-picked GCP centres in ODM lists are good to a few pixels (as in `copr.rs`).
const SIGMA_PX: f64 = 2.0;
/// Averaged handheld-GPS targets: decimetre class.
const CONTROL_SIGMA_M: f64 = 0.1;
/// Kite photos: the camera is above the ground by more than this (metres)…
const MIN_HEIGHT_M: f64 = 5.0;
/// … and its height agrees with f · (ground distance / image distance) of the GCP pair it sees
/// within this fraction (the photos are not exactly nadir, which the ratio ignores).
const HEIGHT_RATIO_TOLERANCE: f64 = 0.25;
/// The reserve's beach and dune flats: the median tie point lies at the GCPs' height (0 m)
/// within this (metres; GCP heights are handheld GPS, the ground has low dunes and shrubs).
const TIE_HEIGHT_TOLERANCE_M: f64 = 1.5;
/// Bundle RMS bound: SIFT ties (σ ≈ 0.7 px) and GCP clicks (σ 2 px), uncalibrated lens.
const MAX_BUNDLE_RMS_PX: f64 = 3.0;

#[test]
fn copr_photos_solve_with_sift_tie_points() {
    let Some(list_path) =
        photomontage_tests::shared_file("data/real/gcp/odm_data_copr/gcp_list.txt")
    else {
        return;
    };
    let folder = list_path.parent().expect("folder").to_path_buf();
    let list = parse_odm_gcp_list(&std::fs::read_to_string(&list_path).expect("readable"))
        .expect("valid ODM list");
    let images = ["IMG_0031.jpg", "IMG_0046.jpg", "IMG_0052.jpg"];
    let mut site = Site::default();
    site.name = "COPR kite photos".into();
    for image in images {
        site.photos.push(Photo {
            id: image.trim_end_matches(".jpg").into(),
            file: folder.join(image).to_str().expect("UTF-8 path").into(),
            taken_at: None,
            interior: None,
            self_calibration: Default::default(),
            exterior: None,
        });
        for o in list.observations(image, SIGMA_PX) {
            site.observations.push(Observation {
                photo: image.trim_end_matches(".jpg").into(),
                point: o.point_id.clone(),
                x_px: o.pixel.x,
                y_px: o.pixel.y,
                sigma_px: SIGMA_PX,
                enabled: true,
            });
        }
    }
    let seen: std::collections::HashSet<String> =
        site.observations.iter().map(|o| o.point.clone()).collect();
    for c in list.control_points([CONTROL_SIGMA_M; 3]).expect("consistent") {
        if seen.contains(&c.id) {
            site.control_points.push(ControlPoint {
                id: c.id,
                xyz: c.point_in_world.coords.into(),
                sigma_m: c.sigma_m,
                crs: None,
                enabled: true,
            });
        }
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("copr.toml");
    site.save(&path).expect("saved");
    let mut doc = SiteDocument::load(&path).expect("loads");

    // Without tie points: nothing solves (as `copr.rs` shows photo by photo).
    let before = solve_site(&doc);
    assert!(before.photos.is_empty(), "{:?}", before.photos.len());
    assert_eq!(before.failures.len(), 3);

    let (matched, report) = match_site(
        &doc,
        &photomontage::features::MatchOptions::default(),
        &photomontage::photo::DecodeLimits::default(),
    )
    .expect("matched");
    for p in &report.report.pairs {
        println!(
            "{} – {}: ratio {}, mutual {}, verified {}",
            p.photo_a, p.photo_b, p.ratio_passed, p.mutual, p.verified
        );
    }
    println!(
        "{} tie points ({} conflicts dropped)",
        report.written, report.report.conflicts_dropped
    );
    assert!(report.written >= 100, "{} tie points", report.written);
    doc.site = matched;
    doc.save().expect("saved");

    let solution = solve_site(&doc);
    for w in &solution.warnings {
        println!("warning: {w}");
    }
    for f in &solution.failures {
        println!("failure: {} {}", f.id, f.error);
    }
    assert!(solution.failures.is_empty());
    assert_eq!(solution.photos.len(), 3);
    let rms = solution.bundle_rms_px.expect("bundle ran");
    println!("bundle RMS {rms:.3} px");
    assert!(rms < MAX_BUNDLE_RMS_PX);

    // The mislabelled pair is still named, and the adjusted camera tells which label is wrong.
    let verdict = solution
        .warnings
        .iter()
        .find(|w| w.contains("fits the adjusted camera"))
        .expect("a verdict on the mislabelled pair");
    assert!(verdict.contains("gcp00") && verdict.contains("gcp04"), "{verdict}");

    let control = |id: &str| {
        doc.site
            .control_points
            .iter()
            .find(|c| c.id == id)
            .expect("control")
            .xyz
    };
    for s in &solution.photos {
        let c = s.camera.pose.camera_center_in_world;
        // The GCP pair seen in the photo: its ground distance over its image distance.
        let (a, b) = if s.id == "IMG_0031" { ("gcp01", "gcp04") } else { ("gcp03", "gcp04") };
        let pixel = |id: &str| {
            let o = doc
                .site
                .observations
                .iter()
                .find(|o| o.photo == s.id && o.point == id)
                .expect("observed");
            nalgebra::Point2::new(o.x_px, o.y_px)
        };
        let ground_m = (nalgebra::Point3::from(control(a)) - nalgebra::Point3::from(control(b))).norm();
        let image_px = (pixel(a) - pixel(b)).norm();
        let implied_height_m = s.camera.intrinsics.focal_px * ground_m / image_px;
        println!(
            "{}: centre ({:.2}, {:.2}, {:.2}) m, RMS {:.2} px; height implied by {a}–{b}: {implied_height_m:.1} m",
            s.id, c.x, c.y, c.z, s.rms_px
        );
        assert!(c.z > MIN_HEIGHT_M, "{}: {}", s.id, c.z);
        assert!(
            (c.z / implied_height_m - 1.0).abs() < HEIGHT_RATIO_TOLERANCE,
            "{}: {} vs {implied_height_m}",
            s.id,
            c.z
        );
    }
    let mut heights: Vec<f64> = solution
        .points
        .iter()
        .filter(|p| !p.is_control)
        .map(|p| p.point_in_world.z)
        .collect();
    heights.sort_by(f64::total_cmp);
    let median = heights[heights.len() / 2];
    println!("{} tie points adjusted, median height {median:.2} m", heights.len());
    assert!(median.abs() < TIE_HEIGHT_TOLERANCE_M, "{median}");
}
