//! AVX2 kernels for x86-64, selected at run time (`is_x86_feature_detected!`): the shooting
//! gather ([`super::shooting`]) and the sky transfer's facet sum ([`super::sky_transfer`]).
//!
//! **Gather.** Per link, the `S` unshot values of the source (kept in
//! registers for the source's whole run) times the factor, added to the receiver's `S` `f32`
//! accumulators eight (then four, then one) at a time. Each lane does the same separate multiply
//! and add as the portable loop (no FMA), so the sums are the same bit for bit; the kernel only
//! does fewer instructions per link.
//!
//! **Facet sum.** Eight facets at a time: their escaped-ray counts (`u8`) widened to `f32`, times
//! the facets' weights, added to eight lane sums; the same multiplies and adds in the same lanes
//! as the portable loop, so again the same bits.
//!
//! # Known limitations
//! x86-64 only (other targets take the portable loop); no gain for `S` < 4; at most 12 values
//! stay in registers (the shooting's strides are 3, 6, 9 and 12).
#![allow(unsafe_code)] // std::arch loads and stores, and the call of a `target_feature` function.

use std::arch::x86_64::{
    _mm_add_ps, _mm_loadl_epi64, _mm_loadu_ps, _mm_mul_ps, _mm_set1_ps, _mm_storeu_ps,
    _mm256_add_ps, _mm256_cvtepi32_ps, _mm256_cvtepu8_epi32, _mm256_loadu_ps, _mm256_mul_ps,
    _mm256_set1_ps, _mm256_setzero_ps, _mm256_storeu_ps,
};

/// Proof that this CPU has AVX2: only [`Token::new`] makes one, after checking.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Token(());

impl Token {
    /// A token if this CPU runs the kernel.
    pub fn new() -> Option<Self> {
        is_x86_feature_detected!("avx2").then_some(Self(()))
    }

    /// For each link `(receiver, factor)`: `acc[receiver·S ..][..S] += factor · src`, in link
    /// order (`receiver` is the offset from the first node of the range `acc` holds). Panics when
    /// the last receiver lies outside `acc` (checked once per run, not per link).
    ///
    /// # Safety
    /// `receivers` must be sorted ascending (as every run of [`super::source_rows::SourceRows`]
    /// is): the kernel indexes `acc` unchecked between the first and the last receiver.
    #[inline]
    pub unsafe fn gather_run<const S: usize>(
        self,
        src: &[f32; S],
        receivers: &[u16],
        factors: &[f32],
        acc: &mut [f32],
    ) {
        // SAFETY: a `Token` exists only if the CPU has AVX2 (`Token::new`); the receivers are
        // sorted (this function's contract).
        unsafe { gather_run_impl::<S>(src, receivers, factors, acc) }
    }

    /// The eight lane sums of `Σ_j hits[8b + j] · weights[b][j]` over blocks `b`
    /// (`hits.len()` = 8 · `weights.len()`).
    #[inline]
    pub fn escaped_lanes(self, hits: &[u8], weights: &[[f32; 8]]) -> [f32; 8] {
        assert_eq!(
            hits.len(),
            8 * weights.len(),
            "eight counts per block of weights"
        );
        // SAFETY: a `Token` exists only if the CPU has AVX2 (`Token::new`).
        unsafe { escaped_lanes_impl(hits, weights) }
    }
}

#[target_feature(enable = "avx2")]
fn escaped_lanes_impl(hits: &[u8], weights: &[[f32; 8]]) -> [f32; 8] {
    let mut acc = _mm256_setzero_ps();
    for (w, h) in weights.iter().zip(hits.chunks_exact(8)) {
        // SAFETY: `h` holds 8 bytes (one unaligned 64-bit load); `w` holds 8 values.
        unsafe {
            let counts =
                _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(h.as_ptr().cast())));
            acc = _mm256_add_ps(acc, _mm256_mul_ps(counts, _mm256_loadu_ps(w.as_ptr())));
        }
    }
    let mut lanes = [0.0_f32; 8];
    // SAFETY: `lanes` holds 8 values.
    unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), acc) };
    lanes
}

/// # Safety
/// As [`Token::gather_run`]: `receivers` sorted ascending.
#[target_feature(enable = "avx2")]
unsafe fn gather_run_impl<const S: usize>(
    src: &[f32; S],
    receivers: &[u16],
    factors: &[f32],
    acc: &mut [f32],
) {
    // Eight source values in one register where S ≥ 8, then four, then one at a time.
    // SAFETY (both loads): 8 ≤ S, and quad_at + 4 ≤ S, values of `src` are read.
    let s8 = (S >= 8).then(|| unsafe { _mm256_loadu_ps(src.as_ptr()) });
    let quad_at = if S >= 8 { 8 } else { 0 };
    let s4 = (quad_at + 4 <= S).then(|| unsafe { _mm_loadu_ps(src.as_ptr().add(quad_at)) });
    let single = quad_at + if s4.is_some() { 4 } else { 0 };
    // One check per run instead of one per link: a run's receivers are sorted (SourceRows), so
    // the last bounds them all.
    let Some(&last) = receivers.last() else {
        return;
    };
    assert!(
        (usize::from(last) + 1) * S <= acc.len(),
        "a run's receivers lie in its range"
    );
    debug_assert!(receivers.is_sorted(), "a run's receivers are sorted");
    let n = receivers.len().min(factors.len());
    let acc = acc.as_mut_ptr();
    for i in 0..n {
        // SAFETY: i < n ≤ both lengths; every receiver is at most the last (sorted, the
        // caller's contract), so `at + S` ≤ `acc.len()` by the check above.
        let (rcv, f) = unsafe { (*receivers.get_unchecked(i), *factors.get_unchecked(i)) };
        let at = usize::from(rcv) * S;
        // SAFETY: `at + S` ≤ `acc.len()` (above): `p` points at S values of `acc`.
        let p = unsafe { acc.add(at) };
        if let Some(v) = s8 {
            // SAFETY: `p` holds S ≥ 8 values; loads and stores are unaligned.
            unsafe {
                _mm256_storeu_ps(
                    p,
                    _mm256_add_ps(_mm256_loadu_ps(p), _mm256_mul_ps(_mm256_set1_ps(f), v)),
                );
            }
        }
        if let Some(v) = s4 {
            // SAFETY: `p` holds S ≥ quad_at + 4 values.
            unsafe {
                let q = p.add(quad_at);
                _mm_storeu_ps(
                    q,
                    _mm_add_ps(_mm_loadu_ps(q), _mm_mul_ps(_mm_set1_ps(f), v)),
                );
            }
        }
        for (j, s) in src.iter().enumerate().skip(single) {
            // SAFETY: j < S values at `p`.
            unsafe { *p.add(j) += f * s };
        }
    }
}
