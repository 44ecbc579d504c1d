//! Gathering sweeps of a relight on the stored links ([`Sweep`]): Gauss–Seidel
//! patch by patch (sequential) or Jacobi (parallel, fixed chunks), each followed by the push
//! (gathered values down to the leaves) and the pull (area-weighted means up). ΔB shooting, the
//! default, lives in [`super::shooting`].

use rayon::prelude::*;

use super::convergence::{ConvergenceRow, StopRule, mean_brightness, relative_change};
use super::hierarchical::Hierarchy;
use super::mesh::Mesh;
use super::topology::Topology;
use super::{Rgb, luminance};

/// The sweep of a relight iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sweep {
    /// Patch by patch, each gathering the newest values (sequential).
    GaussSeidel,
    /// All receivers from the previous sweep's values (parallel).
    Jacobi,
    /// Only the change is passed on: the difference from the old solution is shot through the
    /// links by source, from the elements where it is not zero, all groups at once
    /// (progressive refinement on ΔB; module `radiosity::shooting`).
    Shooting,
}

/// The links as compressed rows per receiver node.
#[derive(Debug, Clone)]
pub(super) struct LinkRows {
    /// Row of node n: `start[n]..start[n + 1]`.
    start: Vec<u32>,
    source: Vec<u32>,
    form_factor: Vec<f32>,
}

impl LinkRows {
    #[allow(clippy::cast_possible_truncation)] // at most `max_links` (5·10⁶) links
    pub(super) fn new(nodes: usize, hierarchy: &Hierarchy) -> Self {
        let mut start = vec![0u32; nodes + 1];
        for l in &hierarchy.links {
            start[l.receiver as usize + 1] += 1;
        }
        for n in 0..nodes {
            start[n + 1] += start[n];
        }
        // Links are sorted by receiver (stable): rows keep the hierarchy's order.
        Self {
            start,
            source: hierarchy.links.iter().map(|l| l.source).collect(),
            form_factor: hierarchy
                .links
                .iter()
                .map(|l| l.form_factor as f32)
                .collect(),
        }
    }

    fn gather(&self, n: usize, b: &[Rgb]) -> Rgb {
        let mut g = [0.0; 3];
        let (lo, hi) = (self.start[n] as usize, self.start[n + 1] as usize);
        for (s, f) in self.source[lo..hi].iter().zip(&self.form_factor[lo..hi]) {
            let bs = &b[*s as usize];
            let f = f64::from(*f);
            for c in 0..3 {
                g[c] += f * bs[c];
            }
        }
        g
    }
}

/// Iterates B = B₀ + ρ·F·B on the stored links from `start` (per element) until the stop rule
/// holds (its mean change measured from the start). Returns the leaves and the rows.
#[allow(clippy::too_many_arguments)]
pub(super) fn iterate(
    mesh: &Mesh,
    rows: &LinkRows,
    topology: &Topology,
    rho: &[Rgb],
    b0: &[Rgb],
    start: &[Rgb],
    group: &str,
    stop: &StopRule,
    sweep: Sweep,
) -> (Vec<Rgb>, Vec<ConvergenceRow>) {
    /// Receivers gathered per parallel task of a Jacobi sweep (fixed, so the split does not
    /// depend on the thread count).
    const JACOBI_CHUNK: usize = 4096;
    let areas = &topology.areas;
    let mut previous_mean = Some(mean_brightness(start, areas));
    let mut b = vec![[0.0; 3]; mesh.nodes.len()];
    for (e, &node) in mesh.elements.iter().enumerate() {
        b[node as usize] = start[e];
    }
    pull_all(mesh, topology, &mut b);
    let mut out_rows = Vec::new();
    let mut acc = vec![[0.0; 3]; mesh.nodes.len()];
    let leaves = |b: &[Rgb]| -> Vec<Rgb> { mesh.elements.iter().map(|&n| b[n as usize]).collect() };
    for pass in 1..=stop.max_passes {
        let update = match sweep {
            // (Shooting relights do not come here; a full sweep is its fallback.)
            Sweep::GaussSeidel | Sweep::Shooting => {
                let mut update = 0.0;
                for &(lo, hi) in &topology.patch_ranges {
                    for (n, a) in acc.iter_mut().enumerate().take(hi).skip(lo) {
                        *a = rows.gather(n, &b);
                    }
                    update += push_pull(topology, rho, b0, &mut acc, &mut b, lo, hi);
                }
                update
            }
            Sweep::Jacobi => {
                acc.par_chunks_mut(JACOBI_CHUNK)
                    .enumerate()
                    .for_each(|(chunk, out)| {
                        for (i, a) in out.iter_mut().enumerate() {
                            *a = rows.gather(chunk * JACOBI_CHUNK + i, &b);
                        }
                    });
                let mut update = 0.0;
                for &(lo, hi) in &topology.patch_ranges {
                    update += push_pull(topology, rho, b0, &mut acc, &mut b, lo, hi);
                }
                update
            }
        };
        let now = leaves(&b);
        let mean = mean_brightness(&now, areas);
        let total: f64 = now.iter().zip(areas).map(|(v, a)| luminance(v) * a).sum();
        let row = ConvergenceRow {
            group: group.to_owned(),
            pass,
            residual: if total > 0.0 { update / total } else { 0.0 },
            mean_change: relative_change(previous_mean, mean),
            mean_brightness: mean,
            interactions: rows.source.len() as u64,
        };
        previous_mean = Some(mean);
        let done = stop.met(&row) || mean <= 0.0;
        out_rows.push(row);
        if done {
            return (now, out_rows);
        }
    }
    (leaves(&b), out_rows)
}

/// Push (gathered values down to the leaves, B = B₀ + ρ·G) and pull (area-weighted means up)
/// over the subtree in nodes `lo..hi` (pre-order); `acc` holds each node's own gather on entry.
/// Returns Σ A·|ΔB|_Y over its leaves.
fn push_pull(
    topology: &Topology,
    rho: &[Rgb],
    b0: &[Rgb],
    acc: &mut [Rgb],
    b: &mut [Rgb],
    lo: usize,
    hi: usize,
) -> f64 {
    let mut update = 0.0;
    for n in lo..hi {
        if n > lo {
            let down = acc[topology.parent[n] as usize];
            for c in 0..3 {
                acc[n][c] += down[c];
            }
        }
        if let Some(e) = topology.element[n] {
            let e = e as usize;
            let v: Rgb = std::array::from_fn(|c| b0[e][c] + rho[e][c] * acc[n][c]);
            let diff: Rgb = std::array::from_fn(|c| (v[c] - b[n][c]).abs());
            update += luminance(&diff) * topology.areas[e];
            b[n] = v;
        }
    }
    for n in (lo..hi).rev() {
        pull_node(topology, n, b);
    }
    update
}

/// An inner node takes the area-weighted mean of its children.
fn pull_node(topology: &Topology, n: usize, b: &mut [Rgb]) {
    if let Some(kids) = topology.children[n] {
        let mut sum = [0.0; 3];
        for k in kids {
            let w = topology.weight[k as usize];
            for c in 0..3 {
                sum[c] += w * b[k as usize][c];
            }
        }
        b[n] = sum;
    }
}

/// Inner nodes take the area-weighted mean of their children (leaves already set).
fn pull_all(mesh: &Mesh, topology: &Topology, b: &mut [Rgb]) {
    for n in (0..mesh.nodes.len()).rev() {
        pull_node(topology, n, b);
    }
}
