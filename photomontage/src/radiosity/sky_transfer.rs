//! The sky's direct light through a precomputed visibility transfer (Tonn & Donath, seed 000:
//! "the geometry-dependent part of the radiosity solution is calculated once … the lighting
//! situation [sun position, sky type] can then be changed interactively").
//!
//! The dome's nodes one level below the roots are the transfer's **facets** (≈ 250 over the
//! hemisphere of the Tonn & Donath dome, ≈ 9° across). At build, every element traces one shadow
//! ray per facet towards the facet's centre from its own direct-light sample points (facet f
//! uses points k ≡ f (mod F), as [`super::sources`] spreads a many-cluster sky), and keeps the
//! number that escaped. A sky then lights element e with normal n by
//!
//! E_e = Σ_f V_ef · max(0, n·S_f) · E_h / H,  S_f = Σ_{i ∈ f} Φ_i·d_i,
//!
//! Φ_i the leaves' ∫L dω of the new sky, H = Σ_i Φ_i·max(0, d_i,z) and E_h the site's horizontal
//! irradiance: each facet is one distant source carrying its irradiance vector S_f exactly, as a
//! cluster of [`IcosahedralDome::cluster`] does, so an unobstructed plane that sees every facet
//! whole (the open ground) gets the all-leaves sum exactly, and a plane that cuts a facet errs by
//! at most Σ_i Φ_i·|d_i − d_f| over the cut facets. A change of sky type or of a sky that follows
//! the sun (CIE general skies, Perez) is a sum over facets per element; no ray is traced.
//!
//! # Known limitations
//! Visibility is resolved per facet (≈ 9°), not per cluster: near the sun a clear sky's clusters
//! are finer, so a shadow cast by the circumsolar sky is softer here than in a fresh
//! [`super::solve`], which traces the clusters of the new sky (docs/methodology.md).

use std::sync::Arc;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::form_factor::FormFactorEngine;
use super::source_rows::{Simd, simd_token};
use super::sources::{DIRECT_RAY_LENGTH_M, DIRECT_RAY_OFFSET_M, DirectSamples, sky_leaf_flux};
use super::twin::Twin;
use super::twin_factors::NaturalFactors;
use super::{RadiosityError, Rgb};
use crate::bvh::Ray;
use crate::sky::SkyModel;
use crate::sky_dome::icosahedral::IcosahedralDome;

/// The sky transfer a natural solve traced, kept for the solve of the scene with the planned
/// objects ([`super::twin`]), with the form factors it computed ([`super::twin_factors`]).
#[derive(Debug, Clone)]
pub struct SkyRays {
    /// The light group it was traced for (its sample points' random streams).
    pub(super) group: usize,
    pub(super) transfer: SkyTransfer,
    /// The hierarchical solve's factors (`None` for other solvers).
    pub(super) factors: Option<Arc<NaturalFactors>>,
}

/// The sky's visibility transfer of one mesh (module doc).
#[derive(Debug, Clone)]
pub(crate) struct SkyTransfer {
    /// The dome whose leaves a sky is evaluated on.
    dome: IcosahedralDome,
    /// Per facet, its dome leaves `start..end`.
    leaves: Vec<(usize, usize)>,
    /// Per facet, 1 / the rays each element traced towards it.
    inv_rays: Vec<f64>,
    /// Per element and facet (element-major, padded with zeros to whole [`LANES`]), the rays
    /// that escaped.
    pub(super) escaped: Vec<u8>,
    /// Per element, its unit normal.
    normals: Vec<Vector3<f64>>,
}

impl SkyTransfer {
    /// Traces the transfer of `engine`'s mesh from the sky group's sample points `samples`.
    ///
    /// # Panics
    /// When `samples` were drawn for another mesh.
    pub(crate) fn new(
        engine: &FormFactorEngine<'_>,
        samples: &DirectSamples,
        dome: &IcosahedralDome,
    ) -> Self {
        Self::beside(engine, samples, dome, None)
    }

    /// [`SkyTransfer::new`] of group `group` for the mesh with the planned objects, reading the
    /// escaped counts of each element's twin in the natural transfer `natural` where `twin`
    /// gives one ([`super::twin`]): the same counts as tracing every ray in the whole scene.
    /// `engine` must draw its sample points from the twins' streams ([`Twin::new`]). A natural
    /// transfer traced for another group, dome or sample count is not used.
    ///
    /// # Panics
    /// As [`SkyTransfer::new`].
    pub(crate) fn beside(
        engine: &FormFactorEngine<'_>,
        samples: &DirectSamples,
        dome: &IcosahedralDome,
        twin: Option<(&Twin, &SkyRays, usize)>,
    ) -> Self {
        let mesh = engine.mesh();
        let tracer = engine.tracer();
        let visibility = engine.params().visibility;
        let points = samples.per_element();
        assert!(
            samples.fits(mesh.elements.len(), points) && points > 0,
            "direct-light samples drawn for another mesh"
        );
        // The facets: each root's children (a root without children is a facet itself).
        let facets: Vec<usize> = dome
            .roots
            .iter()
            .flat_map(|&r| {
                let kids = &dome.nodes[r].children;
                if kids.is_empty() {
                    vec![r]
                } else {
                    kids.clone()
                }
            })
            .collect();
        let f_count = facets.len();
        let padded = f_count.next_multiple_of(LANES);
        // Read for every element: one compact array, not the dome's nodes.
        let dirs: Vec<Vector3<f64>> = facets
            .iter()
            .map(|&f| dome.nodes[f].centre_dir_in_world)
            .collect();
        // A facet reaches in front of a plane iff n·d_f > −sin(r_f), r_f its angular radius.
        let reach: Vec<f64> = facets
            .iter()
            .map(|&f| {
                let node = &dome.nodes[f];
                let cos_min = dome.leaves[node.leaf_start..node.leaf_end]
                    .iter()
                    .map(|l| l.centre_dir_in_world.dot(&node.centre_dir_in_world))
                    .fold(1.0_f64, f64::min)
                    .clamp(-1.0, 1.0);
                -(1.0 - cos_min * cos_min).sqrt()
            })
            .collect();
        let rays: Vec<usize> = (0..f_count)
            .map(|f| {
                (f % points..points)
                    .step_by(f_count)
                    .count()
                    .min(usize::from(u8::MAX))
            })
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let inv_rays: Vec<f64> = rays.iter().map(|&r| 1.0 / r as f64).collect();
        let first_point: Vec<usize> = (0..f_count).map(|f| f % points).collect();
        // The twin's transfer, where it was traced for this group on the same dome with the
        // same rays per facet.
        let twin = twin.filter(|(t, natural, group)| {
            natural.group == *group
                && t.twin_of.len() == mesh.elements.len()
                && natural.transfer.dome.nodes.len() == dome.nodes.len()
                && natural.transfer.inv_rays == inv_rays
        });
        // Per facet, its ray with the direction the tracer gives it (normalised, `f32`, with
        // its inverse): only the origin changes from ray to ray.
        #[allow(clippy::cast_possible_truncation)]
        let facet_rays: Vec<Ray> = dirs
            .iter()
            .map(|dir| {
                tracer.ray_from_world(
                    &Point3::origin(),
                    dir,
                    DIRECT_RAY_OFFSET_M as f32,
                    DIRECT_RAY_LENGTH_M,
                )
            })
            .collect();
        let mut escaped = vec![0u8; mesh.elements.len() * padded];
        escaped
            .par_chunks_mut(padded * ELEMENTS_PER_TASK)
            .enumerate()
            .for_each(|(task, out)| {
                let mut origins = Vec::with_capacity(points);
                // The element's rays in the whole scene, traced together (one stack), and the
                // facet each counts for.
                let (mut batch, mut batch_facets, mut blocked) =
                    (Vec::new(), Vec::new(), Vec::new());
                for (i, out) in out.chunks_exact_mut(padded).enumerate() {
                    let e = task * ELEMENTS_PER_TASK + i;
                    let normal = mesh.element_node(e).normal_in_world;
                    let points_of_e = samples.of_element(e);
                    // The sample points in the tracer's frame, once per element.
                    origins.clear();
                    origins.extend(points_of_e.iter().map(|p| tracer.local_from_world(p)));
                    // The twin's escaped counts per facet, and the planned objects' tracer.
                    let twin_counts = twin.and_then(|(t, natural, _)| {
                        t.twin_of[e].map(|w| {
                            let w = w as usize;
                            (
                                &natural.transfer.escaped[w * padded..w * padded + f_count],
                                t,
                                t.element_cone(e),
                            )
                        })
                    });
                    batch.clear();
                    batch_facets.clear();
                    for (f, (dir, facet_ray)) in dirs.iter().zip(&facet_rays).enumerate() {
                        if normal.dot(dir) <= reach[f] {
                            continue;
                        }
                        // None escaped the natural scene: none escapes with more in it; all
                        // escaped: only the planned objects can stop them (module doc of
                        // `twin`); else every ray in the whole scene.
                        let (blockers, twin) = match twin_counts {
                            Some((counts, _, _)) if counts[f] == 0 => continue,
                            Some((counts, t, cone)) if usize::from(counts[f]) == rays[f] => {
                                // All escaped the natural scene; outside the cone towards the
                                // planned objects they escape the whole scene too.
                                let artificial = match &t.artificial {
                                    Some(a)
                                        if !cone.is_some_and(|(axis, cos)| axis.dot(dir) < cos) =>
                                    {
                                        a
                                    }
                                    _ => {
                                        out[f] = counts[f];
                                        continue;
                                    }
                                };
                                (artificial, Some(t))
                            }
                            _ => (tracer, None),
                        };
                        let mut hits = 0u8;
                        // Points f mod P, f mod P + F, … (`rays`), without a division per facet.
                        for k in (0..rays[f]).map(|j| first_point[f] + j * f_count) {
                            if twin.is_some_and(|t| !t.may_meet_artificial(&points_of_e[k], dir)) {
                                hits += 1;
                                continue;
                            }
                            let ray = Ray {
                                origin: origins[k],
                                ..*facet_ray
                            };
                            if !visibility {
                                hits += 1;
                            } else if twin.is_none() {
                                batch.push(ray);
                                batch_facets.push(f);
                            } else if !blockers.any_hit(&ray) {
                                hits += 1;
                            }
                        }
                        out[f] = hits;
                    }
                    blocked.resize(batch.len(), false);
                    tracer.any_hits_here(&batch, &mut blocked);
                    for (&f, &b) in batch_facets.iter().zip(&blocked) {
                        out[f] += u8::from(!b);
                    }
                }
            });
        Self {
            dome: dome.clone(),
            leaves: facets
                .iter()
                .map(|&f| (dome.nodes[f].leaf_start, dome.nodes[f].leaf_end))
                .collect(),
            inv_rays,
            escaped,
            normals: (0..mesh.elements.len())
                .map(|e| mesh.element_node(e).normal_in_world)
                .collect(),
        }
    }

    /// The dome whose leaves a sky is evaluated on (the transfer clusters the sky on it too).
    pub(crate) fn dome(&self) -> &IcosahedralDome {
        &self.dome
    }

    /// Number of facets.
    #[cfg(test)]
    pub(crate) fn facets(&self) -> usize {
        self.leaves.len()
    }

    /// Direct irradiance per element from the sky `model` with the sun in `sun_dir_in_world`,
    /// scaled to the unobstructed horizontal irradiance `horizontal_irradiance_rgb` (module doc;
    /// no ground term). Each element on its own: the same values on any number of threads.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidSource`] when the model gives no light above the horizon.
    pub(crate) fn direct(
        &self,
        model: &SkyModel,
        sun_dir_in_world: &Vector3<f64>,
        horizontal_irradiance_rgb: Rgb,
    ) -> Result<Vec<Rgb>, RadiosityError> {
        let dome = &self.dome;
        let (flux, horizontal) = sky_leaf_flux(model, sun_dir_in_world, dome)?;
        // Per facet, its irradiance vector over the escaped fraction's denominator, by axis
        // (f32: the facet sum needs 1e-6, not 1e-16), LANES facets per block, the last block
        // padded with zero vectors.
        let f_count = self.leaves.len();
        let blocks = f_count.div_ceil(LANES);
        let mut axes = vec![[[0.0_f32; LANES]; 3]; blocks];
        for (f, (&(a, b), &inv)) in self.leaves.iter().zip(&self.inv_rays).enumerate() {
            let s: Vector3<f64> = dome.leaves[a..b]
                .iter()
                .zip(&flux[a..b])
                .map(|(l, phi)| l.centre_dir_in_world * *phi)
                .sum();
            for (axis, v) in axes[f / LANES].iter_mut().zip([s.x, s.y, s.z]) {
                #[allow(clippy::cast_possible_truncation)]
                {
                    axis[f % LANES] = (v * inv) as f32;
                }
            }
        }
        let scale = horizontal_irradiance_rgb.map(|k| k / horizontal);
        let stride = blocks * LANES;
        let simd = simd_token();
        let mut out = vec![[0.0; 3]; self.normals.len()];
        out.par_chunks_mut(ELEMENTS_PER_TASK)
            .zip(self.normals.par_chunks(ELEMENTS_PER_TASK))
            .zip(self.escaped.par_chunks(ELEMENTS_PER_TASK * stride))
            .for_each(|((out, normals), escaped)| {
                // max(0, n·S_f) per facet for the normal of the element before: elements come
                // patch by patch, so most share their predecessor's normal and its weights.
                let mut weights = vec![[0.0_f32; LANES]; blocks];
                let mut weights_of: Option<Vector3<f64>> = None;
                for ((e, n), hits) in out
                    .iter_mut()
                    .zip(normals)
                    .zip(escaped.chunks_exact(stride))
                {
                    if weights_of != Some(*n) {
                        facet_weights(n, &axes, &mut weights);
                        weights_of = Some(*n);
                    }
                    let sum = escaped_sum(simd, hits, &weights);
                    *e = scale.map(|k| k * sum);
                }
            });
        Ok(out)
    }
}

/// Elements per parallel task of [`SkyTransfer::beside`] and [`SkyTransfer::direct`].
const ELEMENTS_PER_TASK: usize = 256;

/// `weights[b][j]` = max(0, n·S_f) for facet f = b·LANES + j (`axes` as in
/// [`SkyTransfer::direct`]), in `f32`.
fn facet_weights(n: &Vector3<f64>, axes: &[[[f32; LANES]; 3]], weights: &mut [[f32; LANES]]) {
    #[allow(clippy::cast_possible_truncation)]
    let [nx, ny, nz] = [n.x as f32, n.y as f32, n.z as f32];
    for ([x, y, z], w) in axes.iter().zip(weights.iter_mut()) {
        for j in 0..LANES {
            w[j] = (nx * x[j] + ny * y[j] + nz * z[j]).max(0.0);
        }
    }
}

/// Σ_f escaped_f · weight_f: LANES partial sums in a fixed order (the same on any machine and
/// thread count; with AVX2 in [`super::gather_avx2`], the same bits), then added lane by lane.
fn escaped_sum(simd: Option<Simd>, hits: &[u8], weights: &[[f32; LANES]]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    let lanes = match simd {
        Some(token) => token.escaped_lanes(hits, weights),
        None => escaped_lanes(hits, weights),
    };
    #[cfg(not(target_arch = "x86_64"))]
    let lanes = {
        let _ = simd;
        escaped_lanes(hits, weights)
    };
    lanes.iter().map(|&v| f64::from(v)).sum()
}

/// The portable loop of [`escaped_sum`].
fn escaped_lanes(hits: &[u8], weights: &[[f32; LANES]]) -> [f32; LANES] {
    let mut lanes = [0.0_f32; LANES];
    for (w, hits) in weights.iter().zip(hits.chunks_exact(LANES)) {
        for j in 0..LANES {
            lanes[j] += f32::from(hits[j]) * w[j];
        }
    }
    lanes
}

/// Partial sums per element in the facet sum.
pub(super) const LANES: usize = 8;

#[cfg(test)]
mod tests {
    use nalgebra::Point3;

    use super::*;
    use crate::bvh::BuildQuality;
    use crate::radiosity::form_factor::FormFactorParams;
    use crate::radiosity::mesh::{Mesh, MeshParams};
    use crate::radiosity::sources::{direct_irradiance_at, sky_sources};
    use crate::radiosity::test_scenes::{add, block, grey, quad};
    use crate::scene::{Scene, SceneTracer};
    use crate::sky_dome::icosahedral::IcosahedralParams;

    /// The open ground gets the horizontal irradiance to the rounding of the f32 facet sum.
    const EXACT_REL_TOL: f64 = 1e-6;
    /// A lone wall under the clear sky against the all-leaves sum: what docs/methodology.md
    /// states (< 1 %); measured 0.46 %. The facets' own bound is checked as well.
    const LONE_WALL_REL_TOL: f64 = 0.01;
    /// Facets against the traced clusters (τ = 0.1) on an occluded yard, area-weighted L1 over
    /// the sum: the two differ in where visibility is sampled (≈ 9° facets against clusters, one
    /// ray per element each) and in the facets' cut error; measured 0.13 %.
    const CLUSTERS_L1_REL_TOL: f64 = 0.01;
    /// The same, for the area-weighted means (the bias): measured 0.05 %.
    const CLUSTERS_MEAN_REL_TOL: f64 = 0.002;

    const WEIGHT: Rgb = [0.3, 0.35, 0.4];

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    fn clear_sky() -> SkyModel {
        SkyModel::cie_general(12).expect("type 12 exists")
    }

    fn sun() -> Vector3<f64> {
        crate::sky::direction_from_elevation_azimuth(0.6, 2.3)
    }

    fn dome() -> IcosahedralDome {
        IcosahedralDome::new(&IcosahedralParams::tonn_donath()).expect("default dome")
    }

    struct Setup {
        mesh: Mesh,
        tracer: SceneTracer,
    }

    impl Setup {
        fn new(scene: &Scene) -> Self {
            let params = MeshParams {
                max_patch_edge_m: 2.0,
                max_element_edge_m: 0.5,
                ..MeshParams::default()
            };
            Self {
                mesh: Mesh::build(scene, &params).expect("mesh"),
                tracer: SceneTracer::new(scene, BuildQuality::Medium).expect("tracer"),
            }
        }

        fn engine(&self) -> FormFactorEngine<'_> {
            FormFactorEngine::new(&self.mesh, &self.tracer, FormFactorParams::default())
                .expect("engine")
        }
    }

    /// A 6 m square of open ground.
    fn ground() -> Scene {
        let mut scene = Scene::new();
        add(
            &mut scene,
            "ground",
            quad(
                p(-3., -3., 0.),
                p(3., -3., 0.),
                p(3., 3., 0.),
                p(-3., 3., 0.),
            ),
            grey("asphalt", 0.3),
        );
        scene
    }

    /// The ground with a block and a wall on it.
    fn yard() -> Scene {
        let mut scene = ground();
        add(
            &mut scene,
            "block",
            block(p(-0.5, -0.5, 0.0), p(0.5, 0.5, 1.0)),
            grey("render", 0.6),
        );
        add(
            &mut scene,
            "wall",
            block(p(1.5, -2.0, 0.0), p(1.7, 2.0, 2.0)),
            grey("brick", 0.5),
        );
        scene
    }

    #[test]
    fn open_ground_gets_the_horizontal_irradiance() {
        let scene = ground();
        let s = Setup::new(&scene);
        let engine = s.engine();
        let dome = dome();
        let t = SkyTransfer::new(&engine, &DirectSamples::new(&engine, 1), &dome);
        assert!(t.facets() > 200, "{} facets", t.facets());
        for model in [clear_sky(), SkyModel::CieOvercast] {
            for e in t.direct(&model, &sun(), WEIGHT).unwrap() {
                for c in 0..3 {
                    assert!(
                        (e[c] - WEIGHT[c]).abs() <= EXACT_REL_TOL * WEIGHT[c],
                        "{model:?}: {e:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_lone_wall_errs_within_the_facets_bound() {
        // A vertical square facing +x, alone: it cuts the facets along its horizon great circle.
        let mut scene = Scene::new();
        add(
            &mut scene,
            "wall",
            quad(p(0., 1., 0.), p(0., -1., 0.), p(0., -1., 2.), p(0., 1., 2.)),
            grey("brick", 0.5),
        );
        let s = Setup::new(&scene);
        let engine = s.engine();
        let dome = dome();
        let t = SkyTransfer::new(&engine, &DirectSamples::new(&engine, 1), &dome);
        let model = clear_sky();
        let (flux, horizontal) = sky_leaf_flux(&model, &sun(), &dome).unwrap();
        let n = s.mesh.element_node(0).normal_in_world;
        let leaf_sum: f64 = dome
            .leaves
            .iter()
            .zip(&flux)
            .map(|(l, phi)| phi * n.dot(&l.centre_dir_in_world).max(0.0))
            .sum();
        // Σ over facets of Σ Φ_i·|d_i − d_f|, d_f the facet's flux-weighted direction.
        let bound: f64 = t
            .leaves
            .iter()
            .map(|&(a, b)| {
                let v: Vector3<f64> = dome.leaves[a..b]
                    .iter()
                    .zip(&flux[a..b])
                    .map(|(l, phi)| l.centre_dir_in_world * *phi)
                    .sum();
                let d = v.normalize();
                dome.leaves[a..b]
                    .iter()
                    .zip(&flux[a..b])
                    .map(|(l, phi)| phi * (l.centre_dir_in_world - d).norm())
                    .sum::<f64>()
            })
            .sum();
        let direct = t.direct(&model, &sun(), WEIGHT).unwrap();
        for e in &direct {
            let got = e[0] / WEIGHT[0] * horizontal;
            assert!(
                got <= leaf_sum * (1.0 + EXACT_REL_TOL) && leaf_sum - got <= bound,
                "{got} against the leaves' {leaf_sum}, bound {bound}"
            );
            assert!(
                (leaf_sum - got) / leaf_sum < LONE_WALL_REL_TOL,
                "{got} against {leaf_sum}"
            );
        }
    }

    #[test]
    fn agrees_with_the_traced_clusters_on_a_yard_and_on_any_thread_count() {
        let scene = yard();
        let s = Setup::new(&scene);
        let engine = s.engine();
        let dome = dome();
        let samples = DirectSamples::new(&engine, 1);
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        };
        let model = clear_sky();
        let [(t1, d1), (t2, d2)] = [1, 2].map(|threads| {
            pool(threads).install(|| {
                let t = SkyTransfer::new(&engine, &samples, &dome);
                let d = t.direct(&model, &sun(), WEIGHT).unwrap();
                (t, d)
            })
        });
        assert_eq!(t1.escaped, t2.escaped);
        assert_eq!(d1, d2);
        let clusters = sky_sources(&model, &sun(), WEIGHT, &dome, 0.1).unwrap();
        let traced = direct_irradiance_at(&engine, &samples, &clusters);
        let (mut l1, mut sum_t, mut sum_f) = (0.0, 0.0, 0.0);
        for (e, (a, b)) in traced.iter().zip(&d1).enumerate() {
            let area = s.mesh.element_node(e).area_m2;
            l1 += (a[1] - b[1]).abs() * area;
            sum_t += a[1] * area;
            sum_f += b[1] * area;
        }
        println!(
            "facets against clusters: L1 {:.4}, means {:.4}",
            l1 / sum_t,
            sum_f / sum_t - 1.0
        );
        assert!(l1 / sum_t < CLUSTERS_L1_REL_TOL, "{}", l1 / sum_t);
        assert!(
            (sum_f / sum_t - 1.0).abs() < CLUSTERS_MEAN_REL_TOL,
            "{}",
            sum_f / sum_t
        );
    }

    /// The facet sum's AVX2 kernel gives the portable loop's lane sums bit for bit, on counts
    /// 0–255 and weights of every magnitude the sum meets (zeros included).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn vector_facet_sum_equals_the_portable_loop() {
        let Some(token) = simd_token() else {
            eprintln!("notice: this CPU has no vector kernel; nothing to compare");
            return;
        };
        let blocks = 37;
        #[allow(clippy::cast_possible_truncation)]
        let hits: Vec<u8> = (0..blocks * LANES)
            .map(|i| (i * 7919 % 256) as u8)
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let weights: Vec<[f32; LANES]> = (0..blocks)
            .map(|b| {
                std::array::from_fn(|j| {
                    let i = b * LANES + j;
                    if i.is_multiple_of(5) {
                        0.0
                    } else {
                        (i * 104_729 % 1000) as f32 * 1.37e-3 * 10f32.powi((i % 7) as i32 - 3)
                    }
                })
            })
            .collect();
        for n in [0, 1, 2, blocks] {
            let (a, b) = (
                escaped_lanes(&hits[..n * LANES], &weights[..n]),
                token.escaped_lanes(&hits[..n * LANES], &weights[..n]),
            );
            assert!(
                a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{n} blocks: {a:?} against {b:?}"
            );
        }
    }
}
