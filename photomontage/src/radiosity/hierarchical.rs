//! Hierarchical radiosity (Hanrahan, Salzman & Aupperle 1991; Cohen & Wallace, seed 002, ch. 7)
//! with BF refinement.
//!
//! The hierarchy is the mesh's quadtree from the patches (roots) down to the elements (leaves).
//! A **link** r ← s lets node r gather F_rs·B_s from node s. Initial linking (HSA91 `Refine`):
//! for every ordered pair of facing patches, the cheap centroid estimate of F_rs (unoccluded,
//! [`FormFactorEngine::centroid_estimate`]) decides: below [`HierarchicalParams::form_factor_tolerance`]
//! (or both leaves) the pair is linked, otherwise the larger of the two is split and its
//! children are tried. Every link then gets the accurate factor with visibility.
//!
//! A pass is one Jacobi step on the links (gather into every node, then push–pull: a node's
//! gathered radiosity is passed down to its leaves, B_leaf = B₀ + ρ·G, and parents take the
//! area-weighted mean of their children). Between passes, BF refinement (HSA91 §4): a link whose
//! transport ρ_r·B_s·F_rs exceeds [`HierarchicalParams::bf_tolerance`] × the mean brightness is
//! replaced by links to the children of the larger node (one level per pass); F_rs there is the
//! larger of the link's factor and its unoccluded centroid estimate, so that a link whose few
//! samples were all shadowed is still refined where its children may see each other. The links are
//! refined with the sum of all light groups (the [`Hierarchy`] is geometry plus the lighting it
//! was refined for); every group is then solved on the same links, so group solutions add up
//! exactly to the solution of the summed sources.
//!
//! On a mesh refined at corners ([`super::MeshParams::corner_element_m`]) the test takes the
//! largest unoccluded point factor over the receiver (its centroid and corners,
//! [`FormFactorEngine::largest_estimate`]) instead of the centroid's: next to a contact (a
//! wall's foot) a receiver's far end sees a source small that its near end sees under up to
//! half its hemisphere, and the centroid's estimate let such links stay coarse, handing the far
//! leaves the near end's light. On the closed-form wall foot of `corner_refinement_tests` the
//! corner elements came out up to +30 % (1–2 cm from the foot) and +8 % (5 cm) with the
//! centroid test, +5 % at 5 cm with this one; it costs ~20 % more links on the Cornell box and
//! the courtyard, which is why meshes without corner refinement (whose leaves near a contact are
//! large enough to average the error away) keep the centroid test.
//!
//! When refinement is over, links whose factor is exactly 0 (all samples occluded) are dropped:
//! they add nothing to any later gather.
//!
//! Links are kept grouped by receiver in a fixed order and each factor has its own random
//! stream, so results are bit-identical on any number of threads.
//!
//! # Known limitations
//! Refinement never removes links (no coarsening when a group is dimmed); a link's factor is the
//! mean over the receiver node, so radiosity varies only at the element level (constant
//! elements, no higher-order bases). Links between nodes of the same scene triangle do not exist
//! (coplanar).

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::convergence::{ConvergenceRow, StopRule, mean_brightness, relative_change};
use super::form_factor::{FormFactorEngine, in_front};
use super::mesh::Mesh;
use super::twin_factors::FactorReuse;
use super::{RadiosityError, Rgb, luminance};

/// An upper bound of an unoccluded point-to-triangle factor with round-off: the exact factor is
/// at most 1 (the clipped triangle's gnomonic image is a convex spherical polygon, whose
/// projected solid angle is at most π); its computed value errs by ~1e-15.
const ESTIMATE_BOUND: f64 = 1.0 + 1e-6;

/// A link's estimate not yet computed (factors are ≥ 0).
const UNKNOWN: f64 = -1.0;

/// Hierarchical-solver tunables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HierarchicalParams {
    /// Initial linking: split while the centroid estimate of F_rs is above this.
    pub form_factor_tolerance: f64,
    /// BF refinement: split a link while ρ_r·B_s·F_rs is above this fraction of the mean
    /// brightness (0 refines every link down to the elements).
    pub bf_tolerance: f64,
    /// Most links kept (refinement stops at this budget).
    pub max_links: usize,
}

impl Default for HierarchicalParams {
    /// F_ε = 0.05, BF ε = 0.002 × mean brightness, at most 5 million links.
    fn default() -> Self {
        Self {
            form_factor_tolerance: 0.05,
            bf_tolerance: 0.002,
            max_links: 5_000_000,
        }
    }
}

/// A gathering link: `receiver` gathers `form_factor` · B(`source`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// Receiving node.
    pub receiver: u32,
    /// Sending node.
    pub source: u32,
    /// F_{receiver → source}.
    pub form_factor: f64,
}

impl Link {
    /// (receiver, source, F).
    #[must_use]
    pub fn triple(&self) -> (u32, u32, f64) {
        (self.receiver, self.source, self.form_factor)
    }
}

/// The links of a refined hierarchy.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    /// Links, sorted by receiver (stable, so in a deterministic order).
    pub links: Vec<Link>,
    /// Convergence of the refinement solve (group "refine").
    pub refinement: Vec<ConvergenceRow>,
}

fn is_leaf(mesh: &Mesh, n: u32) -> bool {
    mesh.nodes[n as usize].children.is_none()
}

fn area(mesh: &Mesh, n: u32) -> f64 {
    mesh.nodes[n as usize].area_m2
}

/// Which side of (r, s) to split: `true` for the receiver. `None` when both are leaves.
fn split_receiver(mesh: &Mesh, r: u32, s: u32) -> Option<bool> {
    match (is_leaf(mesh, r), is_leaf(mesh, s)) {
        (true, true) => None,
        (true, false) => Some(false),
        (false, true) => Some(true),
        (false, false) => Some(area(mesh, r) >= area(mesh, s)),
    }
}

fn children(mesh: &Mesh, n: u32) -> [u32; 4] {
    mesh.nodes[n as usize].children.unwrap_or([n; 4])
}

/// HSA91 `Refine` for one ordered pair, with the cheap oracle; appends (r, s) pairs.
fn initial_pairs(
    engine: &FormFactorEngine<'_>,
    tolerance: f64,
    r: u32,
    s: u32,
    out: &mut Vec<(u32, u32)>,
) {
    let mesh = engine.mesh();
    if !engine.facing(r, s) {
        return;
    }
    let split = if engine.centroid_estimate(r, s) <= tolerance {
        None
    } else {
        split_receiver(mesh, r, s)
    };
    match split {
        None => out.push((r, s)),
        Some(true) => {
            for c in children(mesh, r) {
                initial_pairs(engine, tolerance, c, s, out);
            }
        }
        Some(false) => {
            for c in children(mesh, s) {
                initial_pairs(engine, tolerance, r, c, out);
            }
        }
    }
}

/// The links of `pairs` with their accurate factors: read from the natural solve where `reuse`
/// has them (the same value, [`super::twin_factors`]), else computed.
fn accurate_links(
    engine: &FormFactorEngine<'_>,
    pairs: &[(u32, u32)],
    reuse: Option<&FactorReuse<'_>>,
) -> Vec<Link> {
    pairs
        .par_iter()
        .map(|&(r, s)| Link {
            receiver: r,
            source: s,
            form_factor: reuse
                .and_then(|u| u.factor(engine, r, s))
                .unwrap_or_else(|| engine.node_to_node(r, s)),
        })
        .collect()
}

/// What the BF test of [`Hierarchy::refine_bf`] found for one link: whether it is split, its
/// unoccluded estimate, and the (receiver, source) pairs that replace it.
type LinkTest = (bool, f64, Vec<(u32, u32)>);

/// Per-node state of a solve.
struct State {
    /// B per node (leaves: solution; inner nodes: area-weighted mean of their leaves).
    b: Vec<Rgb>,
}

impl Hierarchy {
    /// Links the patches and refines the links by BF for the summed initial exitance `b0_all`
    /// (per element), iterating until no link is refined and the stop rule holds.
    ///
    /// # Errors
    /// Invalid parameters, [`RadiosityError::Cancelled`].
    pub fn build(
        engine: &FormFactorEngine<'_>,
        params: &HierarchicalParams,
        b0_all: &[Rgb],
        stop: &StopRule,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
    ) -> Result<Self, RadiosityError> {
        Self::build_reusing(engine, params, b0_all, stop, cancel, on_pass, None)
            .map(|(hierarchy, _)| hierarchy)
    }

    /// [`Hierarchy::build`] reading the factors `reuse` has from the natural solve
    /// ([`super::twin_factors`]; the same links as computing them all, when `engine` names its
    /// streams after the twins); also returns every link whose factor it computed or read
    /// (refined and dropped ones too), for a later solve beside this one.
    ///
    /// # Errors
    /// As [`Hierarchy::build`].
    pub(super) fn build_reusing(
        engine: &FormFactorEngine<'_>,
        params: &HierarchicalParams,
        b0_all: &[Rgb],
        stop: &StopRule,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
        reuse: Option<&FactorReuse<'_>>,
    ) -> Result<(Self, Vec<Link>), RadiosityError> {
        stop.validate()?;
        for (name, value) in [
            ("form_factor_tolerance", params.form_factor_tolerance),
            ("bf_tolerance", params.bf_tolerance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(RadiosityError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and ≥ 0",
                });
            }
        }
        let mesh = engine.mesh();
        let patches = &mesh.patches;
        // Every pair of patches is tested for facing first on a compact copy of their
        // triangles, read in order: the nodes themselves lie far apart (each patch before its
        // subtree), and fetching them for every pair cost more than the test.
        let shapes: Vec<([Point3<f64>; 3], Vector3<f64>)> = patches
            .iter()
            .map(|&p| {
                let node = &mesh.nodes[p as usize];
                (node.vertices_in_world_m, node.normal_in_world)
            })
            .collect();
        let pair_lists: Vec<Option<Vec<(u32, u32)>>> = patches
            .par_iter()
            .zip(&shapes)
            .map(|(&r, (r_vertices, r_normal))| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let mut out = Vec::new();
                for (&s, (s_vertices, s_normal)) in patches.iter().zip(&shapes) {
                    // The same test as `FormFactorEngine::facing`, which `initial_pairs`
                    // repeats for the pairs that pass.
                    if r == s
                        || !in_front(r_vertices, r_normal, s_vertices)
                        || !in_front(s_vertices, s_normal, r_vertices)
                    {
                        continue;
                    }
                    initial_pairs(engine, params.form_factor_tolerance, r, s, &mut out);
                }
                Some(out)
            })
            .collect();
        let mut pairs = Vec::new();
        for list in pair_lists {
            pairs.extend(list.ok_or(RadiosityError::Cancelled)?);
        }
        let mut hierarchy = Self {
            links: accurate_links(engine, &pairs, reuse),
            refinement: Vec::new(),
        };
        let mut computed = hierarchy.links.clone();
        hierarchy.sort();
        // Per link, its unoccluded estimate once computed (`UNKNOWN` before): a pure function of
        // the link's nodes, kept between the refinement passes.
        let mut estimates = vec![UNKNOWN; hierarchy.links.len()];
        let mut state = State {
            b: initial_node_b(mesh, b0_all),
        };
        let mut previous_mean = None;
        for pass in 1..=stop.max_passes {
            if cancel.load(Ordering::Relaxed) {
                return Err(RadiosityError::Cancelled);
            }
            let update = hierarchy.pass(mesh, b0_all, &mut state);
            let (row, mean) = hierarchy.row("refine", pass, mesh, &state, update, previous_mean);
            previous_mean = Some(mean);
            on_pass(&row);
            let refined = if hierarchy.links.len() < params.max_links {
                hierarchy.refine_bf(
                    engine,
                    params,
                    &state,
                    mean,
                    &mut estimates,
                    reuse,
                    &mut computed,
                )
            } else {
                0
            };
            let done = refined == 0 && (stop.met(&row) || mean <= 0.0);
            hierarchy.refinement.push(row);
            if done {
                break;
            }
        }
        hierarchy.drop_occluded();
        Ok((hierarchy, computed))
    }

    /// Drops, once refinement is over, the links whose factor is exactly 0 (every sample pair
    /// occluded): they add nothing to any later gather, so every solve and relight gives the
    /// same sums without reading them. On the city block of the relight benches they are 63 %
    /// of the links (walls and ground hidden from each other by the buildings). Refinement
    /// itself still sees them: its test uses the unoccluded estimate, so a shadowed link can
    /// still be split. (Dropping *weak* links as well was tried and rejected: a budget on F
    /// alone drops the links to small, bright sources — a lamp's emitting patch — and took 6 %
    /// off the Cornell box's patch means.)
    fn drop_occluded(&mut self) {
        self.links.retain(|l| l.form_factor != 0.0);
    }

    fn sort(&mut self) {
        self.links.sort_by_key(|l| l.receiver);
    }

    /// Replaces links failing the BF test by links to the children of the larger node; returns
    /// how many were replaced. The test of each link reads that link alone, so the links are
    /// tested in parallel and then rebuilt in their order: the same links on any number of
    /// threads.
    #[allow(clippy::too_many_arguments)]
    fn refine_bf(
        &mut self,
        engine: &FormFactorEngine<'_>,
        params: &HierarchicalParams,
        state: &State,
        mean: f64,
        estimates: &mut Vec<f64>,
        reuse: Option<&FactorReuse<'_>>,
        computed: &mut Vec<Link>,
    ) -> usize {
        let mesh = engine.mesh();
        let threshold = params.bf_tolerance * mean;
        // Per link: whether it is split, its estimate, and the facing child pairs that replace
        // it (found here, in parallel, in the order the serial loop below would find them).
        let tests: Vec<LinkTest> = self
            .links
            .par_iter()
            .zip(estimates.par_iter())
            .map(|(link, &known)| {
                let rho = mesh.reflectance_rgb(link.receiver as usize);
                let bs = &state.b[link.source as usize];
                let rho_b = (0..3).map(|c| rho[c] * bs[c]).fold(0.0, f64::max);
                // The transport ρ·B·max(F, estimate) > threshold, as max(ρ·B·F, ρ·B·estimate)
                // (a product of non-negative factors is monotone, so the two are equal bit for
                // bit). A link whose samples were all occluded may still be partly visible from
                // its children: the test uses the unoccluded centroid estimate as well (on a
                // mesh refined at corners, the largest point factor over the receiver: module
                // doc). The estimate, the costly part, is computed only when ρ·B·F alone does
                // not decide and a point factor (≤ 1; [`ESTIMATE_BOUND`] with round-off) could,
                // and only once per link.
                let over = |f: f64| rho_b * f > threshold;
                let mut estimate = known;
                let split_needed = over(link.form_factor)
                    || (over(ESTIMATE_BOUND) && {
                        if estimate == UNKNOWN {
                            estimate = if mesh.corner_refined {
                                engine.largest_estimate(link.receiver, link.source)
                            } else {
                                engine.centroid_estimate(link.receiver, link.source)
                            };
                        }
                        over(estimate)
                    });
                let split = if split_needed {
                    split_receiver(mesh, link.receiver, link.source)
                } else {
                    None
                };
                let pairs = match split {
                    None => Vec::new(),
                    Some(true) => children(mesh, link.receiver)
                        .into_iter()
                        .filter(|&c| engine.facing(c, link.source))
                        .map(|c| (c, link.source))
                        .collect(),
                    Some(false) => children(mesh, link.source)
                        .into_iter()
                        .filter(|&c| engine.facing(link.receiver, c))
                        .map(|c| (link.receiver, c))
                        .collect(),
                };
                (split.is_some(), estimate, pairs)
            })
            .collect();
        let mut keep = Vec::with_capacity(self.links.len());
        let mut kept_estimates = Vec::with_capacity(self.links.len());
        let mut new_pairs = Vec::new();
        let mut refined = 0;
        for (link, (split, estimate, pairs)) in self.links.iter().zip(tests) {
            if split {
                refined += 1;
                new_pairs.extend(pairs);
            } else {
                keep.push(*link);
                kept_estimates.push(estimate);
            }
        }
        if refined > 0 {
            let mut new_links = accurate_links(engine, &new_pairs, reuse);
            computed.extend_from_slice(&new_links);
            // By receiver, as `sort`, with each link's estimate beside it: the kept links are
            // in receiver order already, so the new ones are sorted (stably) and merged after
            // the kept ones of the same receiver — the order a stable sort of the kept links
            // followed by the new ones gives.
            new_links.par_sort_by_key(|l| l.receiver);
            let (links, merged_estimates) = merge_by_receiver(keep, kept_estimates, new_links);
            self.links = links;
            *estimates = merged_estimates;
        } else {
            *estimates = kept_estimates;
        }
        refined
    }

    /// One Jacobi pass: gather over the links, push–pull; returns Σ A·|ΔB|_Y over leaves.
    fn pass(&self, mesh: &Mesh, b0: &[Rgb], state: &mut State) -> f64 {
        let mut gathered = vec![[0.0; 3]; mesh.nodes.len()];
        // Links are sorted by receiver: gather each receiver's run in parallel, in order.
        let runs: Vec<&[Link]> = self
            .links
            .chunk_by(|a, b| a.receiver == b.receiver)
            .collect();
        let sums: Vec<(u32, Rgb)> = runs
            .par_iter()
            .map(|run| {
                let mut g = [0.0; 3];
                for l in *run {
                    let bs = &state.b[l.source as usize];
                    for c in 0..3 {
                        g[c] += l.form_factor * bs[c];
                    }
                }
                (run[0].receiver, g)
            })
            .collect();
        for (r, g) in sums {
            gathered[r as usize] = g;
        }
        let mut new_b = state.b.clone();
        // Each patch's subtree is its own run of nodes (`Mesh::add_subtree` numbers them in
        // preorder): the patches are pushed and pulled in parallel, each writing its run, and
        // their updates summed in patch order (the same sum on any number of threads).
        let runs = patch_runs(&mesh.patches, &mut new_b);
        let updates: Vec<f64> = runs
            .into_par_iter()
            .map(|(p, run)| {
                let mut update = 0.0;
                push_pull(
                    mesh,
                    p,
                    [0.0; 3],
                    &gathered,
                    b0,
                    &mut NodeRun {
                        first: p,
                        values: run,
                    },
                    &state.b,
                    &mut update,
                );
                update
            })
            .collect();
        state.b = new_b;
        updates.iter().sum()
    }

    fn row(
        &self,
        group: &str,
        pass: u32,
        mesh: &Mesh,
        state: &State,
        update: f64,
        previous_mean: Option<f64>,
    ) -> (ConvergenceRow, f64) {
        let leaves = leaf_b(mesh, &state.b);
        let areas: Vec<f64> = mesh
            .elements
            .iter()
            .map(|&n| mesh.nodes[n as usize].area_m2)
            .collect();
        let mean = mean_brightness(&leaves, &areas);
        let total: f64 = leaves
            .iter()
            .zip(&areas)
            .map(|(v, a)| luminance(v) * a)
            .sum();
        (
            ConvergenceRow {
                group: group.to_owned(),
                pass,
                residual: if total > 0.0 { update / total } else { 0.0 },
                mean_change: relative_change(previous_mean, mean),
                mean_brightness: mean,
                interactions: self.links.len() as u64,
            },
            mean,
        )
    }

    /// Solves one light group on the fixed links: Jacobi passes until the stop rule holds.
    /// Returns the radiosity per element and the convergence rows.
    ///
    /// # Errors
    /// Invalid stop rule, [`RadiosityError::Cancelled`].
    pub fn solve(
        &self,
        mesh: &Mesh,
        b0: &[Rgb],
        group: &str,
        stop: &StopRule,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
    ) -> Result<(Vec<Rgb>, Vec<ConvergenceRow>), RadiosityError> {
        stop.validate()?;
        let mut state = State {
            b: initial_node_b(mesh, b0),
        };
        let mut rows = Vec::new();
        let mut previous_mean = None;
        for pass in 1..=stop.max_passes {
            if cancel.load(Ordering::Relaxed) {
                return Err(RadiosityError::Cancelled);
            }
            let update = self.pass(mesh, b0, &mut state);
            let (row, mean) = self.row(group, pass, mesh, &state, update, previous_mean);
            previous_mean = Some(mean);
            on_pass(&row);
            let done = stop.met(&row) || mean <= 0.0;
            rows.push(row);
            if done {
                break;
            }
        }
        Ok((leaf_b(mesh, &state.b), rows))
    }
}

/// B per node from per-element values: leaves take theirs, parents the area-weighted mean.
fn initial_node_b(mesh: &Mesh, b0: &[Rgb]) -> Vec<Rgb> {
    let mut b = vec![[0.0; 3]; mesh.nodes.len()];
    for &p in &mesh.patches {
        pull(mesh, p, b0, &mut b);
    }
    b
}

fn pull(mesh: &Mesh, n: u32, leaf_values: &[Rgb], b: &mut [Rgb]) -> Rgb {
    let node = &mesh.nodes[n as usize];
    let value = match (node.children, node.element) {
        (None, Some(e)) => leaf_values[e as usize],
        (Some(kids), _) => {
            let mut sum = [0.0; 3];
            for k in kids {
                let v = pull(mesh, k, leaf_values, b);
                let w = mesh.nodes[k as usize].area_m2 / node.area_m2;
                for c in 0..3 {
                    sum[c] += w * v[c];
                }
            }
            sum
        }
        (None, None) => [0.0; 3],
    };
    b[n as usize] = value;
    value
}

/// The kept links (`keep`, in receiver order, with their estimates `kept_estimates`) and the
/// new links (`new`, in receiver order) in one receiver order, the kept links first among those
/// of one receiver; the new links' estimates are [`UNKNOWN`].
fn merge_by_receiver(
    keep: Vec<Link>,
    kept_estimates: Vec<f64>,
    new: Vec<Link>,
) -> (Vec<Link>, Vec<f64>) {
    let total = keep.len() + new.len();
    let mut links = Vec::with_capacity(total);
    let mut estimates = Vec::with_capacity(total);
    let mut kept = keep.into_iter().zip(kept_estimates).peekable();
    for l in new {
        while let Some((k, e)) = kept.next_if(|(k, _)| k.receiver <= l.receiver) {
            links.push(k);
            estimates.push(e);
        }
        links.push(l);
        estimates.push(UNKNOWN);
    }
    for (k, e) in kept {
        links.push(k);
        estimates.push(e);
    }
    (links, estimates)
}

/// The node values of one patch's subtree: nodes `first ..` of the mesh.
struct NodeRun<'a> {
    first: u32,
    values: &'a mut [Rgb],
}

/// Splits `b` (per node) into one run per patch of `patches` (in increasing order), from the
/// patch's node to the next patch's; the nodes before the first patch (ancestors above the patch
/// level) are in none.
fn patch_runs<'a>(patches: &[u32], b: &'a mut [Rgb]) -> Vec<(u32, &'a mut [Rgb])> {
    let mut runs = Vec::with_capacity(patches.len());
    let first = patches.first().map_or(b.len(), |&p| p as usize);
    let (_, mut rest) = b.split_at_mut(first);
    for (k, &p) in patches.iter().enumerate() {
        let end = patches.get(k + 1).map_or(rest.len(), |&q| (q - p) as usize);
        let (run, tail) = rest.split_at_mut(end);
        runs.push((p, run));
        rest = tail;
    }
    runs
}

#[allow(clippy::too_many_arguments)]
fn push_pull(
    mesh: &Mesh,
    n: u32,
    down: Rgb,
    gathered: &[Rgb],
    b0: &[Rgb],
    new_b: &mut NodeRun<'_>,
    old_b: &[Rgb],
    update: &mut f64,
) -> Rgb {
    let node = &mesh.nodes[n as usize];
    let g: Rgb = std::array::from_fn(|c| down[c] + gathered[n as usize][c]);
    let value = match (node.children, node.element) {
        (None, Some(e)) => {
            let rho = mesh.reflectance_rgb(n as usize);
            let v: Rgb = std::array::from_fn(|c| b0[e as usize][c] + rho[c] * g[c]);
            let old = old_b[n as usize];
            let diff: Rgb = std::array::from_fn(|c| (v[c] - old[c]).abs());
            *update += luminance(&diff) * node.area_m2;
            v
        }
        (Some(kids), _) => {
            let mut sum = [0.0; 3];
            for k in kids {
                let v = push_pull(mesh, k, g, gathered, b0, new_b, old_b, update);
                let w = mesh.nodes[k as usize].area_m2 / node.area_m2;
                for c in 0..3 {
                    sum[c] += w * v[c];
                }
            }
            sum
        }
        (None, None) => [0.0; 3],
    };
    // A node outside its patch's run would break `patch_runs`' preorder: this panics then.
    new_b.values[(n - new_b.first) as usize] = value;
    value
}

fn leaf_b(mesh: &Mesh, b: &[Rgb]) -> Vec<Rgb> {
    mesh.elements.iter().map(|&n| b[n as usize]).collect()
}

#[cfg(test)]
#[path = "hierarchical_tests.rs"]
mod tests;
