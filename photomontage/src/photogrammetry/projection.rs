//! Projection of a world point with analytic Jacobians for the adjustments (collinearity
//! equations, Durisch 1992 §3.5; derivatives as in Hartley & Zisserman 2004, App. 6, with the
//! rotation updated by a local rotation-vector increment, `R ← R·exp([δθ]×)`).
//!
//! Parameter blocks: pose = (δC_x, δC_y, δC_z, δθ_x, δθ_y, δθ_z) with δθ in the camera frame;
//! intrinsics = (focal, principal point x, principal point y, k1, k2).
//!
//! # Known limitations
//! Derivatives with respect to k3, p1 and p2 are not provided (never estimated).

use nalgebra::{Matrix2x3, Matrix3, Point2, Point3, Rotation3, SMatrix, Vector3};

use super::SelfCalibration;
use crate::camera::{Camera, Intrinsics, Pose};

/// Points closer to the camera plane than this (metres, camera z) count as behind the camera:
/// the projection is singular there.
pub(crate) const MIN_DEPTH_M: f64 = 1e-9;

/// A projected point with its derivatives.
pub(crate) struct ProjectionJacobian {
    pub pixel: Point2<f64>,
    /// ∂pixel/∂(δC, δθ).
    pub d_pose: SMatrix<f64, 2, 6>,
    /// ∂pixel/∂(focal, ppx, ppy, k1, k2).
    pub d_intrinsics: SMatrix<f64, 2, 5>,
    /// ∂pixel/∂X (world point).
    pub d_point: Matrix2x3<f64>,
}

/// Skew-symmetric cross-product matrix: `skew(a) b = a × b`.
pub(crate) fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Projects `point_in_world`; `None` when it is not in front of the camera.
pub(crate) fn project_with_jacobian(
    camera: &Camera,
    point_in_world: &Point3<f64>,
) -> Option<ProjectionJacobian> {
    let r_wc = camera.pose.rotation_world_from_camera.matrix();
    let r_cw = r_wc.transpose();
    let p = r_cw * (point_in_world - camera.pose.camera_center_in_world);
    if p.z <= MIN_DEPTH_M {
        return None;
    }
    let inv_z = 1.0 / p.z;
    let n = Point2::new(p.x * inv_z, p.y * inv_z);
    let intr = &camera.intrinsics;
    let dist = &intr.distortion;
    let d = dist.distort(n);
    let pixel = Point2::new(
        intr.focal_px * d.x + intr.principal_point_px[0],
        intr.focal_px * d.y + intr.principal_point_px[1],
    );
    let dn_dp = Matrix2x3::new(inv_z, 0.0, -n.x * inv_z, 0.0, inv_z, -n.y * inv_z);
    let dpix_dp = intr.focal_px * dist.distort_jacobian(n) * dn_dp;
    let d_center = -dpix_dp * r_cw;
    let d_theta = dpix_dp * skew(&p);
    let mut d_pose = SMatrix::<f64, 2, 6>::zeros();
    d_pose.fixed_view_mut::<2, 3>(0, 0).copy_from(&d_center);
    d_pose.fixed_view_mut::<2, 3>(0, 3).copy_from(&d_theta);
    let r2 = n.x * n.x + n.y * n.y;
    let f = intr.focal_px;
    let d_intrinsics = SMatrix::<f64, 2, 5>::from_row_slice(&[
        d.x,
        1.0,
        0.0,
        f * n.x * r2,
        f * n.x * r2 * r2,
        d.y,
        0.0,
        1.0,
        f * n.y * r2,
        f * n.y * r2 * r2,
    ]);
    Some(ProjectionJacobian {
        pixel,
        d_pose,
        d_intrinsics,
        d_point: dpix_dp * r_cw,
    })
}

/// Indices into (focal, ppx, ppy, k1, k2) of the freed intrinsic parameters.
pub(crate) fn intrinsic_indices(free: &SelfCalibration) -> Vec<usize> {
    let mut out = Vec::with_capacity(5);
    if free.focal {
        out.push(0);
    }
    if free.principal_point {
        out.extend([1, 2]);
    }
    if free.k1 {
        out.push(3);
    }
    if free.k2 {
        out.push(4);
    }
    out
}

/// Pose after a (δC, δθ) increment.
pub(crate) fn apply_pose_increment(pose: &Pose, delta: &[f64]) -> Pose {
    let rotation = pose.rotation_world_from_camera
        * Rotation3::new(Vector3::new(delta[3], delta[4], delta[5]));
    Pose {
        rotation_world_from_camera: Rotation3::from_matrix_eps(
            rotation.matrix(),
            1e-15,
            8,
            rotation,
        ),
        camera_center_in_world: pose.camera_center_in_world
            + Vector3::new(delta[0], delta[1], delta[2]),
    }
}

/// Intrinsics after an increment of the freed parameters (order of [`intrinsic_indices`]).
pub(crate) fn apply_intrinsics_increment(
    intrinsics: &Intrinsics,
    free: &SelfCalibration,
    delta: &[f64],
) -> Intrinsics {
    let mut out = *intrinsics;
    for (k, &index) in intrinsic_indices(free).iter().enumerate() {
        match index {
            0 => out.focal_px += delta[k],
            1 => out.principal_point_px[0] += delta[k],
            2 => out.principal_point_px[1] += delta[k],
            3 => out.distortion.k1 += delta[k],
            _ => out.distortion.k2 += delta[k],
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::BrownConrady;

    /// Central differences with h = 1e-6 on O(1)…O(1e3) quantities agree with analytic
    /// derivatives to ~1e-6 relative; 1e-5 relative leaves margin.
    const JACOBIAN_RELATIVE_TOLERANCE: f64 = 1e-5;

    fn camera() -> Camera {
        let mut intrinsics = Intrinsics::centred(1500.0, [2000, 1500]);
        intrinsics.distortion = BrownConrady {
            k1: -0.1,
            k2: 0.03,
            ..BrownConrady::default()
        };
        Camera {
            intrinsics,
            pose: Pose {
                rotation_world_from_camera: Rotation3::new(Vector3::new(1.2, -0.3, 0.4)),
                camera_center_in_world: Point3::new(1.0, -2.0, 3.0),
            },
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= JACOBIAN_RELATIVE_TOLERANCE * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let cam = camera();
        let x = cam.pose.world_from_camera(&Point3::new(0.4, -0.3, 5.0));
        let j = project_with_jacobian(&cam, &x).expect("in front");
        let h = 1e-6;
        let all = SelfCalibration {
            focal: true,
            principal_point: true,
            k1: true,
            k2: true,
        };
        for k in 0..6 {
            let mut dp = [0.0; 6];
            dp[k] = h;
            let mut dm = [0.0; 6];
            dm[k] = -h;
            let cp = Camera {
                pose: apply_pose_increment(&cam.pose, &dp),
                ..cam
            };
            let cm = Camera {
                pose: apply_pose_increment(&cam.pose, &dm),
                ..cam
            };
            let num = (cp.project(&x).expect("p") - cm.project(&x).expect("m")) / (2.0 * h);
            assert!(
                close(num.x, j.d_pose[(0, k)]) && close(num.y, j.d_pose[(1, k)]),
                "pose {k}"
            );
        }
        for k in 0..5 {
            let mut dp = [0.0; 5];
            dp[k] = h;
            let mut dm = [0.0; 5];
            dm[k] = -h;
            let cp = Camera {
                intrinsics: apply_intrinsics_increment(&cam.intrinsics, &all, &dp),
                ..cam
            };
            let cm = Camera {
                intrinsics: apply_intrinsics_increment(&cam.intrinsics, &all, &dm),
                ..cam
            };
            let num = (cp.project(&x).expect("p") - cm.project(&x).expect("m")) / (2.0 * h);
            assert!(
                close(num.x, j.d_intrinsics[(0, k)]) && close(num.y, j.d_intrinsics[(1, k)]),
                "intrinsic {k}"
            );
        }
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h;
            let num =
                (cam.project(&(x + e)).expect("p") - cam.project(&(x - e)).expect("m")) / (2.0 * h);
            assert!(
                close(num.x, j.d_point[(0, k)]) && close(num.y, j.d_point[(1, k)]),
                "point {k}"
            );
        }
    }
}
