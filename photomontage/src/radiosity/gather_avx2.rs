//! AVX2 kernel of the shooting gather ([`super::shooting`]) for x86-64, selected at run time
//! (`is_x86_feature_detected!`): per link, the `S` unshot values of the source (kept in
//! registers for the source's whole run) times the factor, added to the receiver's `S`
//! accumulators four (then two, then one) at a time. Each lane does the same separate multiply
//! and add as the portable loop (no FMA), so the sums are the same bit for bit; the kernel only
//! does fewer instructions per link.
//!
//! # Known limitations
//! x86-64 only (other targets take the portable loop); no gain for `S` < 4 beyond the paired
//! lanes.
#![allow(unsafe_code)] // std::arch loads and stores, and the call of a `target_feature` function.

use std::arch::x86_64::{
    __m256d, _mm_add_pd, _mm_loadu_pd, _mm_mul_pd, _mm_set1_pd, _mm_storeu_pd, _mm256_add_pd,
    _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
};

/// Proof that this CPU has AVX2: only [`Token::new`] makes one, after checking.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Token(());

impl Token {
    /// A token if this CPU runs the kernel.
    pub fn new() -> Option<Self> {
        is_x86_feature_detected!("avx2").then_some(Self(()))
    }

    /// For each link `(receiver, factor)` of `links`: `acc[(receiver − base)·S ..][..S] +=
    /// factor · src`, in link order.
    #[inline]
    pub fn gather_run<const S: usize>(
        self,
        src: &[f64; S],
        receivers: &[u32],
        factors: &[f32],
        base: usize,
        acc: &mut [f64],
    ) {
        // SAFETY: a `Token` exists only if the CPU has AVX2 (`Token::new`).
        unsafe { gather_run_impl::<S>(src, receivers, factors, base, acc) }
    }
}

/// Vectors of four source values kept in registers (at most three, S ≤ 12).
const MAX_QUADS: usize = 3;

#[target_feature(enable = "avx2")]
fn gather_run_impl<const S: usize>(
    src: &[f64; S],
    receivers: &[u32],
    factors: &[f32],
    base: usize,
    acc: &mut [f64],
) {
    let quads = (S / 4).min(MAX_QUADS);
    let mut s4 = [_mm256_setzero_pd(); MAX_QUADS];
    for (q, v) in s4.iter_mut().enumerate().take(quads) {
        // SAFETY: 4q + 4 ≤ S values of `src` are read.
        *v = unsafe { _mm256_loadu_pd(src.as_ptr().add(4 * q)) };
    }
    let pair = 4 * quads + 2 <= S;
    // SAFETY (pair): 4·quads + 2 ≤ S values of `src` are read.
    let s2 = pair.then(|| unsafe { _mm_loadu_pd(src.as_ptr().add(4 * quads)) });
    let single = 4 * quads + if pair { 2 } else { 0 };
    for (rcv, f) in receivers.iter().zip(factors) {
        let f = f64::from(*f);
        let at = (*rcv as usize - base) * S;
        let dst: &mut [f64; S] = (&mut acc[at..at + S])
            .try_into()
            .unwrap_or_else(|_| unreachable!("S values per node"));
        let f4: __m256d = _mm256_set1_pd(f);
        for (q, v) in s4.iter().enumerate().take(quads) {
            // SAFETY: `dst` holds S ≥ 4q + 4 values; loads and stores are unaligned.
            unsafe {
                let p = dst.as_mut_ptr().add(4 * q);
                _mm256_storeu_pd(p, _mm256_add_pd(_mm256_loadu_pd(p), _mm256_mul_pd(f4, *v)));
            }
        }
        if let Some(v) = s2 {
            // SAFETY: `dst` holds S ≥ 4·quads + 2 values.
            unsafe {
                let p = dst.as_mut_ptr().add(4 * quads);
                _mm_storeu_pd(
                    p,
                    _mm_add_pd(_mm_loadu_pd(p), _mm_mul_pd(_mm_set1_pd(f), v)),
                );
            }
        }
        for j in single..S {
            dst[j] += f * src[j];
        }
    }
}
