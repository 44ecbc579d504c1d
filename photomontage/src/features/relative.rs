//! Relative orientation of two photos with known interior orientation: Nistér's five-point
//! algorithm in RANSAC (D. Nistér, *An efficient solution to the five-point relative pose
//! problem*, IEEE PAMI 26(6) 2004; OpenCV `findEssentialMat`), the pose chosen among the four
//! decompositions of E by the most points in front of both cameras (`recoverPose`; Hartley &
//! Zisserman 2004 §9.6.2). Unlike the eight-point algorithm it stays well posed when the scene
//! is (nearly) planar, as kite and drone photos of flat ground are.
//!
//! Pixels are first normalised with each photo's own intrinsics (distortion removed), so the
//! two photos may have different cameras; the RANSAC bound is [`RELATIVE_THRESHOLD_PX`]
//! divided by the mean focal length.
//!
//! # Known limitations
//! A pure rotation (no baseline) has no relative orientation; it is refused by the caller's
//! intersection gate rather than detected here.

use nalgebra::{Matrix3, Point2, Rotation3, Vector3};
use opencv::calib3d;
use opencv::core::{self, Mat, Point2d, Vector};
use opencv::prelude::*;

use crate::photogrammetry::PhotogrammetryError;
use crate::photogrammetry::block_start::{RelativePose, StartPhoto};

/// RANSAC inlier bound of the five-point solver, in pixels (SIFT matches are good to about a
/// pixel; lens distortion left in the intrinsics adds some).
pub const RELATIVE_THRESHOLD_PX: f64 = 2.0;

fn degenerate(a: &StartPhoto, b: &StartPhoto, what: &str) -> PhotogrammetryError {
    PhotogrammetryError::Degenerate {
        reason: format!(
            "relative orientation of photos {} and {}: {what}",
            a.id, b.id
        ),
    }
}

/// The relative orientation of photo b with respect to photo a from their matched pixels.
///
/// # Errors
/// [`PhotogrammetryError::NotEnoughPoints`] for fewer than five matches,
/// [`PhotogrammetryError::Degenerate`] naming the photos when OpenCV finds no essential matrix.
pub fn relative_orientation(
    a: &StartPhoto,
    b: &StartPhoto,
    matches: &[(Point2<f64>, Point2<f64>)],
) -> Result<RelativePose, PhotogrammetryError> {
    if matches.len() < 5 {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: 5,
            found: matches.len(),
        });
    }
    let cv = |e: opencv::Error| degenerate(a, b, &e.to_string());
    let norm_a: Vector<Point2d> = matches
        .iter()
        .map(|(pa, _)| {
            let n = a.intrinsics.normalised_from_pixel(*pa);
            Point2d::new(n.x, n.y)
        })
        .collect();
    let norm_b: Vector<Point2d> = matches
        .iter()
        .map(|(_, pb)| {
            let n = b.intrinsics.normalised_from_pixel(*pb);
            Point2d::new(n.x, n.y)
        })
        .collect();
    let focal = 0.5 * (a.intrinsics.focal_px + b.intrinsics.focal_px);
    let identity = Mat::eye(3, 3, core::CV_64F)
        .map_err(cv)?
        .to_mat()
        .map_err(cv)?;
    core::set_rng_seed(0).map_err(cv)?;
    let mut mask = Mat::default();
    let e = calib3d::find_essential_mat(
        &norm_a,
        &norm_b,
        &identity,
        calib3d::RANSAC,
        0.999,
        RELATIVE_THRESHOLD_PX / focal,
        10_000,
        &mut mask,
    )
    .map_err(cv)?;
    // Several solutions come stacked (3k × 3); the first is the RANSAC winner.
    if e.rows() < 3 || e.cols() != 3 {
        return Err(degenerate(a, b, "no essential matrix found"));
    }
    let e3 = e
        .row_range(&core::Range::new(0, 3).map_err(cv)?)
        .map_err(cv)?
        .try_clone()
        .map_err(cv)?;
    let mut r = Mat::default();
    let mut t = Mat::default();
    let in_front = calib3d::recover_pose_estimated(
        &e3, &norm_a, &norm_b, &identity, &mut r, &mut t, &mut mask,
    )
    .map_err(cv)?;
    if in_front < 5 {
        return Err(degenerate(
            a,
            b,
            &format!("only {in_front} matches lie in front of both cameras"),
        ));
    }
    let mut rm = Matrix3::zeros();
    for i in 0..3 {
        for j in 0..3 {
            rm[(i, j)] = *r.at_2d::<f64>(i as i32, j as i32).map_err(cv)?;
        }
    }
    let tv = Vector3::new(
        *t.at::<f64>(0).map_err(cv)?,
        *t.at::<f64>(1).map_err(cv)?,
        *t.at::<f64>(2).map_err(cv)?,
    );
    Ok(RelativePose {
        rotation_b_from_a: Rotation3::from_matrix(&rm),
        translation_b_from_a: tv.normalize(),
    })
}
