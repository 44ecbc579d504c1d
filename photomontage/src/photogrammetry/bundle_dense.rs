//! The dense normal equations of the bundle adjustment, as the solver assembled them before the
//! sparse path of [`super::normal`] replaced them: N stored in full (memory O(points²)), the
//! point blocks eliminated from the stored N. Compiled for tests only, as the reference the
//! sparse assembly and reduction are checked against (same cameras to 1e-9 relative).

use nalgebra::{DMatrix, DVector, Matrix3};

use super::normal::{Covariances, PointRef, Problem, State};
use crate::photogrammetry::least_squares::{MIN_DAMPING_DIAGONAL, spd_inverse};
use crate::photogrammetry::projection::project_with_jacobian;

/// The full N with its camera-column count and number of unknown points.
pub(crate) struct DenseNormal {
    n: DMatrix<f64>,
    nc: usize,
    points: usize,
}

/// (N, g, cost) assembled densely over all unknowns.
pub(super) fn normal_equations(
    problem: &Problem,
    s: &State,
) -> Option<(DenseNormal, DVector<f64>, f64)> {
    let nc = problem.camera_columns;
    let m = nc + 3 * problem.priors.len();
    let mut n = DMatrix::zeros(m, m);
    let mut g = DVector::zeros(m);
    let mut cost = 0.0;
    for o in problem.observations.iter().filter(|o| o.active) {
        let camera = &s.cameras[o.photo];
        let pj = project_with_jacobian(camera, &Problem::point_position(s, o.point))?;
        let w = 1.0 / o.observation.sigma_px;
        let r = (pj.pixel - o.observation.pixel) * w;
        cost += r.norm_squared();
        let cols = &problem.intrinsic_columns[o.photo];
        let k = 6 + cols.len();
        let mut jc = DMatrix::zeros(2, k);
        jc.view_mut((0, 0), (2, 6)).copy_from(&(pj.d_pose * w));
        for (c, &col) in cols.iter().enumerate() {
            jc[(0, 6 + c)] = pj.d_intrinsics[(0, col)] * w;
            jc[(1, 6 + c)] = pj.d_intrinsics[(1, col)] * w;
        }
        let oc = problem.offsets[o.photo];
        let jct = jc.transpose();
        let mut ncc = n.view_mut((oc, oc), (k, k));
        ncc += &jct * &jc;
        let mut gc = g.rows_mut(oc, k);
        gc += &jct * DVector::from_column_slice(r.as_slice());
        if let PointRef::Unknown(q) = o.point {
            let op = nc + 3 * q;
            let jp = pj.d_point * w;
            let jpt = jp.transpose();
            let mut block = n.fixed_view_mut::<3, 3>(op, op);
            block += jpt * jp;
            let ncp = &jct * DMatrix::from_column_slice(2, 3, jp.as_slice());
            let mut upper = n.view_mut((oc, op), (k, 3));
            upper += &ncp;
            let mut lower = n.view_mut((op, oc), (3, k));
            lower += ncp.transpose();
            let mut gp = g.fixed_rows_mut::<3>(op);
            gp += jpt * r;
        }
    }
    for (q, dropped) in problem.dropped.iter().enumerate() {
        if *dropped {
            let op = nc + 3 * q;
            for i in 0..3 {
                n[(op + i, op + i)] += 1.0;
            }
        }
    }
    for (q, prior) in problem.priors.iter().enumerate() {
        if let Some((x0, sigma)) = prior {
            let op = nc + 3 * q;
            let d = s.points[q] - x0;
            for i in 0..3 {
                let w2 = 1.0 / (sigma[i] * sigma[i]);
                n[(op + i, op + i)] += w2;
                g[op + i] += d[i] * w2;
                cost += d[i] * d[i] * w2;
            }
        }
    }
    let points = problem.priors.len();
    Some((DenseNormal { n, nc, points }, g, cost))
}

type Reduced = (DMatrix<f64>, DVector<f64>, Vec<Matrix3<f64>>);

impl DenseNormal {
    pub(super) fn diagonal(&self) -> DVector<f64> {
        self.n.diagonal()
    }

    pub(super) fn solve_damped(&self, lambda: f64, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        let mut damped = self.n.clone();
        for i in 0..damped.nrows() {
            damped[(i, i)] += lambda * self.n[(i, i)].max(MIN_DAMPING_DIAGONAL);
        }
        let (s, rs, cinv) = reduce(&damped, rhs, self.nc, self.points)?;
        let xc = s.cholesky()?.solve(&rs);
        let mut x = DVector::zeros(self.nc + 3 * self.points);
        x.rows_mut(0, self.nc).copy_from(&xc);
        for (q, ci) in cinv.iter().enumerate() {
            let o = self.nc + 3 * q;
            let bq = damped.view((0, o), (self.nc, 3));
            let r = rhs.fixed_rows::<3>(o) - bq.transpose() * &xc;
            x.fixed_rows_mut::<3>(o).copy_from(&(ci * r));
        }
        Some(x)
    }

    pub(super) fn covariances(&self, with_points: bool) -> Option<Covariances> {
        let zero = DVector::zeros(self.nc + 3 * self.points);
        let (s, _, cinv) = reduce(&self.n, &zero, self.nc, self.points)?;
        let s_inv = spd_inverse(&s)?;
        let points = with_points.then(|| {
            cinv.iter()
                .enumerate()
                .map(|(q, ci)| {
                    let bq = self.n.view((0, self.nc + 3 * q), (self.nc, 3));
                    let t = ci * bq.transpose();
                    ci + &t * &s_inv * t.transpose()
                })
                .collect()
        });
        Some(Covariances {
            cameras: s_inv,
            points,
        })
    }
}

/// Reduced camera system S = A − B C⁻¹ Bᵀ, its right-hand side and the C_q⁻¹.
fn reduce(n: &DMatrix<f64>, b: &DVector<f64>, nc: usize, points: usize) -> Option<Reduced> {
    let mut s = n.view((0, 0), (nc, nc)).clone_owned();
    let mut rs = b.rows(0, nc).clone_owned();
    let mut cinv = Vec::with_capacity(points);
    for q in 0..points {
        let o = nc + 3 * q;
        let ci = n.fixed_view::<3, 3>(o, o).into_owned().try_inverse()?;
        let bq = n.view((0, o), (nc, 3));
        // Only cameras observing q have non-zero rows in B_q.
        let rows: Vec<usize> = (0..nc)
            .filter(|&i| bq.row(i).iter().any(|v| *v != 0.0))
            .collect();
        let bci: Vec<nalgebra::RowVector3<f64>> = rows
            .iter()
            .map(|&i| bq.fixed_view::<1, 3>(i, 0) * ci)
            .collect();
        let bq_rhs = b.fixed_rows::<3>(o);
        for (a, &i) in rows.iter().enumerate() {
            for &j in &rows {
                s[(i, j)] -= (bci[a] * bq.fixed_view::<1, 3>(j, 0).transpose())[0];
            }
            rs[i] -= (bci[a] * bq_rhs)[0];
        }
        cinv.push(ci);
    }
    Some((s, rs, cinv))
}
