//! Known-answer tests of [`super::bundle_adjust`] on seeded synthetic blocks.

use super::*;
use crate::photogrammetry::PhotogrammetryError;
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

/// Sparse and dense paths solve the same normal equations and differ only in the order of
/// floating-point sums; both stop when every step is below 1e-10 σ. 1e-9 relative is far above
/// that difference and far below any reported precision.
const SPARSE_DENSE_RELATIVE: f64 = 1e-9;

fn assert_close(what: &str, a: f64, b: f64, scale: f64) {
    assert!(
        (a - b).abs() <= SPARSE_DENSE_RELATIVE * a.abs().max(b.abs()).max(scale),
        "{what}: sparse {a} vs dense {b}"
    );
}

#[test]
fn sparse_normal_equations_give_the_dense_solution() {
    // Everything the solver does at once: weighted and fixed control, focal length and k1 per
    // photo, a gross error removed by the outlier rounds, point covariances.
    let spec = BlockSpec {
        photos: 8,
        points: 80,
        control: 8,
        control_sigma_m: 0.01,
        sigma_px: 0.5,
        initial_center_error_m: 0.3,
        initial_rotation_error: 0.005,
        seed: 16,
    };
    let b = block(&spec);
    let mut control = b.control.clone();
    control[0].sigma_m = [0.0; 3];
    control[1].sigma_m = [0.0, 0.0, 0.02];
    let mut ph = photos(&b);
    for p in &mut ph {
        p.camera.intrinsics.focal_px *= 1.02;
        p.self_calibration.focal = true;
        p.self_calibration.k1 = true;
    }
    ph[3].observations[5].pixel.y -= 30.0;
    let options = BundleOptions {
        point_covariance: true,
        ..BundleOptions::default()
    };
    let sparse = bundle_adjust(&ph, &control, &options).expect("solvable");
    let dense = bundle_adjust_dense_reference(&ph, &control, &options).expect("solvable");
    assert!(sparse.converged && dense.converged);
    assert_eq!(sparse.redundancy, dense.redundancy);
    assert_close("σ0", sparse.sigma0, dense.sigma0, 0.0);
    let flagged: usize = sparse.photos.iter().map(|p| p.outliers.len()).sum();
    assert_eq!(flagged, 1, "{:?}", sparse.warnings);
    for (s, d) in sparse.photos.iter().zip(&dense.photos) {
        assert_eq!(s.outliers, d.outliers);
        assert_eq!(s.estimated, d.estimated);
        let (cs, cd) = (&s.camera, &d.camera);
        for axis in 0..3 {
            let id = &s.id;
            assert_close(
                &format!("{id} centre"),
                cs.pose.camera_center_in_world[axis],
                cd.pose.camera_center_in_world[axis],
                1.0,
            );
            assert_close(
                &format!("{id} σ centre"),
                s.sigma_center_m[axis],
                d.sigma_center_m[axis],
                0.0,
            );
            assert_close(
                &format!("{id} σ angle"),
                s.sigma_angles_deg[axis],
                d.sigma_angles_deg[axis],
                0.0,
            );
        }
        let rs = cs.pose.rotation_world_from_camera.matrix();
        let rd = cd.pose.rotation_world_from_camera.matrix();
        for (a, b) in rs.iter().zip(rd.iter()) {
            assert_close(&format!("{} rotation", s.id), *a, *b, 1.0);
        }
        assert_close("focal", cs.intrinsics.focal_px, cd.intrinsics.focal_px, 1.0);
        assert_close(
            "k1",
            cs.intrinsics.distortion.k1,
            cd.intrinsics.distortion.k1,
            1.0,
        );
        assert_close(
            "σ focal",
            s.sigma_focal_px.unwrap_or(0.0),
            d.sigma_focal_px.unwrap_or(0.0),
            0.0,
        );
    }
    for (s, d) in sparse.points.iter().zip(&dense.points) {
        assert_eq!(s.id, d.id);
        for axis in 0..3 {
            assert_close(&s.id, s.point_in_world[axis], d.point_in_world[axis], 1.0);
            assert_close(&s.id, s.sigma_m[axis], d.sigma_m[axis], 0.0);
        }
    }
}

#[test]
#[allow(clippy::float_cmp)] // exact: fixed control's σ is set to 0, and the camera σ are computed
// by the same operations with and without point covariances
fn point_covariances_only_on_request() {
    let spec = BlockSpec {
        photos: 4,
        points: 30,
        control: 6,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.1,
        initial_rotation_error: 0.001,
        seed: 17,
    };
    let b = block(&spec);
    let without = bundle_adjust(&photos(&b), &b.control, &BundleOptions::default()).expect("ok");
    let with = bundle_adjust(
        &photos(&b),
        &b.control,
        &BundleOptions {
            point_covariance: true,
            ..BundleOptions::default()
        },
    )
    .expect("ok");
    for (a, b) in without.points.iter().zip(&with.points) {
        if a.is_control {
            assert_eq!(a.sigma_m, [0.0; 3]);
        } else {
            assert!(a.sigma_m.iter().all(|s| s.is_nan()), "{}", a.id);
            assert!(b.sigma_m.iter().all(|s| *s > 0.0), "{}", b.id);
        }
        assert_eq!(a.point_in_world, b.point_in_world);
    }
    assert_eq!(
        without.photos[0].sigma_center_m,
        with.photos[0].sigma_center_m
    );
}

#[test]
fn points_behind_a_photo_are_an_error_naming_photo_and_points() {
    let spec = BlockSpec {
        photos: 5,
        points: 40,
        control: 10,
        control_sigma_m: 0.0,
        sigma_px: 0.5,
        initial_center_error_m: 0.1,
        initial_rotation_error: 0.001,
        seed: 18,
    };
    let b = block(&spec);
    let mut ph = photos(&b);
    // Photo 2 starts turned half round about the vertical: everything it observes is behind it.
    let pose = &mut ph[2].camera.pose;
    pose.rotation_world_from_camera =
        nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
            * pose.rotation_world_from_camera;
    let control_seen: Vec<String> = ph[2]
        .observations
        .iter()
        .map(|o| o.point_id.clone())
        .filter(|id| id.starts_with('c'))
        .collect();
    assert!(!control_seen.is_empty());
    match bundle_adjust(&ph, &b.control, &BundleOptions::default()) {
        Err(PhotogrammetryError::PointsBehindCamera { photo, point_ids }) => {
            assert_eq!(photo.as_deref(), Some("photo02"));
            for id in &control_seen {
                assert!(point_ids.contains(id), "{id} missing from {point_ids:?}");
            }
            let seen: Vec<&str> = ph[2]
                .observations
                .iter()
                .map(|o| o.point_id.as_str())
                .collect();
            assert!(point_ids.iter().all(|id| seen.contains(&id.as_str())));
        }
        other => panic!("expected PointsBehindCamera, got {other:?}"),
    }
}
