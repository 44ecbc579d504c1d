//! Zhang's closed-form start: plane-to-image homographies by the normalised DLT, intrinsics
//! from the image of the absolute conic B = K⁻ᵀK⁻¹, and each view's pose (Z. Zhang, "A flexible
//! new technique for camera calibration", IEEE PAMI 22(11), 2000, §3.1 and Appendices A–B;
//! Hartley & Zisserman 2004 §4.4 for the normalisation).
//!
//! Homographies are estimated in image coordinates scaled by the image size (x' = (x − w/2)/s,
//! s = max(w, h)) so that the 6-vector b of B is well conditioned; K is scaled back at the end.
//!
//! # Known limitations
//! Needs at least three views of the board in different orientations for the five parameters
//! of K (two with zero skew imposed); with fewer, or with parallel boards, B is undetermined and
//! an error says so. Distortion is not modelled here: it starts at zero for the refinement.

use nalgebra::{DMatrix, Matrix3, Point2, Rotation3, Vector3};

use super::CalibrationError;

/// The similarity that takes `points` to centroid 0 and mean distance √2 (Hartley).
fn normalising_transform(points: &[Point2<f64>]) -> Matrix3<f64> {
    let n = points.len().max(1) as f64;
    let c = points
        .iter()
        .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
        / n;
    let mean = points.iter().map(|p| (p.coords - c).norm()).sum::<f64>() / n;
    let s = if mean > 0.0 {
        std::f64::consts::SQRT_2 / mean
    } else {
        1.0
    };
    Matrix3::new(s, 0.0, -s * c.x, 0.0, s, -s * c.y, 0.0, 0.0, 1.0)
}

fn apply(m: &Matrix3<f64>, p: &Point2<f64>) -> Point2<f64> {
    let v = m * Vector3::new(p.x, p.y, 1.0);
    Point2::new(v.x / v.z, v.y / v.z)
}

/// The homography H with image ~ H·(X, Y, 1) from ≥ 4 correspondences (normalised DLT).
#[must_use]
pub fn homography(plane: &[Point2<f64>], image: &[Point2<f64>]) -> Option<Matrix3<f64>> {
    if plane.len() < 4 || plane.len() != image.len() {
        return None;
    }
    let tp = normalising_transform(plane);
    let ti = normalising_transform(image);
    let mut a = DMatrix::<f64>::zeros(2 * plane.len(), 9);
    for (k, (p, q)) in plane.iter().zip(image).enumerate() {
        let p = apply(&tp, p);
        let q = apply(&ti, q);
        let (x, y) = (p.x, p.y);
        let (u, v) = (q.x, q.y);
        let r0 = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u];
        let r1 = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, -v];
        for j in 0..9 {
            a[(2 * k, j)] = r0[j];
            a[(2 * k + 1, j)] = r1[j];
        }
    }
    let h = smallest_right_singular_vector(&a)?;
    let hn = Matrix3::new(h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8]);
    let hm = ti.try_inverse()? * hn * tp;
    let scale = hm[(2, 2)];
    if scale.abs() < f64::EPSILON * hm.norm() {
        return Some(hm / hm.norm());
    }
    Some(hm / scale)
}

/// Unit vector x minimising |A x| (eigenvector of AᵀA with the smallest eigenvalue).
fn smallest_right_singular_vector(a: &DMatrix<f64>) -> Option<Vec<f64>> {
    let ata = a.transpose() * a;
    let eig = nalgebra::SymmetricEigen::try_new(ata, f64::EPSILON, 1000)?;
    let (k, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    Some(eig.eigenvectors.column(k).iter().copied().collect())
}

/// v_ij of Zhang's eq. (8) for columns i, j of H.
fn v(h: &Matrix3<f64>, i: usize, j: usize) -> [f64; 6] {
    let (hi, hj) = (h.column(i), h.column(j));
    [
        hi[0] * hj[0],
        hi[0] * hj[1] + hi[1] * hj[0],
        hi[1] * hj[1],
        hi[2] * hj[0] + hi[0] * hj[2],
        hi[2] * hj[1] + hi[1] * hj[2],
        hi[2] * hj[2],
    ]
}

/// K (zero skew imposed) from the homographies of ≥ 3 views, in the pixel frame where the
/// homographies were computed.
///
/// # Errors
/// [`CalibrationError::Degenerate`] when B is not positive definite (too few or parallel views).
pub fn intrinsics_from_homographies(hs: &[Matrix3<f64>]) -> Result<Matrix3<f64>, CalibrationError> {
    if hs.len() < 3 {
        return Err(CalibrationError::TooFewViews { found: hs.len() });
    }
    // 2 rows per view plus the zero-skew row B12 = 0 (Zhang §3.1, "if γ = 0 … add [0,1,0,0,0,0]").
    let mut vm = DMatrix::<f64>::zeros(2 * hs.len() + 1, 6);
    for (k, h) in hs.iter().enumerate() {
        let h = h / h.norm();
        let v12 = v(&h, 0, 1);
        let v11 = v(&h, 0, 0);
        let v22 = v(&h, 1, 1);
        for j in 0..6 {
            vm[(2 * k, j)] = v12[j];
            vm[(2 * k + 1, j)] = v11[j] - v22[j];
        }
    }
    vm[(2 * hs.len(), 1)] = 1.0;
    let degenerate = |reason: &str| CalibrationError::Degenerate {
        reason: reason.to_owned(),
    };
    let b = smallest_right_singular_vector(&vm).ok_or_else(|| degenerate("no null vector of V"))?;
    // Zhang, Appendix B.
    let [mut b11, mut b12, mut b22, mut b13, mut b23, mut b33] =
        [b[0], b[1], b[2], b[3], b[4], b[5]];
    if b11 < 0.0 {
        for x in [&mut b11, &mut b12, &mut b22, &mut b13, &mut b23, &mut b33] {
            *x = -*x;
        }
    }
    let d = b11 * b22 - b12 * b12;
    if !(b11 > 0.0 && d > 0.0) {
        return Err(degenerate(
            "the image of the absolute conic is not positive definite: the board views are too few or too nearly parallel",
        ));
    }
    let v0 = (b12 * b13 - b11 * b23) / d;
    let lambda = b33 - (b13 * b13 + v0 * (b12 * b13 - b11 * b23)) / b11;
    if lambda / b11 <= 0.0 {
        return Err(degenerate("λ/B11 ≤ 0 in Zhang's closed form"));
    }
    let alpha = (lambda / b11).sqrt();
    let beta = (lambda * b11 / d).sqrt();
    let gamma = -b12 * alpha * alpha * beta / lambda;
    let u0 = gamma * v0 / beta - b13 * alpha * alpha / lambda;
    Ok(Matrix3::new(alpha, 0.0, u0, 0.0, beta, v0, 0.0, 0.0, 1.0))
}

/// The pose (R_camera_from_board, t) of one view from K and its homography (Zhang §3.1), R made
/// orthonormal by SVD (Appendix C) and the board put in front of the camera.
#[must_use]
pub fn pose_from_homography(
    k: &Matrix3<f64>,
    h: &Matrix3<f64>,
) -> Option<(Rotation3<f64>, Vector3<f64>)> {
    let k_inv = k.try_inverse()?;
    let a1 = k_inv * h.column(0);
    let a2 = k_inv * h.column(1);
    let a3 = k_inv * h.column(2);
    let mut lambda = 1.0 / a1.norm();
    let mut t = lambda * a3;
    if t.z < 0.0 {
        lambda = -lambda;
        t = -t;
    }
    let r1 = lambda * a1;
    let r2 = lambda * a2;
    let r3 = r1.cross(&r2);
    let q = Matrix3::from_columns(&[r1, r2, r3]);
    let svd = q.svd(true, true);
    let r = svd.u? * svd.v_t?;
    let r = if r.determinant() < 0.0 { -r } else { r };
    Some((Rotation3::from_matrix_unchecked(r), t))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Noise-free synthetic views give K back to rounding (closed form, exact data).
    const EXACT_TOLERANCE: f64 = 1e-6;

    #[test]
    fn closed_form_recovers_k_and_poses_from_exact_views() {
        let k = Matrix3::new(800.0, 0.0, 330.0, 0.0, 800.0, 245.0, 0.0, 0.0, 1.0);
        let plane: Vec<Point2<f64>> = (0..6)
            .flat_map(|j| {
                (0..9).map(move |i| Point2::new(0.03 * f64::from(i), 0.03 * f64::from(j)))
            })
            .collect();
        let poses = [
            (
                Vector3::new(0.3, -0.2, 0.1),
                Vector3::new(-0.12, -0.08, 0.6),
            ),
            (
                Vector3::new(-0.25, 0.35, -0.05),
                Vector3::new(-0.1, -0.1, 0.7),
            ),
            (
                Vector3::new(0.1, 0.2, 0.4),
                Vector3::new(-0.15, -0.05, 0.55),
            ),
            (
                Vector3::new(-0.4, -0.1, 0.2),
                Vector3::new(-0.1, -0.06, 0.65),
            ),
        ];
        let mut hs = Vec::new();
        for (w, t) in &poses {
            let r = Rotation3::new(*w);
            let image: Vec<Point2<f64>> = plane
                .iter()
                .map(|p| {
                    let x = k * (r * Vector3::new(p.x, p.y, 0.0) + t);
                    Point2::new(x.x / x.z, x.y / x.z)
                })
                .collect();
            hs.push(homography(&plane, &image).unwrap());
        }
        let got = intrinsics_from_homographies(&hs).unwrap();
        assert!((got - k).norm() < EXACT_TOLERANCE * k.norm(), "{got}");
        for (h, (w, t)) in hs.iter().zip(&poses) {
            let (r, tt) = pose_from_homography(&got, h).unwrap();
            assert!((r.scaled_axis() - w).norm() < EXACT_TOLERANCE);
            assert!((tt - t).norm() < EXACT_TOLERANCE);
        }
    }
}
