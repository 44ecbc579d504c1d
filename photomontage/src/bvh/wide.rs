//! The CPU layout of the BVH: an 8-wide tree whose nodes keep their children's boxes in
//! structure-of-arrays form, and leaves of up to four triangles in "Triangle4" form (Wald,
//! Benthin & Boulos 2008, "Getting rid of packets", and Embree's `BVH8` + `Triangle4`, Wald et
//! al. 2014, §4–5), so that one SIMD instruction tests a ray against eight boxes or four
//! triangles.
//!
//! The tree is collapsed from obvhs's binary PLOC tree (Meister & Bittner 2018) with
//! reinsertion and SAH leaf collapse (leaves of at most [`LEAF_TRIANGLES_MAX`] triangles): each
//! wide node repeatedly opens the child binary node of largest surface area until it has eight
//! children or only leaves are left (Wald et al. 2008, §3.1; Embree's "open largest" rule).
//!
//! Triangles are stored with the precomputed edges and normal of obvhs's `RtTriangle`
//! (`e1 = v0 − v1`, `e2 = v2 − v0`, `ng = e1 × e2`), so that the traversal kernels can evaluate
//! Möller–Trumbore (1997) with the same floating-point operations in the same order as
//! `RtTriangle::intersect` and return bit-identical distances.
//!
//! # Known limitations
//! The collapse is greedy (largest area first), not the cost-optimal collapse of Ylitie et al.
//! 2017; boxes are uncompressed `f32` (224 bytes a node), so the tree takes more memory than a
//! quantised CWBVH. The build after PLOC is sequential.

use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::rt_triangle::RtTriangle;

use super::BvhError;

/// Children per node (the AVX width in `f32`).
pub(super) const WIDTH: usize = 8;
/// Triangles per leaf block (the SSE width in `f32`).
pub(super) const LANES: usize = 4;
/// The SAH leaf collapse of the binary tree makes leaves of at most this many triangles.
pub(super) const LEAF_TRIANGLES_MAX: u32 = 4;

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
/// Unused lanes repeat lane 0 (the same hit twice changes nothing).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Tri4 {
    /// Vertex 0.
    pub v0: [[f32; LANES]; 3],
    /// `v0 − v1`.
    pub e1: [[f32; LANES]; 3],
    /// `v2 − v0`.
    pub e2: [[f32; LANES]; 3],
    /// `e1 × e2` (points against the counter-clockwise normal).
    pub ng: [[f32; LANES]; 3],
    /// Triangle ids in the caller's order.
    pub ids: [u32; LANES],
}

impl Tri4 {
    fn new(lanes: &[(u32, RtTriangle)]) -> Self {
        let mut b = Self {
            v0: [[0.0; LANES]; 3],
            e1: [[0.0; LANES]; 3],
            e2: [[0.0; LANES]; 3],
            ng: [[0.0; LANES]; 3],
            ids: [0; LANES],
        };
        for lane in 0..LANES {
            let (id, t) = lanes.get(lane).unwrap_or(&lanes[0]);
            b.ids[lane] = *id;
            for (dst, src) in [
                (&mut b.v0, t.v0),
                (&mut b.e1, t.e1),
                (&mut b.e2, t.e2),
                (&mut b.ng, t.ng),
            ] {
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
        RtTriangle {
            v0: get(&self.v0),
            e1: get(&self.e1),
            e2: get(&self.e2),
            ng: get(&self.ng),
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
    /// Triangle references in the leaves (pre-split triangles count once per reference).
    pub references: usize,
}

/// Collapses obvhs's binary tree over `triangles` (ids are indices into `triangles`).
pub(super) fn collapse(bvh2: &Bvh2, triangles: &[RtTriangle]) -> Result<WideBvh, BvhError> {
    let mut w = WideBvh {
        nodes: Vec::with_capacity(bvh2.nodes.len() / 4 + 1),
        blocks: Vec::with_capacity(bvh2.primitive_indices.len() / 2 + 1),
        root: EMPTY_CHILD,
        stack_max: 1,
        references: bvh2.primitive_indices.len(),
    };
    // Work list of (wide node index, binary node id) whose children are still to be filled.
    let mut work: Vec<(usize, usize)> = Vec::new();
    w.root = w.code_of(bvh2, triangles, 0, &mut work)?;
    while let Some((wide, id)) = work.pop() {
        let mut open: Vec<usize> = Vec::with_capacity(WIDTH);
        let first = bvh2.nodes[id].first_index as usize;
        open.extend([first, first + 1]);
        while open.len() < WIDTH {
            let largest = open
                .iter()
                .enumerate()
                .filter(|&(_, &c)| !bvh2.nodes[c].is_leaf())
                .max_by(|a, b| {
                    let area = |c: usize| bvh2.nodes[c].aabb().half_area();
                    area(*a.1).total_cmp(&area(*b.1))
                })
                .map(|(slot, _)| slot);
            let Some(slot) = largest else { break };
            let c = open.swap_remove(slot);
            let f = bvh2.nodes[c].first_index as usize;
            open.extend([f, f + 1]);
        }
        for (slot, &c) in open.iter().enumerate() {
            let code = w.code_of(bvh2, triangles, c, &mut work)?;
            let aabb = bvh2.nodes[c].aabb();
            let node = &mut w.nodes[wide];
            node.children[slot] = code;
            for axis in 0..3 {
                node.bounds[2 * axis][slot] = aabb.min[axis];
                node.bounds[2 * axis + 1][slot] = aabb.max[axis];
            }
        }
    }
    w.stack_max = w.stack_need();
    Ok(w)
}

impl WideBvh {
    /// The child code of binary node `id`: a new wide node (queued on `work`) or a leaf.
    fn code_of(
        &mut self,
        bvh2: &Bvh2,
        triangles: &[RtTriangle],
        id: usize,
        work: &mut Vec<(usize, usize)>,
    ) -> Result<u32, BvhError> {
        let node = &bvh2.nodes[id];
        if node.is_leaf() {
            let first = node.first_index as usize;
            let prims = &bvh2.primitive_indices[first..first + node.prim_count as usize];
            let aabb = node.aabb();
            return self.leaf_code(prims, triangles, [aabb.min, aabb.max]);
        }
        let index = self.push_node()?;
        work.push((index as usize, id));
        Ok(index)
    }

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
        let first = self.blocks.len();
        let count = prims.len().div_ceil(LANES).max(1);
        if first + count > BLOCK_INDEX_LIMIT {
            return Err(BvhError::TooManyTriangles {
                count: triangles.len(),
            });
        }
        for chunk in prims.chunks(LANES) {
            let lanes: Vec<(u32, RtTriangle)> =
                chunk.iter().map(|&p| (p, triangles[p as usize])).collect();
            self.blocks.push(Tri4::new(&lanes));
        }
        // Both fit their bit fields (checked above), so the casts are exact.
        #[allow(clippy::cast_possible_truncation)]
        Ok(LEAF_FLAG | (((count - 1) as u32) << LEAF_COUNT_SHIFT) | first as u32)
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
}

/// A traversal stack entry: a child code and its entry distance.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct StackEntry {
    pub code: u32,
    pub t_near: f32,
}
