//! Absolute orientation: the similarity (7-parameter Helmert) transform taking a photogrammetric
//! model, built from relative orientation in an arbitrary frame and scale, onto the world frame
//! of the control points (Wolf & Dewitt, *Elements of Photogrammetry*, §11.13 and §16.5).
//!
//! - Three or more non-collinear control points in the model: closed form of Umeyama, *Least-
//!   squares estimation of transformation parameters between two point patterns*, IEEE PAMI 13(4)
//!   1991 (rotation by SVD with the reflection guard of eq. 39–43).
//! - Two control points in the model and further control seen in one photo only (rays): the
//!   two points fix scale, translation and the rotation up to a turn about their line; the turn
//!   that points the rays most nearly at their control points is found by a scan at
//!   [`SCAN_STEP_DEG`] followed by golden-section refinement. (The datum needs seven numbers: two
//!   points give six, each ray two more.)
//!
//! The result is a start for the bundle adjustment, which then weighs every observation.
//!
//! # Known limitations
//! The two-point case needs the two points well apart compared with their model σ; the rays
//! are weighted equally by angle, not by their pixel σ.

use nalgebra::{Matrix3, Point3, Rotation3, Unit, Vector3};

use super::PhotogrammetryError;
use crate::camera::{Camera, Pose};

/// Step of the scan over the turn about the line of two control points (degrees).
pub const SCAN_STEP_DEG: f64 = 0.5;
/// Below this ratio of the second to the first principal extent the points are collinear.
const COLLINEAR_RATIO: f64 = 1e-3;

/// `point_in_world = scale · rotation · point_in_model + translation`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    pub scale: f64,
    pub rotation_world_from_model: Rotation3<f64>,
    pub translation_m: Vector3<f64>,
}

impl Similarity {
    /// A model point in the world frame.
    #[must_use]
    pub fn world_from_model(&self, point_in_model: &Point3<f64>) -> Point3<f64> {
        Point3::from(
            self.scale * (self.rotation_world_from_model * point_in_model.coords)
                + self.translation_m,
        )
    }

    /// A camera of the model moved into the world frame (its intrinsics unchanged).
    #[must_use]
    pub fn camera_in_world(&self, camera_in_model: &Camera) -> Camera {
        Camera {
            intrinsics: camera_in_model.intrinsics,
            pose: Pose {
                rotation_world_from_camera: self.rotation_world_from_model
                    * camera_in_model.pose.rotation_world_from_camera,
                camera_center_in_world: self
                    .world_from_model(&camera_in_model.pose.camera_center_in_world),
            },
        }
    }
}

/// A ray of the model (from a camera centre through an observed pixel) towards a control point
/// known in the world only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlRay {
    pub origin_in_model: Point3<f64>,
    pub dir_in_model: Vector3<f64>,
    pub point_in_world: Point3<f64>,
}

/// Umeyama's least-squares similarity from ≥ 3 non-collinear point pairs (model, world).
///
/// # Errors
/// [`PhotogrammetryError::NotEnoughPoints`] for fewer than three pairs,
/// [`PhotogrammetryError::Collinear`] when the model points lie on a line.
pub fn similarity_from_points(
    pairs: &[(Point3<f64>, Point3<f64>)],
) -> Result<Similarity, PhotogrammetryError> {
    if pairs.len() < 3 {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: 3,
            found: pairs.len(),
        });
    }
    let n = pairs.len() as f64;
    let mean_m = pairs.iter().fold(Vector3::zeros(), |a, p| a + p.0.coords) / n;
    let mean_w = pairs.iter().fold(Vector3::zeros(), |a, p| a + p.1.coords) / n;
    let mut cov = Matrix3::zeros();
    let mut scatter_m = Matrix3::zeros();
    let mut var_m = 0.0;
    for (m, w) in pairs {
        let dm = m.coords - mean_m;
        let dw = w.coords - mean_w;
        cov += dw * dm.transpose();
        scatter_m += dm * dm.transpose();
        var_m += dm.norm_squared();
    }
    let mut extents: Vec<f64> = scatter_m.symmetric_eigenvalues().iter().copied().collect();
    extents.sort_by(|a, b| b.total_cmp(a));
    if extents[1] <= COLLINEAR_RATIO * COLLINEAR_RATIO * extents[0] || var_m <= 0.0 {
        return Err(PhotogrammetryError::Collinear);
    }
    let svd = cov.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(PhotogrammetryError::Degenerate {
            reason: "SVD of the absolute-orientation covariance failed".to_owned(),
        });
    };
    let mut s = Matrix3::identity();
    if (u * v_t).determinant() < 0.0 {
        s[(2, 2)] = -1.0;
    }
    let r = u * s * v_t;
    let d = svd.singular_values;
    let trace_ds = d[0] * s[(0, 0)] + d[1] * s[(1, 1)] + d[2] * s[(2, 2)];
    let scale = trace_ds / var_m;
    let rotation = Rotation3::from_matrix_unchecked(r);
    Ok(Similarity {
        scale,
        rotation_world_from_model: rotation,
        translation_m: mean_w - scale * (rotation * mean_m),
    })
}

/// The similarity from two point pairs (model, world) and rays to further control points.
///
/// # Errors
/// [`PhotogrammetryError::NotEnoughPoints`] without a ray, `Degenerate` when the two points
/// coincide in the model or the world.
pub fn similarity_from_two_points_and_rays(
    pairs: [(Point3<f64>, Point3<f64>); 2],
    rays: &[ControlRay],
) -> Result<Similarity, PhotogrammetryError> {
    if rays.is_empty() {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: 3,
            found: 2,
        });
    }
    let [(a_m, a_w), (b_m, b_w)] = pairs;
    let (ab_m, ab_w) = (b_m - a_m, b_w - a_w);
    if ab_m.norm() <= f64::EPSILON * a_m.coords.norm().max(1.0) || ab_w.norm() <= 1e-9 {
        return Err(PhotogrammetryError::Degenerate {
            reason: "the two control points coincide".to_owned(),
        });
    }
    let scale = ab_w.norm() / ab_m.norm();
    let base = Rotation3::rotation_between(&ab_m, &ab_w).unwrap_or_else(|| {
        // Antiparallel: a half turn about any axis normal to the line.
        let normal = ab_m
            .cross(&Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or(Vector3::y());
        Rotation3::from_axis_angle(&Unit::new_normalize(normal), std::f64::consts::PI)
    });
    let axis = Unit::new_normalize(ab_w);
    let similarity = |turn: f64| {
        let rotation = Rotation3::from_axis_angle(&axis, turn) * base;
        Similarity {
            scale,
            rotation_world_from_model: rotation,
            translation_m: a_w.coords - scale * (rotation * a_m.coords),
        }
    };
    // Sum of squared angles between each transformed ray and the direction to its point.
    let cost = |turn: f64| {
        let s = similarity(turn);
        rays.iter()
            .map(|r| {
                let origin = s.world_from_model(&r.origin_in_model);
                let dir = s.rotation_world_from_model * r.dir_in_model;
                (r.point_in_world - origin).angle(&dir).powi(2)
            })
            .sum::<f64>()
    };
    let step = SCAN_STEP_DEG.to_radians();
    let steps = (std::f64::consts::TAU / step).round() as usize;
    let best = (0..steps)
        .map(|i| i as f64 * step)
        .min_by(|a, b| cost(*a).total_cmp(&cost(*b)))
        .unwrap_or(0.0);
    // Golden-section search within one step either side.
    let (mut lo, mut hi) = (best - step, best + step);
    let g = (5.0_f64.sqrt() - 1.0) / 2.0;
    for _ in 0..60 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if cost(x1) < cost(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    Ok(similarity(0.5 * (lo + hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact data: the transform is recovered to round-off.
    const EXACT_TOLERANCE: f64 = 1e-9;
    /// The two-point scan ends in a golden-section search converged far below this (radians).
    const TURN_TOLERANCE: f64 = 1e-7;

    fn truth() -> Similarity {
        Similarity {
            scale: 37.5,
            rotation_world_from_model: Rotation3::from_euler_angles(0.3, -1.1, 2.4),
            translation_m: Vector3::new(235_260.0, 3_811_200.0, 12.0),
        }
    }

    fn model_points() -> Vec<Point3<f64>> {
        vec![
            Point3::new(0.1, 0.2, 1.0),
            Point3::new(-0.3, 0.25, 1.1),
            Point3::new(0.05, -0.4, 0.9),
            Point3::new(0.4, 0.1, 1.3),
        ]
    }

    #[test]
    fn umeyama_recovers_a_known_similarity() {
        let t = truth();
        let pairs: Vec<_> = model_points()
            .into_iter()
            .map(|m| (m, t.world_from_model(&m)))
            .collect();
        let s = similarity_from_points(&pairs).expect("solvable");
        assert!((s.scale - t.scale).abs() < EXACT_TOLERANCE * t.scale);
        assert!(
            (s.rotation_world_from_model.inverse() * t.rotation_world_from_model).angle()
                < EXACT_TOLERANCE
        );
        assert!((s.translation_m - t.translation_m).norm() < 1e-6);
        let collinear = [
            (Point3::origin(), Point3::origin()),
            (Point3::new(1.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)),
            (Point3::new(2.0, 0.0, 0.0), Point3::new(2.0, 0.0, 0.0)),
        ];
        assert_eq!(
            similarity_from_points(&collinear),
            Err(PhotogrammetryError::Collinear)
        );
    }

    #[test]
    fn two_points_and_a_ray_fix_the_turn() {
        let t = truth();
        let m = model_points();
        let pairs = [
            (m[0], t.world_from_model(&m[0])),
            (m[1], t.world_from_model(&m[1])),
        ];
        // A camera centre of the model sees the third point.
        let origin = Point3::new(0.0, 0.0, 0.0);
        let ray = ControlRay {
            origin_in_model: origin,
            dir_in_model: (m[2] - origin).normalize(),
            point_in_world: t.world_from_model(&m[2]),
        };
        let s = similarity_from_two_points_and_rays(pairs, &[ray]).expect("solvable");
        assert!(
            (s.rotation_world_from_model.inverse() * t.rotation_world_from_model).angle()
                < TURN_TOLERANCE
        );
        assert!((s.world_from_model(&m[3]) - t.world_from_model(&m[3])).norm() < 1e-4);
        assert!(matches!(
            similarity_from_two_points_and_rays(pairs, &[]),
            Err(PhotogrammetryError::NotEnoughPoints { .. })
        ));
    }
}
