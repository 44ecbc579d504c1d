//! Brown–Conrady radial and tangential lens distortion (Brown, *Decentering distortion of
//! lenses*, 1966; coefficient order and signs as OpenCV `calib3d`: k1 k2 p1 p2 k3).
//!
//! # Known limitations
//! The inverse is iterative (fixed point, then Newton); it converges wherever the forward model
//! is monotonic in r, which holds for ordinary photographic lenses.

use nalgebra::{Matrix2, Point2};
use serde::{Deserialize, Serialize};

/// Distortion coefficients on normalised image coordinates.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BrownConrady {
    pub k1: f64,
    pub k2: f64,
    pub k3: f64,
    pub p1: f64,
    pub p2: f64,
}

/// Undistortion stops when the forward model reproduces the input to this (normalised) distance:
/// 1e-12 is ~1e-8 px even for a 10 000 px focal length.
const UNDISTORT_TOLERANCE: f64 = 1e-12;
const UNDISTORT_MAX_ITERATIONS: usize = 50;

impl BrownConrady {
    /// Whether every coefficient is zero.
    #[must_use]
    pub fn is_zero(&self) -> bool {
        [self.k1, self.k2, self.k3, self.p1, self.p2]
            .iter()
            .all(|c| *c == 0.0)
    }

    /// Distorted normalised coordinate of an ideal normalised coordinate.
    #[must_use]
    pub fn distort(&self, p: Point2<f64>) -> Point2<f64> {
        let (x, y) = (p.x, p.y);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        Point2::new(
            x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x),
            y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y,
        )
    }

    /// Jacobian of [`Self::distort`] with respect to (x, y).
    #[must_use]
    pub fn distort_jacobian(&self, p: Point2<f64>) -> Matrix2<f64> {
        let (x, y) = (p.x, p.y);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        // d(radial)/d(r2)
        let dradial = self.k1 + r2 * (2.0 * self.k2 + 3.0 * self.k3 * r2);
        let dxd_dx = radial + x * dradial * 2.0 * x + 2.0 * self.p1 * y + self.p2 * 6.0 * x;
        let dxd_dy = x * dradial * 2.0 * y + 2.0 * self.p1 * x + self.p2 * 2.0 * y;
        let dyd_dx = y * dradial * 2.0 * x + self.p1 * 2.0 * x + 2.0 * self.p2 * y;
        let dyd_dy = radial + y * dradial * 2.0 * y + self.p1 * 6.0 * y + 2.0 * self.p2 * x;
        Matrix2::new(dxd_dx, dxd_dy, dyd_dx, dyd_dy)
    }

    /// Ideal normalised coordinate of a distorted one (Newton iteration on the forward model).
    #[must_use]
    pub fn undistort(&self, distorted: Point2<f64>) -> Point2<f64> {
        if self.is_zero() {
            return distorted;
        }
        let mut p = distorted;
        for _ in 0..UNDISTORT_MAX_ITERATIONS {
            let residual = self.distort(p) - distorted;
            if residual.norm() < UNDISTORT_TOLERANCE {
                break;
            }
            let step = self
                .distort_jacobian(p)
                .try_inverse()
                .map_or(residual, |inv| inv * residual);
            p -= step;
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round trip: distort then undistort returns the input to 1e-10 (normalised units).
    const ROUND_TRIP_TOLERANCE: f64 = 1e-10;

    #[test]
    fn undistort_inverts_distort() {
        let d = BrownConrady {
            k1: -0.266,
            k2: -0.0386,
            k3: 0.238,
            p1: 0.00178,
            p2: -0.00028,
        };
        for &(x, y) in &[(0.0, 0.0), (0.3, -0.2), (-0.5, 0.35), (0.55, 0.4)] {
            let p = Point2::new(x, y);
            let back = d.undistort(d.distort(p));
            assert!((back - p).norm() < ROUND_TRIP_TOLERANCE, "{p} -> {back}");
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let d = BrownConrady {
            k1: 0.1,
            k2: -0.05,
            k3: 0.01,
            p1: 0.002,
            p2: -0.001,
        };
        let p = Point2::new(0.3, -0.25);
        let h = 1e-7;
        let j = d.distort_jacobian(p);
        let fx = (d.distort(Point2::new(p.x + h, p.y)) - d.distort(Point2::new(p.x - h, p.y)))
            / (2.0 * h);
        let fy = (d.distort(Point2::new(p.x, p.y + h)) - d.distort(Point2::new(p.x, p.y - h)))
            / (2.0 * h);
        assert!((j[(0, 0)] - fx.x).abs() < 1e-6 && (j[(1, 0)] - fx.y).abs() < 1e-6);
        assert!((j[(0, 1)] - fy.x).abs() < 1e-6 && (j[(1, 1)] - fy.y).abs() < 1e-6);
    }
}
