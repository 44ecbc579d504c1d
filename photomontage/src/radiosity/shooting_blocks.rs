//! The per-patch passes of [`super::shoot`] cut into fixed blocks of whole patches: each block is
//! one task that writes only its own nodes, elements and patch powers, so a pass gives the same
//! values on any number of threads.

use super::super::topology::Topology;
use super::{PatchPowers, groups_of, patch_powers};

/// Elements per [`PatchBlock`] (at least; a block ends at a patch's end): enough to amortise a
/// task, few enough to balance two to dozens of threads on 50 000 elements.
pub(super) const BLOCK_ELEMENTS: usize = 256;

/// Consecutive patches, with their nodes and elements (half-open ranges): the unit of the
/// per-patch passes. The node range runs from the first patch's first node to the last patch's
/// last, so it holds the nodes between them (above the patches), which no pass writes.
pub(super) struct PatchBlock {
    pub(super) patches: (usize, usize),
    pub(super) nodes: (usize, usize),
    pub(super) elements: (usize, usize),
}

/// The patches cut into blocks of at least [`BLOCK_ELEMENTS`] elements, in patch order (a
/// fixed partition: a pass gives the same values on any number of threads, each patch being
/// computed on its own).
pub(super) fn patch_blocks(topology: &Topology) -> Vec<PatchBlock> {
    let (ranges, elements) = (&topology.patch_ranges, &topology.patch_elements);
    let mut out = Vec::new();
    let mut first = 0;
    for p in 0..ranges.len() {
        let last = p + 1 == ranges.len();
        if elements[p].1 - elements[first].0 >= BLOCK_ELEMENTS || last {
            out.push(PatchBlock {
                patches: (first, p + 1),
                nodes: (ranges[first].0, ranges[p].1),
                elements: (elements[first].0, elements[p].1),
            });
            first = p + 1;
        }
    }
    out
}

/// One block's leaves: B and the unshot part of its elements, and its patches' powers.
pub(super) struct BlockLeaves<'a> {
    pub(super) b: &'a mut [f64],
    pub(super) u: &'a mut [f32],
    total: &'a mut [f64],
    unshot: &'a mut [f64],
}

impl BlockLeaves<'_> {
    /// Sums the powers of patch `p` of `block` from its elements' B and unshot part (`K` groups,
    /// 0: any number).
    pub(super) fn sum_powers<const K: usize>(
        &mut self,
        topology: &Topology,
        block: &PatchBlock,
        p: usize,
    ) {
        let k = groups_of::<K>(self.total.len() / (block.patches.1 - block.patches.0));
        let stride = 3 * k;
        let (elo, ehi) = topology.patch_elements[p];
        let (x, y) = (
            (elo - block.elements.0) * stride,
            (ehi - block.elements.0) * stride,
        );
        let i = p - block.patches.0;
        patch_powers::<K>(
            &topology.areas[elo..ehi],
            &self.b[x..y],
            &self.u[x..y],
            &mut self.total[i * k..(i + 1) * k],
            &mut self.unshot[i * k..(i + 1) * k],
        );
    }
}

/// The leaves of every block: `b` and `u` (`stride` values per element) and the patches' powers
/// (`k` per patch) cut into the blocks' ranges.
pub(super) fn block_leaves<'a>(
    blocks: &[PatchBlock],
    stride: usize,
    k: usize,
    b: &'a mut [f64],
    u: &'a mut [f32],
    powers: &'a mut PatchPowers,
) -> Vec<BlockLeaves<'a>> {
    let PatchPowers { total, unshot } = powers;
    split_blocks(blocks, |b| b.elements, stride, b)
        .into_iter()
        .zip(split_blocks(blocks, |b| b.elements, stride, u))
        .zip(split_blocks(blocks, |b| b.patches, k, total))
        .zip(split_blocks(blocks, |b| b.patches, k, unshot))
        .map(|(((b, u), total), unshot)| BlockLeaves {
            b,
            u,
            total,
            unshot,
        })
        .collect()
}

/// `data` cut into the blocks' ranges (`range` of each block, `stride` values per unit; what
/// lies between blocks is left out).
pub(super) fn split_blocks<'a, T>(
    blocks: &[PatchBlock],
    range: impl Fn(&PatchBlock) -> (usize, usize),
    stride: usize,
    data: &'a mut [T],
) -> Vec<&'a mut [T]> {
    let (mut rest, mut at) = (data, 0);
    blocks
        .iter()
        .map(|block| {
            let (lo, hi) = range(block);
            let (_, tail) = std::mem::take(&mut rest).split_at_mut((lo - at) * stride);
            let (mine, tail) = tail.split_at_mut((hi - lo) * stride);
            rest = tail;
            at = hi;
            mine
        })
        .collect()
}
