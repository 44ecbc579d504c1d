//! The CPU layout of the BVH: an 8-wide tree whose nodes keep their children's boxes in
//! structure-of-arrays form, and leaves of one or two blocks of four triangles in "Triangle4"
//! form (Wald, Benthin & Boulos 2008, "Getting rid of packets", and Embree's `BVH8` +
//! `Triangle4`, Wald et al. 2014, §4–5), so that one SIMD instruction tests a ray against eight
//! boxes or four triangles.
//!
//! The tree is collapsed from a binary tree with one triangle a leaf (binned SAH,
//! [`super::sah`], or obvhs's PLOC, Meister & Bittner 2018, from [`binary_tree`]) by the
//! surface-area-heuristic-optimal dynamic programme of Ylitie, Karras & Laine 2017 (§3.1, as
//! in obvhs's CWBVH converter but with this module's costs: a leaf costs per block of four,
//! not per triangle): every binary node is either a leaf of at most [`LEAF_TRIANGLES_MAX`]
//! triangles, an 8-wide node, or hands its children up to its parent. The leaves of one node
//! then share blocks where they fit ([`WideBvh::pack_leaves`]).
//!
//! Triangles are stored with the precomputed edges of obvhs's `RtTriangle` (`e1 = v0 − v1`,
//! `e2 = v2 − v0`; the kernels recompute its `ng = e1 × e2` exactly), so that the traversal
//! kernels evaluate Möller–Trumbore (1997) with the same floating-point operations in the same
//! order as `RtTriangle::intersect` and return bit-identical distances.
//!
//! # Known limitations
//! The two cost constants were chosen among a few values by benchmark, not fitted. Boxes are
//! uncompressed `f32` (224 bytes a node, 160 a block), so the tree takes more memory than a
//! quantised CWBVH (128-byte quantised nodes were tried: incoherent rays no faster, primary
//! rays 10–15 % slower from the dequantisation). The collapse is sequential and its table takes 64 bytes per
//! binary node while it runs.

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::{Bvh2, reinsertion::ReinsertionOptimizer};
use obvhs::ploc::PlocBuilder;
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

use super::BvhError;

/// Children per node (the AVX width in `f32`).
pub(super) const WIDTH: usize = 8;
/// Triangles per leaf block (the SSE width in `f32`).
pub(super) const LANES: usize = 4;
/// The collapse makes leaves of at most this many triangles (two blocks).
const LEAF_TRIANGLES_MAX: u32 = 8;
/// Surface-area-heuristic cost of a node test, per unit of the node's half area.
const COST_NODE: f32 = 1.0;
/// Cost of a four-triangle block test, in the same unit (any of 1–4 triangles costs one block).
/// Measured on the Embree benchmark: 1.0 traced city_10k up to 10 % faster than 2.0 (fuller
/// nodes), terrain_1m within noise.
const COST_BLOCK: f32 = 1.0;

/// Child code flag of a leaf: bits 27–30 hold the block count − 1, bits 0–26 the first block.
pub(super) const LEAF_FLAG: u32 = 1 << 31;
const LEAF_COUNT_SHIFT: u32 = 27;
/// Most blocks one leaf code can name (4 bits of count).
const LEAF_BLOCKS_MAX: usize = 16;
/// Blocks addressable by the 27 index bits.
const BLOCK_INDEX_LIMIT: usize = 1 << LEAF_COUNT_SHIFT;
/// Child code of an empty slot (its box is empty, so it is never entered).
pub(super) const EMPTY_CHILD: u32 = 0;

/// Decodes a leaf code into its block range.
#[inline(always)]
pub(super) fn leaf_blocks(code: u32) -> std::ops::Range<usize> {
    let first = (code & (BLOCK_INDEX_LIMIT as u32 - 1)) as usize;
    let count = ((code & !LEAF_FLAG) >> LEAF_COUNT_SHIFT) as usize + 1;
    first..first + count
}

/// An 8-wide node: child boxes as structure of arrays, then the child codes (a node index, or
/// [`LEAF_FLAG`] with a block range, see [`leaf_blocks`]).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Node8 {
    /// `bounds[2·axis]` are the children's minima along `axis`, `bounds[2·axis + 1]` the maxima.
    /// Empty slots have min = +∞ and max = −∞.
    pub bounds: [[f32; WIDTH]; 6],
    /// Child codes.
    pub children: [u32; WIDTH],
}

impl Node8 {
    fn empty() -> Self {
        let mut bounds = [[f32::INFINITY; WIDTH]; 6];
        for axis in 0..3 {
            bounds[2 * axis + 1] = [f32::NEG_INFINITY; WIDTH];
        }
        Self {
            bounds,
            children: [EMPTY_CHILD; WIDTH],
        }
    }
}

/// Four triangles in structure-of-arrays form (`[component][lane]`), with the caller's ids.
/// Unused lanes repeat lane 0 (the same hit twice changes nothing). The normal `ng = e1 × e2`
/// is recomputed by the kernels (same operations as `RtTriangle::new`, so the same bits): 160
/// bytes a block instead of 208 matter more than nine multiply/subtracts.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Tri4 {
    /// Vertex 0.
    pub v0: [[f32; LANES]; 3],
    /// `v0 − v1`.
    pub e1: [[f32; LANES]; 3],
    /// `v2 − v0`.
    pub e2: [[f32; LANES]; 3],
    /// Triangle ids in the caller's order.
    pub ids: [u32; LANES],
}

impl Tri4 {
    fn new(lanes: &[(u32, RtTriangle)]) -> Self {
        let mut b = Self {
            v0: [[0.0; LANES]; 3],
            e1: [[0.0; LANES]; 3],
            e2: [[0.0; LANES]; 3],
            ids: [0; LANES],
        };
        for lane in 0..LANES {
            let (id, t) = lanes.get(lane).unwrap_or(&lanes[0]);
            b.ids[lane] = *id;
            for (dst, src) in [(&mut b.v0, t.v0), (&mut b.e1, t.e1), (&mut b.e2, t.e2)] {
                dst[0][lane] = src.x;
                dst[1][lane] = src.y;
                dst[2][lane] = src.z;
            }
        }
        b
    }

    /// Lane `lane` as obvhs's triangle (the exact stored values).
    pub fn triangle(&self, lane: usize) -> RtTriangle {
        let get = |c: &[[f32; LANES]; 3]| Vec3A::new(c[0][lane], c[1][lane], c[2][lane]);
        let (e1, e2) = (get(&self.e1), get(&self.e2));
        RtTriangle {
            v0: get(&self.v0),
            e1,
            e2,
            ng: e1.cross(e2),
        }
    }
}

/// The wide tree.
#[derive(Clone, Debug)]
pub(super) struct WideBvh {
    pub nodes: Vec<Node8>,
    pub blocks: Vec<Tri4>,
    /// Code of the root (a node index or a leaf).
    pub root: u32,
    /// Most stack entries a traversal can need (pushes of all but one child along a path, + 1).
    pub stack_max: usize,
    /// Triangle references in the leaves (one per triangle).
    pub references: usize,
    /// Whether the tree is larger than a core's L2 cache, where node and block loads miss:
    /// then the AVX2 kernel prefetches entered children and batch closest-hit queries walk two
    /// rays in turn (small trees would only pay the instructions).
    pub large: bool,
}

/// Trees above this many bytes of nodes and blocks count as [`WideBvh::large`].
const LARGE_MIN_BYTES: usize = 512 << 10;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Leaf,
    Internal,
    Distribute,
}

/// One entry of the collapse table: the best cost of a binary subtree given `i + 1` slots of
/// its wide parent, and how to reach it.
#[derive(Clone, Copy, Debug)]
struct Decision {
    cost: f32,
    kind: Kind,
    /// Slots − 1 given to the left and right binary children.
    left: u8,
    right: u8,
}

/// The dynamic programme of Ylitie, Karras & Laine 2017 (§3.1) over a binary tree with one
/// triangle per leaf, with this module's costs: `decisions[n·WIDTH + i]` for `i + 1` slots.
struct Plan {
    decisions: Vec<Decision>,
}

impl Plan {
    fn new(bvh2: &Bvh2) -> Self {
        let unset = Decision {
            cost: f32::INFINITY,
            kind: Kind::Distribute,
            left: 0,
            right: 0,
        };
        let mut decisions = vec![unset; bvh2.nodes.len() * WIDTH];

        let mut prim_count = vec![0u32; bvh2.nodes.len()];
        // Parents before children, then processed in reverse.
        let mut order = Vec::with_capacity(bvh2.nodes.len());
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            order.push(n);
            let node = &bvh2.nodes[n];
            if !node.is_leaf() {
                let f = node.first_index as usize;
                stack.extend([f, f + 1]);
            }
        }
        for &n in order.iter().rev() {
            let node = &bvh2.nodes[n];
            let area = node.aabb().half_area();
            let d = &mut decisions[n * WIDTH..(n + 1) * WIDTH];
            if node.is_leaf() {
                prim_count[n] = node.prim_count;
                #[allow(clippy::cast_precision_loss)]
                let cost = area * COST_BLOCK * node.prim_count.div_ceil(LANES as u32) as f32;
                d.fill(Decision {
                    cost,
                    kind: Kind::Leaf,
                    left: 0,
                    right: 0,
                });
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            let count = prim_count[l] + prim_count[r];
            prim_count[n] = count;
            let cost_of = |c: usize, i: usize| decisions[c * WIDTH + i].cost;
            // One slot: a leaf, or a wide node whose 8 slots the two children share.
            let mut best = (f32::INFINITY, 0, 0);
            for k in 0..WIDTH - 1 {
                let c = cost_of(l, k) + cost_of(r, WIDTH - 2 - k);
                if c < best.0 {
                    best = (c, k, WIDTH - 2 - k);
                }
            }
            #[allow(clippy::cast_precision_loss)]
            let cost_leaf = if count <= LEAF_TRIANGLES_MAX {
                area * COST_BLOCK * count.div_ceil(LANES as u32) as f32
            } else {
                f32::INFINITY
            };
            let cost_internal = best.0 + area * COST_NODE;
            // Slot counts fit u8.
            #[allow(clippy::cast_possible_truncation)]
            let mut row = [Decision {
                cost: cost_leaf.min(cost_internal),
                kind: if cost_leaf < cost_internal {
                    Kind::Leaf
                } else {
                    Kind::Internal
                },
                left: best.1 as u8,
                right: best.2 as u8,
            }; WIDTH];
            // i + 1 slots: as with i slots, or split between the children.
            for i in 1..WIDTH - 1 {
                row[i] = row[i - 1];
                for k in 0..i {
                    let c = cost_of(l, k) + cost_of(r, i - k - 1);
                    if c < row[i].cost {
                        #[allow(clippy::cast_possible_truncation)]
                        let dist = Decision {
                            cost: c,
                            kind: Kind::Distribute,
                            left: k as u8,
                            right: (i - k - 1) as u8,
                        };
                        row[i] = dist;
                    }
                }
            }
            row[WIDTH - 1] = row[WIDTH - 2];
            decisions[n * WIDTH..(n + 1) * WIDTH].copy_from_slice(&row);
        }
        Self { decisions }
    }

    /// Appends the children of binary node `n` given `i + 1` slots (for the node itself, `i` = 0
    /// means its own wide node).
    fn children(
        &self,
        bvh2: &Bvh2,
        n: usize,
        i: usize,
        out: &mut [usize; WIDTH],
        count: &mut usize,
    ) {
        let node = &bvh2.nodes[n];
        if node.is_leaf() {
            out[*count] = n;
            *count += 1;
            return;
        }
        let d = self.decisions[n * WIDTH + i];
        let f = node.first_index as usize;
        for (c, slots) in [(f, d.left as usize), (f + 1, d.right as usize)] {
            if self.decisions[c * WIDTH + slots].kind == Kind::Distribute {
                self.children(bvh2, c, slots, out, count);
            } else {
                out[*count] = c;
                *count += 1;
            }
        }
    }
}

/// obvhs's binary tree with one triangle per leaf: PLOC and reinsertion with `params`, as
/// `obvhs::cwbvh::builder::build_cwbvh_from_tris` makes it (without its pre-splits).
pub(super) fn binary_tree(triangles: &[Triangle], params: &BvhBuildParams) -> Bvh2 {
    let n = u32::try_from(triangles.len()).unwrap_or(u32::MAX);
    let mut bvh2 = PlocBuilder::with_capacity(triangles.len()).build(
        params.ploc_search_distance,
        triangles,
        (0..n).collect(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// Collapses obvhs's binary tree (leaves of one triangle) over `triangles` (ids are indices
/// into `triangles`) by the decisions of [`Plan`] (Ylitie et al. 2017, §3.1: each binary node
/// becomes a leaf of at most [`LEAF_TRIANGLES_MAX`] triangles, a wide node, or distributes its
/// children upwards).
pub(super) fn collapse(bvh2: &Bvh2, triangles: &[RtTriangle]) -> Result<WideBvh, BvhError> {
    let mut w = WideBvh {
        nodes: Vec::with_capacity(bvh2.nodes.len() / 8 + 1),
        blocks: Vec::with_capacity(bvh2.primitive_indices.len() / 3 + 1),
        root: EMPTY_CHILD,
        stack_max: 1,
        references: bvh2.primitive_indices.len(),
        large: false,
    };
    if bvh2.nodes.is_empty() {
        return Err(BvhError::Empty);
    }
    let plan = Plan::new(bvh2);
    // Work list of (wide node index, binary node id) whose children are still to be filled.
    let mut work: Vec<(usize, usize)> = Vec::new();
    w.root = w.push_node()?;
    work.push((0, 0));
    let mut subtree: Vec<usize> = Vec::new();
    let mut leaves: Vec<(usize, Vec<u32>)> = Vec::with_capacity(WIDTH);
    while let Some((wide, id)) = work.pop() {
        let mut children = [0usize; WIDTH];
        let mut count = 0;
        plan.children(bvh2, id, 0, &mut children, &mut count);
        leaves.clear();
        for (slot, &c) in children.iter().enumerate().take(count) {
            let node = &bvh2.nodes[c];
            let code = if node.is_leaf() || plan.decisions[c * WIDTH].kind == Kind::Leaf {
                // All triangles of the binary subtree.
                let mut prims = Vec::with_capacity(LANES);
                subtree.clear();
                subtree.push(c);
                while let Some(n) = subtree.pop() {
                    let n = &bvh2.nodes[n];
                    if n.is_leaf() {
                        let first = n.first_index as usize;
                        prims.extend_from_slice(
                            &bvh2.primitive_indices[first..first + n.prim_count as usize],
                        );
                    } else {
                        let f = n.first_index as usize;
                        subtree.extend([f + 1, f]);
                    }
                }
                if prims.len() > LEAF_BLOCKS_MAX * LANES {
                    let aabb = node.aabb();
                    w.leaf_code(&prims, triangles, [aabb.min, aabb.max])?
                } else {
                    leaves.push((slot, prims));
                    EMPTY_CHILD // set by `pack_leaves` below
                }
            } else {
                let index = w.push_node()?;
                work.push((index as usize, c));
                index
            };
            let aabb = bvh2.nodes[c].aabb();
            let node = &mut w.nodes[wide];
            node.children[slot] = code;
            for axis in 0..3 {
                node.bounds[2 * axis][slot] = aabb.min[axis];
                node.bounds[2 * axis + 1][slot] = aabb.max[axis];
            }
        }
        for (slot, code) in w.pack_leaves(&leaves, triangles)? {
            w.nodes[wide].children[slot] = code;
        }
    }
    w.stack_max = w.stack_need();
    w.large = std::mem::size_of_val(w.nodes.as_slice())
        + std::mem::size_of_val(w.blocks.as_slice())
        > LARGE_MIN_BYTES;
    Ok(w)
}

impl WideBvh {
    fn push_node(&mut self) -> Result<u32, BvhError> {
        let index = u32::try_from(self.nodes.len())
            .ok()
            .filter(|&i| i < LEAF_FLAG)
            .ok_or(BvhError::TooManyTriangles {
                count: self.nodes.len() * WIDTH,
            })?;
        self.nodes.push(Node8::empty());
        Ok(index)
    }

    /// Codes for the leaf children `(slot, triangles)` of one node, whose triangles share
    /// blocks where they fit: a leaf of up to four triangles goes into the fullest of this
    /// node's blocks with room (best fit, larger leaves first), a larger leaf takes blocks of
    /// its own whose last one others may fill. Testing a block tests all its lanes, so a
    /// visit to one leaf may also test a sibling's triangles: every hit found is a true hit
    /// of the ray, so results are unchanged, while terrain-like trees of leaves of one to
    /// three triangles need about a quarter fewer blocks (less memory traffic per ray).
    fn pack_leaves(
        &mut self,
        leaves: &[(usize, Vec<u32>)],
        triangles: &[RtTriangle],
    ) -> Result<Vec<(usize, u32)>, BvhError> {
        let mut order: Vec<usize> = (0..leaves.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(leaves[i].1.len()));
        let mut lanes_of: Vec<Vec<u32>> = Vec::new();
        let mut placed = Vec::with_capacity(leaves.len());
        for i in order {
            let (slot, prims) = &leaves[i];
            if prims.len() > LANES {
                let first = lanes_of.len();
                lanes_of.extend(prims.chunks(LANES).map(<[u32]>::to_vec));
                placed.push((*slot, first, lanes_of.len() - first));
            } else {
                let fit = lanes_of
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| b.len() + prims.len() <= LANES)
                    .max_by_key(|(_, b)| b.len())
                    .map(|(j, _)| j);
                let j = fit.unwrap_or_else(|| {
                    lanes_of.push(Vec::with_capacity(LANES));
                    lanes_of.len() - 1
                });
                lanes_of[j].extend_from_slice(prims);
                placed.push((*slot, j, 1));
            }
        }
        let base = self.blocks.len();
        if base + lanes_of.len() > BLOCK_INDEX_LIMIT {
            return Err(BvhError::TooManyTriangles {
                count: triangles.len(),
            });
        }
        for block in &lanes_of {
            let lanes: Vec<(u32, RtTriangle)> =
                block.iter().map(|&p| (p, triangles[p as usize])).collect();
            self.blocks.push(Tri4::new(&lanes));
        }
        // Indices below BLOCK_INDEX_LIMIT and counts up to LEAF_BLOCKS_MAX fit their fields.
        #[allow(clippy::cast_possible_truncation)]
        Ok(placed
            .into_iter()
            .map(|(slot, first, count)| {
                (
                    slot,
                    LEAF_FLAG | (((count - 1) as u32) << LEAF_COUNT_SHIFT) | (base + first) as u32,
                )
            })
            .collect())
    }

    /// A leaf over `prims`; a leaf larger than one code can name becomes a node of leaves with
    /// the same (conservative) box.
    fn leaf_code(
        &mut self,
        prims: &[u32],
        triangles: &[RtTriangle],
        bounds: [Vec3A; 2],
    ) -> Result<u32, BvhError> {
        if prims.len() > LEAF_BLOCKS_MAX * LANES {
            let index = self.push_node()?;
            let per_child = prims.len().div_ceil(WIDTH);
            for (slot, chunk) in prims.chunks(per_child).enumerate() {
                let code = self.leaf_code(chunk, triangles, bounds)?;
                let node = &mut self.nodes[index as usize];
                node.children[slot] = code;
                for axis in 0..3 {
                    node.bounds[2 * axis][slot] = bounds[0][axis];
                    node.bounds[2 * axis + 1][slot] = bounds[1][axis];
                }
            }
            return Ok(index);
        }
        let codes = self.pack_leaves(&[(0, prims.to_vec())], triangles)?;
        Ok(codes[0].1)
    }

    /// Nodes are created parent first, so one reverse pass gives each node the most entries a
    /// traversal below it can push.
    fn stack_need(&self) -> usize {
        let mut need = vec![0usize; self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let node = &self.nodes[i];
            let mut used = 0usize;
            let mut below = 0;
            for (slot, &c) in node.children.iter().enumerate() {
                if node.bounds[0][slot] > node.bounds[1][slot] {
                    continue; // empty slot
                }
                used += 1;
                if c & LEAF_FLAG == 0 {
                    below = below.max(need[c as usize]);
                }
            }
            need[i] = used.saturating_sub(1) + below;
        }
        let root = if self.root & LEAF_FLAG == 0 {
            need.first().copied().unwrap_or(0)
        } else {
            0
        };
        root + 1
    }
}

/// Below this magnitude a direction component is replaced by ±this value before taking its
/// reciprocal (Embree's `rcp_safe`), so that box slabs stay finite and never `0 · ∞`.
const DIRECTION_MIN: f32 = 1e-18;

/// A ray with what every node test needs.
#[derive(Clone, Copy, Debug)]
pub(super) struct PreparedRay {
    pub origin: [f32; 3],
    pub direction: [f32; 3],
    pub inv_direction: [f32; 3],
    pub t_min: f32,
    pub t_max: f32,
}

impl PreparedRay {
    #[inline(always)]
    pub fn new(ray: &obvhs::ray::Ray) -> Self {
        let rcp = |x: f32| {
            let x = if x.abs() < DIRECTION_MIN {
                DIRECTION_MIN.copysign(x)
            } else {
                x
            };
            1.0 / x
        };
        Self {
            origin: ray.origin.to_array(),
            direction: ray.direction.to_array(),
            inv_direction: ray.direction.to_array().map(rcp),
            t_min: ray.tmin,
            t_max: ray.tmax,
        }
    }

    /// Bounds rows of the near and far planes per axis (by the direction's sign).
    #[inline(always)]
    pub fn near_far_rows(&self) -> ([usize; 3], [usize; 3]) {
        let near = |axis: usize| 2 * axis + usize::from(self.inv_direction[axis] < 0.0);
        (
            [near(0), near(1), near(2)],
            [near(0) ^ 1, near(1) ^ 1, near(2) ^ 1],
        )
    }
}

/// A triangle hit inside the wide tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LeafHit {
    pub block: u32,
    pub lane: u32,
    pub t: f32,
    /// Barycentrics as `RtTriangle::intersect` computes them: `(r·e2, r·e1) · (1/det)`.
    pub u: f32,
    pub v: f32,
}

/// A traversal stack entry: a child code and its entry distance.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct StackEntry {
    pub code: u32,
    pub t_near: f32,
}

/// Pushes `entry` at `*sp`, keeping the run of entries from `base` up sorted far to near (the
/// nearest on top, popped first): the insertion step of ordered closest-hit traversal.
#[inline(always)]
pub(super) fn push_sorted(
    stack: &mut [StackEntry],
    base: usize,
    sp: &mut usize,
    entry: StackEntry,
) {
    let mut j = *sp;
    stack[j] = entry;
    while j > base && stack[j - 1].t_near < stack[j].t_near {
        stack.swap(j - 1, j);
        j -= 1;
    }
    *sp += 1;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle(i: u32) -> RtTriangle {
        #[allow(clippy::cast_precision_loss)]
        let x = i as f32;
        RtTriangle::new(
            Vec3A::new(x, 0.0, 0.0),
            Vec3A::new(x + 1.0, 0.0, 0.0),
            Vec3A::new(x, 1.0, 0.0),
        )
    }

    /// Leaves of 3, 1, 2, 2 and 5 triangles: the 5 takes two blocks (4 + 1), the 3 fills the
    /// second, the 2 + 2 share a third, the 1 goes to the fullest block with room (the third
    /// would overflow, so a fourth): four blocks instead of six, and every leaf's block range
    /// holds all of its triangles.
    #[test]
    fn sibling_leaves_share_blocks() {
        let triangles: Vec<RtTriangle> = (0..13).map(triangle).collect();
        let leaves: Vec<(usize, Vec<u32>)> = vec![
            (0, vec![0, 1, 2]),
            (1, vec![3]),
            (2, vec![4, 5]),
            (3, vec![6, 7]),
            (4, vec![8, 9, 10, 11, 12]),
        ];
        let mut w = WideBvh {
            nodes: Vec::new(),
            blocks: Vec::new(),
            root: EMPTY_CHILD,
            stack_max: 1,
            references: 13,
            large: false,
        };
        let codes = w.pack_leaves(&leaves, &triangles).unwrap();
        assert_eq!(w.blocks.len(), 4, "blocks used");
        assert_eq!(codes.len(), leaves.len());
        for (slot, prims) in &leaves {
            let code = codes.iter().find(|(s, _)| s == slot).unwrap().1;
            assert_ne!(code & LEAF_FLAG, 0);
            let ids: Vec<u32> = leaf_blocks(code).flat_map(|b| w.blocks[b].ids).collect();
            for p in prims {
                assert!(ids.contains(p), "leaf {slot} lost triangle {p}");
            }
            let expected_blocks = prims.len().div_ceil(LANES);
            assert_eq!(leaf_blocks(code).len(), expected_blocks, "leaf {slot}");
        }
    }
}
