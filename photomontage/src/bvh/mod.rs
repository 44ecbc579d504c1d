//! Bounding volume hierarchy over triangles for the CPU. A binary tree is built top-down by
//! binned SAH (`sah`, Wald 2007; or obvhs 0.4's PLOC, Meister & Bittner 2018, for fast
//! builds); `wide` collapses it by the
//! surface-area-heuristic-optimal programme of Ylitie, Karras & Laine 2017 into an 8-wide tree with
//! structure-of-arrays child boxes and "Triangle4" leaves (Wald, Benthin & Boulos 2008, "Getting
//! rid of packets"; Embree's `BVH8` + `Triangle4`, Wald et al. 2014). Traversal is ordered (nearest
//! child first) for closest hits and early-exit for any-hit, with Möller–Trumbore intersection
//! (1997) in `f32` computed exactly as obvhs's `RtTriangle::intersect`. The kernel is chosen once
//! when the BVH is built: explicit AVX2 + FMA (`avx2`) where the CPU has them, otherwise portable
//! code (`portable`; SSE2 by the compiler on x86-64). Closest-hit returns the triangle id,
//! distance, barycentrics and geometric normal; any-hit answers shadow queries; batch queries
//! spread over rayon (and, for closest hits on trees larger than the caches, walk two rays in
//! turn per thread with the AVX2 kernel, so that their cache misses overlap).
//!
//! Triangle ids in results are the caller's order. Batch queries split the rays into fixed
//! chunks of [`RAY_CHUNK`], so results are independent of the thread count.
//!
//! # Known limitations
//! Single precision: build the BVH in a local frame near the geometry (see
//! [`crate::scene::tracer`]). Intersection is not watertight: a ray through a shared edge can miss
//! both triangles in rare float ties (the Embree comparison counts these). No ray
//! packets, no AVX-512 kernel. No instancing and no motion blur.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod huge;
mod portable;
mod sah;
mod wide;

use glam::Vec3A;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::{BvhBuildParams, rt_triangle::RtTriangle, triangle::Triangle};
use rayon::prelude::*;

pub use obvhs::ray::Ray;

use wide::{LeafHit, PreparedRay, StackEntry, WideBvh};

/// Rays per rayon task in the batch queries (large enough to amortise scheduling, small enough
/// to balance two to dozens of threads on a million rays).
pub const RAY_CHUNK: usize = 4096;

/// Traversal stacks up to this many entries live on the call stack; deeper trees use the heap.
const INLINE_STACK: usize = 96;

/// Errors building a BVH.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BvhError {
    /// No triangles.
    #[error("cannot build a BVH over zero triangles")]
    Empty,
    /// More triangles than 32-bit ids (or the tree's leaf codes) can address.
    #[error("{count} triangles exceed the 32-bit id range")]
    TooManyTriangles {
        /// Triangle count.
        count: usize,
    },
    /// A vertex is NaN or infinite.
    #[error("triangle {triangle_id} has a non-finite vertex")]
    NonFinite {
        /// Offending triangle.
        triangle_id: usize,
    },
    /// The requested traversal kernel does not run on this CPU.
    #[error("the {kernel:?} traversal kernel is not available on this CPU")]
    KernelUnavailable {
        /// The kernel asked for.
        kernel: Kernel,
    },
}

/// BVH build effort: which binary tree the wide collapse starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    /// obvhs's PLOC (Meister & Bittner 2018) with its "fast" preset: the quickest build, slower
    /// traversal (interactive edits).
    Fast,
    /// Top-down binned SAH ([`sah`], Wald 2007): the default; on the Embree benchmark about
    /// 25 % faster primary rays than PLOC on a heightfield.
    #[default]
    Medium,
    /// The binned SAH tree improved by obvhs's reinsertion (Meister & Bittner 2018 §5), which
    /// lowers its SAH cost; slower build, traversal measured within noise of `Medium`.
    High,
}

/// Fraction of nodes reinsertion reconsiders per batch for [`BuildQuality::High`] (obvhs's
/// "medium" preset value).
const HIGH_REINSERTION_RATIO: f32 = 0.05;

/// The traversal code the queries run (chosen by [`Bvh::build`] for this CPU).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// Plain Rust on `f32` arrays (any architecture; SSE2 by the compiler on x86-64).
    Portable,
    /// Explicit AVX2 + FMA intrinsics (x86-64 CPUs that have both).
    Avx2Fma,
}

impl Kernel {
    /// Whether this CPU can run the kernel.
    #[must_use]
    pub fn is_available(self) -> bool {
        match self {
            Self::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Self::Avx2Fma => avx2::Token::new().is_some(),
            #[cfg(not(target_arch = "x86_64"))]
            Self::Avx2Fma => false,
        }
    }

    /// The fastest kernel this CPU runs.
    #[must_use]
    pub fn best_available() -> Self {
        if Self::Avx2Fma.is_available() {
            Self::Avx2Fma
        } else {
            Self::Portable
        }
    }
}

/// A closest-hit result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhHit {
    /// Index of the triangle in the order given to [`Bvh::build`].
    pub triangle_id: u32,
    /// Ray parameter of the hit (distance when the direction is unit length).
    pub t: f32,
    /// Barycentric weights (u, v) of vertices 1 and 2; vertex 0 has 1 − u − v.
    pub barycentric: [f32; 2],
    /// Unit geometric normal `(v1 − v0) × (v2 − v0)`, normalised (front side is counter-clockwise).
    pub normal_geometric: [f32; 3],
}

/// The selected kernel, with the proof that the CPU runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dispatch {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2(avx2::Token),
}

impl Dispatch {
    fn new(kernel: Kernel) -> Option<Self> {
        match kernel {
            Kernel::Portable => Some(Self::Portable),
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2Fma => avx2::Token::new().map(Self::Avx2),
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2Fma => None,
        }
    }

    fn kernel(self) -> Kernel {
        match self {
            Self::Portable => Kernel::Portable,
            #[cfg(target_arch = "x86_64")]
            Self::Avx2(_) => Kernel::Avx2Fma,
        }
    }
}

/// A wide BVH over triangles.
#[derive(Clone)]
pub struct Bvh {
    wide: WideBvh,
    dispatch: Dispatch,
}

impl std::fmt::Debug for Bvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bvh")
            .field("leaf_blocks", &self.wide.blocks.len())
            .field("nodes", &self.wide.nodes.len())
            .field("references", &self.wide.references)
            .field("stack_max", &self.wide.stack_max)
            .field("kernel", &self.kernel())
            .finish()
    }
}

impl Bvh {
    /// Builds the BVH; uses the current rayon pool. Selects [`Kernel::best_available`].
    ///
    /// # Errors
    /// [`BvhError`] for no triangles, too many, or non-finite vertices.
    pub fn build(triangles: &[[Vec3A; 3]], quality: BuildQuality) -> Result<Self, BvhError> {
        if triangles.is_empty() {
            return Err(BvhError::Empty);
        }
        if u32::try_from(triangles.len()).is_err() {
            return Err(BvhError::TooManyTriangles {
                count: triangles.len(),
            });
        }
        if let Some(triangle_id) = triangles
            .iter()
            .position(|t| !t.iter().all(|v| v.is_finite()))
        {
            return Err(BvhError::NonFinite { triangle_id });
        }
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|t| Triangle {
                v0: t[0],
                v1: t[1],
                v2: t[2],
            })
            .collect();
        let bvh2 = match quality {
            BuildQuality::Fast => wide::binary_tree(&tris, &BvhBuildParams::fast_build()),
            BuildQuality::Medium => sah::binary_tree(&tris),
            BuildQuality::High => {
                let mut bvh2 = sah::binary_tree(&tris);
                ReinsertionOptimizer::default().run(&mut bvh2, HIGH_REINSERTION_RATIO, None);
                bvh2
            }
        };
        let rt: Vec<RtTriangle> = tris.iter().map(RtTriangle::from).collect();
        drop(tris);
        let mut wide = wide::collapse(&bvh2, &rt)?;
        wide.nodes = huge::on_huge_pages(std::mem::take(&mut wide.nodes));
        wide.blocks = huge::on_huge_pages(std::mem::take(&mut wide.blocks));
        Ok(Self {
            wide,
            dispatch: Dispatch::new(Kernel::best_available()).unwrap_or(Dispatch::Portable),
        })
    }

    /// The traversal kernel the queries use.
    #[must_use]
    pub fn kernel(&self) -> Kernel {
        self.dispatch.kernel()
    }

    /// Makes the queries use `kernel` (to compare kernels, or to test one).
    ///
    /// # Errors
    /// [`BvhError::KernelUnavailable`] if this CPU cannot run it (nothing changes).
    pub fn set_kernel(&mut self, kernel: Kernel) -> Result<(), BvhError> {
        self.dispatch = Dispatch::new(kernel).ok_or(BvhError::KernelUnavailable { kernel })?;
        Ok(())
    }

    /// Number of triangles in the leaves.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.wide.references
    }

    /// Runs `f` with a traversal stack of the size this tree needs: the smallest of three
    /// inline sizes that holds it (the stack is zeroed per query, a `memset` that a radiosity
    /// precompute's millions of shadow rays paid at 3–4 % of its time with one 96-entry size).
    #[inline]
    fn with_stack<R>(&self, f: impl FnOnce(&mut [StackEntry]) -> R) -> R {
        let need = self.wide.stack_max;
        if need <= INLINE_STACK / 4 {
            let mut stack = [StackEntry::default(); INLINE_STACK / 4];
            f(&mut stack)
        } else if need <= INLINE_STACK / 2 {
            let mut stack = [StackEntry::default(); INLINE_STACK / 2];
            f(&mut stack)
        } else if need <= INLINE_STACK {
            let mut stack = [StackEntry::default(); INLINE_STACK];
            f(&mut stack)
        } else {
            f(&mut vec![StackEntry::default(); self.wide.stack_max])
        }
    }

    #[inline]
    fn closest_leaf_hit(&self, ray: &Ray, stack: &mut [StackEntry]) -> Option<LeafHit> {
        let ray = PreparedRay::new(ray);
        match self.dispatch {
            Dispatch::Portable => portable::closest(&self.wide, &ray, stack),
            #[cfg(target_arch = "x86_64")]
            Dispatch::Avx2(token) => token.closest(&self.wide, &ray, stack),
        }
    }

    #[inline]
    fn any_hit_with(&self, ray: &Ray, stack: &mut [StackEntry]) -> bool {
        let ray = PreparedRay::new(ray);
        match self.dispatch {
            Dispatch::Portable => portable::any(&self.wide, &ray, stack),
            #[cfg(target_arch = "x86_64")]
            Dispatch::Avx2(token) => token.any(&self.wide, &ray, stack),
        }
    }

    /// The hit record of a leaf hit: the kernel's barycentrics, and the normal computed with
    /// obvhs's `RtTriangle` from the stored values.
    fn hit_record(leaf: LeafHit, blocks: &[wide::Tri4]) -> BvhHit {
        let block = &blocks[leaf.block as usize];
        let tri = block.triangle(leaf.lane as usize);
        let n = tri.compute_normal();
        BvhHit {
            triangle_id: block.ids[leaf.lane as usize],
            t: leaf.t,
            barycentric: [leaf.u, leaf.v],
            normal_geometric: [n.x, n.y, n.z],
        }
    }

    #[inline]
    fn closest_hit_with(&self, ray: &Ray, stack: &mut [StackEntry]) -> Option<BvhHit> {
        self.closest_leaf_hit(ray, stack)
            .map(|leaf| Self::hit_record(leaf, &self.wide.blocks))
    }

    /// The closest intersection with `ray.tmin ≤ t ≤ ray.tmax`.
    #[must_use]
    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<BvhHit> {
        self.with_stack(|stack| self.closest_hit_with(ray, stack))
    }

    /// Whether anything is hit with `ray.tmin ≤ t ≤ ray.tmax` (shadow rays: set `tmax` just short
    /// of the light).
    #[must_use]
    #[inline]
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.with_stack(|stack| self.any_hit_with(ray, stack))
    }

    /// Closest hits of many rays, in parallel on the current rayon pool.
    ///
    /// # Panics
    /// If `out` and `rays` differ in length.
    pub fn closest_hits_into(&self, rays: &[Ray], out: &mut [Option<BvhHit>]) {
        assert_eq!(rays.len(), out.len(), "one output per ray");
        rays.par_chunks(RAY_CHUNK)
            .zip(out.par_chunks_mut(RAY_CHUNK))
            .for_each(|(rays, out)| {
                #[cfg(target_arch = "x86_64")]
                if let Dispatch::Avx2(token) = self.dispatch
                    && self.wide.large
                {
                    self.closest_pairs_into(token, rays, out);
                    return;
                }
                self.with_stack(|stack| {
                    for (ray, o) in rays.iter().zip(out) {
                        *o = self.closest_hit_with(ray, stack);
                    }
                });
            });
    }

    /// Closest hits two rays at a time with the AVX2 kernel's interleaved traversal.
    #[cfg(target_arch = "x86_64")]
    fn closest_pairs_into(&self, token: avx2::Token, rays: &[Ray], out: &mut [Option<BvhHit>]) {
        let record = |leaf: Option<LeafHit>| leaf.map(|l| Self::hit_record(l, &self.wide.blocks));
        self.with_stack(|stack_a| {
            self.with_stack(|stack_b| {
                let mut rays_2 = rays.chunks_exact(2);
                let mut out_2 = out.chunks_exact_mut(2);
                for (r, o) in (&mut rays_2).zip(&mut out_2) {
                    let (a, b) = (PreparedRay::new(&r[0]), PreparedRay::new(&r[1]));
                    let [hit_a, hit_b] =
                        token.closest_pair(&self.wide, [&a, &b], [&mut *stack_a, &mut *stack_b]);
                    o[0] = record(hit_a);
                    o[1] = record(hit_b);
                }
                for (r, o) in rays_2.remainder().iter().zip(out_2.into_remainder()) {
                    *o = self.closest_hit_with(r, stack_a);
                }
            });
        });
    }

    /// Any-hit answers of many rays, in parallel on the current rayon pool.
    ///
    /// # Panics
    /// If `out` and `rays` differ in length.
    pub fn any_hits_into(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one output per ray");
        rays.par_chunks(RAY_CHUNK)
            .zip(out.par_chunks_mut(RAY_CHUNK))
            .for_each(|(rays, out)| {
                self.with_stack(|stack| {
                    for (ray, o) in rays.iter().zip(out) {
                        *o = self.any_hit_with(ray, stack);
                    }
                });
            });
    }

    /// Any-hit answers of `rays` in order on the calling thread, with one traversal stack for
    /// all of them (zeroed once, not per ray: a kernel reads only the entries it pushed). For a
    /// caller that is itself one task of a parallel loop (a radiosity sky transfer's rays of one
    /// element).
    ///
    /// # Panics
    /// If `out` and `rays` differ in length.
    pub fn any_hits_here(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one output per ray");
        self.with_stack(|stack| {
            for (ray, o) in rays.iter().zip(out) {
                *o = self.any_hit_with(ray, stack);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3a;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Brute force and BVH run the same f32 intersection code, so t agrees exactly; 1e-6 relative
    /// only absorbs nothing but documents the comparison.
    const T_REL_TOL: f32 = 1e-6;

    fn random_soup(n: usize, seed: u64) -> Vec<[Vec3A; 3]> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let c = vec3a(
                    rng.random_range(-10.0..10.0),
                    rng.random_range(-10.0..10.0),
                    rng.random_range(-10.0..10.0),
                );
                let mut v = || {
                    c + vec3a(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    )
                };
                [v(), v(), v()]
            })
            .collect()
    }

    fn brute_force(tris: &[[Vec3A; 3]], ray: &Ray) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for (i, t) in tris.iter().enumerate() {
            let d = RtTriangle::new(t[0], t[1], t[2]).intersect(ray);
            if d.is_finite() && best.is_none_or(|(_, b)| d < b) {
                best = Some((u32::try_from(i).unwrap(), d));
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_oracle() {
        let tris = random_soup(2000, 1);
        let bvh = Bvh::build(&tris, BuildQuality::Medium).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                let o = vec3a(
                    rng.random_range(-12.0..12.0),
                    rng.random_range(-12.0..12.0),
                    rng.random_range(-12.0..12.0),
                );
                let d = vec3a(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
                .normalize();
                Ray::new_inf(o, d)
            })
            .collect();
        let mut hits = vec![None; rays.len()];
        bvh.closest_hits_into(&rays, &mut hits);
        let mut any = vec![false; rays.len()];
        bvh.any_hits_into(&rays, &mut any);
        // One stack for every ray of a batch answers as a fresh stack per ray.
        let mut here = vec![false; rays.len()];
        bvh.any_hits_here(&rays, &mut here);
        assert_eq!(here, any);
        let mut n_hit = 0;
        for ((ray, hit), any) in rays.iter().zip(&hits).zip(&any) {
            let oracle = brute_force(&tris, ray);
            assert_eq!(hit.is_some(), oracle.is_some());
            assert_eq!(*any, oracle.is_some());
            if let (Some(h), Some((id, t))) = (hit, oracle) {
                n_hit += 1;
                assert!((h.t - t).abs() <= T_REL_TOL * t, "{} vs {t}", h.t);
                // Equal t from different triangles is a legitimate tie; otherwise same id.
                if (h.t - t).abs() > 0.0 {
                    assert_eq!(h.triangle_id, id);
                }
            }
        }
        assert!(n_hit > 200, "the test must exercise hits, got {n_hit}");
    }

    #[test]
    fn hit_record_has_barycentrics_and_normal() {
        let tri = [
            vec3a(0.0, 0.0, 0.0),
            vec3a(2.0, 0.0, 0.0),
            vec3a(0.0, 4.0, 0.0),
        ];
        let bvh = Bvh::build(&[tri], BuildQuality::Fast).unwrap();
        let ray = Ray::new_inf(vec3a(0.5, 1.0, 3.0), vec3a(0.0, 0.0, -1.0));
        let h = bvh.closest_hit(&ray).unwrap();
        assert!((h.t - 3.0).abs() < 1e-6);
        // Point (0.5, 1, 0) = 0.25·v1 + 0.25·v2 + 0.5·v0.
        assert!(
            (h.barycentric[0] - 0.25).abs() < 1e-6 && (h.barycentric[1] - 0.25).abs() < 1e-6,
            "{:?}",
            h.barycentric
        );
        assert!((h.normal_geometric[2] - 1.0).abs() < 1e-6 && h.normal_geometric[0].abs() < 1e-6);
        // Shadow ray stopped short of the triangle does not hit it.
        assert!(!bvh.any_hit(&Ray::new(ray.origin, ray.direction, 0.0, 2.9)));
        assert!(bvh.any_hit(&Ray::new(ray.origin, ray.direction, 0.0, 3.1)));
    }

    #[test]
    fn thread_count_does_not_change_results() {
        let tris = random_soup(500, 3);
        let bvh = Bvh::build(&tris, BuildQuality::Fast).unwrap();
        let rays: Vec<Ray> = (0..10_000)
            .map(|i| {
                let a = f32::from(u16::try_from(i).unwrap()) * 0.001;
                Ray::new_inf(
                    vec3a(0.0, 0.0, -15.0),
                    vec3a(a.sin() * 0.5, a.cos() * 0.5, 1.0).normalize(),
                )
            })
            .collect();
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut out = vec![None; rays.len()];
            pool.install(|| bvh.closest_hits_into(&rays, &mut out));
            out
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn build_errors() {
        assert_eq!(
            Bvh::build(&[], BuildQuality::Fast).unwrap_err(),
            BvhError::Empty
        );
        let bad = [[
            vec3a(0.0, 0.0, 0.0),
            vec3a(f32::NAN, 0.0, 0.0),
            vec3a(0.0, 1.0, 0.0),
        ]];
        assert_eq!(
            Bvh::build(&bad, BuildQuality::Fast).unwrap_err(),
            BvhError::NonFinite { triangle_id: 0 }
        );
    }

    /// Every kernel this CPU runs (the tests force each one).
    fn kernels() -> Vec<Kernel> {
        [Kernel::Portable, Kernel::Avx2Fma]
            .into_iter()
            .filter(|k| k.is_available())
            .collect()
    }

    fn with_kernel(bvh: &Bvh, kernel: Kernel) -> Bvh {
        let mut b = bvh.clone();
        b.set_kernel(kernel).unwrap();
        b
    }

    fn random_rays(n: usize, seed: u64, extent: f32) -> Vec<Ray> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let o = vec3a(
                    rng.random_range(-extent..extent),
                    rng.random_range(-extent..extent),
                    rng.random_range(-extent..extent),
                );
                let d = vec3a(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
                .normalize();
                let t_min = rng.random_range(0.0..2.0);
                let t_max = rng.random_range(t_min..40.0);
                Ray::new(o, d, t_min, t_max)
            })
            .collect()
    }

    /// Checks closest and any hit of every ray against the brute-force oracle: same `t` bit for
    /// bit (all kernels evaluate `RtTriangle::intersect`'s arithmetic), the same triangle unless
    /// two triangles tie exactly, and the hit record of that triangle. Returns the hit count.
    fn check_against_oracle(tris: &[[Vec3A; 3]], bvh: &Bvh, rays: &[Ray]) -> usize {
        let mut n_hit = 0;
        for ray in rays {
            let oracle = brute_force(tris, ray);
            let hit = bvh.closest_hit(ray);
            assert_eq!(
                hit.is_some(),
                oracle.is_some(),
                "{:?} {ray:?}",
                bvh.kernel()
            );
            assert_eq!(
                bvh.any_hit(ray),
                oracle.is_some(),
                "{:?} {ray:?}",
                bvh.kernel()
            );
            if let (Some(h), Some((id, t))) = (hit, oracle) {
                n_hit += 1;
                assert_eq!(h.t.to_bits(), t.to_bits(), "{:?} {ray:?}", bvh.kernel());
                let tri = tris[h.triangle_id as usize];
                let rt = RtTriangle::new(tri[0], tri[1], tri[2]);
                assert_eq!(rt.intersect(ray).to_bits(), t.to_bits(), "tie partner at t");
                if h.triangle_id == id {
                    // u, v as `RtTriangle::intersect` forms them (a product with 1/det;
                    // `compute_barycentric` divides, which can differ in the last bit).
                    let r = ray.direction.cross(rt.v0 - ray.origin);
                    let inv_det = 1.0 / rt.ng.dot(ray.direction);
                    let uv = [r.dot(rt.e2) * inv_det, r.dot(rt.e1) * inv_det];
                    let n = rt.compute_normal();
                    // Same stored values, same arithmetic: the same bits.
                    assert_eq!(h.barycentric.map(f32::to_bits), uv.map(f32::to_bits));
                    assert_eq!(
                        h.normal_geometric.map(f32::to_bits),
                        [n.x, n.y, n.z].map(f32::to_bits)
                    );
                }
            }
        }
        n_hit
    }

    #[test]
    fn every_kernel_matches_brute_force_with_t_limits() {
        let tris = random_soup(1500, 11);
        let mut bvh = Bvh::build(&tris, BuildQuality::Medium).unwrap();
        let rays = random_rays(1500, 12, 12.0);
        // A tree this small is traversed without prefetching and one ray at a time; force the
        // large-tree traversal too (prefetches and two rays in turn: the answers must not change).
        assert!(!bvh.wide.large);
        for large in [false, true] {
            bvh.wide.large = large;
            for kernel in kernels() {
                let bvh = with_kernel(&bvh, kernel);
                let n_hit = check_against_oracle(&tris, &bvh, &rays);
                assert!(
                    n_hit > 150,
                    "{kernel:?}: the test must exercise hits, got {n_hit}"
                );
                // Batches (an odd count: pairs and one ray alone) answer as single queries.
                let odd = &rays[..rays.len() - 1];
                let mut hits = vec![None; odd.len()];
                bvh.closest_hits_into(odd, &mut hits);
                let mut any = vec![false; odd.len()];
                bvh.any_hits_into(odd, &mut any);
                for ((ray, hit), any) in odd.iter().zip(&hits).zip(&any) {
                    assert_eq!(
                        *hit,
                        bvh.closest_hit(ray),
                        "{kernel:?} large {large} {ray:?}"
                    );
                    assert_eq!(*any, bvh.any_hit(ray), "{kernel:?} large {large} {ray:?}");
                }
            }
        }
    }

    #[test]
    fn every_kernel_and_quality_matches_brute_force_on_axis_rays() {
        let tris = random_soup(800, 21);
        let mut rng = ChaCha8Rng::seed_from_u64(22);
        let axes = [
            vec3a(1.0, 0.0, 0.0),
            vec3a(-1.0, 0.0, 0.0),
            vec3a(0.0, 1.0, 0.0),
            vec3a(0.0, -1.0, 0.0),
            vec3a(0.0, 0.0, 1.0),
            vec3a(0.0, 0.0, -1.0),
        ];
        let rays: Vec<Ray> = (0..1200)
            .map(|i| {
                let o = vec3a(
                    rng.random_range(-12.0..12.0),
                    rng.random_range(-12.0..12.0),
                    rng.random_range(-12.0..12.0),
                );
                Ray::new_inf(o, axes[i % axes.len()])
            })
            .collect();
        for quality in [BuildQuality::Fast, BuildQuality::High] {
            let bvh = Bvh::build(&tris, quality).unwrap();
            for kernel in kernels() {
                let n_hit = check_against_oracle(&tris, &with_kernel(&bvh, kernel), &rays);
                assert!(n_hit > 100, "{kernel:?}: too few hits ({n_hit})");
            }
        }
    }

    #[test]
    fn rays_in_the_plane_of_faces() {
        // A floor of unit squares at z = 0 and a wall at x = 5.
        let mut tris = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                let (x, y) = (i as f32 - 5.0, j as f32 - 5.0);
                let [a, b, c, d] = [
                    vec3a(x, y, 0.0),
                    vec3a(x + 1.0, y, 0.0),
                    vec3a(x + 1.0, y + 1.0, 0.0),
                    vec3a(x, y + 1.0, 0.0),
                ];
                tris.extend([[a, b, c], [a, c, d]]);
            }
        }
        tris.push([
            vec3a(5.0, -5.0, -1.0),
            vec3a(5.0, 5.0, -1.0),
            vec3a(5.0, 0.0, 4.0),
        ]);
        let bvh = Bvh::build(&tris, BuildQuality::Medium).unwrap();
        for kernel in kernels() {
            let bvh = with_kernel(&bvh, kernel);
            // In the floor plane, along x: the floor is edge-on (determinant 0), the wall is hit.
            let grazing = Ray::new_inf(vec3a(-7.0, 0.3, 0.0), vec3a(1.0, 0.0, 0.0));
            let h = bvh.closest_hit(&grazing).unwrap();
            assert_eq!(h.triangle_id, 200, "{kernel:?}");
            assert!(
                (h.t - 12.0).abs() <= T_REL_TOL * 12.0,
                "{kernel:?}: {}",
                h.t
            );
            // Parallel above the floor and short of the wall: nothing.
            let above = Ray::new(vec3a(-7.0, 0.3, 0.5), vec3a(1.0, 0.0, 0.0), 0.0, 11.9);
            assert!(bvh.closest_hit(&above).is_none() && !bvh.any_hit(&above));
            // Straight down onto the floor.
            let down = Ray::new_inf(vec3a(0.25, 0.5, 3.0), vec3a(0.0, 0.0, -1.0));
            let t = bvh.closest_hit(&down).unwrap().t;
            assert!((t - 3.0).abs() <= T_REL_TOL * 3.0, "{kernel:?}: {t}");
            let rays: Vec<Ray> = (0..400)
                .map(|i| {
                    let a = i as f32 * 0.0157;
                    Ray::new_inf(vec3a(0.1, 0.2, 0.0), vec3a(a.cos(), a.sin(), 0.0))
                })
                .collect();
            check_against_oracle(&tris, &bvh, &rays);
        }
    }

    #[test]
    fn oversized_binary_leaf_is_split_into_blocks() {
        // A hand-made binary tree whose only leaf holds 300 triangles (more than one leaf code
        // can name), traced against the oracle.
        let tris = random_soup(300, 31);
        let rt: Vec<RtTriangle> = tris
            .iter()
            .map(|t| RtTriangle::new(t[0], t[1], t[2]))
            .collect();
        let mut aabb = obvhs::aabb::Aabb::empty();
        for t in &tris {
            for v in t {
                aabb.extend(*v);
            }
        }
        let bvh2 = obvhs::bvh2::Bvh2 {
            nodes: vec![obvhs::bvh2::node::Bvh2Node::new(aabb, 300, 0)],
            primitive_indices: (0..300).collect(),
            ..Default::default()
        };
        let wide = wide::collapse(&bvh2, &rt).unwrap();
        assert_eq!(wide.references, 300);
        let mut bvh = Bvh {
            wide,
            dispatch: Dispatch::Portable,
        };
        for kernel in kernels() {
            bvh.set_kernel(kernel).unwrap();
            let n_hit = check_against_oracle(&tris, &bvh, &random_rays(1000, 32, 12.0));
            assert!(n_hit > 40, "{kernel:?}: too few hits ({n_hit})");
        }
    }

    #[test]
    fn unavailable_kernel_is_refused() {
        let mut bvh = Bvh::build(&random_soup(10, 41), BuildQuality::Fast).unwrap();
        assert_eq!(bvh.kernel(), Kernel::best_available());
        for kernel in [Kernel::Portable, Kernel::Avx2Fma] {
            let result = bvh.set_kernel(kernel);
            if kernel.is_available() {
                assert_eq!(result, Ok(()));
                assert_eq!(bvh.kernel(), kernel);
            } else {
                assert_eq!(result, Err(BvhError::KernelUnavailable { kernel }));
            }
        }
    }
}
