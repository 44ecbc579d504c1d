//! The links stored by source for ΔB shooting ([`super::shooting`]), and the gather that reads
//! them: the links are split at a set of receiver-node ranges ([`receiver_ranges_for`],
//! balanced by links received) and stored range by range, and within a range source by source,
//! so each range is one task that walks its own arrays forwards and writes only its own
//! receivers. A receiver's sum runs over the shot nodes in node order and each run in receiver
//! order, exactly as one thread would, so the result is the same bit for bit on any number of
//! threads and with any number of ranges. With AVX2 the same sums run in the vector kernel of
//! [`super::gather_avx2`].
//!
//! The number of ranges trades the parallel split against the cost of a run: every shot node
//! has one run per range, so more ranges make shorter runs (on the studio's city block a 1° sun
//! step reads about 1 M links of 13 000 shot nodes, 5 links a run with 16 ranges; its gathers
//! took 3.4 ms with 16 ranges, 2.8 ms with 8 and 2.2 ms with 4 on one thread). So the rows take
//! two ranges per thread of the pool that builds them, at least 4 and at most 16.

use super::hierarchical::Link;

/// The most nodes a receiver range holds: a receiver is stored as its `u16` offset from the
/// range's first node (6 bytes a link with its factor, not 8), so a wider range is cut.
pub(super) const MAX_RANGE_NODES: usize = 1 << 16;
/// Receiver ranges of a shooting round for a pool of `threads` threads (module doc): the links
/// of every source row are split at the same receiver-node boundaries, and each range is
/// accumulated by one task. The sums do not depend on it.
pub(super) fn receiver_ranges_for(threads: usize) -> usize {
    (2 * threads).clamp(4, 16)
}

/// The vector kernel's token where the CPU has one.
#[cfg(target_arch = "x86_64")]
pub(super) type Simd = super::gather_avx2::Token;
/// No vector kernel off x86-64.
#[cfg(not(target_arch = "x86_64"))]
pub(super) type Simd = ();

#[cfg(target_arch = "x86_64")]
pub(super) fn simd_token() -> Option<Simd> {
    Simd::new()
}

#[cfg(not(target_arch = "x86_64"))]
pub(super) fn simd_token() -> Option<Simd> {
    None
}

/// The links as compressed rows per **source** node (receiver and factor), stored per receiver
/// range: range r holds, source by source, the links whose receiver lies in
/// `bounds[r]..bounds[r + 1]`, each source's run sorted by receiver. A receiver is stored as
/// its offset from `bounds[r]` (at most [`MAX_RANGE_NODES`] nodes a range). A range's task so reads its
/// own contiguous arrays in source order, with no cut of a long row to look up per source.
#[derive(Debug, Clone)]
pub(super) struct SourceRows {
    nodes: usize,
    /// Receiver ranges.
    ranges: usize,
    /// Run of source n in range r: `start[r·(nodes+1) + n]..start[r·(nodes+1) + n + 1]`.
    start: Vec<u32>,
    /// Receiver offset from its range's first node.
    receiver: Vec<u16>,
    form_factor: Vec<f32>,
    /// Receiver node ranges: range r is `bounds[r]..bounds[r + 1]` (balanced by links).
    pub(super) bounds: Vec<u32>,
    /// Links per source node, all ranges.
    row_len: Vec<u32>,
}

impl SourceRows {
    /// Transposes `links` (any order; each source's run is sorted by receiver, stably) into the
    /// ranges of the current rayon pool ([`receiver_ranges_for`]).
    pub(super) fn new(nodes: usize, links: &[Link]) -> Self {
        Self::with_ranges(
            nodes,
            links,
            receiver_ranges_for(rayon::current_num_threads()),
        )
    }

    /// Receiver ranges.
    pub(super) fn ranges(&self) -> usize {
        self.ranges
    }

    /// [`SourceRows::new`] into `ranges` receiver ranges (at least 1).
    #[allow(clippy::cast_possible_truncation)] // at most `max_links` links, node ids are u32
    pub(super) fn with_ranges(nodes: usize, links: &[Link], ranges: usize) -> Self {
        let ranges = ranges.max(1);
        let mut into = vec![0u64; nodes];
        for l in links {
            into[l.receiver as usize] += 1;
        }
        // Range boundaries at equal shares of the links received.
        let total: u64 = into.iter().sum();
        let mut bounds = vec![0u32; ranges + 1];
        let mut seen = 0u64;
        let mut r = 1;
        for (n, &k) in into.iter().enumerate() {
            while r < ranges && seen * ranges as u64 >= r as u64 * total {
                bounds[r] = n as u32;
                r += 1;
            }
            seen += k;
        }
        for b in &mut bounds[r..] {
            *b = nodes as u32;
        }
        // Ranges wider than MAX_RANGE_NODES are cut into equal parts (the sums do not depend on
        // the ranges).
        let mut cut = vec![0u32];
        for w in bounds.windows(2) {
            let (lo, hi) = (w[0] as usize, w[1] as usize);
            let parts = (hi - lo).div_ceil(MAX_RANGE_NODES).max(1);
            cut.extend((1..=parts).map(|i| (lo + (hi - lo) * i / parts) as u32));
        }
        let bounds = cut;
        let ranges = bounds.len() - 1;
        let range_of = |receiver: u32| bounds[1..].partition_point(|&b| b <= receiver);
        let width = nodes + 1;
        let mut start = vec![0u32; ranges * width];
        for l in links {
            start[range_of(l.receiver) * width + l.source as usize + 1] += 1;
        }
        // One prefix sum over range-major (range, source) runs.
        let mut acc = 0u32;
        for r in 0..ranges {
            let row = &mut start[r * width..(r + 1) * width];
            row[0] = acc;
            for n in 0..nodes {
                acc += row[n + 1];
                row[n + 1] = acc;
            }
        }
        let mut next: Vec<u32> = (0..ranges * width).map(|i| start[i]).collect();
        let mut pairs = vec![(0u16, 0f32); links.len()];
        for l in links {
            let range = range_of(l.receiver);
            let at = range * width + l.source as usize;
            let i = next[at] as usize;
            next[at] += 1;
            let offset = u16::try_from(l.receiver - bounds[range])
                .unwrap_or_else(|_| unreachable!("a range holds at most MAX_RANGE_NODES nodes"));
            pairs[i] = (offset, l.form_factor as f32);
        }
        for r in 0..ranges {
            for n in 0..nodes {
                let (a, z) = (
                    start[r * width + n] as usize,
                    start[r * width + n + 1] as usize,
                );
                pairs[a..z].sort_by_key(|&(rcv, _)| rcv);
            }
        }
        let (receiver, form_factor) = pairs.into_iter().unzip();
        let mut row_len = vec![0u32; nodes];
        for l in links {
            row_len[l.source as usize] += 1;
        }
        Self {
            nodes,
            ranges,
            start,
            receiver,
            form_factor,
            bounds,
            row_len,
        }
    }

    /// The links of node `n`'s row into receiver range `r`.
    fn cut(&self, n: usize, r: usize) -> std::ops::Range<usize> {
        let i = r * (self.nodes + 1) + n;
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// Links whose source is node `n`.
    pub(super) fn row_len(&self, n: usize) -> u64 {
        u64::from(self.row_len[n])
    }

    /// Per patch (node range), the links read when it is shot: all its nodes carry unshot
    /// radiosity then. Geometry only, so a transfer computes it once.
    pub(super) fn patch_links(&self, patch_ranges: &[(usize, usize)]) -> Vec<u64> {
        patch_ranges
            .iter()
            .map(|&(lo, hi)| (lo..hi).map(|n| self.row_len(n)).sum())
            .collect()
    }
}

/// Receiver range `r` gathers the unshot values `un` (`S` per node) of the `active` nodes
/// through their links into `acc` (the range's nodes from `bounds[r]` on, `S` per node): a receiver's sum runs over
/// `active` in order and each row in receiver order. With an AVX2 `token` the same sums run in
/// the vector kernel (bit for bit the same).
pub(super) fn gather_range<const S: usize>(
    rows: &SourceRows,
    r: usize,
    active: &[usize],
    un: &[f32],
    acc: &mut [f32],
    token: Option<Simd>,
) {
    for &n in active {
        let src: &[f32; S] = un[n * S..(n + 1) * S]
            .try_into()
            .unwrap_or_else(|_| unreachable!("S values per node"));
        let links = rows.cut(n, r);
        let (receivers, factors) = (&rows.receiver[links.clone()], &rows.form_factor[links]);
        #[cfg(target_arch = "x86_64")]
        if let Some(token) = token {
            // SAFETY: each source's run is sorted by receiver (`SourceRows::new`, and nothing
            // else writes the rows).
            #[allow(unsafe_code)] // the vector kernel's contract (gather_avx2.rs)
            unsafe {
                token.gather_run::<S>(src, receivers, factors, acc)
            };
            continue;
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = token;
        for (rcv, &f) in receivers.iter().zip(factors) {
            let at = usize::from(*rcv) * S;
            let dst: &mut [f32; S] = (&mut acc[at..at + S])
                .try_into()
                .unwrap_or_else(|_| unreachable!("S values per node"));
            for (d, s) in dst.iter_mut().zip(src) {
                *d += f * s;
            }
        }
    }
}

/// [`gather_range`] for any number of values per node.
pub(super) fn gather_range_dyn(
    rows: &SourceRows,
    r: usize,
    active: &[usize],
    un: &[f32],
    acc: &mut [f32],
    stride: usize,
) {
    for &n in active {
        let src = &un[n * stride..(n + 1) * stride];
        let links = rows.cut(n, r);
        for (rcv, f) in rows.receiver[links.clone()]
            .iter()
            .zip(&rows.form_factor[links])
        {
            let f = *f;
            let at = usize::from(*rcv) * stride;
            for (d, s) in acc[at..at + stride].iter_mut().zip(src) {
                *d += f * s;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every link lands in exactly one receiver range, the one holding its receiver; each
    /// source's links in a range are sorted by receiver; a source's runs over all ranges are its
    /// links; the ranges tile the nodes and the runs tile the arrays in (range, source) order.
    #[test]
    fn receiver_ranges_partition_every_row() {
        let nodes = 997;
        let mut state = 12_345u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) % m
        };
        #[allow(clippy::cast_possible_truncation)]
        let links: Vec<Link> = (0..20_000)
            .map(|_| Link {
                receiver: next(nodes) as u32,
                source: next(nodes) as u32,
                form_factor: 0.001,
            })
            .collect();
        let rows = SourceRows::with_ranges(nodes as usize, &links, 16);
        assert_eq!(rows.bounds[0], 0);
        assert_eq!(rows.bounds[rows.ranges()] as usize, nodes as usize);
        assert!(rows.bounds.windows(2).all(|w| w[0] <= w[1]));
        let mut at = 0;
        for r in 0..rows.ranges() {
            for n in 0..nodes as usize {
                let cut = rows.cut(n, r);
                assert_eq!(
                    cut.start, at,
                    "runs tile the arrays in (range, source) order"
                );
                at = cut.end;
            }
        }
        assert_eq!(at, links.len());
        for n in 0..nodes as usize {
            let mut expected: Vec<u32> = links
                .iter()
                .filter(|l| l.source as usize == n)
                .map(|l| l.receiver)
                .collect();
            expected.sort_unstable();
            let mut got = Vec::new();
            for r in 0..rows.ranges() {
                let (lo, hi) = (rows.bounds[r], rows.bounds[r + 1]);
                let run: Vec<u32> = rows.receiver[rows.cut(n, r)]
                    .iter()
                    .map(|&o| lo + u32::from(o))
                    .collect();
                assert!(run.windows(2).all(|w| w[0] <= w[1]));
                assert!(run.iter().all(|&x| lo <= x && x < hi));
                got.extend_from_slice(&run);
            }
            assert_eq!(got, expected, "row of node {n}");
            assert_eq!(rows.row_len(n), expected.len() as u64);
        }
        // Balanced: no range holds more than twice its share of the links.
        let share = links.len() / rows.ranges();
        for r in 0..rows.ranges() {
            let k: usize = (0..nodes as usize).map(|n| rows.cut(n, r).len()).sum();
            assert!(k <= 2 * share, "range {r} holds {k} links, share {share}");
        }
    }

    /// A receiver range wider than [`MAX_RANGE_NODES`] is cut (a receiver is stored as a `u16`
    /// offset in its range): 200 000 nodes asked for in one range make 4 ranges of at most
    /// 65 536 nodes, and the gathered sums, with and without the vector kernel, equal a plain
    /// loop over the active sources' links sorted by (source, receiver), bit for bit. Mutation
    /// check: storing the receiver without taking its range's first node off breaks it.
    #[test]
    fn wide_ranges_are_cut_and_sum_as_the_links() {
        const S: usize = 3;
        let nodes = 200_000usize;
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
        let links: Vec<Link> = (0..30_000u64)
            .map(|i| Link {
                receiver: (i * 2_654_435_761 % nodes as u64) as u32,
                source: (i * 40_503 % 997) as u32,
                form_factor: 1e-3 * (1 + i % 89) as f64 / 7.0,
            })
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let un: Vec<f32> = (0..nodes * S)
            .map(|i| ((i * 6151 % 1000) as f32 - 400.0) * 2.9e-3)
            .collect();
        let active: Vec<usize> = (0..997).filter(|n| n % 3 != 1).collect();
        let mut sorted: Vec<&Link> = links.iter().filter(|l| l.source % 3 != 1).collect();
        sorted.sort_by_key(|l| (l.source, l.receiver));
        let mut expected = vec![0.5_f32; nodes * S];
        for l in sorted {
            #[allow(clippy::cast_possible_truncation)]
            let f = l.form_factor as f32;
            for c in 0..S {
                expected[l.receiver as usize * S + c] += f * un[l.source as usize * S + c];
            }
        }
        let rows = SourceRows::with_ranges(nodes, &links, 1);
        assert_eq!(rows.ranges(), 4);
        assert!(
            rows.bounds
                .windows(2)
                .all(|w| (w[1] - w[0]) as usize <= MAX_RANGE_NODES)
        );
        for token in [None, simd_token()] {
            let mut acc = vec![0.5_f32; nodes * S];
            for r in 0..rows.ranges() {
                let (lo, hi) = (rows.bounds[r] as usize, rows.bounds[r + 1] as usize);
                gather_range::<S>(&rows, r, &active, &un, &mut acc[lo * S..hi * S], token);
            }
            assert!(
                acc.iter()
                    .zip(&expected)
                    .all(|(a, e)| a.to_bits() == e.to_bits()),
                "vector kernel: {}",
                token.is_some()
            );
        }
    }

    /// The AVX2 kernel gives the portable loop's sums bit for bit, for every stride the
    /// shooting uses.
    #[test]
    fn vector_gather_equals_the_portable_loop() {
        fn check<const S: usize>(rows: &SourceRows, nodes: usize, token: Simd) {
            #[allow(clippy::cast_precision_loss)]
            let un: Vec<f32> = (0..nodes * S)
                .map(|i| ((i * 7919 % 1000) as f32 - 500.0) * 1.37e-3)
                .collect();
            let active: Vec<usize> = (0..nodes).filter(|n| n % 3 != 1).collect();
            for r in 0..rows.ranges() {
                let width = (rows.bounds[r + 1] - rows.bounds[r]) as usize * S;
                let (mut a, mut b) = (vec![0.25_f32; width], vec![0.25_f32; width]);
                gather_range::<S>(rows, r, &active, &un, &mut a, None);
                gather_range::<S>(rows, r, &active, &un, &mut b, Some(token));
                assert!(
                    a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                    "S = {S}, range {r}"
                );
            }
        }
        let Some(token) = simd_token() else {
            eprintln!("notice: this CPU has no vector kernel; nothing to compare");
            return;
        };
        let nodes = 301;
        #[allow(clippy::cast_possible_truncation)]
        let links: Vec<Link> = (0..6000u64)
            .map(|i| Link {
                receiver: (i * 2_654_435_761 % nodes) as u32,
                source: (i * 40_503 % nodes) as u32,
                form_factor: 1e-4 * (1 + i % 97) as f64,
            })
            .collect();
        let rows = SourceRows::new(nodes as usize, &links);
        check::<3>(&rows, nodes as usize, token);
        check::<6>(&rows, nodes as usize, token);
        check::<9>(&rows, nodes as usize, token);
        check::<12>(&rows, nodes as usize, token);
    }

    /// The sums do not depend on the number of ranges: 1, 4, 7 and 16 ranges give the same
    /// receiver values bit for bit (the reason a pool may pick its own, `receiver_ranges_for`).
    /// Mutation check: walking the shot nodes backwards in odd ranges breaks it.
    #[test]
    fn any_number_of_ranges_gives_the_same_sums() {
        const S: usize = 3;
        let nodes = 433usize;
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
        let links: Vec<Link> = (0..9000u64)
            .map(|i| Link {
                receiver: (i * 2_654_435_761 % nodes as u64) as u32,
                source: ((i * i * 31 + i / 3) % nodes as u64) as u32,
                form_factor: 1e-3 * (1 + i % 89) as f64 / 7.0,
            })
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let un: Vec<f32> = (0..nodes * S)
            .map(|i| ((i * 6151 % 1000) as f32 - 400.0) * 2.9e-3)
            .collect();
        let active: Vec<usize> = (0..nodes).filter(|n| n % 5 != 2).collect();
        let sums = |ranges: usize| -> Vec<u32> {
            let rows = SourceRows::with_ranges(nodes, &links, ranges);
            assert_eq!(rows.ranges(), ranges);
            let mut acc = vec![0.5_f32; nodes * S];
            for r in 0..rows.ranges() {
                let (lo, hi) = (rows.bounds[r] as usize, rows.bounds[r + 1] as usize);
                gather_range::<S>(
                    &rows,
                    r,
                    &active,
                    &un,
                    &mut acc[lo * S..hi * S],
                    simd_token(),
                );
            }
            acc.iter().map(|v| v.to_bits()).collect()
        };
        let one = sums(1);
        for ranges in [4, 7, 16] {
            assert_eq!(sums(ranges), one, "{ranges} ranges");
        }
        assert_eq!(receiver_ranges_for(1), 4);
        assert_eq!(receiver_ranges_for(3), 6);
        assert_eq!(receiver_ranges_for(64), 16);
    }
}
