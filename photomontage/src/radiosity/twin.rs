//! Twin rays: the solve of a site scene with its planned objects reuses the sky rays that the
//! solve of the same scene without them (the photographed state) has traced.
//!
//! A site is solved twice, with and without the planned objects, and both meshes are cut alike
//! on the natural surfaces (`site::render_radiosity` refines both along the sun shadow edges of
//! both scenes), so a natural element of the mesh with the planned objects has a **twin** in the
//! natural mesh with the same vertices. An element with a twin draws its direct-light sample
//! points from its twin's random stream ([`super::form_factor::FormFactorEngine::with_direct_streams`]),
//! so the two solves trace the same rays; an element without one (on a planned object) draws
//! from a stream after the natural mesh's last.
//!
//! The scene with the planned objects is the natural scene plus those objects, so a ray escapes
//! it iff it escapes the natural scene and misses the planned objects. The sky transfer
//! (`super::sky_transfer`, about 125 rays per element, most of a site precompute's shadow rays) of an
//! element with a twin therefore reads the twin's escaped count per sky facet: none escaped →
//! none escapes here; all escaped → only the planned objects' own small BVH is tested; a mixed
//! count (several rays per facet) traces the whole scene again. The tracers share one local frame
//! ([`SceneTracer::new_in_frame_of`]), so each ray is the same `f32` ray against the same `f32`
//! triangles, and the counts equal those of tracing the whole scene (tested against it).
//!
//! The same rays on both sides are also common random numbers (Kahn & Marshall 1953): the
//! sampling noise of an element far from the planned objects is the same with and without them,
//! so it cancels in the difference the differential renderer takes (cases B and D3).

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::mesh::{Mesh, MeshNode};
use crate::bvh::BuildQuality;
use crate::scene::{Scene, SceneError, SceneTracer};

/// What the solve with the planned objects borrows from the natural one (module doc).
#[derive(Debug)]
pub struct Twin {
    /// Per element of the mesh with the planned objects, its twin in the natural mesh.
    pub(super) twin_of: Vec<Option<u32>>,
    /// Per element of the mesh with the planned objects, its direct-light random stream.
    pub(super) streams: Vec<u64>,
    /// The planned objects alone, in the local frame of the whole scene's tracer; `None` for
    /// [`Twin::identity`] (nothing planned).
    pub(super) artificial: Option<SceneTracer>,
    /// Their bounding box, world metres, widened by [`BOX_MARGIN_M`].
    artificial_box_in_world_m: [Point3<f64>; 2],
    /// The centre and radius of the widened box's bounding sphere, world metres.
    artificial_sphere_in_world_m: (Point3<f64>, f64),
    /// Per element of the mesh with the planned objects, [`Twin::cone_from_node`] of its node,
    /// computed once (a sun step reads it for every element in full sun).
    element_cones: Vec<Option<(Vector3<f64>, f64)>>,
}

/// The planned objects' box is widened by this much before a ray is tested against it, metres
/// (far above the `f32` rounding of their vertices in the tracer's local frame, < 0.5 mm).
const BOX_MARGIN_M: f64 = 0.05;

/// A point this close to the planned objects' sphere (relative) is treated as inside it.
const CONE_SLACK: f64 = 1.0 + 1e-6;
/// The cone's cosine is lowered by this much (a wider cone) against round-off.
const CONE_COS_SLACK: f64 = 1e-9;

impl Twin {
    /// The twins `twin_of` ([`twin_elements`]) of the elements of the mesh with the planned
    /// objects (traced by `tracer`) in the natural mesh of `natural_elements` elements (traced by
    /// `natural_tracer`), with `artificial`, the planned objects alone, traced in `tracer`'s
    /// local frame; `mesh` is the mesh with the planned objects. `None` when there is nothing
    /// planned or the two tracers' frames differ (the same rays would then not be the same
    /// `f32` rays).
    ///
    /// # Errors
    /// The planned objects' tracer cannot be built.
    pub fn new(
        twin_of: Vec<Option<u32>>,
        natural_elements: usize,
        natural_tracer: &SceneTracer,
        tracer: &SceneTracer,
        artificial: &Scene,
        mesh: &Mesh,
    ) -> Result<Option<Self>, SceneError> {
        let Some(artificial_box_in_world_m) = artificial.bounding_box_in_world_m() else {
            return Ok(None);
        };
        if natural_tracer.local_origin_in_world_m() != tracer.local_origin_in_world_m() {
            return Ok(None);
        }
        let artificial = SceneTracer::new_in_frame_of(artificial, BuildQuality::Medium, tracer)?;
        let after = natural_elements as u64;
        let streams = twin_of
            .iter()
            .enumerate()
            .map(|(e, t)| t.map_or(after + e as u64, u64::from))
            .collect();
        let [lo, hi] = artificial_box_in_world_m;
        let margin = Vector3::repeat(BOX_MARGIN_M);
        let (lo, hi) = (lo - margin, hi + margin);
        let mut twin = Self {
            twin_of,
            streams,
            artificial: Some(artificial),
            artificial_box_in_world_m: [lo, hi],
            artificial_sphere_in_world_m: (nalgebra::center(&lo, &hi), (hi - lo).norm() / 2.0),
            element_cones: Vec::new(),
        };
        twin.element_cones = (0..mesh.elements.len())
            .into_par_iter()
            .map(|e| twin.cone_from_node(mesh.element_node(e)))
            .collect();
        Ok(Some(twin))
    }

    /// The twin of a mesh in a solve of the same scene with other colours (a spectral pass
    /// beside the first, `site::spectral_radiosity`): every element is its own twin and nothing
    /// is planned, so every sky ray's count and every form factor the first solve computed is
    /// read, not traced again (the same rays on the same geometry: the same answers). The
    /// caller checks that the meshes are the same ([`twin_elements`] maps every element to
    /// itself) and that the tracers share their local frame.
    #[must_use]
    pub fn identity(mesh: &Mesh) -> Self {
        let n = mesh.elements.len();
        let inf = f64::INFINITY;
        Self {
            twin_of: (0..n).map(|e| u32::try_from(e).ok()).collect(),
            streams: (0..n as u64).collect(),
            artificial: None,
            // An empty box: nothing to meet.
            artificial_box_in_world_m: [Point3::new(inf, inf, inf), Point3::new(-inf, -inf, -inf)],
            artificial_sphere_in_world_m: (Point3::origin(), 0.0),
            // A cone no direction enters (its cosine above 1): no ray can meet what is planned.
            element_cones: vec![Some((Vector3::z(), 2.0)); n],
        }
    }

    /// Whether something is planned (false for [`Twin::identity`]).
    #[must_use]
    pub(super) fn plans_something(&self) -> bool {
        self.artificial.is_some()
    }

    /// The directions in which a ray from within `radius_m` of `centre_in_world_m` can meet the
    /// planned objects: the cone (unit axis, cosine of its half-angle) that their bounding
    /// sphere widened by `radius_m` subtends from the centre (a ray p + t·d with |p − centre| ≤
    /// r stays within r of the parallel ray from the centre); `None` when the centre is inside
    /// it (every direction may).
    #[must_use]
    pub(super) fn cone_towards_artificial(
        &self,
        centre_in_world_m: &Point3<f64>,
        radius_m: f64,
    ) -> Option<(Vector3<f64>, f64)> {
        let (sphere_centre, sphere_radius) = &self.artificial_sphere_in_world_m;
        let v = sphere_centre - centre_in_world_m;
        let distance = v.norm();
        let r = sphere_radius + radius_m;
        if distance <= r * CONE_SLACK {
            return None;
        }
        let sin = r / distance;
        // A slightly wider cone than the exact one (round-off never excludes a direction).
        Some((v / distance, (1.0 - sin * sin).sqrt() - CONE_COS_SLACK))
    }

    /// [`Twin::cone_towards_artificial`] for rays from any point of the mesh node `node`: from
    /// its centroid, widened by its farthest vertex.
    #[must_use]
    pub(super) fn cone_from_node(&self, node: &MeshNode) -> Option<(Vector3<f64>, f64)> {
        let centre = node.centroid_in_world_m();
        let radius = node
            .vertices_in_world_m
            .iter()
            .map(|v| (v - centre).norm())
            .fold(0.0, f64::max);
        self.cone_towards_artificial(&centre, radius)
    }

    /// [`Twin::cone_from_node`] of element `e` of the mesh with the planned objects, as computed
    /// when the twins were made.
    #[must_use]
    pub(super) fn element_cone(&self, e: usize) -> Option<(Vector3<f64>, f64)> {
        self.element_cones[e]
    }

    /// Whether the ray from `origin_in_world_m` along `dir_in_world` (t ≥ 0) meets the planned
    /// objects' widened box: a ray that does not cannot hit them (slab test, Kay & Kajiya 1986).
    #[must_use]
    pub(super) fn may_meet_artificial(
        &self,
        origin_in_world_m: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
    ) -> bool {
        if !self.plans_something() {
            return false;
        }
        let [lo, hi] = &self.artificial_box_in_world_m;
        let (mut near, mut far) = (0.0_f64, f64::INFINITY);
        for a in 0..3 {
            let (o, d) = (origin_in_world_m[a], dir_in_world[a]);
            if d == 0.0 {
                if o < lo[a] || o > hi[a] {
                    return false;
                }
                continue;
            }
            let (t_lo, t_hi) = ((lo[a] - o) / d, (hi[a] - o) / d);
            near = near.max(t_lo.min(t_hi));
            far = far.min(t_lo.max(t_hi));
            if near > far {
                return false;
            }
        }
        true
    }

    /// The planned objects' bounding box widened by [`BOX_MARGIN_M`], world metres.
    #[must_use]
    pub(super) fn artificial_box_in_world_m(&self) -> &[Point3<f64>; 2] {
        &self.artificial_box_in_world_m
    }

    /// Elements of the mesh with the planned objects that have a twin.
    #[must_use]
    pub fn twins(&self) -> usize {
        self.twin_of.iter().flatten().count()
    }
}

/// The bits of a node's vertices, in order: the key that finds its twin.
pub(super) fn vertex_bits(node: &MeshNode) -> [u64; 9] {
    let v = &node.vertices_in_world_m;
    std::array::from_fn(|k| v[k / 3][k % 3].to_bits())
}

/// Per element of `to`, the element of `from` with the same vertices in the same order (the
/// natural surfaces, meshed alike in both); `None` elsewhere.
#[must_use]
pub fn twin_elements(from: &Mesh, to: &Mesh) -> Vec<Option<u32>> {
    let key = |mesh: &Mesh, e: usize| vertex_bits(mesh.element_node(e));
    let by_vertices: HashMap<[u64; 9], u32> = (0..from.elements.len())
        .map(|e| (key(from, e), u32::try_from(e).unwrap_or(u32::MAX)))
        .collect();
    (0..to.elements.len())
        .map(|e| by_vertices.get(&key(to, e)).copied())
        .collect()
}
