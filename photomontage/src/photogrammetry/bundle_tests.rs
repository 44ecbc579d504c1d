//! Known-answer tests of [`super::bundle_adjust`] on seeded synthetic blocks.

use super::*;
use crate::photogrammetry::synthetic::{BlockSpec, block, rotation_error};

/// Errors must lie within this many reported σ per axis: for Gaussian errors a 4.5 σ excursion
/// has probability ~7e-6, and the 30 × 300 block makes ~1000 checks.
const SIGMA_BOUND: f64 = 4.5;

fn photos(b: &crate::photogrammetry::synthetic::SyntheticBlock) -> Vec<BundlePhoto> {
    b.initial_cameras
        .iter()
        .zip(&b.observations)
        .enumerate()
        .map(|(i, (c, o))| BundlePhoto {
            id: format!("photo{i:02}"),
            camera: *c,
            observations: o.clone(),
            self_calibration: SelfCalibration::default(),
        })
        .collect()
}

fn check(spec: &BlockSpec) -> BundleReport {
    let b = block(spec);
    let options = BundleOptions {
        point_covariance: true,
        ..BundleOptions::default()
    };
    let report = bundle_adjust(&photos(&b), &b.control, &options).expect("solvable");
    assert!(report.converged, "{:?}", report.warnings);
    for (p, truth) in report.photos.iter().zip(&b.true_cameras) {
        let dc = p.camera.pose.camera_center_in_world - truth.pose.camera_center_in_world;
        for axis in 0..3 {
            assert!(
                dc[axis].abs() <= SIGMA_BOUND * p.sigma_center_m[axis],
                "{}: centre error {dc} vs σ {:?}",
                p.id,
                p.sigma_center_m
            );
        }
        let angle = rotation_error(
            &truth.pose.rotation_world_from_camera,
            &p.camera.pose.rotation_world_from_camera,
        );
        let sigma = p
            .sigma_angles_deg
            .iter()
            .map(|s| s * s)
            .sum::<f64>()
            .sqrt()
            .to_radians();
        assert!(
            angle <= SIGMA_BOUND * sigma,
            "{}: rotation {angle} vs σ {sigma}",
            p.id
        );
    }
    let truth: HashMap<&str, Point3<f64>> =
        b.points.iter().map(|(id, x)| (id.as_str(), *x)).collect();
    for pt in report.points.iter().filter(|p| !p.is_control) {
        let d = pt.point_in_world - truth[pt.id.as_str()];
        for axis in 0..3 {
            assert!(
                d[axis].abs() <= SIGMA_BOUND * pt.sigma_m[axis],
                "{}: {d} vs {:?}",
                pt.id,
                pt.sigma_m
            );
        }
    }
    report
}

#[test]
fn small_block_recovers_truth_within_sigma() {
    let report = check(&BlockSpec {
        photos: 6,
        points: 40,
        control: 6,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.5,
        initial_rotation_error: 0.01,
        seed: 11,
    });
    assert!((report.sigma0 - 1.0).abs() < 0.2, "σ0 {}", report.sigma0);
}

#[test]
fn block_of_30_photos_and_300_points_recovers_truth_within_sigma() {
    let report = check(&BlockSpec {
        photos: 30,
        points: 300,
        control: 12,
        control_sigma_m: 0.005,
        sigma_px: 0.5,
        initial_center_error_m: 0.5,
        initial_rotation_error: 0.01,
        seed: 12,
    });
    // σ̂0 of a correctly weighted adjustment with thousands of redundant observations is 1
    // within a few percent.
    assert!((report.sigma0 - 1.0).abs() < 0.05, "σ0 {}", report.sigma0);
    assert!(report.redundancy > 1000);
}

#[test]
fn gross_errors_in_tie_points_are_flagged() {
    let spec = BlockSpec {
        photos: 6,
        points: 40,
        control: 6,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.5,
        initial_rotation_error: 0.01,
        seed: 13,
    };
    let b = block(&spec);
    let mut ph = photos(&b);
    // A tie point seen in at least four photos, so the bad ray is identifiable.
    let bad = ph[2]
        .observations
        .iter()
        .position(|o| {
            o.point_id.starts_with('t')
                && ph
                    .iter()
                    .filter(|p| p.observations.iter().any(|x| x.point_id == o.point_id))
                    .count()
                    >= 4
        })
        .expect("a well-observed tie point");
    let bad_id = ph[2].observations[bad].point_id.clone();
    ph[2].observations[bad].pixel.x += 40.0;
    let report = bundle_adjust(&ph, &b.control, &BundleOptions::default()).expect("solvable");
    assert_eq!(report.photos[2].outliers, vec![bad_id]);
    let flagged: usize = report.photos.iter().map(|p| p.outliers.len()).sum();
    assert_eq!(flagged, 1);
}

#[test]
fn no_control_is_degenerate() {
    let spec = BlockSpec {
        photos: 4,
        points: 20,
        control: 0,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.1,
        initial_rotation_error: 0.001,
        seed: 14,
    };
    let b = block(&spec);
    assert!(matches!(
        bundle_adjust(&photos(&b), &b.control, &BundleOptions::default()),
        Err(PhotogrammetryError::Degenerate { .. } | PhotogrammetryError::NoConvergence)
    ));
}

#[test]
fn focal_lengths_are_estimated_per_photo_where_supported() {
    let spec = BlockSpec {
        photos: 8,
        points: 80,
        control: 8,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.3,
        initial_rotation_error: 0.005,
        seed: 15,
    };
    let b = block(&spec);
    let mut ph = photos(&b);
    for p in &mut ph {
        p.camera.intrinsics.focal_px *= 1.03;
        p.self_calibration.focal = true;
    }
    let report = bundle_adjust(&ph, &b.control, &BundleOptions::default()).expect("solvable");
    for (p, truth) in report.photos.iter().zip(&b.true_cameras) {
        assert!(p.estimated.focal, "{:?}", report.warnings);
        let sigma = p.sigma_focal_px.expect("estimated");
        let error = p.camera.intrinsics.focal_px - truth.intrinsics.focal_px;
        assert!(
            error.abs() <= SIGMA_BOUND * sigma,
            "{}: focal error {error} vs σ {sigma}",
            p.id
        );
    }
}

#[test]
fn non_finite_start_pose_or_absurd_focal_is_refused_naming_it() {
    let spec = BlockSpec {
        photos: 3,
        points: 20,
        control: 6,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.1,
        initial_rotation_error: 0.001,
        seed: 15,
    };
    let b = block(&spec);
    let mut nan_pose = photos(&b);
    nan_pose[1].camera.pose.camera_center_in_world.x = f64::NAN;
    let err = bundle_adjust(&nan_pose, &b.control, &BundleOptions::default()).unwrap_err();
    assert_eq!(
        err,
        PhotogrammetryError::NonFinite {
            what: "start pose of photo photo01".to_owned()
        }
    );
    let mut tiny_focal = photos(&b);
    tiny_focal[2].camera.intrinsics.focal_px = 1e-200;
    assert!(matches!(
        bundle_adjust(&tiny_focal, &b.control, &BundleOptions::default()),
        Err(PhotogrammetryError::IntrinsicOutOfRange {
            field: "focal_px",
            ..
        })
    ));
}
