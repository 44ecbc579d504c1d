//! The element lookup behind [`super::Solution::irradiance_at`] (module `query`), in two
//! parts:
//!
//! - **geometry** ([`LookupGeometry`]): the hash grid of the element boxes
//!   ([`super::element_grid`]), each element's triangle as the point tests read it, and the
//!   shared vertices of nodal averaging (Cohen & Wallace, seed 002, §9.2: the corners of the
//!   same plane that coincide) with, per vertex, the element corners that meet there. It depends
//!   on the mesh's geometry only, so a relit solution (sun, sky, a colour) takes it over from the
//!   solution it replaces ([`super::Solution::reuse_query_geometry`]);
//! - **values** ([`ElementLocator`]): per element corner the averaged irradiance (total and
//!   direct), per element the total radiosity and whether it reflects. They are made anew for
//!   every solution, element- and vertex-parallel, with the sums in the same order as one pass
//!   over the elements would add them (so the same bits on any number of threads).
//!
//! A studio relight used to build both parts again on the preview's first query: about 24 ms per
//! solution of the 50 000-element city block, on one thread, after every sun step.
//!
//! Built lazily by the first query, the lookup is made on the querying thread alone: a render
//! queries from rayon's workers, and a parallel build inside the cell's initialisation could
//! steal a render task that queries the same cell (a re-entrant initialisation, which
//! deadlocks). [`Solution::prepare_queries`] builds it in parallel outside the cell.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::element_grid::ElementGrid;
use super::mesh::Mesh;
use super::surface_point::{TriangleShape, vertex_key};
use super::{Rgb, Solution};

/// A query point lies on an element when it is within this distance of its plane, metres
/// (survey points on a façade are good to a centimetre).
pub const ON_SURFACE_TOL_M: f64 = 0.02;

/// A query normal matches an element's when their angle is below acos of this (≈ 18°).
pub const NORMAL_MATCH_COS: f64 = 0.95;

/// Barycentric slack when locating a point on an element (points on shared edges).
const BARYCENTRIC_SLACK: f64 = 1e-6;

/// Padding of the element boxes in the lookup grid, metres: a located point lies within
/// [`ON_SURFACE_TOL_M`] of the plane and about as far outside an edge, so within √2 of that of
/// the triangle on any axis; twice the tolerance holds it.
const GRID_PAD_M: f64 = 2.0 * ON_SURFACE_TOL_M + BARYCENTRIC_SLACK;

/// The geometry part of the lookup (module doc).
#[derive(Debug)]
pub(crate) struct LookupGeometry {
    /// The mesh it was built for: its geometry hash and element count.
    geometry_hash: u64,
    elements: usize,
    pub(super) grid: ElementGrid,
    /// Per element, its triangle as the lookup tests it.
    pub(super) shapes: Vec<TriangleShape>,
    /// Per element, the shared vertex of each corner.
    corner_vertex: Vec<[u32; 3]>,
    /// Per shared vertex v, `corners[corner_start[v]..corner_start[v + 1]]` are the elements of
    /// the corners that meet there, in element order (an element once per such corner).
    corner_start: Vec<u32>,
    corners: Vec<u32>,
}

/// `f` of `0..n`, over rayon's pool when `parallel` (the same values either way).
fn map_indices<T: Send>(parallel: bool, n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if parallel {
        (0..n).into_par_iter().map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

impl LookupGeometry {
    fn new(mesh: &Mesh, parallel: bool) -> Self {
        let n = mesh.elements.len();
        let mut ids: FxHashMap<[i64; 6], u32> = FxHashMap::default();
        let corner_vertex: Vec<[u32; 3]> = (0..n)
            .map(|e| {
                let node = mesh.element_node(e);
                node.vertices_in_world_m.map(|v| {
                    let next = u32::try_from(ids.len()).unwrap_or(u32::MAX);
                    *ids.entry(vertex_key(&v, &node.normal_in_world))
                        .or_insert(next)
                })
            })
            .collect();
        // Counting sort of the corners by vertex, stable in element order.
        let mut corner_start = vec![0u32; ids.len() + 1];
        for v in corner_vertex.iter().flatten() {
            corner_start[*v as usize + 1] += 1;
        }
        for v in 0..ids.len() {
            corner_start[v + 1] += corner_start[v];
        }
        let mut fill: Vec<u32> = corner_start[..ids.len()].to_vec();
        let mut corners = vec![0u32; 3 * n];
        for (e, vs) in corner_vertex.iter().enumerate() {
            for v in vs {
                let slot = &mut fill[*v as usize];
                corners[*slot as usize] = u32::try_from(e).unwrap_or(u32::MAX);
                *slot += 1;
            }
        }
        let shapes = map_indices(parallel, n, |e| {
            let node = mesh.element_node(e);
            TriangleShape::new(&node.vertices_in_world_m, &node.normal_in_world)
        });
        Self {
            geometry_hash: mesh.geometry_hash,
            elements: n,
            grid: ElementGrid::new(mesh, GRID_PAD_M),
            shapes,
            corner_vertex,
            corner_start,
            corners,
        }
    }

    /// Whether it was built for `mesh`'s geometry.
    fn fits(&self, mesh: &Mesh) -> bool {
        self.geometry_hash == mesh.geometry_hash && self.elements == mesh.elements.len()
    }

    /// The element `point` lies on (normal within [`NORMAL_MATCH_COS`], plane within
    /// [`ON_SURFACE_TOL_M`]) and its barycentric weights.
    pub(super) fn locate(
        &self,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> Option<(usize, [f64; 3])> {
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for e in self.grid.candidates(point) {
            let shape = &self.shapes[e as usize];
            if shape.normal.dot(normal) < NORMAL_MATCH_COS {
                continue;
            }
            let distance = shape.distance_m(point);
            if distance > ON_SURFACE_TOL_M {
                continue;
            }
            let w = shape.weights(point);
            let outside = w.iter().map(|&x| (-x).max(0.0)).sum::<f64>() * shape.longest_edge_m;
            if outside > BARYCENTRIC_SLACK + ON_SURFACE_TOL_M {
                continue;
            }
            let score = distance + outside;
            // The lowest score, and of equal scores the lowest element (candidates come level
            // by level, so the order alone does not decide).
            if best.is_none_or(|(s, b, _)| score.total_cmp(&s).then((e as usize).cmp(&b)).is_lt()) {
                let clamped = w.map(|x| x.max(0.0));
                let sum: f64 = clamped.iter().sum();
                best = Some((score, e as usize, clamped.map(|x| x / sum)));
            }
        }
        best.map(|(_, e, w)| (e, w))
    }
}

/// The element lookup of one solution: the geometry it shares, and its values (module doc).
#[derive(Debug, Clone)]
pub(crate) struct ElementLocator {
    pub(super) geometry: Arc<LookupGeometry>,
    /// Per shared vertex: (total, direct) irradiance averaged over its corners
    /// ([`Self::vertex_values`] reads an element's three).
    vertex_means: Vec<(Rgb, Rgb)>,
    /// Per element, total radiosity B (for gathers).
    pub(super) radiosity: Vec<Rgb>,
    /// Per element: reflects (ρ > 0 in some channel).
    pub(super) reflects: Vec<bool>,
}

impl ElementLocator {
    /// The lookup of `solution`, on the geometry it was lent where that fits its mesh; over
    /// rayon's pool when `parallel` (never inside a cell's initialisation, module doc).
    pub(super) fn new(solution: &Solution, parallel: bool) -> Self {
        let mesh = &solution.mesh;
        let geometry = match solution.query_geometry.get() {
            Some(g) if g.fits(mesh) => Arc::clone(g),
            _ => {
                let g = Arc::new(LookupGeometry::new(mesh, parallel));
                // A solution lent none, or one of other geometry, keeps this one for its clones.
                let _ = solution.query_geometry.set(Arc::clone(&g));
                g
            }
        };
        let n = mesh.elements.len();
        // Per element, Σ over groups (in their order) of the total and direct irradiance, and
        // of the radiosity.
        let per_element: Vec<(Rgb, Rgb, Rgb)> = map_indices(parallel, n, |e| {
            let (mut total, mut direct, mut b) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            for g in &solution.groups {
                // The emitters group owns the emission (`LightGroup::emitters`).
                let h = g.irradiance_of(mesh, e, g.name == "emitters");
                for c in 0..3 {
                    total[c] += h[c];
                    direct[c] += g.direct_irradiance_rgb[e][c];
                    b[c] += g.radiosity_rgb[e][c];
                }
            }
            (total, direct, b)
        });
        // Per shared vertex, the mean over its corners, summed in element order.
        let vertices = geometry.corner_start.len() - 1;
        let vertex_means: Vec<(Rgb, Rgb)> = map_indices(parallel, vertices, |v| {
            let (mut t, mut d, mut k) = ([0.0; 3], [0.0; 3], 0.0);
            let range = geometry.corner_start[v] as usize..geometry.corner_start[v + 1] as usize;
            for &e in &geometry.corners[range] {
                let (total, direct, _) = &per_element[e as usize];
                for c in 0..3 {
                    t[c] += total[c];
                    d[c] += direct[c];
                }
                k += 1.0;
            }
            (t.map(|x| x / k), d.map(|x| x / k))
        });
        let reflects = map_indices(parallel, n, |e| {
            mesh.element_reflectance_rgb(e).iter().any(|&r| r > 0.0)
        });
        Self {
            geometry,
            vertex_means,
            radiosity: per_element.into_iter().map(|(_, _, b)| b).collect(),
            reflects,
        }
    }

    /// Element `e`'s (total, direct) irradiance at its three corners, averaged at the shared
    /// vertices (module doc); `None` for an element the mesh does not have.
    pub(super) fn vertex_values(&self, e: usize) -> Option<[(Rgb, Rgb); 3]> {
        self.geometry
            .corner_vertex
            .get(e)
            .map(|corners| corners.map(|v| self.vertex_means[v as usize]))
    }

    /// The element `point` lies on and its barycentric weights ([`LookupGeometry::locate`]).
    pub(super) fn locate(
        &self,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> Option<(usize, [f64; 3])> {
        self.geometry.locate(point, normal)
    }
}

impl Solution {
    /// Lends `previous`'s lookup geometry to this solution when both meshes have the same
    /// geometry (a relight of it), so that this solution's first point query computes only its
    /// values (module doc).
    pub fn reuse_query_geometry(&self, previous: &Solution) {
        if let Some(g) = previous.query_geometry.get()
            && g.fits(&self.mesh)
        {
            let _ = self.query_geometry.set(Arc::clone(g));
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::super::transfer::{LightingChange, RelightStrategy, Sweep};
    use super::super::transfer_tests::{build, lighting, params, sun_at, yard};
    use super::*;

    /// The per-vertex means as one pass over the elements adds them (the code this module
    /// replaced): the reference the parallel sums must equal bit for bit.
    fn one_pass_vertex_values(solution: &Solution) -> Vec<[(Rgb, Rgb); 3]> {
        let mesh = &solution.mesh;
        let n = mesh.elements.len();
        let mut total = vec![[0.0; 3]; n];
        let mut direct = vec![[0.0; 3]; n];
        for g in &solution.groups {
            let h = g.irradiance_rgb(mesh, g.name == "emitters");
            for e in 0..n {
                for c in 0..3 {
                    total[e][c] += h[e][c];
                    direct[e][c] += g.direct_irradiance_rgb[e][c];
                }
            }
        }
        let mut sums: FxHashMap<[i64; 6], (Rgb, Rgb, f64)> = FxHashMap::default();
        for e in 0..n {
            let node = mesh.element_node(e);
            for v in &node.vertices_in_world_m {
                let s = sums
                    .entry(vertex_key(v, &node.normal_in_world))
                    .or_insert(([0.0; 3], [0.0; 3], 0.0));
                for c in 0..3 {
                    s.0[c] += total[e][c];
                    s.1[c] += direct[e][c];
                }
                s.2 += 1.0;
            }
        }
        (0..n)
            .map(|e| {
                let node = mesh.element_node(e);
                node.vertices_in_world_m.map(|v| {
                    let (t, d, k) = sums[&vertex_key(&v, &node.normal_in_world)];
                    (t.map(|x| x / k), d.map(|x| x / k))
                })
            })
            .collect()
    }

    fn bits(values: &[[(Rgb, Rgb); 3]]) -> Vec<u64> {
        values
            .iter()
            .flatten()
            .flat_map(|(t, d)| t.iter().chain(d).map(|x| x.to_bits()))
            .collect()
    }

    #[test]
    fn the_parallel_sums_are_the_one_pass_means_bit_for_bit() {
        let t = build(
            &yard([0.6, 0.5, 0.4]),
            &lighting(),
            &params(RelightStrategy::LinearResponses, Sweep::Shooting),
        );
        let solution = t.solution();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let locator = pool.install(|| ElementLocator::new(solution, true));
        let alone = ElementLocator::new(solution, false);
        let values = |l: &ElementLocator| -> Vec<[(Rgb, Rgb); 3]> {
            (0..solution.mesh.elements.len())
                .map(|e| l.vertex_values(e).unwrap())
                .collect()
        };
        assert_eq!(bits(&values(&locator)), bits(&values(&alone)));
        assert!(values(&locator).len() > 100);
        assert_eq!(
            bits(&values(&locator)),
            bits(&one_pass_vertex_values(solution))
        );
        let b: Vec<u64> = solution
            .total_radiosity_rgb()
            .iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect();
        let b_locator: Vec<u64> = locator
            .radiosity
            .iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect();
        assert_eq!(b_locator, b);
        // Corners sharing a vertex on the ground average more than one element.
        assert!(
            (0..geometry_vertices(&locator.geometry)).any(|v| locator.geometry.corner_start[v + 1]
                - locator.geometry.corner_start[v]
                > 2)
        );
    }

    fn geometry_vertices(g: &LookupGeometry) -> usize {
        g.corner_start.len() - 1
    }

    #[test]
    fn a_relit_solution_takes_over_the_geometry_and_answers_the_same() {
        let mut t = build(
            &yard([0.6, 0.5, 0.4]),
            &lighting(),
            &params(RelightStrategy::LinearResponses, Sweep::Shooting),
        );
        let before = t.solution().without_direct_of(&|_| false);
        before.prepare_queries();
        let relit = t
            .relight(&LightingChange {
                sun: Some(Some(sun_at(0.5, 2.5))),
                ..LightingChange::default()
            })
            .unwrap();
        let own = relit.without_direct_of(&|_| false);
        let lent = relit.without_direct_of(&|_| false);
        lent.reuse_query_geometry(&before);
        assert!(own.query_geometry.get().is_none());
        assert!(Arc::ptr_eq(
            lent.query_geometry.get().unwrap(),
            before.query_geometry.get().unwrap()
        ));
        let mut answered = 0;
        for i in 0..40 {
            let x = -2.9 + 0.145 * f64::from(i);
            for (p, n) in [
                (Point3::new(x, 0.3 * x, 0.0), Vector3::z()),
                (Point3::new(1.5, x * 0.6, 1.0), -Vector3::x()),
            ] {
                let (a, b) = (own.irradiance_at(&p, &n), lent.irradiance_at(&p, &n));
                assert_eq!(a, b, "point {p}");
                answered += usize::from(a.is_some());
            }
        }
        assert!(answered > 60, "{answered} points on elements");
        // Not lent across geometries: another scene's solution keeps building its own.
        let other = build(
            &yard([0.6, 0.5, 0.4]),
            &lighting(),
            &params(RelightStrategy::LinearResponses, Sweep::Shooting),
        );
        let mut moved = (*other.solution().mesh).clone();
        moved.geometry_hash ^= 1;
        let elsewhere = Solution {
            mesh: Arc::new(moved),
            ..other.solution().without_direct_of(&|_| false)
        };
        elsewhere.reuse_query_geometry(&before);
        assert!(elsewhere.query_geometry.get().is_none());
    }
}
