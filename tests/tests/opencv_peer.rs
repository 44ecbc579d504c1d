//! Peer comparison with OpenCV 5.0 on the shared benchmark data (`bench/data/opencv/*.json`,
//! results in `bench/peers/results/opencv.json`): our resection must be no less accurate than
//! `solvePnP(SOLVEPNP_ITERATIVE)` and our one-image self-calibration no less accurate than
//! `calibrateCamera` (focal length, k1, k2 free; principal point fixed).
//!
//! Both programs minimise the same reprojection error on the same data, so the answers agree to
//! solver precision; the comparison allows [`PEER_SLACK`] for that.

use nalgebra::{Matrix3, Point2, Point3, Rotation3};
use photomontage::camera::Intrinsics;
use photomontage::photogrammetry::{ControlPoint, ImageObservation, ResectionOptions, resect};
use serde_json::Value;

/// Relative slack on "no worse than the peer": both converge to the same least-squares
/// minimum, OpenCV's LM stops at a relative step of ~1e-6… so differences of 0.1 % of the
/// error are solver tolerance, not accuracy.
const PEER_SLACK: f64 = 1e-3;

fn load(relative: &str) -> Option<Value> {
    let path = photomontage_tests::shared_file(relative)?;
    let text = std::fs::read_to_string(path).expect("readable");
    Some(serde_json::from_str(&text).expect("valid JSON"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

fn matrix3(v: &Value) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| f(&v[r][c]))
}

struct Problem {
    control: Vec<ControlPoint>,
    observations: Vec<ImageObservation>,
    intrinsics: Intrinsics,
    true_center: Point3<f64>,
    true_world_from_camera: Rotation3<f64>,
}

fn problem(data: &Value) -> Problem {
    let k = matrix3(&data["K"]);
    let size =
        [0, 1].map(|i| u32::try_from(data["image_size"][i].as_u64().expect("size")).expect("fits"));
    let sigma_px = f(&data["noise"]["sigma_px"]);
    let mut control = Vec::new();
    let mut observations = Vec::new();
    for (i, (x, p)) in data["object_points"]
        .as_array()
        .expect("array")
        .iter()
        .zip(data["image_points_observed"].as_array().expect("array"))
        .enumerate()
    {
        let id = format!("p{i:02}");
        control.push(ControlPoint {
            id: id.clone(),
            point_in_world: Point3::new(f(&x[0]), f(&x[1]), f(&x[2])),
            sigma_m: [0.0; 3],
        });
        observations.push(ImageObservation {
            point_id: id,
            pixel: Point2::new(f(&p[0]), f(&p[1])),
            sigma_px,
        });
    }
    let mut intrinsics = Intrinsics::centred(k[(0, 0)], size);
    intrinsics.principal_point_px = [k[(0, 2)], k[(1, 2)]];
    let c = &data["true_pose"]["camera_center_world"];
    Problem {
        control,
        observations,
        intrinsics,
        true_center: Point3::new(f(&c[0]), f(&c[1]), f(&c[2])),
        true_world_from_camera: Rotation3::from_matrix(
            &matrix3(&data["true_pose"]["R_world_to_cam"]).transpose(),
        ),
    }
}

#[test]
fn pnp_accuracy_is_no_worse_than_opencv_iterative() {
    let Some(peers) = load("bench/peers/results/opencv.json") else {
        return;
    };
    for n in ["12", "50"] {
        let Some(data) = load(&format!("bench/data/opencv/pnp_{n}.json")) else {
            return;
        };
        let p = problem(&data);
        let r = resect(
            &p.control,
            &p.observations,
            &ResectionOptions::new(p.intrinsics),
        )
        .expect("solvable");
        let position_error_m = (r.camera.pose.camera_center_in_world - p.true_center).norm();
        let rotation_error_deg = (p.true_world_from_camera.inverse()
            * r.camera.pose.rotation_world_from_camera)
            .angle()
            .to_degrees();
        let methods = &peers["pnp"][n]["methods"];
        println!(
            "pnp_{n}: ours position {position_error_m:.6} m, rotation {rotation_error_deg:.6} deg, rms {:.4} px, outliers {:?}",
            r.rms_px, r.outliers
        );
        for m in ["ITERATIVE", "SQPNP", "EPNP"] {
            println!(
                "pnp_{n}: OpenCV {m:9} position {:.6} m, rotation {:.6} deg",
                f(&methods[m]["position_error_m"]),
                f(&methods[m]["rotation_error_deg"])
            );
        }
        let theirs = &methods["ITERATIVE"];
        assert!(position_error_m <= f(&theirs["position_error_m"]) * (1.0 + PEER_SLACK));
        assert!(rotation_error_deg <= f(&theirs["rotation_error_deg"]) * (1.0 + PEER_SLACK));
    }
}

#[test]
fn one_image_focal_length_is_no_worse_than_opencv_calibrate_camera() {
    let (Some(peers), Some(data)) = (
        load("bench/peers/results/opencv.json"),
        load("bench/data/opencv/calib_50.json"),
    ) else {
        return;
    };
    let p = problem(&data);
    let true_focal_px = p.intrinsics.focal_px;
    let theirs = &peers["calibrate_camera"];
    let mut initial = p.intrinsics;
    initial.focal_px = f(&theirs["initial_f_px"]);
    let mut options = ResectionOptions::new(initial);
    options.self_calibration.focal = true;
    options.self_calibration.k1 = true;
    options.self_calibration.k2 = true;
    let r = resect(&p.control, &p.observations, &options).expect("solvable");
    let focal_error_px = (r.camera.intrinsics.focal_px - true_focal_px).abs();
    println!(
        "calib_50: ours f {:.4} px (error {focal_error_px:.4}, σ {:?}), k1 {:.5}, k2 {:.5}, rms {:.4} px, warnings {:?}",
        r.camera.intrinsics.focal_px,
        r.sigma_focal_px,
        r.camera.intrinsics.distortion.k1,
        r.camera.intrinsics.distortion.k2,
        r.rms_px,
        r.warnings
    );
    println!(
        "calib_50: OpenCV f {:.4} px (error {:.4}), k1 {:.5}, k2 {:.5}",
        f(&theirs["f_px"]),
        f(&theirs["f_error_px"]),
        f(&theirs["k1"]),
        f(&theirs["k2"])
    );
    assert!(
        r.estimated.focal && r.estimated.k1 && r.estimated.k2,
        "{:?}",
        r.warnings
    );
    assert!(focal_error_px <= f(&theirs["f_error_px"]) * (1.0 + PEER_SLACK));
}
