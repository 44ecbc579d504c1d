//! An independent check of a solved camera with OpenCV's `solvePnP` (iterative Levenberg–
//! Marquardt on the reprojection error, `SOLVEPNP_ITERATIVE`, started from our pose): a second
//! implementation of the same least-squares problem, so on the same points, intrinsics and equal
//! weights both must reach the same minimum. The difference of camera centre (metres) and
//! rotation (degrees) is printed in `solve`'s report.
//!
//! World coordinates are reduced to the centroid of the points first (survey coordinates of
//! 10⁶ m would cost OpenCV digits).
//!
//! # Known limitations
//! OpenCV weighs every point equally, while our solvers weigh by σ (and in the bundle adjust the
//! points too): with unequal σ the two agree only to within the cameras' own σ.

use nalgebra::{Matrix3, Point2, Point3, Rotation3, Vector3};
use opencv::calib3d;
use opencv::core::{Mat, Point2d, Point3d, Vector};
use opencv::prelude::*;
use serde::Serialize;

use super::FeatureError;
use crate::camera::{Camera, Pose};

/// How far OpenCV's pose is from ours.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PnpCheck {
    pub points: usize,
    /// |C_opencv − C_ours| (metres).
    pub center_difference_m: f64,
    /// Angle of R_oursᵀ R_opencv (degrees).
    pub rotation_difference_deg: f64,
    /// OpenCV's camera.
    #[serde(skip)]
    pub camera: Camera,
}

fn mat3(m: &Mat) -> Result<Matrix3<f64>, FeatureError> {
    let mut out = Matrix3::zeros();
    for i in 0..3 {
        for j in 0..3 {
            #[allow(clippy::cast_possible_wrap, clippy::cast_possible_truncation)]
            let v = *m.at_2d::<f64>(i as i32, j as i32)?;
            out[(i, j)] = v;
        }
    }
    Ok(out)
}

fn vec3(m: &Mat) -> Result<Vector3<f64>, FeatureError> {
    Ok(Vector3::new(
        *m.at::<f64>(0)?,
        *m.at::<f64>(1)?,
        *m.at::<f64>(2)?,
    ))
}

/// Re-solves `camera`'s pose with OpenCV from world points and their pixels, starting from
/// `camera`, with its intrinsics fixed.
///
/// # Errors
/// Fewer than four points ([`FeatureError::Geometry`]) or an OpenCV failure.
pub fn pnp_check(
    camera: &Camera,
    points: &[(Point3<f64>, Point2<f64>)],
) -> Result<PnpCheck, FeatureError> {
    if points.len() < 4 {
        return Err(FeatureError::Geometry(format!(
            "solvePnP needs at least 4 points, {} given",
            points.len()
        )));
    }
    let origin = points
        .iter()
        .fold(Vector3::zeros(), |a, (x, _)| a + x.coords)
        / points.len() as f64;
    let object: Vector<Point3d> = points
        .iter()
        .map(|(x, _)| {
            let d = x.coords - origin;
            Point3d::new(d.x, d.y, d.z)
        })
        .collect();
    let image: Vector<Point2d> = points.iter().map(|(_, p)| Point2d::new(p.x, p.y)).collect();
    let intr = &camera.intrinsics;
    let k = Mat::from_slice_2d(&[
        [intr.focal_px, 0.0, intr.principal_point_px[0]],
        [0.0, intr.focal_px, intr.principal_point_px[1]],
        [0.0, 0.0, 1.0],
    ])?;
    let d = intr.distortion;
    let dist = Mat::from_slice(&[d.k1, d.k2, d.p1, d.p2, d.k3])?.try_clone()?;
    // Ours: x_cam = Rᵀ (X − C); OpenCV: x_cam = R_cv X' + t with X' = X − origin.
    let r_cw = camera.pose.rotation_world_from_camera.inverse();
    let t = -(r_cw * (camera.pose.camera_center_in_world.coords - origin));
    let mut rvec = Mat::default();
    let r_mat = Mat::from_slice_2d(&[
        [r_cw[(0, 0)], r_cw[(0, 1)], r_cw[(0, 2)]],
        [r_cw[(1, 0)], r_cw[(1, 1)], r_cw[(1, 2)]],
        [r_cw[(2, 0)], r_cw[(2, 1)], r_cw[(2, 2)]],
    ])?;
    calib3d::rodrigues_def(&r_mat, &mut rvec)?;
    let mut tvec = Mat::from_slice(&[t.x, t.y, t.z])?
        .reshape(1, 3)?
        .try_clone()?;
    let ok = calib3d::solve_pnp(
        &object,
        &image,
        &k,
        &dist,
        &mut rvec,
        &mut tvec,
        true,
        calib3d::SOLVEPNP_ITERATIVE,
    )?;
    if !ok {
        return Err(FeatureError::Geometry("solvePnP did not converge".into()));
    }
    let mut r_out = Mat::default();
    calib3d::rodrigues_def(&rvec, &mut r_out)?;
    let r_cv = Rotation3::from_matrix(&mat3(&r_out)?);
    let t_cv = vec3(&tvec)?;
    let rotation_world_from_camera = r_cv.inverse();
    let center = Point3::from(origin - (rotation_world_from_camera * t_cv));
    let opencv_camera = Camera {
        intrinsics: *intr,
        pose: Pose {
            rotation_world_from_camera,
            camera_center_in_world: center,
        },
    };
    Ok(PnpCheck {
        points: points.len(),
        center_difference_m: (center - camera.pose.camera_center_in_world).norm(),
        // Through the quaternion: acos of the trace turns NaN when round-off puts it past 3.
        rotation_difference_deg: nalgebra::UnitQuaternion::from_rotation_matrix(
            &(camera.pose.rotation_world_from_camera.inverse() * rotation_world_from_camera),
        )
        .angle()
        .to_degrees(),
        camera: opencv_camera,
    })
}
