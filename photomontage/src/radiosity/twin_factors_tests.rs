//! The twin form factors of [`super::twin_factors`] against the brute force: every factor
//! computed on the mesh with the planned objects.
#![allow(clippy::unwrap_used)]

use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use super::convergence::StopRule;
use super::covered::mark_covered;
use super::form_factor::FormFactorEngine;
use super::hierarchical::{HierarchicalParams, Hierarchy, Link};
use super::twin::vertex_bits;
use super::twin_factors::{FactorReuse, NaturalFactors};
use super::twin_tests::block_pair;

fn bits(links: &[Link]) -> Vec<(u32, u32, u64)> {
    links
        .iter()
        .map(|l| (l.receiver, l.source, l.form_factor.to_bits()))
        .collect()
}

/// The hierarchy of the city block with its planned building, built reading the natural
/// block's factors where the twins allow, has the same links with the same factors, bit for
/// bit, as the one that computes every factor with the same streams; most factors are read;
/// and the building's box test is needed (reading every twin pair's natural factor would give
/// other values), as is the open fraction in the twin key (the ground under the building).
#[test]
fn twin_factors_equal_computing_every_factor() {
    let mut pair = block_pair();
    mark_covered(&mut pair.natural_mesh, &pair.natural_tracer, &pair.ff);
    mark_covered(&mut pair.mesh, &pair.tracer, &pair.ff);
    let never = AtomicBool::new(false);
    // Coarser than the default, for a test's time (a few refinement passes still run).
    let params = HierarchicalParams {
        bf_tolerance: 0.05,
        ..HierarchicalParams::default()
    };
    let stop = StopRule::default();
    let b0 = |n: usize| vec![[0.4, 0.5, 0.6]; n];
    let natural_engine =
        FormFactorEngine::new(&pair.natural_mesh, &pair.natural_tracer, pair.ff).unwrap();
    let (_, computed) = Hierarchy::build_reusing(
        &natural_engine,
        &params,
        &b0(pair.natural_mesh.elements.len()),
        &stop,
        &never,
        &|_| {},
        None,
    )
    .unwrap();
    let natural = NaturalFactors::new(
        Arc::new(pair.natural_mesh.clone()),
        pair.ff,
        computed.iter().map(Link::triple),
    );
    assert!(natural.len() > 1000, "{} natural factors", natural.len());
    let reuse = FactorReuse::new(&natural, &pair.twin, &pair.mesh, pair.ff).unwrap();
    let engine = FormFactorEngine::new(&pair.mesh, &pair.tracer, pair.ff)
        .unwrap()
        .with_node_streams(Some(reuse.streams()));
    let b0_all = b0(pair.mesh.elements.len());
    let build = |reuse: Option<&FactorReuse<'_>>| {
        Hierarchy::build_reusing(&engine, &params, &b0_all, &stop, &never, &|_| {}, reuse).unwrap()
    };
    let (shared, shared_computed) = build(Some(&reuse));
    let (brute, brute_computed) = build(None);
    for (name, a, b) in [
        ("links", &shared.links, &brute.links),
        ("computed", &shared_computed, &brute_computed),
    ] {
        assert_eq!(a.len(), b.len(), "{name}: count");
        let (a, b) = (bits(a), bits(b));
        let first = a.iter().zip(&b).position(|(x, y)| x != y);
        assert!(first.is_none(), "{name}: first difference at {first:?}");
    }
    // Most factors are read, not computed.
    let read = brute_computed
        .iter()
        .filter(|l| reuse.factor(&engine, l.receiver, l.source).is_some())
        .count();
    assert!(
        read * 2 > brute_computed.len(),
        "{read} of {} factors read",
        brute_computed.len()
    );
    // Twin pairs whose natural factor differs from the computed one: the building stops some
    // of their rays, and the box test keeps them from being read.
    let twin_nodes = super::twin_factors::twin_nodes(&pair.natural_mesh, &pair.mesh);
    let natural_by_pair: HashMap<(u32, u32), u64> = computed
        .iter()
        .map(|l| ((l.receiver, l.source), l.form_factor.to_bits()))
        .collect();
    let differing = brute_computed
        .iter()
        .filter(|l| {
            let (Some(r), Some(s)) = (
                twin_nodes[l.receiver as usize],
                twin_nodes[l.source as usize],
            ) else {
                return false;
            };
            natural_by_pair
                .get(&(r, s))
                .is_some_and(|&f| f != l.form_factor.to_bits())
        })
        .count();
    assert!(
        differing > 10,
        "{differing} twin pairs the building changes"
    );
    // Nodes under the building have the same vertices as natural nodes but less open area:
    // they are not twins.
    assert!(reuse.twins() < pair.mesh.nodes.len());
    let natural_vertices: HashSet<[u64; 9]> =
        pair.natural_mesh.nodes.iter().map(vertex_bits).collect();
    let same_vertices = pair
        .mesh
        .nodes
        .iter()
        .zip(&twin_nodes)
        .filter(|(node, t)| t.is_none() && natural_vertices.contains(&vertex_bits(node)))
        .count();
    assert!(same_vertices > 0, "covered ground nodes without a twin");
}

/// Factors computed with another quadrature are not read.
#[test]
fn factors_of_another_quadrature_are_not_read() {
    let pair = block_pair();
    let natural = NaturalFactors::new(
        Arc::new(pair.natural_mesh.clone()),
        pair.ff,
        std::iter::empty(),
    );
    let mut other = pair.ff;
    other.samples_per_axis += 1;
    assert!(FactorReuse::new(&natural, &pair.twin, &pair.mesh, other).is_none());
    assert!(FactorReuse::new(&natural, &pair.twin, &pair.mesh, pair.ff).is_some());
}
