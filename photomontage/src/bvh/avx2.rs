//! AVX2 + FMA traversal of the wide tree ([`super::wide`]) for x86-64, selected at run time
//! (`is_x86_feature_detected!`) by [`super::Bvh`]: one 8-wide slab test per node with the
//! near/far planes chosen by the direction's signs and `fmsub(plane, 1/d, o/d)` (Embree's
//! `BVH8` node intersector; Wald et al. 2008 "Getting rid of packets", §3), ordered closest-hit
//! traversal with a sorted push of the hit children, early-exit any-hit, and a 4-wide SSE
//! Möller–Trumbore (1997) on "Triangle4" leaves with the same operations in the same order as
//! obvhs's `RtTriangle::intersect` (no FMA there), so distances match the portable kernel and
//! the scalar oracle bit for bit. On trees larger than the caches, batch closest-hit queries
//! walk two rays in turn, one node or leaf each (software interleaving, so that the cache
//! misses of two independent traversals overlap).
//!
//! # Known limitations
//! No packets for coherent rays; any-hit queries are not interleaved (measured no faster). The slab test with FMA rounds differently
//! from the portable kernel's, which can only change which of two triangles at the same
//! distance (a float tie) is reported.
#![allow(unsafe_code)] // std::arch loads and the calls of `target_feature` functions.

use std::arch::x86_64::{
    __m128, __m256, _CMP_LE_OQ, _MM_HINT_T0, _mm_add_ps, _mm_cmpge_ps, _mm_cmple_ps, _mm_cmpneq_ps,
    _mm_div_ps, _mm_loadu_ps, _mm_movemask_ps, _mm_mul_ps, _mm_or_ps, _mm_prefetch, _mm_set1_ps,
    _mm_setzero_ps, _mm_storeu_ps, _mm_sub_ps, _mm256_cmp_ps, _mm256_fmsub_ps, _mm256_loadu_ps,
    _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps,
    _mm256_storeu_ps,
};

use super::wide::{
    LANES, LEAF_FLAG, LeafHit, Node8, PreparedRay, StackEntry, Tri4, WIDTH, WideBvh, leaf_blocks,
    push_sorted,
};

/// Proof that this CPU has AVX2 and FMA: only [`Token::new`] makes one, after checking.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Token(());

impl Token {
    /// A token if this CPU runs the kernel.
    pub fn new() -> Option<Self> {
        (is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")).then_some(Self(()))
    }

    /// The closest hit (see [`closest_impl`]).
    #[inline]
    pub fn closest(
        self,
        bvh: &WideBvh,
        ray: &PreparedRay,
        stack: &mut [StackEntry],
    ) -> Option<LeafHit> {
        // SAFETY: a `Token` exists only if the CPU has AVX2 and FMA (`Token::new`).
        unsafe { closest_impl(bvh, ray, stack) }
    }

    /// The closest hits of two rays (see [`closest_pair_impl`]).
    #[inline]
    pub fn closest_pair(
        self,
        bvh: &WideBvh,
        rays: [&PreparedRay; 2],
        stacks: [&mut [StackEntry]; 2],
    ) -> [Option<LeafHit>; 2] {
        // SAFETY: as in `closest`.
        unsafe { closest_pair_impl(bvh, rays, stacks) }
    }

    /// The any-hit answer (see [`any_impl`]).
    #[inline]
    pub fn any(self, bvh: &WideBvh, ray: &PreparedRay, stack: &mut [StackEntry]) -> bool {
        // SAFETY: as in `closest`.
        unsafe { any_impl(bvh, ray, stack) }
    }
}

#[target_feature(enable = "avx2,fma")]
#[inline]
fn load8(a: &[f32; WIDTH]) -> __m256 {
    // SAFETY: `a` is 8 readable `f32`; the unaligned load has no alignment requirement.
    unsafe { _mm256_loadu_ps(a.as_ptr()) }
}

#[target_feature(enable = "avx2,fma")]
#[inline]
fn load4(a: &[f32; LANES]) -> __m128 {
    // SAFETY: `a` is 4 readable `f32`; the unaligned load has no alignment requirement.
    unsafe { _mm_loadu_ps(a.as_ptr()) }
}

/// The ray broadcast for node tests.
#[derive(Clone, Copy)]
struct RayLanes {
    inv: [__m256; 3],
    origin_times_inv: [__m256; 3],
    t_min: __m256,
    near: [usize; 3],
    far: [usize; 3],
}

#[target_feature(enable = "avx2,fma")]
#[inline]
fn ray_lanes(ray: &PreparedRay) -> RayLanes {
    let inv = ray.inv_direction.map(|x| _mm256_set1_ps(x));
    let o = ray.origin;
    let (near, far) = ray.near_far_rows();
    RayLanes {
        inv,
        origin_times_inv: [
            _mm256_mul_ps(_mm256_set1_ps(o[0]), inv[0]),
            _mm256_mul_ps(_mm256_set1_ps(o[1]), inv[1]),
            _mm256_mul_ps(_mm256_set1_ps(o[2]), inv[2]),
        ],
        t_min: _mm256_set1_ps(ray.t_min),
        near,
        far,
    }
}

/// The 8-wide slab test: the entry distances and the mask of boxes entered before `t_max`.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn node_test(node: &Node8, r: &RayLanes, t_max: __m256) -> (__m256, u32) {
    let slab = |row: usize, axis: usize| {
        _mm256_fmsub_ps(
            load8(&node.bounds[row]),
            r.inv[axis],
            r.origin_times_inv[axis],
        )
    };
    let t_near = _mm256_max_ps(
        _mm256_max_ps(slab(r.near[0], 0), slab(r.near[1], 1)),
        _mm256_max_ps(slab(r.near[2], 2), r.t_min),
    );
    let t_far = _mm256_min_ps(
        _mm256_min_ps(slab(r.far[0], 0), slab(r.far[1], 1)),
        _mm256_min_ps(slab(r.far[2], 2), t_max),
    );
    let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far));
    #[allow(clippy::cast_sign_loss)] // an 8-bit mask
    (t_near, mask as u32)
}

/// Möller–Trumbore on four triangles, operation for operation as `RtTriangle::intersect`:
/// the mask of lanes hit within `[t_min, t_max]`, the distances and the barycentrics `u`, `v`.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn tri4_test(b: &Tri4, ray: &PreparedRay, t_max: f32) -> (u32, [__m128; 3]) {
    let d = ray.direction.map(|x| _mm_set1_ps(x));
    let c = [0, 1, 2].map(|a| _mm_sub_ps(load4(&b.v0[a]), _mm_set1_ps(ray.origin[a])));
    // r = d × c
    let r = [
        _mm_sub_ps(_mm_mul_ps(d[1], c[2]), _mm_mul_ps(d[2], c[1])),
        _mm_sub_ps(_mm_mul_ps(d[2], c[0]), _mm_mul_ps(d[0], c[2])),
        _mm_sub_ps(_mm_mul_ps(d[0], c[1]), _mm_mul_ps(d[1], c[0])),
    ];
    let dot = |a: &[__m128; 3], b: [__m128; 3]| {
        _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(a[0], b[0]), _mm_mul_ps(a[1], b[1])),
            _mm_mul_ps(a[2], b[2]),
        )
    };
    let e1 = [0, 1, 2].map(|a| load4(&b.e1[a]));
    let e2 = [0, 1, 2].map(|a| load4(&b.e2[a]));
    // ng = e1 × e2, as `RtTriangle::new`.
    let ng = [
        _mm_sub_ps(_mm_mul_ps(e1[1], e2[2]), _mm_mul_ps(e1[2], e2[1])),
        _mm_sub_ps(_mm_mul_ps(e1[2], e2[0]), _mm_mul_ps(e1[0], e2[2])),
        _mm_sub_ps(_mm_mul_ps(e1[0], e2[1]), _mm_mul_ps(e1[1], e2[0])),
    ];
    let inv_det = _mm_div_ps(_mm_set1_ps(1.0), dot(&ng, d));
    let u = _mm_mul_ps(dot(&r, e2), inv_det);
    let v = _mm_mul_ps(dot(&r, e1), inv_det);
    let w = _mm_sub_ps(_mm_sub_ps(_mm_set1_ps(1.0), u), v);
    let t = _mm_mul_ps(dot(&ng, c), inv_det);
    // Sign bits of u, v, w (−0 counts as outside, as in obvhs).
    let outside = _mm_movemask_ps(_mm_or_ps(_mm_or_ps(u, v), w));
    let det_ok = _mm_movemask_ps(_mm_cmpneq_ps(inv_det, _mm_setzero_ps()));
    let in_range = _mm_movemask_ps(_mm_cmpge_ps(t, _mm_set1_ps(ray.t_min)))
        & _mm_movemask_ps(_mm_cmple_ps(t, _mm_set1_ps(t_max)));
    #[allow(clippy::cast_sign_loss)] // a 4-bit mask
    ((det_ok & in_range & !outside) as u32 & 0xf, [t, u, v])
}

/// Cache lines asked for per child.
const PREFETCH_LINES: usize = 4;

/// Asks the cache for the children in `mask` (nodes or leaf blocks) before they are visited,
/// so that their misses overlap instead of following one another down the tree.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn prefetch_children(bvh: &WideBvh, node: &Node8, mut mask: u32) {
    while mask != 0 {
        let code = node.children[mask.trailing_zeros() as usize];
        mask &= mask - 1;
        let start = if code & LEAF_FLAG == 0 {
            bvh.nodes.as_ptr().wrapping_add(code as usize).cast::<i8>()
        } else {
            let first = leaf_blocks(code).start;
            bvh.blocks.as_ptr().wrapping_add(first).cast::<i8>()
        };
        // Prefetching never faults, whatever the address. Four lines cover a node's boxes
        // and codes, or a leaf's first block and part of its second.
        for line in 0..PREFETCH_LINES {
            _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(64 * line));
        }
    }
}

/// The closest hit, or `None`. `stack` must hold [`WideBvh::stack_max`] entries.
#[target_feature(enable = "avx2,fma")]
fn closest_impl(bvh: &WideBvh, ray: &PreparedRay, stack: &mut [StackEntry]) -> Option<LeafHit> {
    traverse(bvh, ray, stack)
}

/// Whether any triangle is hit within `[t_min, t_max]`. `stack` as for [`closest_impl`].
/// Children are visited in slot order: stopping the ordered traversal at its first hit measured
/// no faster on the Embree benchmark's rays.
#[target_feature(enable = "avx2,fma")]
fn any_impl(bvh: &WideBvh, ray: &PreparedRay, stack: &mut [StackEntry]) -> bool {
    let lanes = ray_lanes(ray);
    let t_max = _mm256_set1_ps(ray.t_max);
    stack[0].code = bvh.root;
    let mut sp = 1;
    'pop: while sp > 0 {
        sp -= 1;
        let mut code = stack[sp].code;
        while code & LEAF_FLAG == 0 {
            let node = &bvh.nodes[code as usize];
            let (_, mut mask) = node_test(node, &lanes, t_max);
            if mask == 0 {
                continue 'pop;
            }
            if bvh.large {
                prefetch_children(bvh, node, mask);
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

/// One ray's ordered closest-hit traversal (nearest child first, pushed children skipped once
/// beyond the closest hit) as a state that advances one node or one leaf per [`Walk::step`],
/// so that two rays can be advanced in turn ([`closest_pair_impl`]).
struct Walk<'s> {
    lanes: RayLanes,
    ray: PreparedRay,
    stack: &'s mut [StackEntry],
    sp: usize,
    /// The node or leaf to visit next; meaningless once `done`.
    code: u32,
    t_max: f32,
    best: Option<LeafHit>,
    done: bool,
}

impl<'s> Walk<'s> {
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn new(bvh: &WideBvh, ray: &PreparedRay, stack: &'s mut [StackEntry]) -> Self {
        Self {
            lanes: ray_lanes(ray),
            ray: *ray,
            stack,
            sp: 0,
            code: bvh.root,
            t_max: ray.t_max,
            best: None,
            done: false,
        }
    }

    /// Continues with the nearest pushed child not beyond the closest hit, or ends.
    #[inline(always)]
    fn pop(&mut self) {
        while self.sp > 0 {
            self.sp -= 1;
            let entry = self.stack[self.sp];
            if entry.t_near <= self.t_max {
                self.code = entry.code;
                return;
            }
        }
        self.done = true;
    }

    /// Visits `self.code`: a node's children are tested and the nearest becomes next (the rest
    /// pushed, sorted far to near); a leaf's blocks are tested, then the walk pops.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn step(&mut self, bvh: &WideBvh) {
        let code = self.code;
        if code & LEAF_FLAG != 0 {
            self.leaf(bvh, code);
            self.pop();
            return;
        }
        let node = &bvh.nodes[code as usize];
        let (t_near_v, mut mask) = node_test(node, &self.lanes, _mm256_set1_ps(self.t_max));
        if mask == 0 {
            self.pop();
            return;
        }
        if bvh.large {
            prefetch_children(bvh, node, mask);
        }
        let first = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if mask == 0 {
            self.code = node.children[first];
            return;
        }
        let mut t_near = [0.0f32; WIDTH];
        // SAFETY: `t_near` is 8 writable `f32`; the unaligned store needs no alignment.
        unsafe { _mm256_storeu_ps(t_near.as_mut_ptr(), t_near_v) };
        let second = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if mask == 0 {
            // Two children: continue with the nearer, push the farther.
            let (near, far) = if t_near[second] < t_near[first] {
                (second, first)
            } else {
                (first, second)
            };
            self.stack[self.sp] = StackEntry {
                code: node.children[far],
                t_near: t_near[far],
            };
            self.sp += 1;
            self.code = node.children[near];
            return;
        }
        // Three or more: push all, keeping the pushed run sorted far to near; pop the nearest.
        let (stack, base) = (&mut *self.stack, self.sp);
        let mut sp = base;
        let mut push = |slot: usize| {
            let entry = StackEntry {
                code: node.children[slot],
                t_near: t_near[slot],
            };
            push_sorted(stack, base, &mut sp, entry);
        };
        push(first);
        push(second);
        while mask != 0 {
            push(mask.trailing_zeros() as usize);
            mask &= mask - 1;
        }
        self.sp = sp - 1;
        self.code = self.stack[self.sp].code;
    }

    /// Tests the blocks of leaf `code`, keeping the closest hit.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn leaf(&mut self, bvh: &WideBvh, code: u32) {
        for block in leaf_blocks(code) {
            let (mut mask, [t_v, u_v, v_v]) = tri4_test(&bvh.blocks[block], &self.ray, self.t_max);
            if mask == 0 {
                continue;
            }
            let mut t = [0.0f32; LANES];
            let mut u = [0.0f32; LANES];
            let mut v = [0.0f32; LANES];
            // SAFETY: each array is 4 writable `f32`; unaligned stores need no alignment.
            unsafe {
                _mm_storeu_ps(t.as_mut_ptr(), t_v);
                _mm_storeu_ps(u.as_mut_ptr(), u_v);
                _mm_storeu_ps(v.as_mut_ptr(), v_v);
            }
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if self.best.is_none_or(|b| t[lane] < b.t) {
                    self.t_max = t[lane];
                    // Block and lane indices fit u32 (checked at build).
                    #[allow(clippy::cast_possible_truncation)]
                    let hit = LeafHit {
                        block: block as u32,
                        lane: lane as u32,
                        t: t[lane],
                        u: u[lane],
                        v: v[lane],
                    };
                    self.best = Some(hit);
                }
            }
        }
    }
}

/// Closest hit of one ray.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn traverse(bvh: &WideBvh, ray: &PreparedRay, stack: &mut [StackEntry]) -> Option<LeafHit> {
    let mut walk = Walk::new(bvh, ray, stack);
    while !walk.done {
        walk.step(bvh);
    }
    walk.best
}

/// Closest hits of two rays, advanced in turn: while one waits for a node or block from
/// memory, the processor works on the other, so two cache misses are in flight instead of
/// one (memory-level parallelism for incoherent rays in trees larger than the caches). Each
/// ray visits exactly what it would alone: the results are the same.
#[target_feature(enable = "avx2,fma")]
fn closest_pair_impl(
    bvh: &WideBvh,
    rays: [&PreparedRay; 2],
    stacks: [&mut [StackEntry]; 2],
) -> [Option<LeafHit>; 2] {
    let [stack_a, stack_b] = stacks;
    let mut a = Walk::new(bvh, rays[0], stack_a);
    let mut b = Walk::new(bvh, rays[1], stack_b);
    while !a.done && !b.done {
        a.step(bvh);
        b.step(bvh);
    }
    while !a.done {
        a.step(bvh);
    }
    while !b.done {
        b.step(bvh);
    }
    [a.best, b.best]
}
