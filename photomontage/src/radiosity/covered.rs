//! Parts of elements covered by a solid standing on them: a ground element straddling the
//! footprint of a wall, a floor element half under a block. The mesh is a uniform subdivision
//! that does not follow such contact lines (no discontinuity meshing), so an element's radiosity
//! is its mean over a lit part and a dark, hidden part. Receiving, that mean is right (the
//! covered part gets no light, as a path tracer's patch mean also counts it dark); emitting, it
//! is wrong: only the open part emits, with exitance B/open, where `open` is the fraction of
//! the element outside the solid. Without the correction the light a wall's foot receives from
//! the ground next to it is diluted by the dark strip under the wall (measured: points 0.6 m up
//! a sunlit courtyard wall 6 % low against Radiance, Cornell block sides 3–4 % low against
//! Mitsuba). The form factor to node q is divided by q's open fraction
//! ([`super::form_factor::FormFactorEngine::node_to_node`]).
//!
//! A sample point is **covered** when it lies inside a closed solid: rays from it along the
//! normal and tilted 60° towards four tangent directions all first meet the back face of a
//! triangle. A point under a canopy or a single sheet sees out sideways and stays open. The open
//! fraction of an element is the share of its n² stratified points (the form-factor points'
//! strata, own stream) that are open; a parent node's is the area-weighted mean of its children's.
//!
//! # Known limitations
//! Works on closed solids only (an open CAD shell standing on the ground is not detected);
//! the fraction is a 16-point estimate (default n = 4), so a 1/16 sliver may be missed.

use std::sync::Arc;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::form_factor::FormFactorParams;
use super::mesh::Mesh;
use crate::scene::SceneTracer;

/// Random stream family of the coverage points.
const COVER_SEED_SALT: u64 = 0xC0FE_0000_0000_0003;
/// Probe rays start this far from the surface, metres (as the direct-light shadow rays).
const PROBE_OFFSET_M: f32 = 1e-4;
/// Probe rays stop here, metres (beyond any site).
const PROBE_LENGTH_M: f32 = 1e7;

/// Sets every node's [`super::mesh::MeshNode::open_fraction`] (module doc).
pub fn mark_covered(mesh: &mut Mesh, tracer: &SceneTracer, params: &FormFactorParams) {
    let n = params.samples_per_axis as usize;
    #[allow(clippy::cast_precision_loss)]
    let inv_n = 1.0 / n as f64;
    let open: Vec<f64> = (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let node = mesh.element_node(e);
            let normal = node.normal_in_world;
            let tangent = (node.vertices_in_world_m[1] - node.vertices_in_world_m[0]).normalize();
            let bitangent = normal.cross(&tangent);
            let (c, s) = (0.5, 0.75_f64.sqrt());
            let dirs: [Vector3<f64>; 5] = [
                normal,
                normal * c + tangent * s,
                normal * c - tangent * s,
                normal * c + bitangent * s,
                normal * c - bitangent * s,
            ];
            let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ COVER_SEED_SALT);
            rng.set_stream(e as u64);
            let mut open = 0usize;
            #[allow(clippy::cast_precision_loss)]
            for k in 0..n * n {
                let u = ((k / n) as f64 + rng.random::<f64>()) * inv_n;
                let v = ((k % n) as f64 + rng.random::<f64>()) * inv_n;
                let x = node.point_at(u, v);
                let inside = dirs.iter().all(|d| {
                    let ray = tracer.ray_from_world(&x, d, PROBE_OFFSET_M, PROBE_LENGTH_M);
                    tracer.closest_hit(&ray).is_some_and(|h| {
                        let g = h.hit.normal_geometric;
                        f64::from(g[0]) * d.x + f64::from(g[1]) * d.y + f64::from(g[2]) * d.z > 0.0
                    })
                });
                if !inside {
                    open += 1;
                }
            }
            #[allow(clippy::cast_precision_loss)]
            let fraction = open as f64 * inv_n * inv_n;
            fraction
        })
        .collect();
    let nodes = Arc::make_mut(&mut mesh.nodes);
    for (e, fraction) in open.into_iter().enumerate() {
        nodes[mesh.elements[e] as usize].open_fraction = fraction;
    }
    // Parents: area-weighted means, children first (post-order from every patch).
    let patches = mesh.patches.clone();
    for p in patches {
        aggregate(mesh, p);
    }
}

fn aggregate(mesh: &mut Mesh, n: u32) -> f64 {
    let Some(children) = mesh.nodes[n as usize].children else {
        return mesh.nodes[n as usize].open_fraction;
    };
    let mut sum = 0.0;
    let mut area = 0.0;
    for c in children {
        let f = aggregate(mesh, c);
        let a = mesh.nodes[c as usize].area_m2;
        sum += f * a;
        area += a;
    }
    let fraction = if area > 0.0 { sum / area } else { 1.0 };
    Arc::make_mut(&mut mesh.nodes)[n as usize].open_fraction = fraction;
    fraction
}
