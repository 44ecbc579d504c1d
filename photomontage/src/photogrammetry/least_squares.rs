//! Dense Levenberg–Marquardt on the normal equations (Marquardt 1963, with the diagonal
//! scaling `(N + λ·diag N) δ = −g`; Nocedal & Wright 2006 §10.3), plus the covariance and
//! parameter-support measures the adjustments report.
//!
//! The problem supplies N = JᵀJ and g = Jᵀr of its whitened residuals r, never J itself, in a
//! representation of its choosing ([`LinearSystem`]): a dense matrix for the resection, the
//! sparse blocks of the bundle adjustment ([`super::bundle`]) solved through the reduced camera
//! system. The damping is applied by the representation, always as `λ·max(N_ii, 10⁻¹²)` on the
//! diagonal, so every representation takes the same steps.
//!
//! # Known limitations
//! The dense representation uses Cholesky at O(n³) in the number of unknowns, fine up to a few
//! thousand; larger problems need a structured representation.

use nalgebra::{DMatrix, DVector};

/// Smallest diagonal element used to scale the damping (keeps a zero column damped).
pub(crate) const MIN_DAMPING_DIAGONAL: f64 = 1e-12;

/// A normal matrix N in some representation.
pub(crate) trait LinearSystem {
    /// Diagonal of N.
    fn diagonal(&self) -> DVector<f64>;
    /// Solves `(N + λ·diag(max(N_ii, MIN_DAMPING_DIAGONAL))) x = rhs`; `None` when singular.
    fn solve_damped(&self, lambda: f64, rhs: &DVector<f64>) -> Option<DVector<f64>>;
}

impl LinearSystem for DMatrix<f64> {
    fn diagonal(&self) -> DVector<f64> {
        DMatrix::diagonal(self)
    }
    fn solve_damped(&self, lambda: f64, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        let mut damped = self.clone();
        for i in 0..self.nrows() {
            damped[(i, i)] += lambda * self[(i, i)].max(MIN_DAMPING_DIAGONAL);
        }
        damped.cholesky().map(|c| c.solve(rhs))
    }
}

/// A weighted least-squares problem in whitened form (cost = Σ r², r = W^½ (f(x) − l)).
pub(crate) trait NormalEquations {
    type State: Clone;
    /// Representation of N.
    type Normal: LinearSystem;
    /// Number of unknowns.
    fn unknowns(&self) -> usize;
    /// Cost at `state`; `None` when the state is invalid (e.g. a point behind a camera).
    fn cost(&self, state: &Self::State) -> Option<f64>;
    /// (N, g, cost) at `state`.
    fn normal_equations(&self, state: &Self::State) -> Option<(Self::Normal, DVector<f64>, f64)>;
    /// `state ⊕ delta`.
    fn update(&self, state: &Self::State, delta: &DVector<f64>) -> Self::State;
}

/// The solution of [`levenberg_marquardt`].
pub(crate) struct Solution<S, N> {
    pub state: S,
    /// Normal matrix at the solution (undamped).
    pub normal: N,
    pub cost: f64,
    pub converged: bool,
}

/// Relative cost decrease below which the iteration stops: 1e-14 is near double rounding of a
/// sum of squares, so further steps cannot change the solution measurably.
const COST_TOLERANCE: f64 = 1e-14;
/// Stop when every step component is below this fraction of its a-priori scale
/// √(diag N)⁻¹, i.e. 1e-10 σ: far below any precision we report.
const STEP_TOLERANCE: f64 = 1e-10;
const MAX_ITERATIONS: usize = 200;

/// Minimises the problem from `start`. Fails only when the start itself is invalid.
pub(crate) fn levenberg_marquardt<P: NormalEquations>(
    problem: &P,
    start: P::State,
) -> Option<Solution<P::State, P::Normal>> {
    let mut state = start;
    let (mut normal, mut gradient, mut cost) = problem.normal_equations(&state)?;
    let n = problem.unknowns();
    let mut lambda = 1e-4;
    let mut converged = false;
    let mut diagonal = normal.diagonal();
    for _ in 0..MAX_ITERATIONS {
        let Some(step) = normal.solve_damped(lambda, &gradient) else {
            lambda *= 10.0;
            if lambda > 1e16 {
                break;
            }
            continue;
        };
        let delta = -step;
        let small_step =
            (0..n).all(|i| delta[i].abs() * diagonal[i].max(1e-300).sqrt() <= STEP_TOLERANCE);
        let trial = problem.update(&state, &delta);
        match problem.cost(&trial) {
            Some(trial_cost) if trial_cost <= cost => {
                let decrease = cost - trial_cost;
                state = trial;
                let Some((nn, gg, cc)) = problem.normal_equations(&state) else {
                    break;
                };
                normal = nn;
                diagonal = normal.diagonal();
                gradient = gg;
                cost = cc;
                lambda = (lambda * 0.1).max(1e-12);
                if small_step || decrease <= COST_TOLERANCE * cost.max(1e-300) {
                    converged = true;
                    break;
                }
            }
            _ => {
                if small_step {
                    converged = true;
                    break;
                }
                lambda *= 10.0;
                if lambda > 1e16 {
                    break;
                }
            }
        }
    }
    Some(Solution {
        state,
        normal,
        cost,
        converged,
    })
}

/// Inverse of a symmetric positive definite matrix, `None` if singular.
pub(crate) fn spd_inverse(normal: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    // Equilibrate so that the diagonal is 1: makes the Cholesky test of singularity scale-free.
    let n = normal.nrows();
    let scale = DVector::from_iterator(n, (0..n).map(|i| 1.0 / normal[(i, i)].max(1e-300).sqrt()));
    let scaled = DMatrix::from_fn(n, n, |i, j| normal[(i, j)] * scale[i] * scale[j]);
    let chol = scaled.cholesky()?;
    let l = chol.l_dirty();
    let min_pivot = (0..n).map(|i| l[(i, i)]).fold(f64::INFINITY, f64::min);
    if min_pivot.is_nan() || min_pivot <= 1e-9 {
        return None;
    }
    let inv = chol.inverse();
    Some(DMatrix::from_fn(n, n, |i, j| {
        inv[(i, j)] * scale[i] * scale[j]
    }))
}

/// Multiple correlation coefficient of unknown `index` with all others:
/// ρ² = 1 − 1 / (N_ii · (N⁻¹)_ii). Near 1 means the data cannot separate it from the rest.
pub(crate) fn multiple_correlation(
    normal: &DMatrix<f64>,
    inverse: &DMatrix<f64>,
    index: usize,
) -> f64 {
    correlation_from_diagonals(normal[(index, index)], inverse[(index, index)])
}

/// ρ = √(1 − 1 / (N_ii · (N⁻¹)_ii)) from the two diagonal elements.
pub(crate) fn correlation_from_diagonals(normal_ii: f64, inverse_ii: f64) -> f64 {
    let product = normal_ii * inverse_ii;
    if product <= 1.0 {
        0.0
    } else {
        (1.0 - 1.0 / product).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fit y = a·exp(b x) to exact data; LM must hit the truth to 1e-9 (well-conditioned).
    const FIT_TOLERANCE: f64 = 1e-9;

    struct Exp {
        xs: Vec<f64>,
        ys: Vec<f64>,
    }

    impl NormalEquations for Exp {
        type State = [f64; 2];
        type Normal = DMatrix<f64>;
        fn unknowns(&self) -> usize {
            2
        }
        fn cost(&self, s: &[f64; 2]) -> Option<f64> {
            Some(
                self.xs
                    .iter()
                    .zip(&self.ys)
                    .map(|(x, y)| (s[0] * (s[1] * x).exp() - y).powi(2))
                    .sum(),
            )
        }
        fn normal_equations(&self, s: &[f64; 2]) -> Option<(DMatrix<f64>, DVector<f64>, f64)> {
            let mut n = DMatrix::zeros(2, 2);
            let mut g = DVector::zeros(2);
            let mut c = 0.0;
            for (x, y) in self.xs.iter().zip(&self.ys) {
                let e = (s[1] * x).exp();
                let r = s[0] * e - y;
                let j = DVector::from_vec(vec![e, s[0] * x * e]);
                n += &j * j.transpose();
                g += &j * r;
                c += r * r;
            }
            Some((n, g, c))
        }
        fn update(&self, s: &[f64; 2], d: &DVector<f64>) -> [f64; 2] {
            [s[0] + d[0], s[1] + d[1]]
        }
    }

    #[test]
    fn fits_an_exponential() {
        let xs: Vec<f64> = (0..20).map(|i| f64::from(i) * 0.1).collect();
        let ys = xs.iter().map(|x| 2.5 * (-1.3 * x).exp()).collect();
        let sol = levenberg_marquardt(&Exp { xs, ys }, [1.0, 0.0]).expect("valid start");
        assert!(sol.converged);
        assert!(
            (sol.state[0] - 2.5).abs() < FIT_TOLERANCE
                && (sol.state[1] + 1.3).abs() < FIT_TOLERANCE
        );
    }

    #[test]
    fn multiple_correlation_of_dependent_columns_is_one() {
        // Columns (1, 1, 1) and (1, 1, 1 + 1e-9): nearly identical → ρ ≈ 1; orthogonal → 0.
        let n = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 4.0]);
        let inv = spd_inverse(&n).expect("spd");
        assert!(multiple_correlation(&n, &inv, 0).abs() < 1e-12);
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 0.9, 0.9, 1.0]);
        let inv = spd_inverse(&m).expect("spd");
        assert!((multiple_correlation(&m, &inv, 0) - 0.9).abs() < 1e-12);
    }
}
