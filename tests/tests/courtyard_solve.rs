//! End to end: solve the bundled courtyard sample site and compare with the generator's truth.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use nalgebra::{Matrix3, Rotation3};
use photomontage::site::{SiteDocument, apply_solution, solve_site, stored_camera};
use photomontage_tests::sample_site;

/// A solved quantity must lie within this many of its reported standard deviations of the truth
/// (a 4σ bound fails by chance about once in 16 000 per coordinate for Gaussian errors).
const SIGMA_BOUND: f64 = 4.0;
/// Floor added to the bound: the generator rounds control coordinates to 1 mm and pixels to 0.01 px.
const ROUNDING_FLOOR_M: f64 = 0.002;

fn truth() -> serde_json::Value {
    let text = std::fs::read_to_string(sample_site("courtyard").join("truth.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn vec3(v: &serde_json::Value) -> [f64; 3] {
    [
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    ]
}

#[test]
fn courtyard_cameras_match_truth_within_reported_sigma() {
    let doc = SiteDocument::load(&sample_site("courtyard").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    assert_eq!(solution.photos.len(), 3);
    let truth = truth();
    for s in &solution.photos {
        let t = &truth["cameras"][&s.id];
        let center = vec3(&t["camera_center"]);
        let got = s.camera.pose.camera_center_in_world;
        for axis in 0..3 {
            let err = (got[axis] - center[axis]).abs();
            let bound = SIGMA_BOUND * s.sigma_center_m[axis] + ROUNDING_FLOOR_M;
            println!(
                "{} axis {axis}: error {err:.4} m, σ {:.4} m",
                s.id, s.sigma_center_m[axis]
            );
            assert!(
                err < bound,
                "{} centre axis {axis}: error {err} m > {bound} m",
                s.id
            );
        }
        let rows: Vec<f64> = t["rotation_world_from_camera"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(vec3)
            .collect();
        let r_true = Rotation3::from_matrix(&Matrix3::from_row_slice(&rows));
        let angle_deg = (r_true.inverse() * s.camera.pose.rotation_world_from_camera)
            .angle()
            .to_degrees();
        let sigma_max = s.sigma_angles_deg.iter().copied().fold(0.0, f64::max);
        println!(
            "{} rotation error {angle_deg:.4}°, σ max {sigma_max:.4}°",
            s.id
        );
        assert!(
            angle_deg < SIGMA_BOUND * 3f64.sqrt() * sigma_max,
            "{}: {angle_deg}°",
            s.id
        );
        assert_eq!(s.solved_by, "bundle");
    }
}

#[test]
fn mislabelled_observation_is_flagged() {
    let doc = SiteDocument::load(&sample_site("courtyard").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    let truth = truth();
    let bad_photo = truth["mislabelled"]["photo"].as_str().unwrap();
    let bad_point = truth["mislabelled"]["point"].as_str().unwrap();
    for s in &solution.photos {
        let expected: Vec<&str> = if s.id == bad_photo {
            vec![bad_point]
        } else {
            vec![]
        };
        assert_eq!(s.outliers, expected, "photo {}", s.id);
    }
}

#[test]
fn tie_points_match_truth_and_survive_a_save() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = SiteDocument::load(&sample_site("courtyard").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    apply_solution(&mut doc.site, &solution);
    let out = dir.path().join("solved.toml");
    doc.save_as(&out).unwrap();
    let again = SiteDocument::load(&out).unwrap();
    let truth = truth();
    assert!(!again.site.tie_points.is_empty());
    for tp in &again.site.tie_points {
        let t = vec3(&truth["points"][&tp.id]);
        for axis in 0..3 {
            let err = (tp.xyz[axis] - t[axis]).abs();
            assert!(
                err < SIGMA_BOUND * tp.sigma_m[axis] + ROUNDING_FLOOR_M,
                "{} axis {axis}: {err} m vs σ {}",
                tp.id,
                tp.sigma_m[axis]
            );
        }
    }
    // The saved cameras are the solved ones, and the photos still resolve from the new folder.
    for s in &solution.photos {
        let cam = stored_camera(&again.site, &s.id).unwrap();
        assert!(
            (cam.pose.camera_center_in_world - s.camera.pose.camera_center_in_world).norm() < 1e-9
        );
        let p = again.site.photos.iter().find(|p| p.id == s.id).unwrap();
        assert!(again.resolve(&p.file).is_file());
    }
}
