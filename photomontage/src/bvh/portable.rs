//! Portable traversal of the wide tree ([`super::wide`]): plain `f32` arrays that the compiler
//! may vectorise for the target's baseline (SSE2 on x86-64). Ordered closest-hit traversal
//! (nearest child first, Wald et al. 2008 §3.2; children farther than the closest hit are
//! skipped when popped) and early-exit any-hit traversal. Triangle tests evaluate
//! Möller–Trumbore exactly as obvhs's `RtTriangle::intersect` does.
//!
//! # Known limitations
//! Slower than the explicit AVX2 kernel ([`super::avx2`]); used where AVX2/FMA is absent and by
//! the tests as the reference of the SIMD path.

use super::wide::{
    LANES, LEAF_FLAG, LeafHit, Node8, PreparedRay, StackEntry, Tri4, WIDTH, WideBvh, leaf_blocks,
    push_sorted,
};

/// Slab test of the ray against the eight child boxes: the hit mask and entry distances.
#[inline(always)]
fn node_test(node: &Node8, ray: &PreparedRay, t_max: f32) -> (u32, [f32; WIDTH]) {
    let (near, far) = ray.near_far_rows();
    let mut t_near = [0.0; WIDTH];
    let mut mask = 0;
    for (i, tn_out) in t_near.iter_mut().enumerate() {
        let slab = |row: usize, axis: usize| {
            (node.bounds[row][i] - ray.origin[axis]) * ray.inv_direction[axis]
        };
        let tn = slab(near[0], 0)
            .max(slab(near[1], 1))
            .max(slab(near[2], 2))
            .max(ray.t_min);
        let tf = slab(far[0], 0)
            .min(slab(far[1], 1))
            .min(slab(far[2], 2))
            .min(t_max);
        *tn_out = tn;
        mask |= u32::from(tn <= tf) << i;
    }
    (mask, t_near)
}

/// Lanes of a block test: distances and barycentrics.
pub(super) struct Tri4Hits {
    pub t: [f32; LANES],
    pub u: [f32; LANES],
    pub v: [f32; LANES],
}

/// Möller–Trumbore on four triangles, operation for operation as `RtTriangle::intersect`
/// (so distances are bit-identical): a mask of lanes hit within `[t_min, t_max]`, their `t`
/// and barycentrics.
#[inline(always)]
pub(super) fn tri4_test(b: &Tri4, ray: &PreparedRay, t_max: f32) -> (u32, Tri4Hits) {
    let [ox, oy, oz] = ray.origin;
    let [dx, dy, dz] = ray.direction;
    let mut out = Tri4Hits {
        t: [f32::INFINITY; LANES],
        u: [0.0; LANES],
        v: [0.0; LANES],
    };
    let mut mask = 0;
    for l in 0..LANES {
        let cx = b.v0[0][l] - ox;
        let cy = b.v0[1][l] - oy;
        let cz = b.v0[2][l] - oz;
        // r = d × c
        let rx = dy * cz - dz * cy;
        let ry = dz * cx - dx * cz;
        let rz = dx * cy - dy * cx;
        let (e1, e2) = (&b.e1, &b.e2);
        // ng = e1 × e2, as `RtTriangle::new`.
        let ng = [
            e1[1][l] * e2[2][l] - e1[2][l] * e2[1][l],
            e1[2][l] * e2[0][l] - e1[0][l] * e2[2][l],
            e1[0][l] * e2[1][l] - e1[1][l] * e2[0][l],
        ];
        let inv_det = 1.0 / ((ng[0] * dx + ng[1] * dy) + ng[2] * dz);
        let u = ((rx * b.e2[0][l] + ry * b.e2[1][l]) + rz * b.e2[2][l]) * inv_det;
        let v = ((rx * b.e1[0][l] + ry * b.e1[1][l]) + rz * b.e1[2][l]) * inv_det;
        let w = 1.0 - u - v;
        // Sign bits, as obvhs: −0 counts as outside.
        let outside = (u.to_bits() | v.to_bits() | w.to_bits()) & 0x8000_0000 != 0;
        if inv_det != 0.0 && !outside {
            let t = ((ng[0] * cx + ng[1] * cy) + ng[2] * cz) * inv_det;
            if t >= ray.t_min && t <= t_max {
                out.t[l] = t;
                out.u[l] = u;
                out.v[l] = v;
                mask |= 1 << l;
            }
        }
    }
    (mask, out)
}

/// The closest hit, or `None`. `stack` must hold [`WideBvh::stack_max`] entries.
pub(super) fn closest(
    bvh: &WideBvh,
    ray: &PreparedRay,
    stack: &mut [StackEntry],
) -> Option<LeafHit> {
    let mut best: Option<LeafHit> = None;
    let mut t_max = ray.t_max;
    stack[0] = StackEntry {
        code: bvh.root,
        t_near: f32::NEG_INFINITY,
    };
    let mut sp = 1;
    'pop: while sp > 0 {
        sp -= 1;
        let entry = stack[sp];
        if entry.t_near > t_max {
            continue;
        }
        let mut code = entry.code;
        while code & LEAF_FLAG == 0 {
            let node = &bvh.nodes[code as usize];
            let (mut mask, t_near) = node_test(node, ray, t_max);
            if mask == 0 {
                continue 'pop;
            }
            let first = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if mask == 0 {
                code = node.children[first];
                continue;
            }
            // Push every hit child, keeping the pushed run sorted far to near; pop the nearest.
            let base = sp;
            let mut push = |slot: usize| {
                let entry = StackEntry {
                    code: node.children[slot],
                    t_near: t_near[slot],
                };
                push_sorted(stack, base, &mut sp, entry);
            };
            push(first);
            while mask != 0 {
                push(mask.trailing_zeros() as usize);
                mask &= mask - 1;
            }
            sp -= 1;
            code = stack[sp].code;
        }
        for block in leaf_blocks(code) {
            let (mut mask, hits) = tri4_test(&bvh.blocks[block], ray, t_max);
            let t = hits.t;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[lane] <= t_max && best.is_none_or(|b| t[lane] < b.t) {
                    t_max = t[lane];
                    // Block and lane indices fit u32 (checked at build).
                    #[allow(clippy::cast_possible_truncation)]
                    let hit = LeafHit {
                        block: block as u32,
                        lane: lane as u32,
                        t: t[lane],
                        u: hits.u[lane],
                        v: hits.v[lane],
                    };
                    best = Some(hit);
                }
            }
        }
    }
    best
}

/// Whether any triangle is hit within `[t_min, t_max]`. `stack` as for [`closest`].
pub(super) fn any(bvh: &WideBvh, ray: &PreparedRay, stack: &mut [StackEntry]) -> bool {
    stack[0].code = bvh.root;
    let mut sp = 1;
    'pop: while sp > 0 {
        sp -= 1;
        let mut code = stack[sp].code;
        while code & LEAF_FLAG == 0 {
            let node = &bvh.nodes[code as usize];
            let (mut mask, _) = node_test(node, ray, ray.t_max);
            if mask == 0 {
                continue 'pop;
            }
            code = node.children[mask.trailing_zeros() as usize];
            mask &= mask - 1;
            while mask != 0 {
                stack[sp].code = node.children[mask.trailing_zeros() as usize];
                sp += 1;
                mask &= mask - 1;
            }
        }
        for block in leaf_blocks(code) {
            if tri4_test(&bvh.blocks[block], ray, ray.t_max).0 != 0 {
                return true;
            }
        }
    }
    false
}
