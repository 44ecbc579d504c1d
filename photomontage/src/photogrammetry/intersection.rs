//! Spatial intersection: the world position of a point from its images in two or more solved
//! photos (Durisch 1992 §4.1, "scene geometry"; Wolf & Dewitt, *Elements of Photogrammetry*,
//! §11.10). Linear start by the least-squares midpoint of the rays (Hartley & Zisserman 2004
//! §12.2 discuss why it is a good start, not a good end), then Levenberg–Marquardt on the
//! weighted reprojection residuals; σ XYZ from σ₀² N⁻¹ with σ₀ = max(1, σ̂₀).
//!
//! # Known limitations
//! The cameras are taken as error-free (their σ does not propagate into the point); use
//! [`super::bundle_adjust`] when camera uncertainty matters. With intersection angles below
//! [`NARROW_INTERSECTION_DEG`] the depth σ grows roughly as 1/sin(angle), so a warning is given.

use nalgebra::{DMatrix, DVector, Matrix3, Point3, Vector3};
use serde::Serialize;

use super::least_squares::{NormalEquations, levenberg_marquardt, spd_inverse};
use super::projection::project_with_jacobian;
use super::{ImageObservation, PhotogrammetryError, validate_intrinsics};
use crate::camera::Camera;

/// Below this largest angle between rays (degrees) the intersection is flagged as narrow: the
/// depth σ is then ≳ 10× the lateral σ.
pub const NARROW_INTERSECTION_DEG: f64 = 5.0;

/// An intersected point.
#[derive(Debug, Clone, Serialize)]
pub struct Intersection {
    pub point_in_world: Point3<f64>,
    /// σ along world X, Y, Z (metres).
    pub sigma_m: [f64; 3],
    /// Largest angle between any two rays at the point (degrees).
    pub max_intersection_angle_deg: f64,
    /// RMS of the reprojection residuals per coordinate.
    pub rms_px: f64,
    /// Projected minus observed pixel per ray, in input order.
    pub residuals_px: Vec<[f64; 2]>,
    /// 2 × rays − 3.
    pub redundancy: i64,
    /// A-posteriori σ₀.
    pub sigma0: f64,
    pub warnings: Vec<String>,
}

struct Problem<'a> {
    rays: &'a [(Camera, ImageObservation)],
    origin: Vector3<f64>,
}

impl NormalEquations for Problem<'_> {
    type State = Point3<f64>;
    type Normal = DMatrix<f64>;
    fn unknowns(&self) -> usize {
        3
    }
    fn cost(&self, x: &Point3<f64>) -> Option<f64> {
        let world = x + self.origin;
        let mut c = 0.0;
        for (camera, o) in self.rays {
            c += ((camera.project(&world)? - o.pixel) / o.sigma_px).norm_squared();
        }
        Some(c)
    }
    fn normal_equations(&self, x: &Point3<f64>) -> Option<(DMatrix<f64>, DVector<f64>, f64)> {
        let world = x + self.origin;
        let mut n = DMatrix::zeros(3, 3);
        let mut g = DVector::zeros(3);
        let mut c = 0.0;
        for (camera, o) in self.rays {
            let pj = project_with_jacobian(camera, &world)?;
            let r = (pj.pixel - o.pixel) / o.sigma_px;
            let j = pj.d_point / o.sigma_px;
            let jt = j.transpose();
            n += DMatrix::from_column_slice(3, 3, (jt * j).as_slice());
            g += DVector::from_column_slice((jt * r).as_slice());
            c += r.norm_squared();
        }
        Some((n, g, c))
    }
    fn update(&self, x: &Point3<f64>, delta: &DVector<f64>) -> Point3<f64> {
        x + Vector3::new(delta[0], delta[1], delta[2])
    }
}

/// Intersects the rays of one point observed in several solved photos.
///
/// # Errors
/// Fewer than two rays, non-finite or invalid input, (nearly) parallel rays, or a point that
/// would lie behind one of the cameras.
pub fn intersect(rays: &[(Camera, ImageObservation)]) -> Result<Intersection, PhotogrammetryError> {
    if rays.len() < 2 {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: 2,
            found: rays.len(),
        });
    }
    let point_id = rays[0].1.point_id.clone();
    let mut warnings = Vec::new();
    for (camera, o) in rays {
        validate_intrinsics(&camera.intrinsics)?;
        let finite = camera
            .pose
            .camera_center_in_world
            .coords
            .iter()
            .all(|v| v.is_finite())
            && camera
                .pose
                .rotation_world_from_camera
                .matrix()
                .iter()
                .all(|v| v.is_finite())
            && o.pixel.x.is_finite()
            && o.pixel.y.is_finite();
        if !finite {
            return Err(PhotogrammetryError::NonFinite {
                what: format!("ray of {}", o.point_id),
            });
        }
        if !(o.sigma_px.is_finite() && o.sigma_px > 0.0) {
            return Err(PhotogrammetryError::InvalidSigma {
                what: format!("observation of {}", o.point_id),
                value: o.sigma_px,
            });
        }
        if o.point_id != point_id {
            warnings.push(format!(
                "rays of different point ids ({point_id}, {}) are intersected together",
                o.point_id
            ));
        }
    }
    // Linear start: the point nearest to all rays, in coordinates reduced to the camera centroid.
    let origin = rays.iter().fold(Vector3::zeros(), |a, (c, _)| {
        a + c.pose.camera_center_in_world.coords
    }) / rays.len() as f64;
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    let mut dirs = Vec::with_capacity(rays.len());
    for (camera, o) in rays {
        let d = camera.ray_dir_in_world(o.pixel);
        let projector = Matrix3::identity() - d * d.transpose();
        let c = camera.pose.camera_center_in_world.coords - origin;
        a += projector;
        b += projector * c;
        dirs.push(d);
    }
    let eigen_min = a.symmetric_eigenvalues().min();
    let start = a
        .try_inverse()
        .filter(|_| eigen_min > 1e-12 * rays.len() as f64)
        .map(|inv| Point3::from(inv * b))
        .ok_or_else(|| PhotogrammetryError::Degenerate {
            reason: format!("the rays of {point_id} are parallel"),
        })?;
    for (camera, o) in rays {
        if camera.pose.camera_from_world(&(start + origin)).z <= 0.0 {
            return Err(PhotogrammetryError::PointBehindCamera {
                point_id: o.point_id.clone(),
            });
        }
    }
    let problem = Problem { rays, origin };
    let solution =
        levenberg_marquardt(&problem, start).ok_or(PhotogrammetryError::NoConvergence)?;
    let point_in_world = solution.state + origin;
    let redundancy = 2 * rays.len() as i64 - 3;
    let sigma0 = if redundancy > 0 {
        (solution.cost / redundancy as f64).sqrt()
    } else {
        1.0
    };
    let covariance =
        spd_inverse(&solution.normal).ok_or_else(|| PhotogrammetryError::Degenerate {
            reason: format!("the intersection of {point_id} is singular"),
        })? * sigma0.max(1.0).powi(2);
    let mut residuals_px = Vec::with_capacity(rays.len());
    let mut sum_sq = 0.0;
    for (camera, o) in rays {
        let p = camera.project(&point_in_world).ok_or_else(|| {
            PhotogrammetryError::PointBehindCamera {
                point_id: o.point_id.clone(),
            }
        })?;
        let v = p - o.pixel;
        sum_sq += v.norm_squared();
        residuals_px.push([v.x, v.y]);
    }
    let mut max_angle = 0.0_f64;
    for i in 0..rays.len() {
        for j in i + 1..rays.len() {
            let di = point_in_world - rays[i].0.pose.camera_center_in_world;
            let dj = point_in_world - rays[j].0.pose.camera_center_in_world;
            max_angle = max_angle.max(di.angle(&dj));
        }
    }
    let max_intersection_angle_deg = max_angle.to_degrees();
    if max_intersection_angle_deg < NARROW_INTERSECTION_DEG {
        warnings.push(format!(
            "narrow intersection of {point_id}: largest ray angle {max_intersection_angle_deg:.2}° < {NARROW_INTERSECTION_DEG}°; depth is poorly determined"
        ));
    }
    if !solution.converged {
        warnings.push("the adjustment stopped before meeting its convergence test".to_owned());
    }
    Ok(Intersection {
        point_in_world,
        sigma_m: [0, 1, 2].map(|i| covariance[(i, i)].max(0.0).sqrt()),
        max_intersection_angle_deg,
        rms_px: (sum_sq / (2 * rays.len()) as f64).sqrt(),
        residuals_px,
        redundancy,
        sigma0,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;
    use crate::photogrammetry::synthetic::look_at;
    use nalgebra::Point2;

    /// Noise-free rays meet exactly; LM stops at ~1e-10 σ, i.e. far below 1e-9 m here.
    const EXACT_TOLERANCE_M: f64 = 1e-9;

    fn camera(center: Point3<f64>, target: Point3<f64>) -> Camera {
        Camera {
            intrinsics: Intrinsics::centred(2000.0, [3000, 2000]),
            pose: look_at(center, target, Vector3::z()),
        }
    }

    fn ray(camera: Camera, point: &Point3<f64>, offset: [f64; 2]) -> (Camera, ImageObservation) {
        let p = camera.project(point).expect("in front");
        (
            camera,
            ImageObservation {
                point_id: "x".to_owned(),
                pixel: Point2::new(p.x + offset[0], p.y + offset[1]),
                sigma_px: 0.5,
            },
        )
    }

    #[test]
    fn exact_rays_meet_at_the_point() {
        let x = Point3::new(3.0, 4.0, 2.0);
        let rays = vec![
            ray(camera(Point3::new(-20.0, -30.0, 5.0), x), &x, [0.0; 2]),
            ray(camera(Point3::new(25.0, -30.0, 8.0), x), &x, [0.0; 2]),
            ray(camera(Point3::new(0.0, -40.0, 30.0), x), &x, [0.0; 2]),
        ];
        let r = intersect(&rays).expect("solvable");
        assert!((r.point_in_world - x).norm() < EXACT_TOLERANCE_M);
        assert!(r.warnings.is_empty(), "{:?}", r.warnings);
        assert!(r.max_intersection_angle_deg > 30.0);
    }

    #[test]
    fn narrow_rays_warn_and_parallel_rays_fail() {
        let x = Point3::new(0.0, 100.0, 0.0);
        let rays = vec![
            ray(camera(Point3::new(0.0, 0.0, 0.0), x), &x, [0.0; 2]),
            ray(camera(Point3::new(2.0, 0.0, 0.0), x), &x, [0.3, 0.0]),
        ];
        let r = intersect(&rays).expect("solvable");
        assert!(r.warnings.iter().any(|w| w.contains("narrow")));
        let far = Point3::new(0.0, 1e12, 0.0);
        let parallel = vec![
            ray(camera(Point3::new(0.0, 0.0, 0.0), far), &far, [0.0; 2]),
            ray(camera(Point3::new(2.0, 0.0, 0.0), far), &far, [0.0; 2]),
        ];
        assert!(matches!(
            intersect(&parallel),
            Err(PhotogrammetryError::Degenerate { .. })
        ));
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = Point3::new(0.0, 10.0, 0.0);
        let one = vec![ray(camera(Point3::origin(), x), &x, [0.0; 2])];
        assert_eq!(
            intersect(&one).err(),
            Some(PhotogrammetryError::NotEnoughPoints {
                required: 2,
                found: 1
            })
        );
        // Two cameras looking away from each other whose rays cross behind the first.
        let c1 = camera(Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 10.0, 0.0));
        let c2 = camera(Point3::new(10.0, 0.0, 0.0), Point3::new(-10.0, -10.0, 0.0));
        let behind = Point3::new(0.0, -10.0, 0.0);
        let p2 = c2.project(&behind).expect("in front of c2");
        let obs = |pixel| ImageObservation {
            point_id: "b".to_owned(),
            pixel,
            sigma_px: 0.5,
        };
        let rays = vec![(c1, obs(Point2::new(1499.5, 999.5))), (c2, obs(p2))];
        assert_eq!(
            intersect(&rays).err(),
            Some(PhotogrammetryError::PointBehindCamera {
                point_id: "b".to_owned()
            })
        );
        let mut nan = vec![
            ray(camera(Point3::new(-5.0, 0.0, 0.0), x), &x, [0.0; 2]),
            ray(camera(Point3::new(5.0, 0.0, 0.0), x), &x, [0.0; 2]),
        ];
        nan[1].1.pixel.x = f64::NAN;
        assert!(matches!(
            intersect(&nan),
            Err(PhotogrammetryError::NonFinite { .. })
        ));
    }
}
