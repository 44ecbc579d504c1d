//! Top-down binned surface-area-heuristic build of the binary tree that [`super::wide`]
//! collapses (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies",
//! §3: centroids binned into [`BINS`] equal intervals per axis, the split plane between bins
//! with the least `A_left·N_left + A_right·N_right`), split down to one triangle a leaf; the
//! wide collapse then chooses the leaves by its own costs. On the Embree benchmark's
//! heightfield this tree traced primary rays about 25 % faster than obvhs's PLOC tree
//! (Morton-code clustering), and incoherent rays up to 10 % faster; see docs/benchmarks.md.
//!
//! Subtrees of more than [`PARALLEL_MIN`] triangles are built in parallel (rayon); node
//! slots are assigned from each subtree's triangle count, so the tree does not depend on the
//! thread count.
//!
//! # Known limitations
//! Object splits only (no spatial splits: long thin triangles keep long thin boxes). Ranges
//! whose centroids all coincide are split at the middle of their order.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::{Bvh2, node::Bvh2Node};
use obvhs::triangle::Triangle;

/// Bins per axis (Wald 2007 uses 16–32; more gave no better tree on the benchmark scenes).
const BINS: usize = 32;
/// Ranges at least this large build their two halves in parallel.
const PARALLEL_MIN: usize = 4096;

/// What every range needs: the triangles' boxes and centroids.
struct Prims {
    aabbs: Vec<Aabb>,
    centres: Vec<Vec3A>,
}

/// The binary tree over `triangles` (one triangle a leaf; ids are indices into `triangles`).
/// `triangles` must not be empty.
pub(super) fn binary_tree(triangles: &[Triangle]) -> Bvh2 {
    let aabbs: Vec<Aabb> = triangles.iter().map(Triangle::aabb).collect();
    let centres: Vec<Vec3A> = aabbs.iter().map(Aabb::center).collect();
    let prims = Prims { aabbs, centres };
    let n = triangles.len();
    // Triangle counts fit u32 (checked by `Bvh::build`).
    #[allow(clippy::cast_possible_truncation)]
    let mut indices: Vec<u32> = (0..n as u32).collect();
    let placeholder = Bvh2Node::new(Aabb::empty(), 0, 0);
    // A full binary tree with n leaves has 2n − 1 nodes.
    let mut nodes = vec![placeholder; 2 * n - 1];
    let (root, below) = nodes.split_at_mut(1);
    root[0] = build(&prims, &mut indices, 0, below, 1);
    Bvh2 {
        nodes,
        primitive_indices: indices,
        ..Default::default()
    }
}

/// Builds the subtree over `indices` (which start at `offset` in the final index list) and
/// returns its root; its other `2n − 2` nodes go to `below`, whose first slot is node
/// `below_start` (the root's two children first, as obvhs requires siblings adjacent).
fn build(
    prims: &Prims,
    indices: &mut [u32],
    offset: usize,
    below: &mut [Bvh2Node],
    below_start: usize,
) -> Bvh2Node {
    let mut bounds = Aabb::empty();
    let mut centre_bounds = Aabb::empty();
    for &i in indices.iter() {
        bounds = bounds.union(&prims.aabbs[i as usize]);
        centre_bounds.extend(prims.centres[i as usize]);
    }
    let n = indices.len();
    if n == 1 {
        // Index positions fit u32 (checked by `Bvh::build`).
        #[allow(clippy::cast_possible_truncation)]
        return Bvh2Node::new(bounds, 1, offset as u32);
    }
    let mid = split(prims, indices, &centre_bounds);
    let (left_indices, right_indices) = indices.split_at_mut(mid);
    let (pair, rest) = below.split_at_mut(2);
    let (left_below, right_below) = rest.split_at_mut(2 * mid - 2);
    let right_start = below_start + 2 + 2 * mid - 2;
    let (left, right) = if mid.min(n - mid) >= PARALLEL_MIN {
        rayon::join(
            || build(prims, left_indices, offset, left_below, below_start + 2),
            || build(prims, right_indices, offset + mid, right_below, right_start),
        )
    } else {
        let left = build(prims, left_indices, offset, left_below, below_start + 2);
        let right = build(prims, right_indices, offset + mid, right_below, right_start);
        (left, right)
    };
    pair[0] = left;
    pair[1] = right;
    // Node indices fit u32 (2n − 1 nodes for n < 2³¹ triangles).
    #[allow(clippy::cast_possible_truncation)]
    Bvh2Node::new(bounds, 0, below_start as u32)
}

/// Reorders `indices` so that the best SAH split is `[..mid]` / `[mid..]` and returns `mid`
/// (0 < mid < len).
fn split(prims: &Prims, indices: &mut [u32], centre_bounds: &Aabb) -> usize {
    let extent = centre_bounds.diagonal();
    let origin = centre_bounds.min;
    #[allow(clippy::cast_precision_loss)]
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(BINS as f32) / extent,
        Vec3A::ZERO,
    );
    // Truncation towards zero is the binning; saturating casts keep it in range.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let bin =
        |c: Vec3A, axis: usize| (((c[axis] - origin[axis]) * scale[axis]) as usize).min(BINS - 1);
    let mut boxes = [[Aabb::empty(); BINS]; 3];
    let mut counts = [[0usize; BINS]; 3];
    for &i in indices.iter() {
        let c = prims.centres[i as usize];
        for axis in 0..3 {
            let b = bin(c, axis);
            boxes[axis][b] = boxes[axis][b].union(&prims.aabbs[i as usize]);
            counts[axis][b] += 1;
        }
    }
    // (cost, axis, last bin on the left)
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if scale[axis] == 0.0 {
            continue;
        }
        let mut right_cost = [0.0f32; BINS];
        let mut acc = Aabb::empty();
        let mut count = 0usize;
        for b in (1..BINS).rev() {
            acc = acc.union(&boxes[axis][b]);
            count += counts[axis][b];
            #[allow(clippy::cast_precision_loss)]
            let cost = acc.half_area() * count as f32;
            right_cost[b] = if count > 0 { cost } else { f32::NAN };
        }
        let mut acc = Aabb::empty();
        let mut count = 0usize;
        for b in 0..BINS - 1 {
            acc = acc.union(&boxes[axis][b]);
            count += counts[axis][b];
            #[allow(clippy::cast_precision_loss)]
            let cost = acc.half_area() * count as f32 + right_cost[b + 1];
            // NaN (an empty side) never compares less.
            if count > 0 && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let Some((_, axis, last_left)) = best else {
        return indices.len() / 2; // all centroids coincide
    };
    let mut mid = 0;
    for k in 0..indices.len() {
        if bin(prims.centres[indices[k] as usize], axis) <= last_left {
            indices.swap(mid, k);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(x: f32, y: f32) -> Triangle {
        Triangle {
            v0: Vec3A::new(x, y, 0.0),
            v1: Vec3A::new(x + 1.0, y, 0.0),
            v2: Vec3A::new(x, y + 1.0, 0.0),
        }
    }

    /// Every triangle in exactly one leaf, siblings adjacent, every child box inside its
    /// parent's; for a grid large enough to build in parallel and for coincident triangles.
    #[test]
    fn tree_is_complete_and_nested() {
        #[allow(clippy::cast_precision_loss)]
        let grid: Vec<Triangle> = (0..10_000)
            .map(|i| tri((i % 100) as f32, (i / 100) as f32))
            .collect();
        let same = vec![tri(3.0, 4.0); 37];
        for triangles in [grid, same] {
            let bvh2 = binary_tree(&triangles);
            assert_eq!(bvh2.nodes.len(), 2 * triangles.len() - 1);
            let mut seen = vec![0u32; triangles.len()];
            let mut stack = vec![0usize];
            while let Some(n) = stack.pop() {
                let node = &bvh2.nodes[n];
                if node.is_leaf() {
                    assert_eq!(node.prim_count, 1);
                    let id = bvh2.primitive_indices[node.first_index as usize] as usize;
                    seen[id] += 1;
                    let b = triangles[id].aabb();
                    assert!(
                        node.aabb().min.cmple(b.min).all() && node.aabb().max.cmpge(b.max).all()
                    );
                    continue;
                }
                for c in [node.first_index as usize, node.first_index as usize + 1] {
                    let child = bvh2.nodes[c].aabb();
                    assert!(node.aabb().min.cmple(child.min).all());
                    assert!(node.aabb().max.cmpge(child.max).all());
                    stack.push(c);
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "each triangle once");
        }
    }
}
