//! Nonlinear refinement of Zhang's start (Zhang 2000 §3.2–3.3): all intrinsics (fx, fy, cx, cy,
//! k1, k2, and optionally p1, p2) and every view's pose minimise the sum of squared reprojection
//! errors, by the workspace's Levenberg–Marquardt ([`crate::photogrammetry`]'s least squares).
//!
//! The Jacobian is by central differences (step 10⁻⁶ of each parameter's scale), exploiting that
//! a view's pose moves only that view's residuals. The distortion is OpenCV's Brown–Conrady
//! (k1 k2 p1 p2, k3 = 0), applied to normalised coordinates before fx, fy, cx, cy.
//!
//! # Known limitations
//! Numerical derivatives: fine for tens of views (≈ 100 unknowns), slower than analytic ones for
//! hundreds.

use nalgebra::{DMatrix, DVector, Point2, Rotation3, Vector3};

use crate::camera::BrownConrady;
use crate::photogrammetry::least_squares::{NormalEquations, levenberg_marquardt, spd_inverse};

/// Intrinsics of the refinement: fx, fy, cx, cy, k1, k2, p1, p2.
pub const INTRINSIC_COUNT: usize = 8;
/// Central-difference step as a fraction of a parameter's scale.
const DIFFERENCE_STEP: f64 = 1e-6;

/// The refined camera and poses.
#[derive(Debug, Clone)]
pub struct Refined {
    /// fx, fy, cx, cy, k1, k2, p1, p2.
    pub intrinsics: [f64; INTRINSIC_COUNT],
    /// σ of each intrinsic (σ₀-scaled); 0 for fixed ones.
    pub sigma: [f64; INTRINSIC_COUNT],
    /// (R_camera_from_board, t) per view.
    pub poses: Vec<(Rotation3<f64>, Vector3<f64>)>,
    /// sqrt(Σ|residual|² / corners): OpenCV's `calibrateCamera` RMS.
    pub rms_px: f64,
    /// RMS per view, same definition.
    pub view_rms_px: Vec<f64>,
    pub converged: bool,
}

/// Pixel of a board point (X, Y, 0) for intrinsics `k` and a pose.
#[must_use]
pub fn project(
    k: &[f64],
    rotation_vector: &Vector3<f64>,
    t: &Vector3<f64>,
    board: &Point2<f64>,
) -> Point2<f64> {
    let r = Rotation3::new(*rotation_vector);
    let x = r * Vector3::new(board.x, board.y, 0.0) + t;
    let n = Point2::new(x.x / x.z, x.y / x.z);
    let d = BrownConrady {
        k1: k[4],
        k2: k[5],
        k3: 0.0,
        p1: k[6],
        p2: k[7],
    }
    .distort(n);
    Point2::new(k[0] * d.x + k[2], k[1] * d.y + k[3])
}

struct Problem<'a> {
    board: &'a [Point2<f64>],
    views: &'a [Vec<Point2<f64>>],
    /// Indices (into the 8 intrinsics) that are free.
    free: Vec<usize>,
}

/// State: the 8 intrinsics followed by (rotation vector, t) per view.
type State = DVector<f64>;

impl Problem<'_> {
    fn view_residuals(&self, s: &State, v: usize, out: &mut Vec<f64>) {
        let k: Vec<f64> = s.rows(0, INTRINSIC_COUNT).iter().copied().collect();
        let o = INTRINSIC_COUNT + 6 * v;
        let w = Vector3::new(s[o], s[o + 1], s[o + 2]);
        let t = Vector3::new(s[o + 3], s[o + 4], s[o + 5]);
        for (b, q) in self.board.iter().zip(&self.views[v]) {
            let p = project(&k, &w, &t, b);
            out.push(p.x - q.x);
            out.push(p.y - q.y);
        }
    }

    fn residuals(&self, s: &State) -> Vec<f64> {
        let mut r = Vec::with_capacity(2 * self.board.len() * self.views.len());
        for v in 0..self.views.len() {
            self.view_residuals(s, v, &mut r);
        }
        r
    }

    fn step(x: f64) -> f64 {
        DIFFERENCE_STEP * x.abs().max(1e-2)
    }
}

impl NormalEquations for Problem<'_> {
    type State = State;
    type Normal = DMatrix<f64>;
    fn unknowns(&self) -> usize {
        self.free.len() + 6 * self.views.len()
    }
    fn cost(&self, s: &State) -> Option<f64> {
        let c: f64 = self.residuals(s).iter().map(|r| r * r).sum();
        c.is_finite().then_some(c)
    }
    fn normal_equations(&self, s: &State) -> Option<(DMatrix<f64>, DVector<f64>, f64)> {
        let r = DVector::from_vec(self.residuals(s));
        let rows = r.len();
        let m = self.unknowns();
        let mut j = DMatrix::<f64>::zeros(rows, m);
        for (c, &i) in self.free.iter().enumerate() {
            let h = Self::step(s[i]);
            let (mut plus, mut minus) = (s.clone(), s.clone());
            plus[i] += h;
            minus[i] -= h;
            let (rp, rm) = (self.residuals(&plus), self.residuals(&minus));
            for row in 0..rows {
                j[(row, c)] = (rp[row] - rm[row]) / (2.0 * h);
            }
        }
        let per_view = 2 * self.board.len();
        for v in 0..self.views.len() {
            for p in 0..6 {
                let i = INTRINSIC_COUNT + 6 * v + p;
                let h = Self::step(s[i]);
                let (mut plus, mut minus) = (s.clone(), s.clone());
                plus[i] += h;
                minus[i] -= h;
                let (mut rp, mut rm) = (Vec::new(), Vec::new());
                self.view_residuals(&plus, v, &mut rp);
                self.view_residuals(&minus, v, &mut rm);
                let col = self.free.len() + 6 * v + p;
                for k in 0..per_view {
                    j[(v * per_view + k, col)] = (rp[k] - rm[k]) / (2.0 * h);
                }
            }
        }
        let cost = r.norm_squared();
        if !cost.is_finite() {
            return None;
        }
        Some((j.transpose() * &j, j.transpose() * r, cost))
    }
    fn update(&self, s: &State, delta: &DVector<f64>) -> State {
        let mut n = s.clone();
        for (c, &i) in self.free.iter().enumerate() {
            n[i] += delta[c];
        }
        for k in 0..6 * self.views.len() {
            n[INTRINSIC_COUNT + k] += delta[self.free.len() + k];
        }
        n
    }
}

/// Refines intrinsics and poses from a start. `tangential` frees p1, p2.
#[must_use]
pub fn refine(
    board: &[Point2<f64>],
    views: &[Vec<Point2<f64>>],
    start_intrinsics: [f64; INTRINSIC_COUNT],
    start_poses: &[(Rotation3<f64>, Vector3<f64>)],
    tangential: bool,
) -> Option<Refined> {
    let mut s = DVector::<f64>::zeros(INTRINSIC_COUNT + 6 * views.len());
    for i in 0..INTRINSIC_COUNT {
        s[i] = start_intrinsics[i];
    }
    for (v, (r, t)) in start_poses.iter().enumerate() {
        let w = r.scaled_axis();
        let o = INTRINSIC_COUNT + 6 * v;
        for a in 0..3 {
            s[o + a] = w[a];
            s[o + 3 + a] = t[a];
        }
    }
    let free: Vec<usize> = if tangential {
        (0..8).collect()
    } else {
        (0..6).collect()
    };
    let problem = Problem {
        board,
        views,
        free: free.clone(),
    };
    let solution = levenberg_marquardt(&problem, s)?;
    let s = solution.state;
    let corners = (board.len() * views.len()) as f64;
    let rms_px = (solution.cost / corners).sqrt();
    let redundancy = 2.0 * corners - problem.unknowns() as f64;
    let sigma0_sq = if redundancy > 0.0 {
        solution.cost / redundancy
    } else {
        1.0
    };
    let mut sigma = [0.0; INTRINSIC_COUNT];
    if let Some(inv) = spd_inverse(&solution.normal) {
        for (c, &i) in free.iter().enumerate() {
            sigma[i] = (inv[(c, c)] * sigma0_sq).max(0.0).sqrt();
        }
    }
    let mut intrinsics = [0.0; INTRINSIC_COUNT];
    for i in 0..INTRINSIC_COUNT {
        intrinsics[i] = s[i];
    }
    let poses: Vec<(Rotation3<f64>, Vector3<f64>)> = (0..views.len())
        .map(|v| {
            let o = INTRINSIC_COUNT + 6 * v;
            (
                Rotation3::new(Vector3::new(s[o], s[o + 1], s[o + 2])),
                Vector3::new(s[o + 3], s[o + 4], s[o + 5]),
            )
        })
        .collect();
    let view_rms_px = (0..views.len())
        .map(|v| {
            let mut r = Vec::new();
            problem.view_residuals(&s, v, &mut r);
            (r.iter().map(|x| x * x).sum::<f64>() / board.len() as f64).sqrt()
        })
        .collect();
    Some(Refined {
        intrinsics,
        sigma,
        poses,
        rms_px,
        view_rms_px,
        converged: solution.converged,
    })
}
