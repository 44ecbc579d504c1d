//! Bounding volume hierarchy over triangles: obvhs's compressed wide BVH8 (CWBVH, Ylitie, Karras
//! & Laine 2017, "Efficient incoherent ray traversal on GPUs using compressed wide BVHs"), built by
//! PLOC (Meister & Bittner 2018) with reinsertion optimisation, traced with Möller–Trumbore
//! intersection (1997) in `f32`. Closest-hit returns the triangle id, distance, barycentrics and
//! geometric normal; any-hit answers shadow queries; batch queries spread over rayon.
//!
//! Triangles are stored in BVH leaf order for locality; ids in results are the caller's order.
//! Batch queries split the rays into fixed chunks of [`RAY_CHUNK`], so results are independent of
//! the thread count.
//!
//! # Known limitations
//! Single precision: build the BVH in a local frame near the geometry (see
//! [`crate::scene::tracer`]). Intersection is not watertight: a ray through a shared edge can miss
//! both triangles in rare float ties (the Embree comparison counts these). No instancing and no
//! motion blur.

use std::time::Duration;

use glam::Vec3A;
use obvhs::{
    BvhBuildParams, cwbvh::CwBvh, ray::RayHit, rt_triangle::RtTriangle, triangle::Triangle,
};
use rayon::prelude::*;

pub use obvhs::ray::Ray;

/// Rays per rayon task in the batch queries (large enough to amortise scheduling, small enough
/// to balance two to dozens of threads on a million rays).
pub const RAY_CHUNK: usize = 4096;

/// Errors building a BVH.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BvhError {
    /// No triangles.
    #[error("cannot build a BVH over zero triangles")]
    Empty,
    /// More triangles than 32-bit ids can address.
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
}

/// BVH build effort (obvhs presets).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    /// Fastest build, slower traversal (interactive edits).
    Fast,
    /// obvhs's "medium": about Embree's build time with faster traversal.
    #[default]
    Medium,
    /// Spatial pre-splits and more reinsertion: best traversal, slow build.
    High,
}

impl BuildQuality {
    fn params(self) -> BvhBuildParams {
        match self {
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::High => BvhBuildParams::slow_build(),
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

/// A CWBVH over triangles.
#[derive(Clone)]
pub struct Bvh {
    cwbvh: CwBvh,
    /// Triangles in leaf order.
    triangles: Vec<RtTriangle>,
}

impl std::fmt::Debug for Bvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bvh")
            .field("triangles", &self.triangles.len())
            .field("nodes", &self.cwbvh.nodes.len())
            .finish()
    }
}

impl Bvh {
    /// Builds the BVH; uses the current rayon pool.
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
        let cwbvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            quality.params(),
            &mut Duration::default(),
        );
        let triangles = cwbvh
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        Ok(Self { cwbvh, triangles })
    }

    /// Number of triangles (in leaf order, pre-splits would count once per reference).
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The closest intersection with `ray.tmin ≤ t ≤ ray.tmax`.
    #[must_use]
    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<BvhHit> {
        let mut hit = RayHit::none();
        let found = self
            .cwbvh
            .ray_traverse(*ray, &mut hit, |r, id| self.triangles[id].intersect(r));
        if !found {
            return None;
        }
        let leaf = hit.primitive_id as usize;
        let tri = &self.triangles[leaf];
        let uv = tri.compute_barycentric(ray);
        let n = tri.compute_normal();
        Some(BvhHit {
            triangle_id: self.cwbvh.primitive_indices[leaf],
            t: hit.t,
            barycentric: [uv.x, uv.y],
            normal_geometric: [n.x, n.y, n.z],
        })
    }

    /// Whether anything is hit with `ray.tmin ≤ t < ray.tmax` (shadow rays: set `tmax` just short
    /// of the light).
    #[must_use]
    #[inline]
    pub fn any_hit(&self, ray: &Ray) -> bool {
        !self
            .cwbvh
            .ray_traverse_miss(*ray, |r, id| self.triangles[id].intersect(r))
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
                for (ray, o) in rays.iter().zip(out) {
                    *o = self.closest_hit(ray);
                }
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
                for (ray, o) in rays.iter().zip(out) {
                    *o = self.any_hit(ray);
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
}
