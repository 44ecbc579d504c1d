//! The sparse normal equations of the bundle adjustment and their solution through the reduced
//! camera system (Triggs, McLauchlan, Hartley & Fitzgibbon, *Bundle adjustment — a modern
//! synthesis*, 2000, §6.1; the photogrammetric "reduced normal equations", Förstner & Wrobel
//! 2016 §15.3.3; Ceres' `SPARSE_SCHUR` does the same with a sparse S).
//!
//! With the unknowns ordered cameras first, points after, the normal matrix is
//!
//! ```text
//!     N = | A   B |      A: camera block (block diagonal, one k×k block per photo)
//!         | Bᵀ  C |      C: block diagonal, one 3×3 block C_q per point
//! ```
//!
//! and B has one k×3 block per observation of an unknown point. Only these blocks are stored:
//! memory O(photos·k² + observations·k·3 + points·9). A step eliminates the points,
//! S = A − Σ_q B_q C_q⁻¹ B_qᵀ (dense, k·photos square), solves S δc = g_c − Σ_q B_q C_q⁻¹ g_q by
//! Cholesky and back-substitutes δ_q = C_q⁻¹ (g_q − B_qᵀ δc). The Levenberg–Marquardt damping
//! λ·max(N_ii, 10⁻¹²) is added to the diagonals of A and of every C_q before the elimination,
//! exactly as the dense solver adds it to N.
//!
//! Covariances: the camera block of N⁻¹ is S⁻¹ (S undamped); the 3×3 block of point q is
//! C_q⁻¹ + C_q⁻¹ B_qᵀ S⁻¹ B_q C_q⁻¹, computed only when asked for.
//!
//! # Known limitations
//! S is dense: time O(photos³·k³) per step and memory O(photos²·k²), fine for hundreds of photos,
//! not for city-scale blocks (those need a sparse or iterative solve of S).

use nalgebra::{DMatrix, DVector, Matrix3, Point3, SMatrix, SVector, Vector3};

use crate::camera::Camera;
use crate::photogrammetry::least_squares::{
    LinearSystem, MIN_DAMPING_DIAGONAL, NormalEquations, spd_inverse,
};
use crate::photogrammetry::projection::{
    apply_intrinsics_increment, apply_pose_increment, intrinsic_indices, project_with_jacobian,
};
use crate::photogrammetry::{ImageObservation, SelfCalibration};

/// Most unknowns of one photo: 6 pose + focal, principal point (2), k1, k2.
pub(super) const MAX_CAMERA_UNKNOWNS: usize = 11;

type CameraMatrix = SMatrix<f64, MAX_CAMERA_UNKNOWNS, MAX_CAMERA_UNKNOWNS>;
type CameraVector = SVector<f64, MAX_CAMERA_UNKNOWNS>;
/// A camera–point block of B (rows beyond the photo's unknowns are zero).
type CrossBlock = SMatrix<f64, MAX_CAMERA_UNKNOWNS, 3>;

#[derive(Clone)]
pub(super) struct State {
    pub cameras: Vec<Camera>,
    /// Reduced coordinates of the unknown points.
    pub points: Vec<Point3<f64>>,
}

pub(super) struct Obs {
    pub photo: usize,
    /// Index of an unknown point, or the fixed point in reduced coordinates.
    pub point: PointRef,
    pub observation: ImageObservation,
    pub active: bool,
}

#[derive(Clone, Copy)]
pub(super) enum PointRef {
    Unknown(usize),
    Fixed(Point3<f64>),
}

/// How the normal equations are stored and solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Assembly {
    /// The blocks of A, B and C only (the production path).
    Sparse,
    /// The full dense N (memory O(points²)), kept as the reference the sparse path is
    /// tested against.
    #[cfg(test)]
    DenseReference,
}

pub(super) struct Problem {
    pub observations: Vec<Obs>,
    /// Per unknown point: surveyed position (reduced) and σ, for weighted control.
    pub priors: Vec<Option<(Point3<f64>, [f64; 3])>>,
    /// Tie points left with fewer than two rays after outlier removal: kept in the system
    /// with an identity block (zero step) and reported without σ.
    pub dropped: Vec<bool>,
    pub free: Vec<SelfCalibration>,
    /// Intrinsic columns (indices into the projection's intrinsic Jacobian) per photo.
    pub intrinsic_columns: Vec<Vec<usize>>,
    /// First column of each photo's block.
    pub offsets: Vec<usize>,
    pub camera_columns: usize,
    /// Per unknown point, the indices of its observations.
    by_point: Vec<Vec<usize>>,
    /// Indices of the observations of fixed points.
    of_fixed: Vec<usize>,
    pub assembly: Assembly,
}

impl Problem {
    pub fn new(
        free: &[SelfCalibration],
        observations: Vec<Obs>,
        priors: Vec<Option<(Point3<f64>, [f64; 3])>>,
        assembly: Assembly,
    ) -> Self {
        let intrinsic_columns: Vec<Vec<usize>> = free.iter().map(intrinsic_indices).collect();
        let mut offsets = Vec::with_capacity(free.len());
        let mut col = 0;
        for c in &intrinsic_columns {
            offsets.push(col);
            col += 6 + c.len();
        }
        let mut by_point = vec![Vec::new(); priors.len()];
        let mut of_fixed = Vec::new();
        for (k, o) in observations.iter().enumerate() {
            match o.point {
                PointRef::Unknown(q) => by_point[q].push(k),
                PointRef::Fixed(_) => of_fixed.push(k),
            }
        }
        Self {
            dropped: vec![false; priors.len()],
            observations,
            priors,
            free: free.to_vec(),
            intrinsic_columns,
            offsets,
            camera_columns: col,
            by_point,
            of_fixed,
            assembly,
        }
    }

    pub fn camera_block(&self, photo: usize) -> usize {
        6 + self.intrinsic_columns[photo].len()
    }

    pub fn point_position(state: &State, r: PointRef) -> Point3<f64> {
        match r {
            PointRef::Unknown(q) => state.points[q],
            PointRef::Fixed(p) => p,
        }
    }

    /// Whitened residual, camera Jacobian (columns beyond the photo's unknowns zero) and point
    /// Jacobian of observation `k`.
    fn linearise(
        &self,
        s: &State,
        k: usize,
    ) -> Option<(
        nalgebra::Vector2<f64>,
        SMatrix<f64, 2, MAX_CAMERA_UNKNOWNS>,
        nalgebra::Matrix2x3<f64>,
    )> {
        let o = &self.observations[k];
        let pj = project_with_jacobian(&s.cameras[o.photo], &Self::point_position(s, o.point))?;
        let w = 1.0 / o.observation.sigma_px;
        let r = (pj.pixel - o.observation.pixel) * w;
        let mut jc = SMatrix::<f64, 2, MAX_CAMERA_UNKNOWNS>::zeros();
        jc.fixed_view_mut::<2, 6>(0, 0).copy_from(&(pj.d_pose * w));
        for (c, &col) in self.intrinsic_columns[o.photo].iter().enumerate() {
            jc[(0, 6 + c)] = pj.d_intrinsics[(0, col)] * w;
            jc[(1, 6 + c)] = pj.d_intrinsics[(1, col)] * w;
        }
        Some((r, jc, pj.d_point * w))
    }

    fn sparse_normal_equations(&self, s: &State) -> Option<SparseNormal> {
        let photos = self.offsets.len();
        let points = self.priors.len();
        let mut camera_blocks = vec![CameraMatrix::zeros(); photos];
        let mut camera_gradient = vec![CameraVector::zeros(); photos];
        let mut point_blocks = vec![Matrix3::zeros(); points];
        let mut point_gradient = vec![Vector3::zeros(); points];
        let mut cross = Vec::new();
        let mut cross_start = Vec::with_capacity(points + 1);
        for &k in &self.of_fixed {
            if !self.observations[k].active {
                continue;
            }
            let (r, jc, _) = self.linearise(s, k)?;
            let p = self.observations[k].photo;
            camera_blocks[p] += jc.transpose() * jc;
            camera_gradient[p] += jc.transpose() * r;
        }
        for q in 0..points {
            cross_start.push(cross.len());
            for &k in &self.by_point[q] {
                if !self.observations[k].active {
                    continue;
                }
                let (r, jc, jp) = self.linearise(s, k)?;
                let p = self.observations[k].photo;
                camera_blocks[p] += jc.transpose() * jc;
                camera_gradient[p] += jc.transpose() * r;
                point_blocks[q] += jp.transpose() * jp;
                point_gradient[q] += jp.transpose() * r;
                cross.push((p, jc.transpose() * jp));
            }
            if self.dropped[q] {
                point_blocks[q] += Matrix3::identity();
            }
            if let Some((x0, sigma)) = &self.priors[q] {
                let d = s.points[q] - x0;
                for i in 0..3 {
                    let w2 = 1.0 / (sigma[i] * sigma[i]);
                    point_blocks[q][(i, i)] += w2;
                    point_gradient[q][i] += d[i] * w2;
                }
            }
        }
        cross_start.push(cross.len());
        Some(SparseNormal {
            sizes: (0..photos).map(|p| self.camera_block(p)).collect(),
            offsets: self.offsets.clone(),
            camera_columns: self.camera_columns,
            camera_blocks,
            camera_gradient,
            point_blocks,
            point_gradient,
            cross,
            cross_start,
        })
    }
}

/// The stored blocks of N (and of g) for one linearisation.
pub(super) struct SparseNormal {
    /// Unknowns per photo.
    sizes: Vec<usize>,
    offsets: Vec<usize>,
    camera_columns: usize,
    /// Per photo, its block of A.
    camera_blocks: Vec<CameraMatrix>,
    camera_gradient: Vec<CameraVector>,
    /// Per point, C_q.
    point_blocks: Vec<Matrix3<f64>>,
    point_gradient: Vec<Vector3<f64>>,
    /// (photo, B block) per active observation of an unknown point, grouped by point.
    cross: Vec<(usize, CrossBlock)>,
    /// Point q's blocks are `cross[cross_start[q]..cross_start[q + 1]]`.
    cross_start: Vec<usize>,
}

/// S, its right-hand side and the C_q⁻¹ of one (damped) linear system.
struct Reduced {
    camera_system: DMatrix<f64>,
    rhs: DVector<f64>,
    point_inverses: Vec<Matrix3<f64>>,
}

impl SparseNormal {
    fn gradient(&self) -> DVector<f64> {
        let mut g = DVector::zeros(self.camera_columns + 3 * self.point_blocks.len());
        for (p, gc) in self.camera_gradient.iter().enumerate() {
            let (o, k) = (self.offsets[p], self.sizes[p]);
            g.rows_mut(o, k).copy_from(&gc.rows(0, k));
        }
        for (q, gp) in self.point_gradient.iter().enumerate() {
            g.fixed_rows_mut::<3>(self.camera_columns + 3 * q)
                .copy_from(gp);
        }
        g
    }

    fn cross(&self, q: usize) -> &[(usize, CrossBlock)] {
        &self.cross[self.cross_start[q]..self.cross_start[q + 1]]
    }

    /// Reduced camera system of `N + λ·diag(max(N_ii, ε))` with right-hand side `rhs`.
    fn reduce(&self, lambda: f64, rhs: &DVector<f64>) -> Option<Reduced> {
        let nc = self.camera_columns;
        let mut s = DMatrix::zeros(nc, nc);
        for (p, block) in self.camera_blocks.iter().enumerate() {
            let (o, k) = (self.offsets[p], self.sizes[p]);
            s.view_mut((o, o), (k, k))
                .copy_from(&block.view((0, 0), (k, k)));
            for i in 0..k {
                s[(o + i, o + i)] += lambda * block[(i, i)].max(MIN_DAMPING_DIAGONAL);
            }
        }
        let mut rs = rhs.rows(0, nc).clone_owned();
        let mut point_inverses = Vec::with_capacity(self.point_blocks.len());
        for (q, block) in self.point_blocks.iter().enumerate() {
            let mut c = *block;
            for i in 0..3 {
                c[(i, i)] += lambda * block[(i, i)].max(MIN_DAMPING_DIAGONAL);
            }
            let ci = c.try_inverse()?;
            let gq = rhs.fixed_rows::<3>(nc + 3 * q);
            let entries = self.cross(q);
            for (a, &(pa, ba)) in entries.iter().enumerate() {
                let (oa, ka) = (self.offsets[pa], self.sizes[pa]);
                let bci = ba * ci;
                let mut ra = rs.rows_mut(oa, ka);
                ra -= (bci * gq).rows(0, ka);
                // S_ab −= B_a C⁻¹ B_bᵀ over the photos' own unknowns only (k ≤ 11, usually 6),
                // for b ≥ a; S_ba is its transpose.
                for (b, &(pb, bb)) in entries.iter().enumerate().skip(a) {
                    let (ob, kb) = (self.offsets[pb], self.sizes[pb]);
                    for i in 0..ka {
                        for j in 0..kb {
                            let v = bci[(i, 0)] * bb[(j, 0)]
                                + bci[(i, 1)] * bb[(j, 1)]
                                + bci[(i, 2)] * bb[(j, 2)];
                            s[(oa + i, ob + j)] -= v;
                            if b != a {
                                s[(ob + j, oa + i)] -= v;
                            }
                        }
                    }
                }
            }
            point_inverses.push(ci);
        }
        Some(Reduced {
            camera_system: s,
            rhs: rs,
            point_inverses,
        })
    }

    fn solve_damped(&self, lambda: f64, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        let nc = self.camera_columns;
        let reduced = self.reduce(lambda, rhs)?;
        let xc = reduced.camera_system.cholesky()?.solve(&reduced.rhs);
        let mut x = DVector::zeros(rhs.len());
        x.rows_mut(0, nc).copy_from(&xc);
        for (q, ci) in reduced.point_inverses.iter().enumerate() {
            let o = nc + 3 * q;
            let mut r = rhs.fixed_rows::<3>(o).clone_owned();
            for &(p, b) in self.cross(q) {
                let (op, k) = (self.offsets[p], self.sizes[p]);
                r -= b.rows(0, k).transpose() * xc.rows(op, k);
            }
            x.fixed_rows_mut::<3>(o).copy_from(&(ci * r));
        }
        Some(x)
    }

    fn diagonal(&self) -> DVector<f64> {
        let nc = self.camera_columns;
        let mut d = DVector::zeros(nc + 3 * self.point_blocks.len());
        for (p, block) in self.camera_blocks.iter().enumerate() {
            for i in 0..self.sizes[p] {
                d[self.offsets[p] + i] = block[(i, i)];
            }
        }
        for (q, block) in self.point_blocks.iter().enumerate() {
            for i in 0..3 {
                d[nc + 3 * q + i] = block[(i, i)];
            }
        }
        d
    }

    /// Camera block of N⁻¹ and, when `with_points`, the 3×3 point blocks of N⁻¹.
    fn covariances(&self, with_points: bool) -> Option<Covariances> {
        let zero = DVector::zeros(self.camera_columns + 3 * self.point_blocks.len());
        let reduced = self.reduce(0.0, &zero)?;
        let cameras = spd_inverse(&reduced.camera_system)?;
        let points = with_points.then(|| {
            reduced
                .point_inverses
                .iter()
                .enumerate()
                .map(|(q, ci)| {
                    let entries = self.cross(q);
                    // T_a = C_q⁻¹ B_aᵀ (3 × k_a), Σ_q = C_q⁻¹ + Σ_ab T_a S⁻¹_ab T_bᵀ.
                    let t: Vec<SMatrix<f64, 3, MAX_CAMERA_UNKNOWNS>> =
                        entries.iter().map(|(_, b)| ci * b.transpose()).collect();
                    let mut cov = *ci;
                    for (a, &(pa, _)) in entries.iter().enumerate() {
                        for (b, &(pb, _)) in entries.iter().enumerate() {
                            let (oa, ka) = (self.offsets[pa], self.sizes[pa]);
                            let (ob, kb) = (self.offsets[pb], self.sizes[pb]);
                            let mut sab = CameraMatrix::zeros();
                            sab.view_mut((0, 0), (ka, kb))
                                .copy_from(&cameras.view((oa, ob), (ka, kb)));
                            cov += t[a] * sab * t[b].transpose();
                        }
                    }
                    cov
                })
                .collect()
        });
        Some(Covariances { cameras, points })
    }
}

/// Covariance blocks of N⁻¹ (to be scaled by the variance factor).
pub(super) struct Covariances {
    /// The camera block (k·photos square).
    pub cameras: DMatrix<f64>,
    /// Per unknown point its 3×3 block, when requested.
    pub points: Option<Vec<Matrix3<f64>>>,
}

/// N in the representation chosen by [`Assembly`].
pub(super) enum BundleNormal {
    Sparse(SparseNormal),
    #[cfg(test)]
    Dense(super::dense::DenseNormal),
}

impl BundleNormal {
    /// Camera and (optionally) point covariance blocks of the undamped N⁻¹.
    pub fn covariances(&self, with_points: bool) -> Option<Covariances> {
        match self {
            Self::Sparse(n) => n.covariances(with_points),
            #[cfg(test)]
            Self::Dense(n) => n.covariances(with_points),
        }
    }
}

impl LinearSystem for BundleNormal {
    fn diagonal(&self) -> DVector<f64> {
        match self {
            Self::Sparse(n) => n.diagonal(),
            #[cfg(test)]
            Self::Dense(n) => n.diagonal(),
        }
    }
    fn solve_damped(&self, lambda: f64, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        match self {
            Self::Sparse(n) => n.solve_damped(lambda, rhs),
            #[cfg(test)]
            Self::Dense(n) => n.solve_damped(lambda, rhs),
        }
    }
}

impl NormalEquations for Problem {
    type State = State;
    type Normal = BundleNormal;
    fn unknowns(&self) -> usize {
        self.camera_columns + 3 * self.priors.len()
    }
    fn cost(&self, s: &State) -> Option<f64> {
        let mut cost = 0.0;
        for o in self.observations.iter().filter(|o| o.active) {
            let p = s.cameras[o.photo].project(&Self::point_position(s, o.point))?;
            cost += ((p - o.observation.pixel) / o.observation.sigma_px).norm_squared();
        }
        for (q, prior) in self.priors.iter().enumerate() {
            if let Some((x0, sigma)) = prior {
                let d = s.points[q] - x0;
                cost += (0..3).map(|i| (d[i] / sigma[i]).powi(2)).sum::<f64>();
            }
        }
        Some(cost)
    }
    fn normal_equations(&self, s: &State) -> Option<(BundleNormal, DVector<f64>, f64)> {
        match self.assembly {
            Assembly::Sparse => {
                let normal = self.sparse_normal_equations(s)?;
                // The cost in the order of `cost`, so accepted steps compare like with like.
                let cost = self.cost(s)?;
                let g = normal.gradient();
                Some((BundleNormal::Sparse(normal), g, cost))
            }
            #[cfg(test)]
            Assembly::DenseReference => {
                let (normal, g, cost) = super::dense::normal_equations(self, s)?;
                Some((BundleNormal::Dense(normal), g, cost))
            }
        }
    }
    fn update(&self, s: &State, delta: &DVector<f64>) -> State {
        let d = delta.as_slice();
        let cameras = s
            .cameras
            .iter()
            .enumerate()
            .map(|(p, c)| {
                let o = self.offsets[p];
                let k = self.camera_block(p);
                Camera {
                    pose: apply_pose_increment(&c.pose, &d[o..o + 6]),
                    intrinsics: apply_intrinsics_increment(
                        &c.intrinsics,
                        &self.free[p],
                        &d[o + 6..o + k],
                    ),
                }
            })
            .collect();
        let points = s
            .points
            .iter()
            .enumerate()
            .map(|(q, x)| {
                let o = self.camera_columns + 3 * q;
                x + Vector3::new(d[o], d[o + 1], d[o + 2])
            })
            .collect();
        State { cameras, points }
    }
}
