//! ΔB shooting on the stored links: the relight of [`super::transfer::Sweep::Shooting`].
//!
//! A relight starts warm at S = B₀′ + (ρ′/ρ)·(B − B₀) (`transfer_commit.rs`). With the old solution B
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
//! Each round chooses the patches it shoots by their unshot power (A·|ΔB| in luminance, relative
//! to each group's total) per link read, best first (Southwell's greedy order, priced by what a
//! shot costs here). A round that cannot be the last stops when what is left is at most 5 % of
//! what it started with (or half the stop rule's residual): the weakest patches wait, and the
//! next round's bounce usually makes them worth shooting or unnecessary. When one round can be
//! the last (every group's unshot power, times what the previous round sent back per unit shot
//! with a 25 % margin, is under 0.9 × the residual), it shoots just enough of each group's power
//! to leave it there. A group stops when its unshot power over its total power is below the
//! residual (a bound on what one more round would add) and its mean brightness changed by less
//! than the stop rule's mean
//! change. Rounds are sequential. Within a round the links are read in parallel, split by a
//! set of receiver-node ranges (`source_rows::receiver_ranges_for`, balanced by links received): the links
//! are stored range by range, and within a range source by source ([`SourceRows`]), so each range
//! is one task that walks its own arrays forwards and writes only its own receivers. A receiver's
//! sum runs over the shot nodes in node order and each run in receiver order, exactly as one
//! thread would, so the result is the same bit for bit on
//! any number of threads. A round's convergence row counts the links it read (`interactions`), the same in every
//! group's row; its residual is the group's unshot power over its total. The per-patch passes
//! (the start, the shot patches' node values, the push to the leaves) run over fixed blocks of
//! whole patches ([`blocks::PatchBlock`]); the push and the powers skip a patch that gathered nothing
//! and was not shot (its B, unshot part and powers cannot have changed). The patches' powers
//! are summed in the same parallel pass that pushes a round's gathers down, and the buffers are
//! kept by the transfer between relights ([`ShootScratch`]), so a relight makes no fresh pages.
//! A group can give its unshot part outright instead of `old` ([`ShotGroup::unshot`]) and have
//! what is left unshot at the stop returned ([`Shot::unshot`]): the transfer keeps that
//! remainder and passes it on with a later relight's D, so relights do not drift
//! (`Transfer::commit_relight`).
//! The shot node values and the gathers are `f32` (a round's increment needs ~1e-6 relative, the
//! factors are `f32` already), and so is the unshot part of the leaves, which is shot as `f32`
//! anyway and whose kept remainder is below the stop rule's residual of B (its rounding, 6e-8 of
//! itself, is far below what a relight resolves); it halves the bytes the per-round passes move
//! for it, and those passes are bound by memory traffic. B stays `f64`.

use super::convergence::{ConvergenceRow, StopRule, relative_change};
use super::source_rows::{SourceRows, gather_range, gather_range_dyn, simd_token};
use super::topology::Topology;
use super::{Rgb, luminance};
use blocks::{BlockLeaves, block_leaves, patch_blocks, split_blocks};
use rayon::prelude::*;

/// One light group to shoot: its old radiosity and its warm start, per element.
pub(super) struct ShotGroup<'a> {
    pub name: &'a str,
    pub old: &'a [Rgb],
    pub start: Vec<Rgb>,
    /// The unshot part given outright (`old` is then not read): the difference with what the
    /// group's last shooting left unshot ([`Shot::unshot`]) carried over.
    pub unshot: Option<Vec<Rgb>>,
    /// Return what is left unshot at the stop ([`Shot::unshot`]).
    pub keep_unshot: bool,
}

impl<'a> ShotGroup<'a> {
    /// D = `start` − `old`, nothing kept.
    pub fn against(name: &'a str, old: &'a [Rgb], start: Vec<Rgb>) -> Self {
        Self {
            name,
            old,
            start,
            unshot: None,
            keep_unshot: false,
        }
    }
}

/// Where [`shoot`] finds the groups' start and unshot part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Leaves {
    /// In the groups: [`ShotGroup`]'s `start`, and `old` or `unshot`.
    InGroups,
    /// Already in the scratch's leaves ([`ShootScratch::leaves`]), written by the caller in one
    /// pass with its warm start: the groups' `start` and `unshot` are only the buffers the
    /// results are read out into (`n` elements each, `unshot` for every group).
    Filled,
}

/// One group's result of [`shoot`].
pub(super) struct Shot {
    /// B per element.
    pub radiosity: Vec<Rgb>,
    /// One row per round.
    pub rows: Vec<ConvergenceRow>,
    /// What is left unshot per element, for a group that asked ([`ShotGroup::keep_unshot`]):
    /// B plus its response is the exact solution.
    pub unshot: Option<Vec<Rgb>>,
    /// The power (area-weighted luminance of |v|) of `radiosity` and of what is left unshot, as
    /// the stop rule read them (summed patch by patch).
    pub powers: [f64; 2],
}

/// The buffers of [`shoot`], kept by the transfer between relights so that a relight neither
/// allocates nor touches a fresh page. `acc` is all zeros between calls; the others are
/// overwritten before they are read. A clone starts empty (the buffers are refilled on use).
#[derive(Default)]
pub(super) struct ShootScratch {
    /// Per element, B (`stride` values).
    b: Vec<f64>,
    /// Per element, the unshot part (`f32`, as it is shot: module doc).
    u: Vec<f32>,
    /// Per node, the unshot values of shot nodes.
    un: Vec<f32>,
    /// Per node, what it gathered in the round.
    acc: Vec<f32>,
    /// Per-element buffers a relight gave back ([`ShootScratch::give_rgb`]), for its next warm
    /// start and the groups' next solutions: a relight then writes into pages it has used before
    /// (a fresh 1.2 MB buffer of the city block costs its page faults again at every relight).
    spare: Vec<Vec<Rgb>>,
}

/// At most this many spare per-element buffers are kept.
const SPARE_BUFFERS: usize = 16;

impl ShootScratch {
    /// A buffer of `n` values whose contents are unspecified (the caller writes every one): a
    /// spare one when there is one.
    pub(super) fn take_rgb(&mut self, n: usize) -> Vec<Rgb> {
        let mut v = self.spare.pop().unwrap_or_default();
        if v.len() != n {
            v.clear();
            v.resize(n, [0.0; 3]);
        }
        v
    }

    /// B and the unshot part per element (`stride` values each, group-major within an
    /// element, as [`shoot`] reads them with [`Leaves::Filled`]), sized for `n_el` elements;
    /// their contents are unspecified until the caller writes every value.
    pub(super) fn leaves(&mut self, n_el: usize, stride: usize) -> (&mut [f64], &mut [f32]) {
        self.b.resize(n_el * stride, 0.0);
        self.u.resize(n_el * stride, 0.0);
        (&mut self.b, &mut self.u)
    }

    /// Keeps `v` for a later [`ShootScratch::take_rgb`] (up to [`SPARE_BUFFERS`]).
    pub(super) fn give_rgb(&mut self, v: Vec<Rgb>) {
        if self.spare.len() < SPARE_BUFFERS && v.capacity() > 0 {
            self.spare.push(v);
        }
    }
}

impl Clone for ShootScratch {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for ShootScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShootScratch")
            .field(
                "values",
                &(self.b.len() + self.u.len() + self.un.len() + self.acc.len()),
            )
            .finish()
    }
}

/// Per patch and group (`k` values per patch): the luminance power A·|v|_Y of its elements' B
/// and of their unshot part.
struct PatchPowers {
    total: Vec<f64>,
    unshot: Vec<f64>,
}

/// Sums, into `total` and `unshot` (`k` each), the power of one patch's elements in `b` and `u`
/// (the patch's own slices, `stride` = 3k values per element), compiled for `K` groups (0: any).
fn patch_powers<const K: usize>(
    areas: &[f64],
    b: &[f64],
    u: &[f32],
    total: &mut [f64],
    unshot: &mut [f64],
) {
    let k = groups_of::<K>(total.len());
    let (total, unshot) = (&mut total[..k], &mut unshot[..k]);
    let stride = 3 * k;
    let power = |v: &[f64]| luminance(&[v[0].abs(), v[1].abs(), v[2].abs()]);
    let power_f32 = |v: &[f32]| {
        luminance(&[
            f64::from(v[0].abs()),
            f64::from(v[1].abs()),
            f64::from(v[2].abs()),
        ])
    };
    total.fill(0.0);
    unshot.fill(0.0);
    for ((&area, b), u) in areas
        .iter()
        .zip(b.chunks_exact(stride))
        .zip(u.chunks_exact(stride))
    {
        for (((t, s), b), u) in total
            .iter_mut()
            .zip(unshot.iter_mut())
            .zip(b.chunks_exact(3))
            .zip(u.chunks_exact(3))
        {
            *t += power(b) * area;
            *s += power_f32(u) * area;
        }
    }
}

/// Per group, the sum over patches in patch order (so the same on any number of threads).
fn group_sums(per_patch: &[f64], k: usize) -> Vec<f64> {
    let mut out = vec![0.0; k];
    for chunk in per_patch.chunks_exact(k) {
        for (o, v) in out.iter_mut().zip(chunk) {
            *o += v;
        }
    }
    out
}

/// Shoots D = start − old (or the given unshot part) of every group (module doc) with
/// reflectance `rho` (per element); `patch_links` are the links read when a patch is shot
/// ([`SourceRows::patch_links`]); `leaves` says whether the groups hold their start or the
/// scratch does. Returns each group's radiosity per element and its convergence rows (and what
/// is left unshot, where asked).
#[allow(clippy::too_many_arguments)]
pub(super) fn shoot(
    topology: &Topology,
    rows: &SourceRows,
    rho: &[Rgb],
    groups: Vec<ShotGroup<'_>>,
    leaves: Leaves,
    stop: &StopRule,
    patch_links: &[u64],
    scratch: &mut ShootScratch,
) -> Vec<Shot> {
    // The per-patch passes run with the number of groups known at compile time (their loops
    // over a node's or an element's values then unroll); more than four groups take the loops
    // with the number read at run time.
    let run = match groups.len() {
        1 => shoot_k::<1>,
        2 => shoot_k::<2>,
        3 => shoot_k::<3>,
        4 => shoot_k::<4>,
        _ => shoot_k::<0>,
    };
    run(
        topology,
        rows,
        rho,
        groups,
        leaves,
        stop,
        patch_links,
        scratch,
    )
}

/// The number of light groups of a shooting compiled for `K` groups (`K` = 0: `k`, read at run
/// time).
#[inline(always)]
fn groups_of<const K: usize>(k: usize) -> usize {
    if K == 0 { k } else { K }
}

/// [`shoot`] for `K` groups (0: any number).
#[allow(clippy::too_many_lines, clippy::too_many_arguments)]
fn shoot_k<const K: usize>(
    topology: &Topology,
    rows: &SourceRows,
    rho: &[Rgb],
    groups: Vec<ShotGroup<'_>>,
    leaves: Leaves,
    stop: &StopRule,
    patch_links: &[u64],
    scratch: &mut ShootScratch,
) -> Vec<Shot> {
    let k = groups_of::<K>(groups.len());
    debug_assert_eq!(k, groups.len(), "shoot_k runs for its number of groups");
    let stride = 3 * k;
    let simd = simd_token();
    let n_el = topology.areas.len();
    let n_nodes = topology.element.len();
    let node_element = |n: usize| topology.element[n];
    let areas = &topology.areas;
    let area_sum: f64 = areas.iter().sum();
    let patches = &topology.patch_ranges;
    let filled = leaves == Leaves::Filled;
    let ShootScratch { b, u, un, acc, .. } = scratch;
    assert!(
        !filled || (b.len() == n_el * stride && u.len() == n_el * stride),
        "filled leaves hold every group's values for every element"
    );
    b.resize(n_el * stride, 0.0);
    u.resize(n_el * stride, 0.0);
    let (b, u): (&mut [f64], &mut [f32]) = (b, u);
    un.resize(n_nodes * stride, 0.0);
    acc.resize(n_nodes * stride, 0.0);
    // Leaves: B and the unshot part, `stride` values per element (group-major within), unless
    // filled already, and the patches' powers; patch by patch in parallel.
    let mut powers = PatchPowers {
        total: vec![0.0; patches.len() * k],
        unshot: vec![0.0; patches.len() * k],
    };
    let blocks = patch_blocks(topology);
    blocks
        .par_iter()
        .zip(block_leaves(&blocks, stride, k, b, u, &mut powers))
        .for_each(|(block, mut leaves)| {
            let stride = 3 * groups_of::<K>(k);
            let BlockLeaves { b, u, .. } = &mut leaves;
            let copied = if filled {
                0..0
            } else {
                block.elements.0..block.elements.1
            };
            for (i, e) in copied.enumerate() {
                for (g, group) in groups.iter().enumerate() {
                    let s = group.start[e];
                    if let Some(given) = &group.unshot {
                        for c in 0..3 {
                            let j = i * stride + 3 * g + c;
                            b[j] = s[c];
                            #[allow(clippy::cast_possible_truncation)]
                            {
                                u[j] = given[e][c] as f32;
                            }
                        }
                        continue;
                    }
                    let o = group.old[e];
                    for c in 0..3 {
                        let j = i * stride + 3 * g + c;
                        b[j] = s[c];
                        // Bit-equal values have nothing to pass on (D = 0 exactly, not a
                        // rounding).
                        #[allow(clippy::cast_possible_truncation)]
                        {
                            u[j] = if s[c].to_bits() == o[c].to_bits() {
                                0.0
                            } else {
                                (s[c] - o[c]) as f32
                            };
                        }
                    }
                }
            }
            for p in block.patches.0..block.patches.1 {
                leaves.sum_powers::<K>(topology, block, p);
            }
        });
    let mut out_rows: Vec<Vec<ConvergenceRow>> = vec![Vec::new(); k];
    let mut total = group_sums(&powers.total, k);
    let mut previous_mean: Vec<f64> = total.iter().map(|t| t / area_sum).collect();
    // Per group, the unshot power a round sends back as unshot power per unit shot (measured
    // after each round; 1 until then, so the first round is never taken for the last).
    let mut bounce = vec![1.0; k];
    for pass in 1..=stop.max_passes {
        let unshot = group_sums(&powers.unshot, k);
        if unshot.iter().all(|&v| v <= 0.0) {
            break;
        }
        let shot_now = choose_patches(&powers.unshot, &unshot, &total, &bounce, patch_links, stop);
        let before = powers.unshot.clone();
        // Node values of the unshot part of every shot patch (leaves up), then clear its leaves;
        // patch by patch in parallel (each writes only its own nodes and elements).
        let (un_parts, u_parts) = (
            split_blocks(&blocks, |b| b.nodes, stride, un),
            split_blocks(&blocks, |b| b.elements, stride, u),
        );
        let active_per_block: Vec<Vec<usize>> = blocks
            .par_iter()
            .zip(un_parts)
            .zip(u_parts)
            .map(|((block, un), u)| {
                let stride = 3 * groups_of::<K>(k);
                let (n0, e0) = (block.nodes.0, block.elements.0);
                let mut active = Vec::new();
                for p in block.patches.0..block.patches.1 {
                    if !shot_now[p] {
                        continue;
                    }
                    let (lo, hi) = patches[p];
                    for n in (lo..hi).rev() {
                        let (head, tail) = un.split_at_mut((n - n0 + 1) * stride);
                        let own = &mut head[(n - n0) * stride..];
                        if let Some(e) = node_element(n) {
                            let e = e as usize - e0;
                            own.copy_from_slice(&u[e * stride..(e + 1) * stride]);
                            u[e * stride..(e + 1) * stride].fill(0.0);
                        } else {
                            own.fill(0.0);
                            for kid in topology.children[n].into_iter().flatten() {
                                let kid = kid as usize;
                                #[allow(clippy::cast_possible_truncation)]
                                let w = topology.weight[kid] as f32;
                                let kid_vals = &tail[(kid - n - 1) * stride..(kid - n) * stride];
                                for (o, v) in own.iter_mut().zip(kid_vals) {
                                    *o += w * v;
                                }
                            }
                        }
                    }
                    active.extend((lo..hi).filter(|&n| {
                        un[(n - n0) * stride..(n - n0 + 1) * stride]
                            .iter()
                            .any(|&v| v != 0.0)
                    }));
                }
                active
            })
            .collect();
        // Patches follow one another in node order, so the active nodes come out sorted: each
        // range task walks its arrays forwards.
        let active: Vec<usize> = active_per_block.into_iter().flatten().collect();
        debug_assert!(active.is_sorted());
        let interactions: u64 = active.iter().map(|&n| rows.row_len(n)).sum();
        // Each receiver range gathers on its own task; a receiver's sum runs over the shot
        // nodes in node order and each run in receiver order, as one thread would.
        let mut ranges: Vec<(usize, &mut [f32])> = Vec::with_capacity(rows.ranges());
        let mut rest: &mut [f32] = acc;
        for r in 0..rows.ranges() {
            let (lo, hi) = (rows.bounds[r] as usize, rows.bounds[r + 1] as usize);
            let (chunk, tail) = std::mem::take(&mut rest).split_at_mut((hi - lo) * stride);
            ranges.push((r, chunk));
            rest = tail;
        }
        let t = simd;
        let un: &[f32] = un;
        ranges.into_par_iter().for_each(|(r, chunk)| match stride {
            3 => gather_range::<3>(rows, r, &active, un, chunk, t),
            6 => gather_range::<6>(rows, r, &active, un, chunk, t),
            9 => gather_range::<9>(rows, r, &active, un, chunk, t),
            12 => gather_range::<12>(rows, r, &active, un, chunk, t),
            _ => gather_range_dyn(rows, r, &active, un, chunk, stride),
        });
        // Push what every node gathered down to its leaves: ΔB = ρ′·G, added and unshot; then
        // clear the patch's gathers and sum its powers. Patch by patch in parallel (each writes
        // only its own nodes, elements and powers).
        blocks
            .par_iter()
            .zip(split_blocks(&blocks, |b| b.nodes, stride, acc))
            .zip(block_leaves(&blocks, stride, k, b, u, &mut powers))
            .for_each(|((block, acc), mut leaves)| {
                let stride = 3 * groups_of::<K>(k);
                let (n0, e0) = (block.nodes.0, block.elements.0);
                for p in block.patches.0..block.patches.1 {
                    let (lo, hi) = patches[p];
                    let acc = &mut acc[(lo - n0) * stride..(hi - n0) * stride];
                    // A patch that gathered nothing (every value ±0) keeps B and its unshot
                    // part; its powers change only if it was shot (its unshot part cleared).
                    let gathered = acc.iter().any(|&v| v != 0.0);
                    if gathered {
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
                                let (e, el) = (e as usize, e as usize - e0);
                                for j in 0..stride {
                                    let db = rho[e][j % 3] * f64::from(acc[(n - lo) * stride + j]);
                                    leaves.b[el * stride + j] += db;
                                    #[allow(clippy::cast_possible_truncation)]
                                    {
                                        leaves.u[el * stride + j] += db as f32;
                                    }
                                }
                            }
                        }
                        acc.fill(0.0);
                    }
                    if gathered || shot_now[p] {
                        leaves.sum_powers::<K>(topology, block, p);
                    }
                }
            });
        total = group_sums(&powers.total, k);
        let unshot_after = group_sums(&powers.unshot, k);
        let mut all_met = true;
        for g in 0..k {
            // What the round sent back, per unit it shot (the estimate for the next round).
            let (mut shot, mut left) = (0.0, 0.0);
            for (p, &now) in shot_now.iter().enumerate() {
                if now {
                    shot += before[p * k + g];
                } else {
                    left += before[p * k + g];
                }
            }
            if shot > 0.0 {
                bounce[g] = ((unshot_after[g] - left) / shot).clamp(0.0, 1.0);
            }
            let mean = total[g] / area_sum;
            let row = ConvergenceRow {
                group: groups[g].name.to_owned(),
                pass,
                residual: if total[g] > 0.0 {
                    unshot_after[g] / total[g]
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
    let (total, unshot) = (group_sums(&powers.total, k), group_sums(&powers.unshot, k));
    // The results go into the groups' own buffers (no fresh pages), in one parallel pass over
    // fixed chunks of elements: a chunk of B and of the unshot part is read for every group
    // while it is in cache, not once per group and buffer.
    let mut shots: Vec<Shot> = groups
        .into_iter()
        .zip(out_rows)
        .enumerate()
        .map(|(g, (group, rows))| {
            let mut radiosity = group.start;
            radiosity.resize(n_el, [0.0; 3]);
            let kept = group.keep_unshot.then(|| {
                let mut unshot = group.unshot.unwrap_or_default();
                unshot.resize(n_el, [0.0; 3]);
                unshot
            });
            Shot {
                radiosity,
                rows,
                unshot: kept,
                powers: [total[g], unshot[g]],
            }
        })
        .collect();
    let (b, u): (&[f64], &[f32]) = (b, u);
    // Per chunk, its part of every output: (group, read from the unshot part, the part).
    let mut chunks: Vec<Vec<(usize, bool, &mut [Rgb])>> = (0..n_el.div_ceil(READ_CHUNK))
        .map(|_| Vec::with_capacity(2 * k))
        .collect();
    for (g, shot) in shots.iter_mut().enumerate() {
        for (c, part) in shot.radiosity.chunks_mut(READ_CHUNK).enumerate() {
            chunks[c].push((g, false, part));
        }
        let kept = shot
            .unshot
            .iter_mut()
            .flat_map(|v| v.chunks_mut(READ_CHUNK));
        for (c, part) in kept.enumerate() {
            chunks[c].push((g, true, part));
        }
    }
    chunks.into_par_iter().enumerate().for_each(|(c, parts)| {
        for (g, from_unshot, part) in parts {
            for (i, o) in part.iter_mut().enumerate() {
                let at = (c * READ_CHUNK + i) * stride + 3 * g;
                *o = if from_unshot {
                    [u[at], u[at + 1], u[at + 2]].map(f64::from)
                } else {
                    [b[at], b[at + 1], b[at + 2]]
                };
            }
        }
    });
    shots
}

/// Elements per chunk of [`shoot`]'s read-out.
const READ_CHUNK: usize = 2048;

/// Safety factor on a group's measured bounce when a round is planned as the last.
const BOUNCE_MARGIN: f64 = 1.25;
/// What a round that is not the last may leave unshot, as a fraction of what it started with.
const EARLY_LEFT: f64 = 0.05;
/// What a last round aims to leave unshot, as a fraction of the stop rule's residual.
const LAST_ROUND_TARGET: f64 = 0.9;

/// The patches a round shoots (module doc). `patch_unshot`: unshot power per patch and group;
/// `unshot`, `total`: per group; `bounce`: per group, unshot power a round sends back per unit
/// it shoots; `patch_links`: links read per patch.
///
/// When one round can leave every group below the residual (its unshot power times its bounce,
/// with [`BOUNCE_MARGIN`], under [`LAST_ROUND_TARGET`] × residual), the round shoots the patches
/// with the most of each group's still needed power per link read, until every group's need is
/// met. Otherwise it shoots the patches with the most unshot power (relative to each group's
/// total) per link read until what is left is at most [`EARLY_LEFT`] of what there was, or half
/// the residual.
fn choose_patches(
    patch_unshot: &[f64],
    unshot: &[f64],
    total: &[f64],
    bounce: &[f64],
    patch_links: &[u64],
    stop: &StopRule,
) -> Vec<bool> {
    let k = unshot.len();
    let n = patch_links.len();
    let scale: Vec<f64> = total
        .iter()
        .map(|&t| if t > 0.0 { 1.0 / t } else { 0.0 })
        .collect();
    let target = LAST_ROUND_TARGET * stop.residual;
    let back: Vec<f64> = bounce
        .iter()
        .map(|b| (b * BOUNCE_MARGIN).min(1.0))
        .collect();
    let last = (0..k).all(|g| back[g] * unshot[g] * scale[g] <= target);
    let mut shot = vec![false; n];
    if last {
        // Power still to shoot per group: u − s + b·s ≤ target.
        let mut need: Vec<f64> = (0..k)
            .map(|g| {
                let u = unshot[g] * scale[g];
                if u <= target {
                    0.0
                } else {
                    (u - target) / (1.0 - back[g])
                }
            })
            .collect();
        let weight: Vec<f64> = need
            .iter()
            .map(|&v| if v > 0.0 { 1.0 / v } else { 0.0 })
            .collect();
        #[allow(clippy::cast_precision_loss)] // link counts far below 2^52
        let worth: Vec<f64> = (0..n)
            .map(|p| {
                let gain: f64 = (0..k)
                    .map(|g| weight[g] * patch_unshot[p * k + g] * scale[g])
                    .sum();
                gain / patch_links[p].max(1) as f64
            })
            .collect();
        for p in best_first(&worth) {
            if need.iter().all(|&v| v <= 0.0) {
                break;
            }
            shot[p] = true;
            for g in 0..k {
                need[g] -= patch_unshot[p * k + g] * scale[g];
            }
        }
        return shot;
    }
    let score: Vec<f64> = (0..n)
        .map(|p| (0..k).map(|g| patch_unshot[p * k + g] * scale[g]).sum())
        .collect();
    let mut left: f64 = score.iter().sum();
    let keep = (EARLY_LEFT * left).max(0.5 * stop.residual);
    #[allow(clippy::cast_precision_loss)] // link counts far below 2^52
    let worth: Vec<f64> = (0..n)
        .map(|p| score[p] / patch_links[p].max(1) as f64)
        .collect();
    for p in best_first(&worth) {
        if left <= keep {
            break;
        }
        left -= score[p];
        shot[p] = true;
    }
    shot
}

/// The patches of positive `worth`, best first, ties broken by the patch index (a strict total
/// order, so the unstable sort gives the one order a stable sort would). Sorted on one key per
/// patch, not through the indices: a positive `f64`'s bits rise with its value, so the key
/// (`u64::MAX` − bits, index) orders by falling worth, then rising index.
fn best_first(worth: &[f64]) -> impl Iterator<Item = usize> {
    let mut keys: Vec<(u64, u32)> = worth
        .iter()
        .enumerate()
        .filter(|&(_, &w)| w > 0.0)
        .map(|(p, &w)| {
            let p = u32::try_from(p).expect("patch indices fit in u32");
            (u64::MAX - w.to_bits(), p)
        })
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|(_, p)| p as usize)
}

#[path = "shooting_blocks.rs"]
mod blocks;

#[cfg(test)]
mod tests {
    use super::best_first;
    use proptest::prelude::*;

    proptest! {
        /// The keyed sort gives the order of the comparator it replaced: falling worth, ties by
        /// rising index, patches of no worth left out (mutation checked: the key without
        /// `u64::MAX −` fails it).
        #[test]
        fn best_first_orders_as_the_comparator(
            worth in prop::collection::vec(
                prop_oneof![Just(0.0), Just(0.25), Just(1.0), 1e-300..1e3_f64, -1.0..0.0_f64],
                0..200,
            )
        ) {
            let mut order: Vec<usize> = (0..worth.len()).filter(|&p| worth[p] > 0.0).collect();
            order.sort_by(|&a, &c| worth[c].total_cmp(&worth[a]).then(a.cmp(&c)));
            prop_assert_eq!(best_first(&worth).collect::<Vec<_>>(), order);
        }
    }
}
