//! Area-to-area form factors with ray-cast visibility (Cohen & Wallace, seed 002, ch. 4).
//!
//! F_pq = (1/A_p) ∫_{A_p} ∫_{A_q} cos θ_p cos θ_q / (π r²) · V dA_q dA_p is evaluated as the mean
//! over N stratified points x_k of p of the exact unoccluded point-to-polygon factor
//! F_{dx_k→q} (Lambert's contour integral, C&W eq. 4.18: F = 1/(2π) Σ_edges β_e n·Γ_e, with q
//! clipped to the hemisphere above x_k), times a visibility V_k ∈ {0, 1} from one shadow ray from
//! x_k to a stratified point y_k of q (Wallace, Elmquist & Haines 1989, who also used analytic
//! point-to-area factors with ray-cast visibility). Without occluders the estimate is exact but
//! for the outer quadrature, whose error falls as N^(−1/2 − 1/2) for a smooth integrand with
//! jittered strata; for a closed enclosure the unoccluded row sums are 1 to rounding.
//!
//! Randomness: the points x_k on the sender p come from p's own ChaCha8 stream (so every factor
//! of a row uses the same points and an unoccluded closed row sums to 1 to rounding); the points
//! y_k and their pairing with the x_k come from the ordered pair's stream (seed = the
//! parameters' seed, stream = p·2³² + q), the way `render::tiling` gives each tile a stream. A
//! factor therefore depends only on the scene, the parameters and the pair, never on the thread
//! count or on the order of evaluation. A mesh solved beside the natural one (`super::twin`)
//! names its nodes' streams after their natural twins ([`FormFactorEngine::with_node_streams`]),
//! so that a pair of twins draws the same points on both sides.
//!
//! # Known limitations
//! Visibility is a binary per-sample estimate, so partly occluded pairs carry Monte Carlo noise
//! (≈ √(V(1−V)/N)); shadow rays use the scene's BVH in `f32` with a relative offset of
//! [`RAY_OFFSET_REL`], so occluders closer than that to either end are missed. Surfaces are
//! one-sided: light leaves a node only through its front.

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::mesh::{Mesh, MeshNode};
use super::{RadiosityError, check_positive};
use crate::scene::SceneTracer;

/// Shadow rays start and stop this fraction of their length (plus [`RAY_OFFSET_ABS_M`]) away
/// from both surfaces, to step over the `f32` rounding of the BVH's hit distance (≈ 1e-7
/// relative) on the surfaces they connect.
pub const RAY_OFFSET_REL: f64 = 1e-4;
/// Absolute part of the shadow-ray offset, metres (the `f32` spacing at 100 m from the tracer's
/// local origin is 7.6e-6 m).
pub const RAY_OFFSET_ABS_M: f64 = 2e-5;

/// Corner points of the refinement test lie this fraction of the way toward the centroid
/// ([`FormFactorEngine::largest_estimate`]): off the edge a touching node shares.
pub const ORACLE_CORNER_INSET: f64 = 0.01;

/// Random stream family of the sender's sample points (apart from the pair streams).
const SENDER_SEED_SALT: u64 = 0x5E4D_E000_0000_0001;

/// Form-factor quadrature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FormFactorParams {
    /// Stratified samples per axis of the unit square on the sending node (N = n² points, each
    /// with one shadow ray).
    pub samples_per_axis: u32,
    /// Seed of the per-pair random streams.
    pub seed: u64,
    /// Cast shadow rays (false: unoccluded factors, for convex enclosures and tests).
    pub visibility: bool,
}

impl Default for FormFactorParams {
    /// 4 × 4 samples per pair, seed 0, visibility on.
    fn default() -> Self {
        Self {
            samples_per_axis: 4,
            seed: 0,
            visibility: true,
        }
    }
}

impl FormFactorParams {
    /// Checks the sample count.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] outside 1…64.
    pub fn validate(&self) -> Result<(), RadiosityError> {
        check_positive("samples_per_axis", f64::from(self.samples_per_axis))?;
        if self.samples_per_axis > 64 {
            return Err(RadiosityError::InvalidParameter {
                name: "samples_per_axis",
                value: f64::from(self.samples_per_axis),
                reason: "must be at most 64",
            });
        }
        Ok(())
    }
}

/// The part of triangle `tri` in the half-space n·(y − x) ≥ 0 above the tangent plane at `x`
/// (Sutherland–Hodgman; a triangle or a quadrilateral), as vectors from `x`; `count` < 3 when
/// nothing is left.
fn clip_above_plane(
    x: &Point3<f64>,
    n: &Vector3<f64>,
    tri: &[Point3<f64>; 3],
) -> ([Vector3<f64>; 4], usize) {
    let mut poly = [Vector3::zeros(); 4];
    let mut count = 0;
    for k in 0..3 {
        let a = tri[k] - x;
        let b = tri[(k + 1) % 3] - x;
        let (da, db) = (n.dot(&a), n.dot(&b));
        if da >= 0.0 {
            poly[count] = a;
            count += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            poly[count] = a + (b - a) * t;
            count += 1;
        }
    }
    (poly, count)
}

/// The unoccluded form factor from a differential area at `x` with unit normal `n` to the
/// triangle `tri` whose front has unit normal `tri_normal` (0 when `x` is behind it): Lambert's
/// contour integral over the part of the triangle above the tangent plane at `x`.
#[must_use]
pub fn point_to_triangle(
    x: &Point3<f64>,
    n: &Vector3<f64>,
    tri: &[Point3<f64>; 3],
    tri_normal: &Vector3<f64>,
) -> f64 {
    Above::new(x, n, tri, tri_normal).map_or(0.0, |above| above.factor(n))
}

/// The part of a triangle that a point's factor integrates over: above the tangent plane at
/// `x`, as seen from a point in front of the triangle. Clipped once per sample, for the factor
/// ([`point_to_triangle`]) and for the shadow ray's end ([`Above::point`]) alike.
struct Above {
    /// The clipped polygon's corners as vectors from `x`.
    poly: [Vector3<f64>; 4],
    /// Its corners (3 or 4).
    count: usize,
}

impl Above {
    /// `None` when `x` is behind the triangle (light leaves it through its front only) or
    /// nothing of it is above the plane.
    fn new(
        x: &Point3<f64>,
        n: &Vector3<f64>,
        tri: &[Point3<f64>; 3],
        tri_normal: &Vector3<f64>,
    ) -> Option<Self> {
        if tri_normal.dot(&(x - tri[0])) <= 0.0 {
            return None;
        }
        let (poly, count) = clip_above_plane(x, n, tri);
        (count >= 3).then_some(Self { poly, count })
    }

    /// Lambert's contour integral over the polygon for the normal `n` at its apex.
    fn factor(&self, n: &Vector3<f64>) -> f64 {
        let (poly, count) = (&self.poly, self.count);
        let mut sum = 0.0;
        for k in 0..count {
            let a = poly[k];
            let b = poly[(k + 1) % count];
            // A corner at the apex adds nothing (its norm is 0 exactly when its square is).
            if a.norm_squared() <= 0.0 || b.norm_squared() <= 0.0 {
                continue;
            }
            let cross = a.cross(&b);
            let cn = cross.norm();
            if cn <= 0.0 {
                continue;
            }
            let angle = cn.atan2(a.dot(&b));
            sum += angle * n.dot(&cross) / cn;
        }
        (sum / std::f64::consts::TAU).abs()
    }

    /// A point of the polygon from the unit-square sample `(u, v)`, uniform in area, so that a
    /// shadow ray to it never tests a part of the triangle the factor has already left out.
    fn point(&self, x: &Point3<f64>, (u, v): (f64, f64)) -> Point3<f64> {
        let (poly, count) = (&self.poly, self.count);
        // Fan (0, k, k + 1): one or two triangles; choose one by area with u, reuse u inside it.
        let area = |k: usize| (poly[k] - poly[0]).cross(&(poly[k + 1] - poly[0])).norm();
        let first = area(1);
        let total = first + if count == 4 { area(2) } else { 0.0 };
        let (k, u) = if count == 4 && total > 0.0 && u * total >= first {
            (2, ((u * total - first) / (total - first)).clamp(0.0, 1.0))
        } else if total > 0.0 && count == 4 {
            (1, (u * total / first).clamp(0.0, 1.0))
        } else {
            (1, u)
        };
        // Uniform in the triangle (a, b, c) from the square (Shirley's square-root map).
        let su = u.sqrt();
        let (a, b, c) = (poly[0], poly[k], poly[k + 1]);
        x + a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v)
    }
}

/// Form factors between mesh nodes, with visibility on the scene's BVH.
#[derive(Debug, Clone, Copy)]
pub struct FormFactorEngine<'a> {
    mesh: &'a Mesh,
    tracer: &'a SceneTracer,
    params: FormFactorParams,
    /// Per element, the random stream of its direct-light sample points (`None`: its index).
    direct_streams: Option<&'a [u64]>,
    /// Per node, the number naming its form-factor streams (`None`: its index).
    node_streams: Option<&'a [u32]>,
}

impl<'a> FormFactorEngine<'a> {
    /// An engine over `mesh`, tracing shadow rays in `tracer` (built from the same scene).
    ///
    /// # Errors
    /// Invalid parameters.
    pub fn new(
        mesh: &'a Mesh,
        tracer: &'a SceneTracer,
        params: FormFactorParams,
    ) -> Result<Self, RadiosityError> {
        params.validate()?;
        Ok(Self {
            mesh,
            tracer,
            params,
            direct_streams: None,
            node_streams: None,
        })
    }

    /// The same engine drawing element e's direct-light sample points
    /// ([`super::sources::DirectSamples`]) from stream `streams[e]` instead of e, so that
    /// elements of two meshes trace the same rays ([`super::twin`]).
    ///
    /// # Panics
    /// When `streams` does not have one entry per element.
    #[must_use]
    pub fn with_direct_streams(mut self, streams: Option<&'a [u64]>) -> Self {
        if let Some(s) = streams {
            assert_eq!(s.len(), self.mesh.elements.len(), "one stream per element");
        }
        self.direct_streams = streams;
        self
    }

    /// The same engine naming node n's form-factor streams (module doc) `streams[n]` instead of
    /// n, so that the nodes of two meshes draw the same sample points ([`super::twin`]).
    ///
    /// # Panics
    /// When `streams` does not have one entry per node.
    #[must_use]
    pub fn with_node_streams(mut self, streams: Option<&'a [u32]>) -> Self {
        if let Some(s) = streams {
            assert_eq!(s.len(), self.mesh.nodes.len(), "one stream per node");
        }
        self.node_streams = streams;
        self
    }

    /// The number naming node `n`'s form-factor streams.
    fn node_stream(&self, n: u32) -> u64 {
        u64::from(self.node_streams.map_or(n, |s| s[n as usize]))
    }

    /// The random stream of element `e`'s direct-light sample points.
    #[must_use]
    pub fn direct_stream(&self, e: usize) -> u64 {
        self.direct_streams.map_or(e as u64, |s| s[e])
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// The tracer.
    #[must_use]
    pub fn tracer(&self) -> &'a SceneTracer {
        self.tracer
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> FormFactorParams {
        self.params
    }

    /// Whether the segment from `from` to `to` (world metres) is free of occluders, ends
    /// excluded by the ray offsets.
    #[must_use]
    pub fn visible(&self, from: &Point3<f64>, to: &Point3<f64>) -> bool {
        let d = to - from;
        let length = d.norm();
        let offset = RAY_OFFSET_REL * length + RAY_OFFSET_ABS_M;
        if length <= 2.0 * offset {
            return true;
        }
        #[allow(clippy::cast_possible_truncation)]
        let ray = self
            .tracer
            .ray_from_world(from, &d, offset as f32, (length - offset) as f32);
        !self.tracer.any_hit(&ray)
    }

    /// Cheap unoccluded estimate of F_pq from p's centroid (the refinement oracle).
    #[must_use]
    pub fn centroid_estimate(&self, p: u32, q: u32) -> f64 {
        let (np, nq) = (self.node(p), self.node(q));
        point_to_triangle(
            &np.centroid_in_world_m(),
            &np.normal_in_world,
            &nq.vertices_in_world_m,
            &nq.normal_in_world,
        )
    }

    /// Unoccluded estimate of the largest point factor F_{dx→q} over p: the largest of the
    /// factors from p's centroid and from its corners (taken [`ORACLE_CORNER_INSET`] of the way
    /// toward the centroid). Where q lies close to one end of p (a wall standing on the ground
    /// next to a ground node), the centroid sees q small while the near corner sees it under up
    /// to half its hemisphere: a link judged by the centroid alone then hands all of p's leaves
    /// the light that only its near end gets (the BF refinement test of
    /// [`super::hierarchical`]).
    #[must_use]
    pub fn largest_estimate(&self, p: u32, q: u32) -> f64 {
        let (np, nq) = (self.node(p), self.node(q));
        let c = np.centroid_in_world_m();
        let at = |x: &Point3<f64>| {
            point_to_triangle(
                x,
                &np.normal_in_world,
                &nq.vertices_in_world_m,
                &nq.normal_in_world,
            )
        };
        np.vertices_in_world_m
            .iter()
            .map(|v| at(&(v + (c - v) * ORACLE_CORNER_INSET)))
            .fold(at(&c), f64::max)
    }

    fn node(&self, n: u32) -> &MeshNode {
        &self.mesh.nodes[n as usize]
    }

    /// Whether p and q can exchange light at all (each has part of itself in front of the
    /// other); false for coplanar and back-to-back pairs.
    #[must_use]
    pub fn facing(&self, p: u32, q: u32) -> bool {
        let (np, nq) = (self.node(p), self.node(q));
        p != q
            && in_front(
                &np.vertices_in_world_m,
                &np.normal_in_world,
                &nq.vertices_in_world_m,
            )
            && in_front(
                &nq.vertices_in_world_m,
                &nq.normal_in_world,
                &np.vertices_in_world_m,
            )
    }

    /// F_pq, the fraction of the light leaving node p that arrives at node q (module doc).
    #[must_use]
    pub fn node_to_node(&self, p: u32, q: u32) -> f64 {
        if !self.facing(p, q) {
            return 0.0;
        }
        let (np, nq) = (self.node(p), self.node(q));
        let n = self.params.samples_per_axis as usize;
        // The sender's points depend on the sender only, so that a row shares them and sums to
        // exactly the unoccluded solid-angle fraction; the receiver's points and the pairing
        // come from the pair's stream.
        let (stream_p, stream_q) = (self.node_stream(p), self.node_stream(q));
        let mut sender_rng = ChaCha8Rng::seed_from_u64(self.params.seed ^ SENDER_SEED_SALT);
        sender_rng.set_stream(stream_p);
        let mut rng = ChaCha8Rng::seed_from_u64(self.params.seed);
        rng.set_stream((stream_p << 32) | stream_q);
        // A random pairing of the strata on p with those on q.
        let mut partner: Vec<usize> = (0..n * n).collect();
        for i in (1..partner.len()).rev() {
            partner.swap(i, rng.random_range(0..=i));
        }
        #[allow(clippy::cast_precision_loss)]
        let inv_n = 1.0 / n as f64;
        #[allow(clippy::cast_precision_loss)]
        let stratum = |k: usize, rng: &mut ChaCha8Rng| {
            let u = ((k / n) as f64 + rng.random::<f64>()) * inv_n;
            let v = ((k % n) as f64 + rng.random::<f64>()) * inv_n;
            (u, v)
        };
        let mut sum = 0.0;
        for (k, &k_q) in partner.iter().enumerate() {
            let (u, v) = stratum(k, &mut sender_rng);
            let x = np.point_at(u, v);
            let (u_q, v_q) = stratum(k_q, &mut rng);
            let Some(above) = Above::new(
                &x,
                &np.normal_in_world,
                &nq.vertices_in_world_m,
                &nq.normal_in_world,
            ) else {
                continue;
            };
            let f = above.factor(&np.normal_in_world);
            if f <= 0.0 {
                continue;
            }
            // The shadow ray goes to the part of q that the factor counts (above x's tangent
            // plane): a point of q behind that plane is hidden by p's own surface and would
            // count the clipped part twice (a bias at junctions, where a receiver's element
            // straddles the footprint of a wall standing on it).
            if self.params.visibility && !self.visible(&x, &above.point(&x, (u_q, v_q))) {
                continue;
            }
            sum += f;
        }
        // q's radiosity is its mean over its whole area, but only its open part emits (the
        // part under a solid standing on it is dark and hidden): the open part's exitance is
        // B_q / open_q, and the factor carries that (super::covered).
        if nq.open_fraction <= 0.0 {
            return 0.0;
        }
        sum * inv_n * inv_n / nq.open_fraction
    }

    /// F from `p` to each of `targets`, computed in parallel (order of `targets`).
    #[must_use]
    pub fn row(&self, p: u32, targets: &[u32]) -> Vec<f64> {
        targets
            .par_iter()
            .map(|&q| self.node_to_node(p, q))
            .collect()
    }

    /// F from each of `senders` to `q`, computed in parallel (order of `senders`).
    #[must_use]
    pub fn column(&self, senders: &[u32], q: u32) -> Vec<f64> {
        senders
            .par_iter()
            .map(|&p| self.node_to_node(p, q))
            .collect()
    }
}

/// Whether some vertex of triangle `b` lies in front of the plane of triangle `a` (vertices,
/// unit normal) by more than 1e-12 of b's reach from a's first vertex: height h >
/// 1e-12·max|v − a₀|, tested as h > 0 and h² > 1e-24·max|v − a₀|² (no square roots: the
/// hierarchical solver asks it for every pair of patches, [`FormFactorEngine::facing`]).
#[must_use]
pub fn in_front(a: &[Point3<f64>; 3], a_normal: &Vector3<f64>, b: &[Point3<f64>; 3]) -> bool {
    let a0 = a[0];
    let offsets = b.map(|v| v - a0);
    let highest = offsets
        .iter()
        .map(|d| a_normal.dot(d))
        .fold(f64::NEG_INFINITY, f64::max);
    if highest <= 0.0 {
        return false;
    }
    let reach2 = offsets
        .iter()
        .map(Vector3::norm_squared)
        .fold(0.0, f64::max);
    highest * highest > 1e-24 * reach2
}
