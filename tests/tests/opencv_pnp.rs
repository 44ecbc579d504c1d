//! OpenCV's `solvePnP` (feature `opencv`, `photomontage::features::pnp`) against our own
//! resection on seeded synthetic photos: both minimise the same reprojection error, so the poses
//! agree to solver precision. (An integration test, so that `.ci/run` builds the library with
//! OpenCV once, for its OpenCV tests here, and not a second time for its unit tests.)
#![cfg(feature = "opencv")]

use photomontage::features::pnp::pnp_check;
use photomontage::photogrammetry::synthetic::{Layout, SceneSpec, single_photo};
use photomontage::photogrammetry::{ResectionOptions, resect};

/// Both solvers minimise the same sum of squares to convergence: their poses agree far
/// below any physical meaning (the brief's 1e-6 at metre scale).
const AGREEMENT_M: f64 = 1e-6;
const AGREEMENT_DEG: f64 = 1e-6;

#[test]
fn opencv_solve_pnp_agrees_with_our_resection() {
    for (layout, seed) in [
        (
            Layout::Volume {
                depth_fraction: 0.3,
            },
            3,
        ),
        (Layout::Ground, 4),
    ] {
        let mut scene = single_photo(&SceneSpec {
            focal_px: 3000.0,
            image_size_px: [4000, 3000],
            distance_m: 50.0,
            points: 12,
            layout,
            sigma_px: 0.5,
            outlier_fraction: 0.0,
            seed,
        });
        // Equal weights in both: error-free control.
        for c in &mut scene.control {
            c.sigma_m = [0.0; 3];
        }
        let ours = resect(
            &scene.control,
            &scene.observations,
            &ResectionOptions::new(scene.camera.intrinsics),
        )
        .expect("solvable");
        // The points our resection used (data snooping may have set one aside).
        let pairs: Vec<_> = scene
            .observations
            .iter()
            .zip(&ours.residuals)
            .filter(|(_, r)| !r.outlier)
            .map(|(o, _)| {
                let c = scene
                    .control
                    .iter()
                    .find(|c| c.id == o.point_id)
                    .expect("control");
                (c.point_in_world, o.pixel)
            })
            .collect();
        println!("{layout:?}: our outliers {:?}", ours.outliers);
        let check = pnp_check(&ours.camera, &pairs).expect("OpenCV solves");
        println!(
            "{layout:?}: centre {:.3e} m, rotation {:.3e}°",
            check.center_difference_m, check.rotation_difference_deg
        );
        assert!(check.center_difference_m < AGREEMENT_M, "{check:?}");
        assert!(check.rotation_difference_deg < AGREEMENT_DEG, "{check:?}");
    }
}
