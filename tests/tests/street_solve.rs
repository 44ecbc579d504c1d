//! End to end: solve the Mitsuba-rendered `street` sample site (sample_sites/street, made by its
//! generate.py) and compare every camera with the generator's truth.json.
//!
//! The site has 1 cm survey noise on the control points and 0.3 px click noise on the
//! observations (seeded), true interior orientation and no blunders.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use nalgebra::{Matrix3, Rotation3};
use photomontage::site::{SiteDocument, solve_site};
use photomontage_tests::sample_site;

/// A solved camera centre must lie within this many of its reported standard deviations of the
/// truth per axis (the brief's bound; Gaussian errors exceed 5σ about once in 1.7 million).
const SIGMA_BOUND: f64 = 5.0;
/// Observations flagged by data snooping (the site has no blunders, so these are false alarms):
/// with 0.3 px click noise one of the 126 observations (V2/B5, a 3.9σ draw) exceeds the solver's
/// 3.5σ normalised-residual threshold; more than this many would mean the solve or the
/// generator's geometry is wrong.
const FALSE_ALARM_BUDGET: usize = 2;
/// Floor added to the bound: the generator rounds control coordinates to 1 mm and pixels to
/// 0.01 px (≤ 0.5 mm at these distances).
const ROUNDING_FLOOR_M: f64 = 0.002;

fn truth() -> serde_json::Value {
    let text = std::fs::read_to_string(sample_site("street").join("truth.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn vec3(v: &serde_json::Value) -> [f64; 3] {
    [0, 1, 2].map(|k| v[k].as_f64().unwrap())
}

#[test]
fn street_cameras_match_truth_within_reported_sigma() {
    let doc = SiteDocument::load(&sample_site("street").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    let truth = truth();
    let n_views = truth["cameras"].as_object().unwrap().len();
    assert_eq!(solution.photos.len(), n_views);
    assert!(n_views >= 3);
    for s in &solution.photos {
        let t = &truth["cameras"][&s.id];
        let center = vec3(&t["camera_center"]);
        let got = s.camera.pose.camera_center_in_world;
        let dist: f64 = (0..3)
            .map(|a| (got[a] - center[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        println!(
            "{}: centre error {:.4} m ({:+.4}, {:+.4}, {:+.4}), σ {:.4?} m, RMS {:.3} px",
            s.id,
            dist,
            got[0] - center[0],
            got[1] - center[1],
            got[2] - center[2],
            s.sigma_center_m,
            s.rms_px
        );
        for axis in 0..3 {
            let err = (got[axis] - center[axis]).abs();
            let bound = SIGMA_BOUND * s.sigma_center_m[axis] + ROUNDING_FLOOR_M;
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
            "{}: rotation error {angle_deg:.4}°, σ max {sigma_max:.4}°",
            s.id
        );
        assert!(
            angle_deg < SIGMA_BOUND * 3f64.sqrt() * sigma_max,
            "{}: {angle_deg}°",
            s.id
        );
        if !s.outliers.is_empty() {
            println!("{}: flagged {:?}", s.id, s.outliers);
        }
    }
    let flagged: usize = solution.photos.iter().map(|s| s.outliers.len()).sum();
    assert!(
        flagged <= FALSE_ALARM_BUDGET,
        "{flagged} observations flagged"
    );
}
