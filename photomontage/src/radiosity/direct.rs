//! The full form-factor matrix and a Gauss–Seidel solve of (I − ρF) B = B₀ (Cohen & Wallace,
//! seed 002, §5.3.2): the reference the progressive and hierarchical solvers are tested against,
//! and a solver for small scenes.
//!
//! The matrix entries are [`FormFactorEngine::node_to_node`] between element nodes, the same
//! values (same per-pair random streams) the other solvers use at the element level.
//!
//! # Known limitations
//! O(n²) memory and form factors: meant for up to a few thousand elements.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::convergence::{ConvergenceRow, StopRule, mean_brightness, relative_change};
use super::form_factor::FormFactorEngine;
use super::{RadiosityError, Rgb, luminance};

/// Largest matrix [`element_matrix`] builds (entries), 2.5·10⁷ (200 MB of f64).
pub const MAX_MATRIX_ENTRIES: usize = 25_000_000;

/// F_ij between all elements, row-major (n × n).
///
/// # Errors
/// [`RadiosityError::TooManyElements`] past [`MAX_MATRIX_ENTRIES`], [`RadiosityError::Cancelled`].
pub fn element_matrix(
    engine: &FormFactorEngine<'_>,
    cancel: &AtomicBool,
) -> Result<Vec<f64>, RadiosityError> {
    let mesh = engine.mesh();
    let n = mesh.elements.len();
    if n.saturating_mul(n) > MAX_MATRIX_ENTRIES {
        return Err(RadiosityError::TooManyElements {
            limit: MAX_MATRIX_ENTRIES.isqrt(),
            object: "(the full form-factor matrix)".into(),
        });
    }
    let rows: Vec<Option<Vec<f64>>> = mesh
        .elements
        .par_iter()
        .map(|&p| {
            if cancel.load(Ordering::Relaxed) {
                None
            } else {
                Some(engine.row(p, &mesh.elements))
            }
        })
        .collect();
    let mut out = Vec::with_capacity(n * n);
    for row in rows {
        out.extend(row.ok_or(RadiosityError::Cancelled)?);
    }
    Ok(out)
}

/// Gauss–Seidel on B_i = B₀_i + ρ_i Σ_j F_ij B_j with the matrix of [`element_matrix`].
///
/// # Errors
/// Invalid stop rule, [`RadiosityError::Cancelled`].
pub fn solve(
    engine: &FormFactorEngine<'_>,
    matrix: &[f64],
    b0: &[Rgb],
    group: &str,
    stop: &StopRule,
    cancel: &AtomicBool,
) -> Result<(Vec<Rgb>, Vec<ConvergenceRow>), RadiosityError> {
    stop.validate()?;
    let mesh = engine.mesh();
    let n = mesh.elements.len();
    let areas: Vec<f64> = (0..n).map(|e| mesh.element_node(e).area_m2).collect();
    let rho: Vec<Rgb> = (0..n).map(|e| mesh.element_reflectance_rgb(e)).collect();
    let mut b = b0.to_vec();
    let mut rows = Vec::new();
    let mut previous_mean = None;
    for pass in 1..=stop.max_passes {
        if cancel.load(Ordering::Relaxed) {
            return Err(RadiosityError::Cancelled);
        }
        let mut update = 0.0;
        for i in 0..n {
            let row = &matrix[i * n..(i + 1) * n];
            let mut gathered = [0.0; 3];
            for (f, bj) in row.iter().zip(&b) {
                for c in 0..3 {
                    gathered[c] += f * bj[c];
                }
            }
            let new: Rgb = std::array::from_fn(|c| b0[i][c] + rho[i][c] * gathered[c]);
            let diff: Rgb = std::array::from_fn(|c| (new[c] - b[i][c]).abs());
            update += luminance(&diff) * areas[i];
            b[i] = new;
        }
        let total: f64 = b.iter().zip(&areas).map(|(v, a)| luminance(v) * a).sum();
        let mean = mean_brightness(&b, &areas);
        let row = ConvergenceRow {
            group: group.to_owned(),
            pass,
            residual: if total > 0.0 { update / total } else { 0.0 },
            mean_change: relative_change(previous_mean, mean),
            mean_brightness: mean,
            interactions: (n * n) as u64,
        };
        previous_mean = Some(mean);
        let done = stop.met(&row) || total <= 0.0;
        rows.push(row);
        if done {
            break;
        }
    }
    Ok((b, rows))
}
