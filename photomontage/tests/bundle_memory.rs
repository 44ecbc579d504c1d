//! The bundle adjustment at the size where the dense normal equations aborted (issue 16:
//! 3·10⁴ tie-point observations) runs under an address-space limit of [`ADDRESS_SPACE_KB`].
//!
//! The test re-runs itself as a child process under `ulimit -v` (the limit cannot be set for
//! one test inside the shared harness process): 5 photos × 6000 points give ~3·10⁴
//! observations and 18 030 unknowns, whose dense normal matrix alone would take 2.6 GB.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::process::Command;

use photomontage::photogrammetry::synthetic::{BlockSpec, block};
use photomontage::photogrammetry::{BundleOptions, BundlePhoto, SelfCalibration, bundle_adjust};

/// Address-space limit of the child (2 GB, the acceptance bound).
const ADDRESS_SPACE_KB: u64 = 2_000_000;
/// Set in the child's environment: run the adjustment instead of spawning.
const CHILD: &str = "PHOTOMONTAGE_BUNDLE_MEMORY_CHILD";
/// The centre error of every photo must stay within this many reported σ (4.5 σ: ~7e-6 per
/// coordinate for Gaussian errors, 15 checks).
const SIGMA_BOUND: f64 = 4.5;
/// At least this many image observations (the size that aborted before).
const MIN_OBSERVATIONS: usize = 30_000;

fn adjust_in_this_process() {
    let b = block(&BlockSpec {
        photos: 5,
        points: 6000,
        control: 12,
        control_sigma_m: 0.005,
        sigma_px: 0.5,
        initial_center_error_m: 0.5,
        initial_rotation_error: 0.01,
        seed: 21,
    });
    let observations: usize = b.observations.iter().map(Vec::len).sum();
    assert!(
        observations >= MIN_OBSERVATIONS,
        "{observations} observations"
    );
    let photos: Vec<BundlePhoto> = b
        .initial_cameras
        .iter()
        .zip(&b.observations)
        .enumerate()
        .map(|(i, (camera, o))| BundlePhoto {
            id: format!("photo{i}"),
            camera: *camera,
            observations: o.clone(),
            self_calibration: SelfCalibration::default(),
        })
        .collect();
    // Two outlier rounds keep the debug-profile run short; the memory is that of one round.
    let options = BundleOptions {
        max_outlier_rounds: 2,
        ..BundleOptions::default()
    };
    let report = bundle_adjust(&photos, &b.control, &options).unwrap();
    for (p, truth) in report.photos.iter().zip(&b.true_cameras) {
        let d = p.camera.pose.camera_center_in_world - truth.pose.camera_center_in_world;
        for axis in 0..3 {
            assert!(
                d[axis].abs() <= SIGMA_BOUND * p.sigma_center_m[axis],
                "{}: centre error {d} vs σ {:?}",
                p.id,
                p.sigma_center_m
            );
        }
    }
    println!("{observations} observations adjusted");
}

#[test]
fn thirty_thousand_observations_adjust_within_2_gb() {
    if std::env::var_os(CHILD).is_some() {
        adjust_in_this_process();
        return;
    }
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KB} && exec \"$0\" \"$@\""
        ))
        .arg(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "thirty_thousand_observations_adjust_within_2_gb",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD, "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && stdout.contains("observations adjusted"),
        "child under ulimit -v {ADDRESS_SPACE_KB} failed ({:?}):\n{stdout}\n{stderr}",
        output.status
    );
}
