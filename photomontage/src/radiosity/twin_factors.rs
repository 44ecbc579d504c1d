//! Twin form factors: the solve of a site scene with its planned objects reuses the form
//! factors that the solve of the same scene without them (the photographed state) computed.
//!
//! The two meshes are cut alike on the natural surfaces ([`super::twin`]), so most nodes of the
//! mesh with the planned objects have a **twin** in the natural mesh: a node with the same
//! vertices (and so the same normal) and the same open fraction ([`super::covered`]). The engine
//! of that mesh names each node's form-factor streams after its twin
//! ([`FormFactorEngine::with_node_streams`]; a node without one after the natural mesh's last
//! node), so a pair of twins draws the same sample points and traces the same shadow rays as the
//! natural pair did.
//!
//! Those rays can meet a planned object only inside the convex hull of the two nodes: each runs
//! from a point x of the receiver to a point y of the source, in front of the receiver's plane
//! (y lies above x's tangent plane, which is the receiver's) and in front of the source's (the
//! point factor of an x behind the source is 0 and casts no ray). When the planned objects' box
//! (widened as the twin widens it) lies outside the two nodes' bounding box, or wholly behind
//! either node's plane, every ray is the same `f32` ray against the same natural triangles and
//! misses the planned ones: the factor equals the natural pair's **bit for bit**, and is read
//! instead of computed. Every other pair is computed, with the same streams (common random
//! numbers, Kahn & Marshall 1953, as the twin's sky rays: the sampling noise of a pair far from
//! the planned objects cancels in the difference the differential renderer takes).
//!
//! Equality with computing every factor is tested (`twin_factors_tests`).

use std::sync::Arc;

use nalgebra::Point3;
use rustc_hash::FxHashMap;

use super::form_factor::{FormFactorEngine, FormFactorParams};
use super::mesh::{Mesh, MeshNode};
use super::twin::{Twin, vertex_bits};

/// The form factors a natural solve computed (every pair it linked, also those refined or
/// dropped later), lent to the solve of the scene with the planned objects.
#[derive(Debug, Clone)]
pub struct NaturalFactors {
    /// The natural mesh (the nodes the pairs name).
    mesh: Arc<Mesh>,
    /// The quadrature the factors were computed with.
    params: FormFactorParams,
    /// (receiver · 2³² + source, F), sorted by the pair.
    by_pair: Vec<(u64, f64)>,
}

fn pair_key(r: u32, s: u32) -> u64 {
    (u64::from(r) << 32) | u64::from(s)
}

impl NaturalFactors {
    /// The factors `computed` as (receiver, source, F) (in any order; a pair computed twice has
    /// the same factor) on `mesh` with `params`.
    #[must_use]
    pub(super) fn new(
        mesh: Arc<Mesh>,
        params: FormFactorParams,
        computed: impl Iterator<Item = (u32, u32, f64)>,
    ) -> Self {
        let mut by_pair: Vec<(u64, f64)> = computed.map(|(r, s, f)| (pair_key(r, s), f)).collect();
        by_pair.sort_unstable_by_key(|&(k, _)| k);
        by_pair.dedup_by_key(|&mut (k, _)| k);
        Self {
            mesh,
            params,
            by_pair,
        }
    }

    /// Pairs whose factor is known.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.by_pair.len()
    }

    fn get(&self, r: u32, s: u32) -> Option<f64> {
        let key = pair_key(r, s);
        self.by_pair
            .binary_search_by_key(&key, |&(k, _)| k)
            .ok()
            .map(|i| self.by_pair[i].1)
    }
}

/// What the solve with the planned objects reads from the natural one's factors (module doc).
#[derive(Debug)]
pub(super) struct FactorReuse<'a> {
    natural: &'a NaturalFactors,
    twin: &'a Twin,
    /// Per node of the mesh with the planned objects, its twin in the natural mesh.
    node_twin_of: Vec<Option<u32>>,
    /// Per node, the number naming its form-factor streams.
    streams: Vec<u32>,
}

impl<'a> FactorReuse<'a> {
    /// The reuse for `mesh` (open fractions marked) solved with `params` beside `natural`;
    /// `None` when the quadratures differ or the streams would not fit 32 bits.
    #[must_use]
    pub(super) fn new(
        natural: &'a NaturalFactors,
        twin: &'a Twin,
        mesh: &Mesh,
        params: FormFactorParams,
    ) -> Option<Self> {
        if natural.params != params {
            return None;
        }
        let after = u32::try_from(natural.mesh.nodes.len()).ok()?;
        u32::try_from(natural.mesh.nodes.len() + mesh.nodes.len()).ok()?;
        let node_twin_of = twin_nodes(&natural.mesh, mesh);
        let streams = node_twin_of
            .iter()
            .zip(0u32..)
            .map(|(t, n)| t.unwrap_or(after + n))
            .collect();
        Some(Self {
            natural,
            twin,
            node_twin_of,
            streams,
        })
    }

    /// Per node, the number naming its form-factor streams (for
    /// [`FormFactorEngine::with_node_streams`]).
    pub(super) fn streams(&self) -> &[u32] {
        &self.streams
    }

    /// Nodes that have a twin.
    #[cfg(test)]
    pub(super) fn twins(&self) -> usize {
        self.node_twin_of.iter().flatten().count()
    }

    /// F_rs read from the natural solve where it equals the computed factor bit for bit
    /// (module doc), else `None`.
    pub(super) fn factor(&self, engine: &FormFactorEngine<'_>, r: u32, s: u32) -> Option<f64> {
        let (tr, ts) = (
            self.node_twin_of[r as usize]?,
            self.node_twin_of[s as usize]?,
        );
        let mesh = engine.mesh();
        let (nr, ns) = (&mesh.nodes[r as usize], &mesh.nodes[s as usize]);
        if self.may_meet_artificial(nr, ns) {
            return None;
        }
        self.natural.get(tr, ts)
    }

    /// Whether a shadow ray between `r` and `s` may meet the planned objects' widened box
    /// (module doc: the two nodes' bounding box, and each node's front half-space).
    fn may_meet_artificial(&self, r: &MeshNode, s: &MeshNode) -> bool {
        if !self.twin.plans_something() {
            return false;
        }
        let [lo, hi] = self.twin.artificial_box_in_world_m();
        let vertices = r.vertices_in_world_m.iter().chain(&s.vertices_in_world_m);
        for a in 0..3 {
            let (min, max) = vertices
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(m, x), v| {
                    (m.min(v[a]), x.max(v[a]))
                });
            if max < lo[a] || min > hi[a] {
                return false;
            }
        }
        !(box_behind(r, lo, hi) || box_behind(s, lo, hi))
    }
}

/// Whether the box `lo`–`hi` lies wholly behind the plane of `node` (its highest corner below
/// the plane).
fn box_behind(node: &MeshNode, lo: &Point3<f64>, hi: &Point3<f64>) -> bool {
    let n = &node.normal_in_world;
    let centre = nalgebra::center(lo, hi);
    let half = (hi - lo) / 2.0;
    let reach = n.x.abs() * half.x + n.y.abs() * half.y + n.z.abs() * half.z;
    n.dot(&(centre - node.vertices_in_world_m[0])) + reach < 0.0
}

/// Per node of `to`, the node of `from` with the same vertices in the same order and the same
/// open fraction (module doc); `None` elsewhere.
#[must_use]
pub(super) fn twin_nodes(from: &Mesh, to: &Mesh) -> Vec<Option<u32>> {
    let key = |node: &MeshNode| (vertex_bits(node), node.open_fraction.to_bits());
    let by_key: FxHashMap<([u64; 9], u64), u32> = from
        .nodes
        .iter()
        .zip(0u32..)
        .map(|(node, n)| (key(node), n))
        .collect();
    to.nodes
        .iter()
        .map(|node| by_key.get(&key(node)).copied())
        .collect()
}
