//! Progressive refinement radiosity (Cohen, Chen, Wallace & Greenberg 1988; Cohen & Wallace,
//! seed 002, §5.3.3): repeatedly the element with the largest unshot power ΔB_s·A_s shoots it,
//! ΔB_j += ρ_j·ΔB_s·F_js. The receivers' factors F_js to the shooter are computed from the
//! receivers' side, as Wallace, Elmquist & Haines (1989) shoot to the receivers' sample points,
//! rather than as F_sj·A_s/A_j by reciprocity: they are then the very entries of the matrix the
//! Gauss–Seidel and hierarchical solvers use, so the solvers converge to the same solution, and
//! the Monte Carlo reciprocity error of sampled factors stays out of the comparison. Each shot
//! needs one column of form factors, computed on demand and cached.
//!
//! A pass is as many shots as there are elements (the work of one Jacobi sweep); after each pass
//! the [`super::convergence`] rule is checked, the residual being the unshot power over the
//! total power (Southwell's residual). Shooter ties go to the lowest index; rows are computed in
//! parallel but each factor has its own random stream, so the result is bit-identical for any
//! thread count.
//!
//! # Known limitations
//! Power is conserved only as well as the sampled factors are reciprocal (Σ_j A_j F_js = A_s
//! holds to the quadrature error). Each shot costs one column (n form factors) the first time
//! an element shoots; scenes of more than
//! a few thousand elements should use [`super::hierarchical`]. No ambient term (Cohen et al.'s
//! display aid) is added: the solution after a pass is the true partial sum.

use std::sync::atomic::{AtomicBool, Ordering};

use super::convergence::{ConvergenceRow, StopRule, mean_brightness, relative_change};
use super::form_factor::FormFactorEngine;
use super::{RadiosityError, Rgb, luminance};

/// Form-factor columns (F_js for all j, one per shooter s) kept between shots and groups.
#[derive(Debug, Clone)]
pub struct RowCache {
    rows: Vec<Option<Vec<f32>>>,
    budget_entries: usize,
    used_entries: usize,
    /// Rows computed so far (cache misses).
    pub rows_computed: u64,
}

impl RowCache {
    /// A cache for `elements` rows holding at most `budget_entries` factors (f32 each).
    #[must_use]
    pub fn new(elements: usize, budget_entries: usize) -> Self {
        Self {
            rows: vec![None; elements],
            budget_entries,
            used_entries: 0,
            rows_computed: 0,
        }
    }

    fn row(&mut self, engine: &FormFactorEngine<'_>, shooter: usize) -> Vec<f32> {
        if let Some(row) = &self.rows[shooter] {
            return row.clone();
        }
        let mesh = engine.mesh();
        #[allow(clippy::cast_possible_truncation)] // factors are in [0, 1]
        let row: Vec<f32> = engine
            .column(&mesh.elements, mesh.elements[shooter])
            .into_iter()
            .map(|f| f as f32)
            .collect();
        self.rows_computed += 1;
        if self.used_entries + row.len() <= self.budget_entries {
            self.used_entries += row.len();
            self.rows[shooter] = Some(row.clone());
        }
        row
    }
}

/// Solves B = B₀ + ρ F B by progressive refinement for one light group.
///
/// `b0` is the group's initial exitance per element. `on_pass` is called after every pass.
///
/// # Errors
/// [`RadiosityError::Cancelled`] when `cancel` is raised (checked before every shot), invalid
/// stop rule.
pub fn solve(
    engine: &FormFactorEngine<'_>,
    b0: &[Rgb],
    group: &str,
    stop: &StopRule,
    cache: &mut RowCache,
    cancel: &AtomicBool,
    on_pass: &dyn Fn(&ConvergenceRow),
) -> Result<(Vec<Rgb>, Vec<ConvergenceRow>), RadiosityError> {
    stop.validate()?;
    let mesh = engine.mesh();
    let n = mesh.elements.len();
    let areas: Vec<f64> = (0..n).map(|e| mesh.element_node(e).area_m2).collect();
    let rho: Vec<Rgb> = (0..n).map(|e| mesh.element_reflectance_rgb(e)).collect();
    let mut b = b0.to_vec();
    let mut unshot = b0.to_vec();
    let mut rows = Vec::new();
    let mut previous_mean = None;
    let mut shots = 0u64;
    for pass in 1..=stop.max_passes {
        for _ in 0..n {
            if cancel.load(Ordering::Relaxed) {
                return Err(RadiosityError::Cancelled);
            }
            // The largest unshot power (sum of channels), lowest index on ties.
            let mut shooter = None;
            let mut best = 0.0;
            for e in 0..n {
                let power = (unshot[e][0] + unshot[e][1] + unshot[e][2]) * areas[e];
                if power > best {
                    best = power;
                    shooter = Some(e);
                }
            }
            let Some(s) = shooter else { break };
            let row = cache.row(engine, s);
            let delta = unshot[s];
            unshot[s] = [0.0; 3];
            shots += 1;
            for (j, &f_js) in row.iter().enumerate() {
                if f_js <= 0.0 {
                    continue;
                }
                let f_js = f64::from(f_js);
                for c in 0..3 {
                    let add = rho[j][c] * delta[c] * f_js;
                    b[j][c] += add;
                    unshot[j][c] += add;
                }
            }
        }
        let mean = mean_brightness(&b, &areas);
        let total: f64 = b.iter().zip(&areas).map(|(v, a)| luminance(v) * a).sum();
        let left: f64 = unshot
            .iter()
            .zip(&areas)
            .map(|(v, a)| luminance(v) * a)
            .sum();
        let residual = if total > 0.0 { left / total } else { 0.0 };
        let row = ConvergenceRow {
            group: group.to_owned(),
            pass,
            residual,
            mean_change: relative_change(previous_mean, mean),
            mean_brightness: mean,
            interactions: shots,
        };
        previous_mean = Some(mean);
        on_pass(&row);
        let done = stop.met(&row) || total <= 0.0 || left <= 0.0;
        rows.push(row);
        if done {
            break;
        }
    }
    Ok((b, rows))
}
