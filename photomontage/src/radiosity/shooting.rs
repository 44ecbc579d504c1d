//! ΔB shooting on the stored links: the relight of [`super::transfer::Sweep::Shooting`].
//!
//! A relight starts warm at S = B₀′ + (ρ′/ρ)·(B − B₀) (transfer.rs). With the old solution B
//! at its fixed point (B − B₀ = ρ·F·B), the residual of S is ρ′·F·(S − B): only the difference
//! D = S − B has not been passed on. D is zero wherever neither ρ nor the direct light changed,
//! so for a material change it lives on that material's elements only. The exact answer is
//! B′ = S + Σ_{k≥1} (ρ′F)^k·D, which progressive refinement (Cohen et al. 1988) computes by
//! *shooting*: D is the unshot radiosity; a round sends the unshot radiosity of the chosen
//! patches through the links **by source** (a node's unshot value is the area-weighted mean of
//! its leaves', as a hierarchical link reads it), pushes what each receiver got down to its
//! leaves (ΔB = ρ′·gathered), adds it to B and makes it the new unshot radiosity. Only links
//! whose source carries unshot radiosity are read, and all light groups travel together on one
//! read of each link.
//!
//! Each round shoots the patches with the most unshot power (A·|ΔB| in luminance, relative to
//! each group's total) until what is left is at most half the stop rule's residual; a group
//! stops when its unshot power over its total power is below the residual (a bound on what one
//! more round would add) and its mean brightness changed by less than the stop rule's mean
//! change. Rounds are sequential. Within a round the links are read in parallel, split by a
//! fixed set of receiver-node ranges ([`RECEIVER_RANGES`], balanced by links received): the links
//! are stored range by range, and within a range source by source ([`SourceRows`]), so each range
//! is one task that walks its own arrays forwards and writes only its own receivers. A receiver's
//! sum runs over the shot nodes in node order and each run in receiver order, exactly as one
//! thread would, so the result is the same bit for bit on
//! any number of threads. A round's convergence row counts the links it read (`interactions`), the same in every
//! group's row; its residual is the group's unshot power over its total.

use super::convergence::{ConvergenceRow, StopRule, relative_change};
use super::hierarchical::Link;
use super::mesh::Mesh;
use super::topology::Topology;
use super::{Rgb, luminance};
use rayon::prelude::*;

/// Receiver ranges of a shooting round: the links of every source row are split at the same
/// receiver-node boundaries, and each range is accumulated by one task. Fixed, so the result
/// does not depend on the thread count.
const RECEIVER_RANGES: usize = 16;

/// The vector kernel's token where the CPU has one.
#[cfg(target_arch = "x86_64")]
type Simd = super::gather_avx2::Token;
/// No vector kernel off x86-64.
#[cfg(not(target_arch = "x86_64"))]
type Simd = ();

#[cfg(target_arch = "x86_64")]
fn simd_token() -> Option<Simd> {
    Simd::new()
}

#[cfg(not(target_arch = "x86_64"))]
fn simd_token() -> Option<Simd> {
    None
}

/// Elements per parallel task of the per-element power sums.
const POWER_CHUNK: usize = 4096;

/// The links as compressed rows per **source** node (receiver and factor), stored per receiver
/// range: range r holds, source by source, the links whose receiver lies in
/// `bounds[r]..bounds[r + 1]`, each source's run sorted by receiver. A range's task so reads its
/// own contiguous arrays in source order, with no cut of a long row to look up per source.
#[derive(Debug, Clone)]
pub(super) struct SourceRows {
    nodes: usize,
    /// Run of source n in range r: `start[r·(nodes+1) + n]..start[r·(nodes+1) + n + 1]`.
    start: Vec<u32>,
    receiver: Vec<u32>,
    form_factor: Vec<f32>,
    /// Receiver node ranges: range r is `bounds[r]..bounds[r + 1]` (balanced by links).
    bounds: Vec<u32>,
    /// Links per source node, all ranges.
    row_len: Vec<u32>,
}

impl SourceRows {
    /// Transposes `links` (any order; each source's run is sorted by receiver, stably).
    #[allow(clippy::cast_possible_truncation)] // at most `max_links` links, node ids are u32
    pub(super) fn new(nodes: usize, links: &[Link]) -> Self {
        let mut into = vec![0u64; nodes];
        for l in links {
            into[l.receiver as usize] += 1;
        }
        // Range boundaries at equal shares of the links received.
        let total: u64 = into.iter().sum();
        let mut bounds = vec![0u32; RECEIVER_RANGES + 1];
        let mut seen = 0u64;
        let mut r = 1;
        for (n, &k) in into.iter().enumerate() {
            while r < RECEIVER_RANGES && seen * RECEIVER_RANGES as u64 >= r as u64 * total {
                bounds[r] = n as u32;
                r += 1;
            }
            seen += k;
        }
        for b in &mut bounds[r..] {
            *b = nodes as u32;
        }
        let range_of = |receiver: u32| bounds[1..].partition_point(|&b| b <= receiver);
        let width = nodes + 1;
        let mut start = vec![0u32; RECEIVER_RANGES * width];
        for l in links {
            start[range_of(l.receiver) * width + l.source as usize + 1] += 1;
        }
        // One prefix sum over range-major (range, source) runs.
        let mut acc = 0u32;
        for r in 0..RECEIVER_RANGES {
            let row = &mut start[r * width..(r + 1) * width];
            row[0] = acc;
            for n in 0..nodes {
                acc += row[n + 1];
                row[n + 1] = acc;
            }
        }
        let mut next: Vec<u32> = (0..RECEIVER_RANGES * width).map(|i| start[i]).collect();
        let mut pairs = vec![(0u32, 0f32); links.len()];
        for l in links {
            let at = range_of(l.receiver) * width + l.source as usize;
            let i = next[at] as usize;
            next[at] += 1;
            pairs[i] = (l.receiver, l.form_factor as f32);
        }
        for r in 0..RECEIVER_RANGES {
            for n in 0..nodes {
                let (a, z) = (
                    start[r * width + n] as usize,
                    start[r * width + n + 1] as usize,
                );
                pairs[a..z].sort_by_key(|&(rcv, _)| rcv);
            }
        }
        let (receiver, form_factor) = pairs.into_iter().unzip();
        let mut row_len = vec![0u32; nodes];
        for l in links {
            row_len[l.source as usize] += 1;
        }
        Self {
            nodes,
            start,
            receiver,
            form_factor,
            bounds,
            row_len,
        }
    }

    /// The links of node `n`'s row into receiver range `r`.
    fn cut(&self, n: usize, r: usize) -> std::ops::Range<usize> {
        let i = r * (self.nodes + 1) + n;
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// Links whose source is node `n`.
    pub(super) fn row_len(&self, n: usize) -> u64 {
        u64::from(self.row_len[n])
    }
}

/// One light group to shoot: its old radiosity and its warm start, per element.
pub(super) struct ShotGroup<'a> {
    pub name: &'a str,
    pub old: &'a [Rgb],
    pub start: Vec<Rgb>,
}

/// Shoots D = start − old of every group (module doc) with reflectance `rho` (per element).
/// Returns each group's radiosity per element and its convergence rows.
#[allow(clippy::too_many_lines)]
pub(super) fn shoot(
    mesh: &Mesh,
    topology: &Topology,
    rows: &SourceRows,
    rho: &[Rgb],
    groups: Vec<ShotGroup<'_>>,
    stop: &StopRule,
) -> Vec<(Vec<Rgb>, Vec<ConvergenceRow>)> {
    let k = groups.len();
    let stride = 3 * k;
    let simd = simd_token();
    let n_el = mesh.elements.len();
    let n_nodes = mesh.nodes.len();
    let node_element = |n: usize| topology.element[n];
    let areas = &topology.areas;
    let area_sum: f64 = areas.iter().sum();
    // Leaves: B and the unshot part, `stride` values per element (group-major within).
    let mut b = vec![0.0; n_el * stride];
    let mut u = vec![0.0; n_el * stride];
    for (g, group) in groups.iter().enumerate() {
        for e in 0..n_el {
            let (s, o) = (group.start[e], group.old[e]);
            for c in 0..3 {
                b[e * stride + 3 * g + c] = s[c];
                // Bit-equal values have nothing to pass on (D = 0 exactly, not a rounding).
                if s[c].to_bits() != o[c].to_bits() {
                    u[e * stride + 3 * g + c] = s[c] - o[c];
                }
            }
        }
    }
    // Luminance power A·|v|_Y of every element and group (`k` per element), in parallel; each
    // value is computed on its own, so the result does not depend on the thread count.
    let powers = |v: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; n_el * k];
        out.par_chunks_mut(k * POWER_CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (i, o) in out.iter_mut().enumerate() {
                    let (e, g) = (chunk * POWER_CHUNK + i / k, i % k);
                    let j = e * stride + 3 * g;
                    *o = luminance(&[v[j].abs(), v[j + 1].abs(), v[j + 2].abs()]) * areas[e];
                }
            });
        out
    };
    let totals = |pw: &[f64]| -> Vec<f64> {
        (0..k)
            .map(|g| (0..n_el).map(|e| pw[e * k + g]).sum())
            .collect()
    };
    let mut out_rows: Vec<Vec<ConvergenceRow>> = vec![Vec::new(); k];
    let mut total = totals(&powers(&b));
    let mut previous_mean: Vec<f64> = total.iter().map(|t| t / area_sum).collect();
    let mut unshot_power = powers(&u);
    let mut un = vec![0.0; n_nodes * stride];
    let mut acc = vec![0.0; n_nodes * stride];
    let patches = &topology.patch_ranges;
    for pass in 1..=stop.max_passes {
        // Unshot power per patch, relative to each group's total.
        let scale: Vec<f64> = total
            .iter()
            .map(|&t| if t > 0.0 { 1.0 / t } else { 0.0 })
            .collect();
        let score: Vec<f64> = patches
            .par_iter()
            .map(|&(lo, hi)| {
                (lo..hi)
                    .filter_map(node_element)
                    .map(|e| {
                        (0..k)
                            .map(|g| unshot_power[e as usize * k + g] * scale[g])
                            .sum::<f64>()
                    })
                    .sum()
            })
            .collect();
        let unshot: f64 = score.iter().sum();
        if unshot <= 0.0 {
            break;
        }
        let mut order: Vec<usize> = (0..patches.len()).filter(|&p| score[p] > 0.0).collect();
        order.sort_by(|&a, &c| score[c].total_cmp(&score[a]).then(a.cmp(&c)));
        let mut left = unshot;
        let mut shot_now = vec![false; patches.len()];
        for &p in &order {
            if left <= 0.5 * stop.residual {
                break;
            }
            left -= score[p];
            shot_now[p] = true;
        }
        // Node values of the unshot part of every shot patch (leaves up), then clear its leaves;
        // patch by patch in parallel (each writes only its own nodes and elements).
        let active_per_patch: Vec<Vec<usize>> = patch_slices(topology, stride, &mut un, &mut u)
            .into_par_iter()
            .map(|(p, un, u)| {
                if !shot_now[p] {
                    return Vec::new();
                }
                let ((lo, hi), (elo, _)) = (patches[p], topology.patch_elements[p]);
                for n in (lo..hi).rev() {
                    let (head, tail) = un.split_at_mut((n - lo + 1) * stride);
                    let own = &mut head[(n - lo) * stride..];
                    if let Some(e) = node_element(n) {
                        let e = e as usize - elo;
                        own.copy_from_slice(&u[e * stride..(e + 1) * stride]);
                        u[e * stride..(e + 1) * stride].fill(0.0);
                    } else {
                        own.fill(0.0);
                        for kid in topology.children[n].into_iter().flatten() {
                            let kid = kid as usize;
                            let w = topology.weight[kid];
                            let kid_vals = &tail[(kid - n - 1) * stride..(kid - n) * stride];
                            for (o, v) in own.iter_mut().zip(kid_vals) {
                                *o += w * v;
                            }
                        }
                    }
                }
                (lo..hi)
                    .filter(|&n| {
                        un[(n - lo) * stride..(n - lo + 1) * stride]
                            .iter()
                            .any(|&v| v != 0.0)
                    })
                    .collect()
            })
            .collect();
        let mut active: Vec<usize> = active_per_patch.into_iter().flatten().collect();
        // Gathered in node order, so that each range task walks its arrays forwards.
        active.sort_unstable();
        let interactions: u64 = active.iter().map(|&n| rows.row_len(n)).sum();
        // Each receiver range gathers on its own task; a receiver's sum runs over the shot
        // nodes in node order and each run in receiver order, as one thread would.
        let mut ranges: Vec<(usize, &mut [f64])> = Vec::with_capacity(RECEIVER_RANGES);
        let mut rest: &mut [f64] = &mut acc;
        for r in 0..RECEIVER_RANGES {
            let (lo, hi) = (rows.bounds[r] as usize, rows.bounds[r + 1] as usize);
            let (chunk, tail) = std::mem::take(&mut rest).split_at_mut((hi - lo) * stride);
            ranges.push((r, chunk));
            rest = tail;
        }
        let t = simd;
        ranges.into_par_iter().for_each(|(r, chunk)| match stride {
            3 => gather_range::<3>(rows, r, &active, &un, chunk, t),
            6 => gather_range::<6>(rows, r, &active, &un, chunk, t),
            9 => gather_range::<9>(rows, r, &active, &un, chunk, t),
            12 => gather_range::<12>(rows, r, &active, &un, chunk, t),
            _ => gather_range_dyn(rows, r, &active, &un, chunk, stride),
        });
        // Push what every node gathered down to its leaves: ΔB = ρ′·G, added and unshot; patch
        // by patch in parallel (each writes only its own nodes and elements).
        patch_slices3(topology, stride, &mut acc, &mut b, &mut u)
            .into_par_iter()
            .for_each(|(p, acc, b, u)| {
                let ((lo, hi), (elo, _)) = (patches[p], topology.patch_elements[p]);
                for n in lo..hi {
                    if n > lo {
                        let parent = topology.parent[n] as usize - lo;
                        let (head, tail) = acc.split_at_mut((n - lo) * stride);
                        for (d, s) in tail[..stride]
                            .iter_mut()
                            .zip(&head[parent * stride..(parent + 1) * stride])
                        {
                            *d += s;
                        }
                    }
                    if let Some(e) = node_element(n) {
                        let (e, el) = (e as usize, e as usize - elo);
                        for j in 0..stride {
                            let db = rho[e][j % 3] * acc[(n - lo) * stride + j];
                            b[el * stride + j] += db;
                            u[el * stride + j] += db;
                        }
                    }
                }
            });
        acc.fill(0.0);
        total = totals(&powers(&b));
        unshot_power = powers(&u);
        let mut all_met = true;
        for g in 0..k {
            let unshot_g: f64 = (0..n_el).map(|e| unshot_power[e * k + g]).sum();
            let mean = total[g] / area_sum;
            let row = ConvergenceRow {
                group: groups[g].name.to_owned(),
                pass,
                residual: if total[g] > 0.0 {
                    unshot_g / total[g]
                } else {
                    0.0
                },
                mean_change: relative_change(Some(previous_mean[g]), mean),
                mean_brightness: mean,
                interactions,
            };
            previous_mean[g] = mean;
            all_met &= stop.met(&row) || mean <= 0.0;
            out_rows[g].push(row);
        }
        if all_met {
            break;
        }
    }
    out_rows
        .into_iter()
        .enumerate()
        .map(|(g, rows)| {
            let values = (0..n_el)
                .map(|e| std::array::from_fn(|c| b[e * stride + 3 * g + c]))
                .collect();
            (values, rows)
        })
        .collect()
}

/// Per patch p: `(p, its nodes' values in `nodes`, its elements' values in `elements`)`, `stride`
/// values per node and per element (nodes between patches, above them, are skipped).
fn patch_slices<'a>(
    topology: &Topology,
    stride: usize,
    nodes: &'a mut [f64],
    elements: &'a mut [f64],
) -> Vec<(usize, &'a mut [f64], &'a mut [f64])> {
    let mut out = Vec::with_capacity(topology.patch_ranges.len());
    let (mut node_rest, mut node_at) = (nodes, 0);
    let mut element_rest = elements;
    for (p, (&(lo, hi), &(elo, ehi))) in topology
        .patch_ranges
        .iter()
        .zip(&topology.patch_elements)
        .enumerate()
    {
        let (_, rest) = std::mem::take(&mut node_rest).split_at_mut((lo - node_at) * stride);
        let (mine, rest) = rest.split_at_mut((hi - lo) * stride);
        node_rest = rest;
        node_at = hi;
        let (el, rest) = std::mem::take(&mut element_rest).split_at_mut((ehi - elo) * stride);
        element_rest = rest;
        out.push((p, mine, el));
    }
    out
}

/// A patch's index, its node values and its values in two element arrays.
type PatchSlices3<'a> = (usize, &'a mut [f64], &'a mut [f64], &'a mut [f64]);

/// [`patch_slices`] with two element arrays.
fn patch_slices3<'a>(
    topology: &Topology,
    stride: usize,
    nodes: &'a mut [f64],
    a: &'a mut [f64],
    b: &'a mut [f64],
) -> Vec<PatchSlices3<'a>> {
    let mut b_rest = b;
    patch_slices(topology, stride, nodes, a)
        .into_iter()
        .map(|(p, n, a)| {
            let (elo, ehi) = topology.patch_elements[p];
            let (mine, rest) = std::mem::take(&mut b_rest).split_at_mut((ehi - elo) * stride);
            b_rest = rest;
            (p, n, a, mine)
        })
        .collect()
}

/// Receiver range `r` gathers the unshot values `un` (`S` per node) of the `active` nodes
/// through their links into `acc` (the range's nodes, `S` per node): a receiver's sum runs over
/// `active` in order and each row in receiver order. With an AVX2 `token` the same sums run in
/// the vector kernel (bit for bit the same).
fn gather_range<const S: usize>(
    rows: &SourceRows,
    r: usize,
    active: &[usize],
    un: &[f64],
    acc: &mut [f64],
    token: Option<Simd>,
) {
    let base = rows.bounds[r] as usize;
    for &n in active {
        let src: &[f64; S] = un[n * S..(n + 1) * S]
            .try_into()
            .unwrap_or_else(|_| unreachable!("S values per node"));
        let links = rows.cut(n, r);
        let (receivers, factors) = (&rows.receiver[links.clone()], &rows.form_factor[links]);
        #[cfg(target_arch = "x86_64")]
        if let Some(token) = token {
            token.gather_run::<S>(src, receivers, factors, base, acc);
            continue;
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = token;
        for (rcv, f) in receivers.iter().zip(factors) {
            let f = f64::from(*f);
            let at = (*rcv as usize - base) * S;
            let dst: &mut [f64; S] = (&mut acc[at..at + S])
                .try_into()
                .unwrap_or_else(|_| unreachable!("S values per node"));
            for (d, s) in dst.iter_mut().zip(src) {
                *d += f * s;
            }
        }
    }
}

/// [`gather_range`] for any number of values per node.
fn gather_range_dyn(
    rows: &SourceRows,
    r: usize,
    active: &[usize],
    un: &[f64],
    acc: &mut [f64],
    stride: usize,
) {
    let base = rows.bounds[r] as usize;
    for &n in active {
        let src = &un[n * stride..(n + 1) * stride];
        let links = rows.cut(n, r);
        for (rcv, f) in rows.receiver[links.clone()]
            .iter()
            .zip(&rows.form_factor[links])
        {
            let f = f64::from(*f);
            let at = (*rcv as usize - base) * stride;
            for (d, s) in acc[at..at + stride].iter_mut().zip(src) {
                *d += f * s;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every link lands in exactly one receiver range, the one holding its receiver; each
    /// source's links in a range are sorted by receiver; a source's runs over all ranges are its
    /// links; the ranges tile the nodes and the runs tile the arrays in (range, source) order.
    #[test]
    fn receiver_ranges_partition_every_row() {
        let nodes = 997;
        let mut state = 12_345u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) % m
        };
        #[allow(clippy::cast_possible_truncation)]
        let links: Vec<Link> = (0..20_000)
            .map(|_| Link {
                receiver: next(nodes) as u32,
                source: next(nodes) as u32,
                form_factor: 0.001,
            })
            .collect();
        let rows = SourceRows::new(nodes as usize, &links);
        assert_eq!(rows.bounds[0], 0);
        assert_eq!(rows.bounds[RECEIVER_RANGES] as usize, nodes as usize);
        assert!(rows.bounds.windows(2).all(|w| w[0] <= w[1]));
        let mut at = 0;
        for r in 0..RECEIVER_RANGES {
            for n in 0..nodes as usize {
                let cut = rows.cut(n, r);
                assert_eq!(
                    cut.start, at,
                    "runs tile the arrays in (range, source) order"
                );
                at = cut.end;
            }
        }
        assert_eq!(at, links.len());
        for n in 0..nodes as usize {
            let mut expected: Vec<u32> = links
                .iter()
                .filter(|l| l.source as usize == n)
                .map(|l| l.receiver)
                .collect();
            expected.sort_unstable();
            let mut got = Vec::new();
            for r in 0..RECEIVER_RANGES {
                let run = &rows.receiver[rows.cut(n, r)];
                assert!(run.windows(2).all(|w| w[0] <= w[1]));
                let (lo, hi) = (rows.bounds[r], rows.bounds[r + 1]);
                assert!(run.iter().all(|&x| lo <= x && x < hi));
                got.extend_from_slice(run);
            }
            assert_eq!(got, expected, "row of node {n}");
            assert_eq!(rows.row_len(n), expected.len() as u64);
        }
        // Balanced: no range holds more than twice its share of the links.
        let share = links.len() / RECEIVER_RANGES;
        for r in 0..RECEIVER_RANGES {
            let k: usize = (0..nodes as usize).map(|n| rows.cut(n, r).len()).sum();
            assert!(k <= 2 * share, "range {r} holds {k} links, share {share}");
        }
    }

    /// The AVX2 kernel gives the portable loop's sums bit for bit, for every stride the
    /// shooting uses.
    #[test]
    fn vector_gather_equals_the_portable_loop() {
        fn check<const S: usize>(rows: &SourceRows, nodes: usize, token: Simd) {
            #[allow(clippy::cast_precision_loss)]
            let un: Vec<f64> = (0..nodes * S)
                .map(|i| ((i * 7919 % 1000) as f64 - 500.0) * 1.37e-3)
                .collect();
            let active: Vec<usize> = (0..nodes).filter(|n| n % 3 != 1).collect();
            for r in 0..RECEIVER_RANGES {
                let width = (rows.bounds[r + 1] - rows.bounds[r]) as usize * S;
                let (mut a, mut b) = (vec![0.25; width], vec![0.25; width]);
                gather_range::<S>(rows, r, &active, &un, &mut a, None);
                gather_range::<S>(rows, r, &active, &un, &mut b, Some(token));
                assert!(
                    a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                    "S = {S}, range {r}"
                );
            }
        }
        let Some(token) = simd_token() else {
            eprintln!("notice: this CPU has no vector kernel; nothing to compare");
            return;
        };
        let nodes = 301;
        #[allow(clippy::cast_possible_truncation)]
        let links: Vec<Link> = (0..6000u64)
            .map(|i| Link {
                receiver: (i * 2_654_435_761 % nodes) as u32,
                source: (i * 40_503 % nodes) as u32,
                form_factor: 1e-4 * (1 + i % 97) as f64,
            })
            .collect();
        let rows = SourceRows::new(nodes as usize, &links);
        check::<3>(&rows, nodes as usize, token);
        check::<6>(&rows, nodes as usize, token);
        check::<9>(&rows, nodes as usize, token);
        check::<12>(&rows, nodes as usize, token);
    }
}
