//! Final gather at element vertices, for the renderer's radiosity mode (issue 13 item 7: "a
//! final gather where the solution is coarse"; Cohen & Wallace, seed 002, §9.3.2; Lischinski,
//! Tampieri & Greenberg 1993 gather the same way from a hierarchical solution's exitances).
//!
//! **Why.** A hierarchical link r ← s carries the *mean* form factor over its receiver node r,
//! and the push–pull hands every element below r the same gathered radiosity (HSA91). BF
//! refinement splits a link only when its own transport is large, so hundreds of weak links from
//! a distant ground each stay at a whole façade triangle while their sum is not weak: the façade
//! gets the right mean but no gradient. On the Mitsuba pair the shaded face of the box came out
//! 10 % too bright at its foot and 5 % too dark at its top, with a step along the diagonal that
//! splits the face into two scene triangles (docs/benchmarks.md).
//!
//! **What.** At each element vertex — shared by the elements of one plane that meet there, as in
//! the nodal averaging of [`super::query`] — `n × n` stratified cosine-distributed rays record
//! which element each one hits (front faces only). The interreflected irradiance at the vertex
//! is then E = Σ_hits B_e / n² (E = π·mean L = mean B for the cosine distribution), for the
//! exitances B of any solution on the same mesh: a relight re-sums, no ray is traced again
//! (Tonn & Donath's split of geometry from lighting, seed 000). A point inside an element takes
//! the barycentric blend of its three vertices. Only the sources' element values enter, never a
//! receiver node's pushed mean, so the gradient across a façade is the gradient of what it sees.
//!
//! Rays start a [`INSET_FRACTION`] of the way from the vertex toward the mean centroid of its
//! elements and [`DIRECT_RAY_OFFSET_M`] off the surface, so that a vertex on a wall's foot does
//! not start in the plane of the ground it stands on. Hits are located on their element by
//! descending the hit scene triangle's quadtree (midpoint splits, [`super::mesh`]).
//!
//! Vertices are gathered on demand ([`OnceLock`]), so only those the renderer reaches cost rays.
//! Each vertex's rays come from a ChaCha8 stream seeded by its position and normal: the result
//! is independent of threads and order, and a vertex of the solutions with and without the
//! artificial objects uses the same rays (their difference carries little noise).
//!
//! **Two meshes, one trace.** The renderer gathers the same vertices on the meshes with and
//! without the artificial objects. [`VertexGather::over`] builds the gathers of the larger mesh
//! on those of the smaller one (its *base*) when every scene triangle of the base is in it: a ray
//! is traced once against the base's triangles and once against the extra triangles alone (a few
//! buildings, cut short at the base hit). The closer hit is the larger scene's closest hit, and
//! the base hit is the base's own; a vertex with the same rays in both meshes (same origin,
//! normal and seed) fills both hit lists from one trace.
//!
//! # Known limitations
//! A Monte Carlo estimate: with 32 × 32 strata the error is about half a percent of the
//! gathered light on average and up to 2–3 % where a sharp outline crosses the hemisphere (a
//! ground's far edge, a shadow edge). The exitance of a
//! hit element is its element mean (no interpolation on the source side).

use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

use glam::Vec3A;
use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::mesh::Mesh;
use super::sources::DIRECT_RAY_OFFSET_M;
use super::surface_point::{CosineFrame, TriangleShape, point_seed, vertex_key};
use super::{RadiosityError, Rgb};
use crate::bvh::{BuildQuality, Ray};
use crate::scene::{Material, ObjectKind, Scene, SceneObject, SceneTracer};

mod exitance;

pub use exitance::GatheredExitance;

/// Stratified rays per axis of a vertex gather (32 × 32 = 1024 rays; 16 × 16 left 8 % errors at
/// single vertices, module tests).
pub const DEFAULT_RAYS_PER_AXIS: u32 = 32;

/// A gather starts this fraction of the way from the vertex toward its elements' mean centroid.
pub const INSET_FRACTION: f64 = 0.02;

/// Rays stop here, metres (beyond any site).
const GATHER_RAY_LENGTH_M: f32 = 1e7;

/// No vertex of the base has the same rays.
const NO_VERTEX: u32 = u32::MAX;

/// Which element each gather ray of a vertex hits, as (element, rays) pairs.
type VertexHits = Box<[(u32, u32)]>;

/// A vertex while its elements are collected: position, normal, sum and count of centroids.
type VertexSum = (Point3<f64>, Vector3<f64>, Vector3<f64>, f64);

/// A scene triangle's identity: its vertices' bits.
type TriangleKey = [u64; 9];

fn triangle_key(v: &[Point3<f64>; 3]) -> TriangleKey {
    let mut key = [0; 9];
    for (k, p) in v.iter().enumerate() {
        for c in 0..3 {
            key[3 * k + c] = p[c].to_bits();
        }
    }
    key
}

/// A tracer of some root nodes' triangles (the mesh's scene triangles).
#[derive(Debug)]
struct RootTracer {
    tracer: SceneTracer,
    /// Root node of each traced triangle (the tracer's triangle ids).
    roots: Vec<u32>,
    /// The triangles' bounding box (low, high corner), world metres, padded by
    /// [`BOUNDS_PAD_M`] and [`BOUNDS_PAD_REL`] of its diagonal.
    bounds: [Point3<f64>; 2],
}

/// Absolute padding of a [`RootTracer`]'s box, metres (far beyond the `f32` tracer's rounding).
const BOUNDS_PAD_M: f64 = 0.01;
/// Relative padding of a [`RootTracer`]'s box, of its diagonal.
const BOUNDS_PAD_REL: f64 = 1e-3;

impl RootTracer {
    /// The roots of `mesh` that `keep` accepts (each root once, as the first node of its
    /// surface); `None` when it accepts none.
    fn new(mesh: &Mesh, keep: &dyn Fn(u32) -> bool) -> Result<Option<Self>, RadiosityError> {
        let mut scene = Scene::new();
        let material = scene.add_material(Material::diffuse("gather", [0.5; 3]))?;
        let object = scene.add_object(SceneObject {
            name: "mesh".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })?;
        let mut roots = Vec::new();
        for id in mesh_roots(mesh) {
            if !keep(id) {
                continue;
            }
            let before = scene.triangles().len();
            scene.add_polygon(
                &mesh.nodes[id as usize].vertices_in_world_m,
                material,
                object,
            )?;
            roots.extend(std::iter::repeat_n(id, scene.triangles().len() - before));
        }
        if roots.is_empty() {
            return Ok(None);
        }
        let tracer = SceneTracer::new(&scene, BuildQuality::Medium)?;
        let (mut lo, mut hi) = (Point3::from([f64::MAX; 3]), Point3::from([f64::MIN; 3]));
        for t in scene.triangles() {
            for v in &t.vertices_in_world_m {
                lo = lo.inf(v);
                hi = hi.sup(v);
            }
        }
        let pad = Vector3::repeat(BOUNDS_PAD_M + BOUNDS_PAD_REL * (hi - lo).norm());
        Ok(Some(Self {
            tracer,
            roots,
            bounds: [lo - pad, hi + pad],
        }))
    }

    /// Whether the ray `origin + t·dir`, 0 ≤ t ≤ `t_max`, meets the padded box (the slab test):
    /// a ray that misses it meets none of the triangles, and the tracer is not asked. Most gather
    /// rays leave the scene without a hit, and this test costs less than the tracer's setup.
    fn may_hit(&self, origin: &Point3<f64>, dir: &Vector3<f64>, t_max: f64) -> bool {
        let [lo, hi] = &self.bounds;
        let (mut near, mut far) = (0.0_f64, t_max);
        for k in 0..3 {
            if dir[k] == 0.0 {
                if origin[k] < lo[k] || origin[k] > hi[k] {
                    return false;
                }
                continue;
            }
            let (a, b) = ((lo[k] - origin[k]) / dir[k], (hi[k] - origin[k]) / dir[k]);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
            if near > far {
                return false;
            }
        }
        true
    }
}

/// The root node of each surface of `mesh`: the scene triangles are the roots of its quadtrees,
/// each added before its subtree, so the first node of each surface.
fn mesh_roots(mesh: &Mesh) -> Vec<u32> {
    let mut seen = vec![false; mesh.surfaces.len()];
    let mut roots = Vec::with_capacity(mesh.surfaces.len());
    for (id, node) in mesh.nodes.iter().enumerate() {
        let s = node.surface as usize;
        if !seen[s] {
            seen[s] = true;
            #[allow(clippy::cast_possible_truncation)] // the element budget keeps ids small
            roots.push(id as u32);
        }
    }
    roots
}

/// The gathers of a smaller mesh that [`VertexGather::over`] builds on.
#[derive(Debug)]
struct Base {
    gather: Arc<VertexGather>,
    /// Per triangle the base traces: the root node of the same triangle in this mesh.
    root_of_base_triangle: Vec<u32>,
    /// Per vertex of this mesh: the base vertex with the same rays, or [`NO_VERTEX`].
    base_vertex: Vec<u32>,
}

/// Per ray direction (world, and normalised in `f32` as the tracers take it), the element of
/// this mesh and the element of the base (or none) it reaches.
type RayElements<'a> = dyn FnMut(&Vector3<f64>, Vec3A) -> [Option<u32>; 2] + 'a;

/// Where one ray stops: the root node of the triangle it hits, the ray and `t`.
type Stop<'a> = (u32, &'a SceneTracer, &'a Ray, f32);

/// Vertex gathers of one mesh (module doc).
#[derive(Debug)]
pub struct VertexGather {
    mesh: Arc<Mesh>,
    /// All roots, or with a base only the roots the base has not (`None` when there are none).
    tracer: Option<RootTracer>,
    base: Option<Base>,
    /// Per surface, its scene triangle (the root of its quadtree; `None` for a surface without
    /// nodes).
    surface_shapes: Vec<Option<TriangleShape>>,
    /// Per element, its three vertex ids.
    element_vertices: Vec<[u32; 3]>,
    /// Per vertex: ray origin (inset and offset), unit normal, random seed.
    origins: Vec<(Point3<f64>, Vector3<f64>, u64)>,
    rays_per_axis: u32,
    hits: Vec<OnceLock<VertexHits>>,
}

impl VertexGather {
    /// The vertices of `mesh` and a tracer of its triangles; nothing is traced yet.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] for `rays_per_axis` outside 1…64; a tracer error.
    pub fn new(mesh: Arc<Mesh>, rays_per_axis: u32) -> Result<Self, RadiosityError> {
        check_rays_per_axis(rays_per_axis)?;
        let tracer = RootTracer::new(&mesh, &|_| true)?;
        Ok(Self::with_tracer(mesh, rays_per_axis, tracer))
    }

    /// The gathers of `mesh` built on `base`, the gathers of a mesh whose scene triangles are all
    /// in `mesh` (the site without its artificial objects): each ray is traced against the base's
    /// triangles and the extra ones apart, and a vertex with the same rays in both fills both
    /// hit lists (module doc). Where `base` does not qualify (a triangle of its scene missing
    /// here, other rays per axis, or a base built on another), this is [`VertexGather::new`].
    ///
    /// # Errors
    /// As [`VertexGather::new`].
    pub fn over(
        mesh: Arc<Mesh>,
        rays_per_axis: u32,
        base: Arc<VertexGather>,
    ) -> Result<Self, RadiosityError> {
        check_rays_per_axis(rays_per_axis)?;
        let Some(base_tracer) = base.tracer.as_ref() else {
            return Self::new(mesh, rays_per_axis);
        };
        if base.base.is_some() || base.rays_per_axis != rays_per_axis {
            return Self::new(mesh, rays_per_axis);
        }
        let root_of_key: HashMap<TriangleKey, u32> = mesh_roots(&mesh)
            .into_iter()
            .map(|r| (triangle_key(&mesh.nodes[r as usize].vertices_in_world_m), r))
            .collect();
        let mut root_of_base_triangle = Vec::with_capacity(base_tracer.roots.len());
        for &r in &base_tracer.roots {
            let key = triangle_key(&base.mesh.nodes[r as usize].vertices_in_world_m);
            let Some(&own) = root_of_key.get(&key) else {
                return Self::new(mesh, rays_per_axis);
            };
            root_of_base_triangle.push(own);
        }
        let mut in_base = vec![false; mesh.nodes.len()];
        for &r in &root_of_base_triangle {
            in_base[r as usize] = true;
        }
        let tracer = RootTracer::new(&mesh, &|r| !in_base[r as usize])?;
        let mut gather = Self::with_tracer(mesh, rays_per_axis, tracer);
        let base_of_rays: HashMap<([u64; 6], u64), u32> = base
            .origins
            .iter()
            .enumerate()
            .map(|(v, o)| {
                #[allow(clippy::cast_possible_truncation)]
                (rays_key(o), v as u32)
            })
            .collect();
        let base_vertex: Vec<u32> = gather
            .origins
            .iter()
            .map(|o| base_of_rays.get(&rays_key(o)).copied().unwrap_or(NO_VERTEX))
            .collect();
        gather.base = Some(Base {
            gather: base,
            root_of_base_triangle,
            base_vertex,
        });
        Ok(gather)
    }

    fn with_tracer(mesh: Arc<Mesh>, rays_per_axis: u32, tracer: Option<RootTracer>) -> Self {
        let mut ids: HashMap<[i64; 6], u32> = HashMap::new();
        // Per vertex: position, normal, sum and count of its elements' centroids.
        let mut sums: Vec<VertexSum> = Vec::new();
        let mut element_vertices = Vec::with_capacity(mesh.elements.len());
        for e in 0..mesh.elements.len() {
            let node = mesh.element_node(e);
            let centroid = node.centroid_in_world_m();
            element_vertices.push(node.vertices_in_world_m.map(|v| {
                let key = vertex_key(&v, &node.normal_in_world);
                #[allow(clippy::cast_possible_truncation)]
                let id = *ids.entry(key).or_insert_with(|| {
                    sums.push((v, node.normal_in_world, Vector3::zeros(), 0.0));
                    (sums.len() - 1) as u32
                });
                let s = &mut sums[id as usize];
                s.2 += centroid.coords;
                s.3 += 1.0;
                id
            }));
        }
        let origins = sums
            .iter()
            .map(|(v, n, centroid_sum, count)| {
                let towards = centroid_sum / *count - v.coords;
                let origin = v + towards * INSET_FRACTION + n * DIRECT_RAY_OFFSET_M;
                (origin, *n, point_seed(0x6A7E_5EED, v, n))
            })
            .collect::<Vec<_>>();
        let hits = (0..origins.len()).map(|_| OnceLock::new()).collect();
        let mut surface_shapes = vec![None; mesh.surfaces.len()];
        for r in mesh_roots(&mesh) {
            let node = &mesh.nodes[r as usize];
            surface_shapes[node.surface as usize] = Some(TriangleShape::new(
                &node.vertices_in_world_m,
                &node.normal_in_world,
            ));
        }
        Self {
            mesh,
            tracer,
            base: None,
            surface_shapes,
            element_vertices,
            origins,
            rays_per_axis,
            hits,
        }
    }

    /// The mesh the gathers belong to.
    #[must_use]
    pub fn mesh(&self) -> &Arc<Mesh> {
        &self.mesh
    }

    /// Number of distinct element vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.origins.len()
    }

    /// The element of root node `root`'s quadtree that holds `point` (a point on the root's
    /// triangle), descending the midpoint splits by barycentric weights.
    fn element_under(&self, root: u32, point: &Point3<f64>) -> Option<u32> {
        let nodes = &self.mesh.nodes;
        let shape = self.surface_shapes[nodes[root as usize].surface as usize].as_ref()?;
        let mut w = shape.weights(point);
        let mut n = root;
        loop {
            let node = &nodes[n as usize];
            let Some(children) = node.children else {
                return node.element;
            };
            // Children [a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca] (mesh.rs).
            let [wa, wb, wc] = w;
            (n, w) = if wa >= 0.5 {
                (children[0], [2.0 * wa - 1.0, 2.0 * wb, 2.0 * wc])
            } else if wb >= 0.5 {
                (children[1], [2.0 * wa, 2.0 * wb - 1.0, 2.0 * wc])
            } else if wc >= 0.5 {
                (children[2], [2.0 * wa, 2.0 * wb, 2.0 * wc - 1.0])
            } else {
                (
                    children[3],
                    [1.0 - 2.0 * wc, 1.0 - 2.0 * wa, 1.0 - 2.0 * wb],
                )
            };
        }
    }

    /// The element a ray that stops at `stop` (direction `dir`) reaches: `None` at the back of a
    /// one-sided surface (which emits nothing) and off every element.
    fn element_at(&self, stop: &Stop<'_>, dir: &Vector3<f64>) -> Option<u32> {
        let &(root, tracer, ray, t) = stop;
        if self.mesh.nodes[root as usize].normal_in_world.dot(dir) >= 0.0 {
            return None;
        }
        self.element_under(root, &tracer.hit_point_in_world_m(ray, t))
    }

    /// The hit list of vertex `v`, tracing its rays the first time (with a base, and a base
    /// vertex with the same rays, the base's list is filled from the same trace).
    fn hits(&self, v: usize) -> &[(u32, u32)] {
        self.hits[v].get_or_init(|| {
            let origin = &self.origins[v].0;
            // Each tracer's ray starts from the vertex in its own local frame.
            let local = |t: &RootTracer| t.tracer.local_from_world(origin);
            let Some(base) = &self.base else {
                let Some(own) = &self.tracer else {
                    return Box::default();
                };
                let from = local(own);
                let [list, _] = self.trace(v, &mut |dir, dir_local| {
                    if !own.may_hit(origin, dir, f64::from(GATHER_RAY_LENGTH_M)) {
                        return [None, None];
                    }
                    let ray = Ray::new(from, dir_local, ray_offset_m(), GATHER_RAY_LENGTH_M);
                    let hit = own.tracer.closest_hit(&ray);
                    let stop = hit.map(|h| {
                        (
                            own.roots[h.hit.triangle_id as usize],
                            &own.tracer,
                            &ray,
                            h.hit.t,
                        )
                    });
                    [stop.and_then(|s| self.element_at(&s, dir)), None]
                });
                return list;
            };
            let b = &*base.gather;
            let base_tracer = b
                .tracer
                .as_ref()
                .expect("a base has a tracer (VertexGather::over)");
            let from_base = local(base_tracer);
            let extra = self.tracer.as_ref().map(|x| (x, local(x)));
            let [own, in_base] = self.trace(v, &mut |dir, dir_local| {
                let base_ray = Ray::new(from_base, dir_local, ray_offset_m(), GATHER_RAY_LENGTH_M);
                let base_hit = if base_tracer.may_hit(origin, dir, f64::from(GATHER_RAY_LENGTH_M)) {
                    base_tracer.tracer.closest_hit(&base_ray)
                } else {
                    None
                };
                let t_base = base_hit.map_or(GATHER_RAY_LENGTH_M, |h| h.hit.t);
                let base_stop = base_hit.map(|h| {
                    let tri = h.hit.triangle_id as usize;
                    (
                        base_tracer.roots[tri],
                        &base_tracer.tracer,
                        &base_ray,
                        h.hit.t,
                        tri,
                    )
                });
                // The extra triangles, only closer than the base's hit.
                let extra_hit = extra.and_then(|(x, from)| {
                    if !x.may_hit(origin, dir, f64::from(t_base)) {
                        return None;
                    }
                    let ray = Ray::new(from, dir_local, ray_offset_m(), t_base);
                    x.tracer.closest_hit(&ray).map(|h| (x, ray, h))
                });
                let own = match (&extra_hit, base_stop) {
                    (Some((x, ray, h)), _) => {
                        let root = x.roots[h.hit.triangle_id as usize];
                        self.element_at(&(root, &x.tracer, ray, h.hit.t), dir)
                    }
                    (None, Some((_, tracer, ray, t, tri))) => {
                        let root = base.root_of_base_triangle[tri];
                        self.element_at(&(root, tracer, ray, t), dir)
                    }
                    (None, None) => None,
                };
                let in_base = base_stop.and_then(|(root, tracer, ray, t, _)| {
                    b.element_at(&(root, tracer, ray, t), dir)
                });
                [own, in_base]
            });
            let w = base.base_vertex[v];
            if w != NO_VERTEX {
                // Ignored when the base traced it meanwhile: the same rays gave the same list.
                let _ = b.hits[w as usize].set(in_base);
            }
            own
        })
    }

    /// The hit lists vertex `v`'s rays give for the two elements `hit` returns per ray
    /// direction (world, and the same normalised in `f32` as the tracers take it), as
    /// (element, rays) pairs.
    fn trace(&self, v: usize, hit: &mut RayElements<'_>) -> [VertexHits; 2] {
        let (_, normal, seed) = &self.origins[v];
        let mut rng = ChaCha8Rng::seed_from_u64(*seed);
        let frame = CosineFrame::new(normal);
        let n = self.rays_per_axis;
        let inv_n = 1.0 / f64::from(n);
        let mut hit_elements = [Vec::with_capacity((n * n) as usize), Vec::new()];
        for i in 0..n {
            for j in 0..n {
                let u1 = (f64::from(i) + rng.random::<f64>()) * inv_n;
                let u2 = (f64::from(j) + rng.random::<f64>()) * inv_n;
                let dir = frame.direction(u1, u2);
                // As `SceneTracer::ray_from_world` takes it.
                let d = dir.normalize();
                #[allow(clippy::cast_possible_truncation)]
                let dir_local = Vec3A::new(d.x as f32, d.y as f32, d.z as f32);
                for (list, e) in hit_elements.iter_mut().zip(hit(&dir, dir_local)) {
                    list.extend(e);
                }
            }
        }
        hit_elements.map(|mut hits| {
            hits.sort_unstable();
            let mut out: Vec<(u32, u32)> = Vec::new();
            for e in hits {
                match out.last_mut() {
                    Some((last, count)) if *last == e => *count += 1,
                    _ => out.push((e, 1)),
                }
            }
            out.into_boxed_slice()
        })
    }

    /// Interreflected irradiance at vertex `v` for the exitances `radiosity_rgb` (per element of
    /// this mesh).
    #[must_use]
    pub fn vertex_indirect_rgb(&self, v: usize, radiosity_rgb: &[Rgb]) -> Rgb {
        let mut sum = [0.0; 3];
        for &(e, count) in self.hits(v) {
            let b = &radiosity_rgb[e as usize];
            for c in 0..3 {
                sum[c] += f64::from(count) * b[c];
            }
        }
        let rays = f64::from(self.rays_per_axis * self.rays_per_axis);
        sum.map(|s| s / rays)
    }
}

/// What makes two vertices' gather rays the same: origin, normal and seed.
fn rays_key(o: &(Point3<f64>, Vector3<f64>, u64)) -> ([u64; 6], u64) {
    let (p, n, seed) = o;
    ([p.x, p.y, p.z, n.x, n.y, n.z].map(f64::to_bits), *seed)
}

/// Gather rays start this far along, metres ([`DIRECT_RAY_OFFSET_M`]).
#[allow(clippy::cast_possible_truncation)]
fn ray_offset_m() -> f32 {
    DIRECT_RAY_OFFSET_M as f32
}

fn check_rays_per_axis(rays_per_axis: u32) -> Result<(), RadiosityError> {
    if (1..=64).contains(&rays_per_axis) {
        Ok(())
    } else {
        Err(RadiosityError::InvalidParameter {
            name: "rays_per_axis",
            value: f64::from(rays_per_axis),
            reason: "must be 1 to 64",
        })
    }
}

#[cfg(test)]
mod tests;
