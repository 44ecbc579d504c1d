//! Known-answer tests of [`super::resect`] on seeded synthetic scenes.

use super::*;
use crate::photogrammetry::synthetic::{Layout, SceneSpec, rotation_error, single_photo};

/// Pose errors must lie within this many reported σ (per axis for the centre, combined for the
/// rotation). For Gaussian errors a 4.5 σ excursion has probability ~7e-6 per check; the test
/// matrix makes a few hundred checks.
const SIGMA_BOUND: f64 = 4.5;
/// At most this many good observations may be flagged per scene: the snooping threshold 3.5
/// gives ~1e-3 false alarms per point, so even one is unlikely in a 100-point scene.
const MAX_FALSE_FLAGS: usize = 1;

struct Lens {
    name: &'static str,
    focal_px: f64,
    distance_m: f64,
}

const IMAGE: [u32; 2] = [4000, 3000];
const LENSES: [Lens; 3] = [
    Lens {
        name: "wide",
        focal_px: 1800.0,
        distance_m: 20.0,
    },
    Lens {
        name: "normal",
        focal_px: 4000.0,
        distance_m: 50.0,
    },
    Lens {
        name: "tele",
        focal_px: 14000.0,
        distance_m: 200.0,
    },
];

fn check_scene(spec: &SceneSpec, label: &str) {
    let scene = single_photo(spec);
    let options = ResectionOptions::new(scene.camera.intrinsics);
    let r = resect(&scene.control, &scene.observations, &options)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let truth = &scene.camera.pose;
    let dc = r.camera.pose.camera_center_in_world - truth.camera_center_in_world;
    for axis in 0..3 {
        assert!(
            dc[axis].abs() <= SIGMA_BOUND * r.sigma_center_m[axis],
            "{label}: centre error {dc} vs σ {:?}",
            r.sigma_center_m
        );
    }
    let angle = rotation_error(
        &truth.rotation_world_from_camera,
        &r.camera.pose.rotation_world_from_camera,
    );
    let sigma_angle = r
        .sigma_angles_deg
        .iter()
        .map(|s| s * s)
        .sum::<f64>()
        .sqrt()
        .to_radians();
    assert!(
        angle <= SIGMA_BOUND * sigma_angle,
        "{label}: rotation error {} deg vs σ {:?}",
        angle.to_degrees(),
        r.sigma_angles_deg
    );
    for id in &scene.outlier_ids {
        assert!(
            r.outliers.contains(id),
            "{label}: outlier {id} missed; flagged {:?}",
            r.outliers
        );
    }
    let false_flags = r
        .outliers
        .iter()
        .filter(|id| !scene.outlier_ids.contains(id))
        .count();
    assert!(
        false_flags <= MAX_FALSE_FLAGS,
        "{label}: false flags {:?}",
        r.outliers
    );
    assert!(r.redundancy >= 2 && r.sigma0.is_finite());
}

#[test]
fn synthetic_cameras_recover_pose_within_reported_sigma() {
    let mut seed = 100;
    for lens in &LENSES {
        for layout in [
            Layout::Volume {
                depth_fraction: 0.3,
            },
            Layout::Ground,
        ] {
            for points in [4, 6, 12, 30, 100] {
                for outlier_fraction in [0.0, 0.2] {
                    if outlier_fraction > 0.0 && points < 12 {
                        // One gross error among fewer than 12 points leaves too little
                        // redundancy for a reliable test (minimal detectable bias ≫ 20 px).
                        continue;
                    }
                    seed += 1;
                    let spec = SceneSpec {
                        focal_px: lens.focal_px,
                        image_size_px: IMAGE,
                        distance_m: lens.distance_m,
                        points,
                        layout,
                        sigma_px: 0.5,
                        outlier_fraction,
                        seed,
                    };
                    let label = format!(
                        "{} {layout:?} n={points} outliers={outlier_fraction}",
                        lens.name
                    );
                    check_scene(&spec, &label);
                }
            }
        }
    }
}

#[test]
fn focal_length_is_estimated_from_volume_control() {
    let spec = SceneSpec {
        focal_px: 3000.0,
        image_size_px: IMAGE,
        distance_m: 30.0,
        points: 50,
        layout: Layout::Volume {
            depth_fraction: 0.4,
        },
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 7,
    };
    let scene = single_photo(&spec);
    let mut initial = scene.camera.intrinsics;
    initial.focal_px *= 1.08;
    let mut options = ResectionOptions::new(initial);
    options.self_calibration.focal = true;
    let r = resect(&scene.control, &scene.observations, &options).expect("solvable");
    assert!(r.estimated.focal, "{:?}", r.warnings);
    let sigma_f = r.sigma_focal_px.expect("estimated");
    assert!((r.camera.intrinsics.focal_px - 3000.0).abs() <= SIGMA_BOUND * sigma_f);
}

#[test]
fn focal_length_of_a_head_on_facade_stays_fixed_with_a_warning() {
    // A planar target parallel to the image plane: focal length and distance are inseparable.
    let spec = SceneSpec {
        focal_px: 4000.0,
        image_size_px: IMAGE,
        distance_m: 40.0,
        points: 30,
        layout: Layout::FacadeHeadOn,
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 8,
    };
    let scene = single_photo(&spec);
    let mut options = ResectionOptions::new(scene.camera.intrinsics);
    options.self_calibration.focal = true;
    let r = resect(&scene.control, &scene.observations, &options).expect("solvable");
    assert!(!r.estimated.focal);
    assert!(
        r.warnings.iter().any(|w| w.starts_with("focal kept fixed")),
        "{:?}",
        r.warnings
    );
    assert!(r.sigma_focal_px.is_none());
}

fn scene(points: usize) -> crate::photogrammetry::synthetic::SyntheticScene {
    single_photo(&SceneSpec {
        focal_px: 3000.0,
        image_size_px: IMAGE,
        distance_m: 30.0,
        points,
        layout: Layout::Volume {
            depth_fraction: 0.3,
        },
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 9,
    })
}

#[test]
fn too_few_points_name_required_and_found() {
    let s = scene(3);
    let options = ResectionOptions::new(s.camera.intrinsics);
    assert_eq!(
        resect(&s.control, &s.observations, &options).err(),
        Some(PhotogrammetryError::NotEnoughPoints {
            required: 4,
            found: 3
        })
    );
    assert_eq!(
        resect(&s.control, &s.observations[..2], &options).err(),
        Some(PhotogrammetryError::NotEnoughPoints {
            required: 4,
            found: 2
        })
    );
}

#[test]
fn invalid_input_is_a_typed_error() {
    let s = scene(8);
    let options = ResectionOptions::new(s.camera.intrinsics);
    // Collinear control.
    let mut collinear = s.control.clone();
    for (i, c) in collinear.iter_mut().enumerate() {
        c.point_in_world = Point3::new(i as f64, 2.0 * i as f64, 0.5 * i as f64);
    }
    assert_eq!(
        resect(&collinear, &s.observations, &options).err(),
        Some(PhotogrammetryError::Collinear)
    );
    // NaN pixel.
    let mut nan = s.observations.clone();
    nan[2].pixel.y = f64::NAN;
    assert!(matches!(
        resect(&s.control, &nan, &options),
        Err(PhotogrammetryError::NonFinite { .. })
    ));
    // NaN control coordinate.
    let mut nan_control = s.control.clone();
    nan_control[1].point_in_world.x = f64::INFINITY;
    assert!(matches!(
        resect(&nan_control, &s.observations, &options),
        Err(PhotogrammetryError::NonFinite { .. })
    ));
    // Duplicate ids.
    let mut dup = s.control.clone();
    dup[3].id = dup[0].id.clone();
    assert_eq!(
        resect(&dup, &s.observations, &options).err(),
        Some(PhotogrammetryError::DuplicateId {
            id: dup[0].id.clone()
        })
    );
    let mut dup_obs = s.observations.clone();
    dup_obs[5].point_id = dup_obs[4].point_id.clone();
    assert!(matches!(
        resect(&s.control, &dup_obs, &options),
        Err(PhotogrammetryError::DuplicateId { .. })
    ));
    // Unknown point.
    let mut unknown = s.observations.clone();
    unknown[0].point_id = "nope".to_owned();
    assert_eq!(
        resect(&s.control, &unknown, &options).err(),
        Some(PhotogrammetryError::UnknownPoint {
            id: "nope".to_owned()
        })
    );
    // Zero σ.
    let mut zero = s.observations.clone();
    zero[0].sigma_px = 0.0;
    assert!(matches!(
        resect(&s.control, &zero, &options),
        Err(PhotogrammetryError::InvalidSigma { .. })
    ));
}

#[test]
fn points_behind_the_camera_are_flagged_not_fitted() {
    // Mirror one control point through the camera centre: it projects to (about) the same
    // pixel but lies behind the camera, so no pose can use it.
    let s = scene(12);
    let mut control = s.control.clone();
    let c = s.camera.pose.camera_center_in_world;
    control[4].point_in_world = c - (control[4].point_in_world - c);
    let options = ResectionOptions::new(s.camera.intrinsics);
    let r = resect(&control, &s.observations, &options).expect("solvable from the others");
    assert!(r.outliers.contains(&control[4].id), "{:?}", r.outliers);
    assert!(
        r.warnings.iter().any(|w| w.contains("behind")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn coincident_plane_points_in_a_small_set_are_an_error() {
    let s = single_photo(&SceneSpec {
        focal_px: 3000.0,
        image_size_px: IMAGE,
        distance_m: 30.0,
        points: 4,
        layout: Layout::Ground,
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 10,
    });
    let mut obs = s.observations.clone();
    obs[3].pixel = obs[1].pixel + nalgebra::Vector2::new(0.7, -0.4);
    let options = ResectionOptions::new(s.camera.intrinsics);
    assert!(matches!(
        resect(&s.control, &obs, &options),
        Err(PhotogrammetryError::CoincidentObservations { .. })
    ));
}

#[test]
fn control_sigma_propagates_into_the_pose_sigma() {
    // Surveyed positions carry 5 cm errors (σ = 0.05 m per axis); at 30 m with f = 3000 px that
    // is ~5 px, ten times σ_px, so the pose σ must come from the control σ to cover the error.
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let s = scene(30);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    let sigma_m = 0.05;
    let control: Vec<ControlPoint> = s
        .control
        .iter()
        .map(|c| {
            let mut e = || -> f64 { StandardNormal.sample(&mut rng) };
            ControlPoint {
                id: c.id.clone(),
                point_in_world: c.point_in_world + Vector3::new(e(), e(), e()) * sigma_m,
                sigma_m: [sigma_m; 3],
            }
        })
        .collect();
    let options = ResectionOptions::new(s.camera.intrinsics);
    let r = resect(&control, &s.observations, &options).expect("solvable");
    assert!(r.outliers.is_empty(), "{:?}", r.outliers);
    let dc = r.camera.pose.camera_center_in_world - s.camera.pose.camera_center_in_world;
    for axis in 0..3 {
        assert!(
            dc[axis].abs() <= SIGMA_BOUND * r.sigma_center_m[axis],
            "{dc} vs {:?}",
            r.sigma_center_m
        );
    }
    // σ₀ stays near 1 because the weights include the control σ.
    assert!(r.sigma0 < 1.5, "σ0 {}", r.sigma0);
}

#[test]
fn absurd_focal_or_principal_point_is_refused_before_any_work() {
    // A focal length of 1e-200 px (or a principal point of 1e300 px) once sent NaN into the P3P
    // quartic and the eigenvalue solver never returned.
    let s = scene(12);
    let mut tiny_focal = s.camera.intrinsics;
    tiny_focal.focal_px = 1e-200;
    let mut far_pp = s.camera.intrinsics;
    far_pp.principal_point_px = [1e300, 1500.0];
    for (intrinsics, field) in [(tiny_focal, "focal_px"), (far_pp, "principal_point_px[0]")] {
        let err = resect(
            &s.control,
            &s.observations,
            &ResectionOptions::new(intrinsics),
        )
        .expect_err("out of range");
        assert!(
            matches!(err, PhotogrammetryError::IntrinsicOutOfRange { field: f, .. } if f == field),
            "{err}"
        );
        assert!(err.to_string().contains(field), "{err}");
    }
}

/// Control points mirrored through the true camera centre: every pixel is unchanged but every
/// point lies behind the camera.
fn mirrored_through_the_camera(
    s: &crate::photogrammetry::synthetic::SyntheticScene,
) -> Vec<ControlPoint> {
    let c = s.camera.pose.camera_center_in_world;
    s.control
        .iter()
        .map(|p| ControlPoint {
            point_in_world: c - (p.point_in_world - c),
            ..p.clone()
        })
        .collect()
}

#[test]
fn control_all_behind_the_camera_is_an_error_naming_the_points() {
    for points in [4, 6, 12] {
        let s = single_photo(&SceneSpec {
            focal_px: 3000.0,
            image_size_px: IMAGE,
            distance_m: 30.0,
            points,
            layout: Layout::Volume {
                depth_fraction: 0.3,
            },
            sigma_px: 0.5,
            outlier_fraction: 0.0,
            seed: 3,
        });
        let control = mirrored_through_the_camera(&s);
        let options = ResectionOptions::new(s.camera.intrinsics);
        match resect(&control, &s.observations, &options) {
            Err(PhotogrammetryError::PointsBehindCamera { photo, point_ids }) => {
                assert_eq!(photo, None);
                let mut expected: Vec<String> = control.iter().map(|c| c.id.clone()).collect();
                let mut got = point_ids.clone();
                expected.sort();
                got.sort();
                assert_eq!(got, expected, "{points} points");
            }
            other => panic!("{points} points: expected PointsBehindCamera, got {other:?}"),
        }
    }
}

#[test]
fn planar_control_behind_the_camera_gives_the_mirrored_camera_with_points_in_front() {
    // The known limitation: the camera mirrored across the plane sees the same pixels with every
    // point in front; that camera is returned, and it has all points at positive depth.
    let s = single_photo(&SceneSpec {
        focal_px: 3000.0,
        image_size_px: IMAGE,
        distance_m: 30.0,
        points: 8,
        layout: Layout::Ground,
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 3,
    });
    let control = mirrored_through_the_camera(&s);
    let options = ResectionOptions::new(s.camera.intrinsics);
    let r = resect(&control, &s.observations, &options).expect("the mirrored camera");
    for c in &control {
        assert!(
            r.camera.pose.camera_from_world(&c.point_in_world).z > 0.0,
            "{}",
            c.id
        );
    }
    assert!(r.outliers.len() <= MAX_FALSE_FLAGS, "{:?}", r.outliers);
}
