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
        let tests: Vec<(Option<bool>, f64)> = self
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
                (split, estimate)
            })
            .collect();
        let mut keep = Vec::with_capacity(self.links.len());
        let mut kept_estimates = Vec::with_capacity(self.links.len());
        let mut new_pairs = Vec::new();
        let mut refined = 0;
        for (link, (split, estimate)) in self.links.iter().zip(tests) {
            match split {
                None => {
                    keep.push(*link);
                    kept_estimates.push(estimate);
                }
                Some(true) => {
                    refined += 1;
                    for c in children(mesh, link.receiver) {
                        if engine.facing(c, link.source) {
                            new_pairs.push((c, link.source));
                        }
                    }
                }
                Some(false) => {
                    refined += 1;
                    for c in children(mesh, link.source) {
                        if engine.facing(link.receiver, c) {
                            new_pairs.push((link.receiver, c));
                        }
                    }
                }
            }
        }
        if refined > 0 {
            let new_links = accurate_links(engine, &new_pairs, reuse);
            computed.extend_from_slice(&new_links);
            keep.extend(new_links);
            kept_estimates.resize(keep.len(), UNKNOWN);
            // By receiver, as `sort`, with each link's estimate beside it (a stable sort: the
            // same order as `sort`).
            let mut paired: Vec<(Link, f64)> = keep.into_iter().zip(kept_estimates).collect();
            paired.sort_by_key(|(l, _)| l.receiver);
            (self.links, *estimates) = paired.into_iter().unzip();
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
        let mut update = 0.0;
        for &p in &mesh.patches {
            push_pull(
                mesh,
                p,
                [0.0; 3],
                &gathered,
                b0,
                &mut new_b,
                &state.b,
                &mut update,
            );
        }
        state.b = new_b;
        update
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

#[allow(clippy::too_many_arguments)]
fn push_pull(
    mesh: &Mesh,
    n: u32,
    down: Rgb,
    gathered: &[Rgb],
    b0: &[Rgb],
    new_b: &mut [Rgb],
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
    new_b[n as usize] = value;
    value
}

fn leaf_b(mesh: &Mesh, b: &[Rgb]) -> Vec<Rgb> {
    mesh.elements.iter().map(|&n| b[n as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dropping the occluded links keeps every other link, in order.
    #[test]
    fn only_links_of_factor_zero_are_dropped() {
        let links: Vec<Link> = (0..40u32)
            .map(|i| Link {
                receiver: i / 8,
                source: i,
                form_factor: match i % 5 {
                    0 => 0.0,
                    1 => 1e-300,
                    _ => f64::from(i) * 1e-3,
                },
            })
            .collect();
        let mut h = Hierarchy {
            links: links.clone(),
            refinement: Vec::new(),
        };
        h.drop_occluded();
        let expected: Vec<Link> = links.into_iter().filter(|l| l.source % 5 != 0).collect();
        assert_eq!(h.links, expected);
    }

    /// The refinement test skips the estimate when even a factor of [`ESTIMATE_BOUND`] could
    /// not pass it: every computed point factor stays under that bound, here for seeded random
    /// triangles seen from points near and far, at grazing angles and next to a contact
    /// (the point on an edge's extension, a hemisphere nearly filled).
    #[test]
    fn point_factors_stay_under_the_refinement_bound() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let mut largest = 0.0_f64;
        for i in 0..200_000 {
            let scale = [1e-3, 1.0, 1e3][i % 3];
            let mut p = || Point3::new(rng.random::<f64>(), rng.random(), rng.random()) * scale;
            let tri = [p(), p(), p()];
            let tri_normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
            if tri_normal.norm() < 1e-12 * scale * scale {
                continue;
            }
            let tri_normal = tri_normal.normalize();
            // A point just in front of the triangle (a nearly filled hemisphere) or anywhere.
            let x = if i % 2 == 0 {
                let w = [rng.random::<f64>(), rng.random::<f64>()];
                let (u, v) = if w[0] + w[1] > 1.0 {
                    (1.0 - w[0], 1.0 - w[1])
                } else {
                    (w[0], w[1])
                };
                tri[0]
                    + (tri[1] - tri[0]) * u
                    + (tri[2] - tri[0]) * v
                    + tri_normal * (scale * 10f64.powf(-6.0 * rng.random::<f64>()))
            } else {
                Point3::new(rng.random::<f64>(), rng.random(), rng.random()) * (2.0 * scale)
            };
            let n = Vector3::new(
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
            );
            let n = if i % 4 == 0 {
                -tri_normal
            } else {
                n.normalize()
            };
            let f = super::super::form_factor::point_to_triangle(&x, &n, &tri, &tri_normal);
            largest = largest.max(f);
        }
        assert!(largest <= ESTIMATE_BOUND, "largest point factor {largest}");
        // The configurations do reach factors near 1 (the bound is tested where it matters).
        assert!(largest > 0.99, "largest point factor {largest}");
    }
}
