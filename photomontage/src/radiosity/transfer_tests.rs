//! Precomputed transfer against full re-solves (sun move, sky change, dimming, material change),
//! determinism of relights, the ground below the horizon on a vertical wall, irradiance queries
//! against closed forms, and the light-placement warnings.
#![allow(clippy::unwrap_used)]
// Scalings and dark groups are exact by construction: these tests compare bits on purpose.
#![allow(clippy::float_cmp)]

use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};

use super::convergence::StopRule;
use super::hierarchical::HierarchicalParams;
use super::mesh::MeshParams;
use super::sources::{GroundBelowHorizon, LightWarning};
use super::transfer::{
    LightingChange, NamedLuminaire, RELIGHT_L1_REL_TOL, RELIGHT_MEAN_REL_TOL, RelightStrategy, Sky,
    Sun, Sweep, Transfer, TransferLighting, TransferParams,
};
use super::{
    FormFactorParams, PointSource, QueryParams, RadiosityError, Rgb, Solution, SolveParams, Solver,
    solve, test_scenes,
};
use crate::scene::Scene;
use crate::sky::{SkyModel, direction_from_elevation_azimuth};

/// The stop rule of the relights and of the re-solves they are compared with: the seed's 1 %
/// mean change, with a residual tight enough that iteration error stays below the comparison.
pub(super) const STOP: StopRule = StopRule {
    mean_change: 0.01,
    residual: 1e-4,
    max_passes: 200,
};

/// Relight against a re-solve on the same links: both stop within the residual 1e-4 of the same
/// fixed point, amplified by 1/(1 − ρF) < 2 here; the f32 link factors add 1e-7. 1e-3 bounds it.
pub(super) const SAME_LINKS_L1_REL_TOL: f64 = 1e-3;
/// Ground and sky clusters keep irradiance vectors exactly; a vertical plane cuts clusters, each
/// erring by at most τ·Φ_cluster (icosahedral.rs); at τ = 0.02 the observed error is below 0.3 %.
const CLUSTER_REL_TOL: f64 = 0.005;
/// Interpolation on an unshadowed plane of equal elements reproduces the element value to
/// rounding; the final gather's direct term is exact to rounding.
const CLOSED_FORM_REL_TOL: f64 = 1e-9;

pub(super) fn params(strategy: RelightStrategy, sweep: Sweep) -> TransferParams {
    TransferParams {
        solve: SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: 2.0,
                max_element_edge_m: 0.5,
                ..MeshParams::default()
            },
            form_factors: FormFactorParams::default(),
            solver: Solver::Hierarchical(HierarchicalParams::default()),
            stop: STOP,
            ..SolveParams::default()
        },
        sky_tolerance: 0.1,
        strategy,
        sweep,
    }
}

/// A 6 m ground square with a 1 m block and a 2 m wall on it; `render` is the block's material.
pub(super) fn yard(render_rho: Rgb) -> Scene {
    let p = Point3::new;
    let mut scene = Scene::new();
    test_scenes::add(
        &mut scene,
        "ground",
        test_scenes::quad(
            p(-3., -3., 0.),
            p(3., -3., 0.),
            p(3., 3., 0.),
            p(-3., 3., 0.),
        ),
        test_scenes::grey("asphalt", 0.3),
    );
    test_scenes::add(
        &mut scene,
        "block",
        test_scenes::block(p(-0.5, -0.5, 0.0), p(0.5, 0.5, 1.0)),
        crate::scene::Material::diffuse("render", render_rho),
    );
    test_scenes::add(
        &mut scene,
        "wall",
        test_scenes::block(p(1.5, -2.0, 0.0), p(1.7, 2.0, 2.0)),
        test_scenes::grey("brick", 0.5),
    );
    scene
}

pub(super) fn sun_at(elevation: f64, azimuth: f64) -> Sun {
    Sun {
        dir_in_world: direction_from_elevation_azimuth(elevation, azimuth),
        normal_irradiance_rgb: [2.0, 1.9, 1.7],
    }
}

fn lamp() -> NamedLuminaire {
    NamedLuminaire {
        name: "luminaire:lamp".into(),
        source: PointSource {
            position_in_world_m: Point3::new(-1.5, 1.0, 1.5),
            luminaire: None,
            intensity_rgb: [3.0, 3.0, 2.5],
        },
        dimming: 1.0,
    }
}

pub(super) fn lighting() -> TransferLighting {
    TransferLighting {
        sun: Some(sun_at(0.6, 2.3)),
        sky: Some(Sky {
            model: SkyModel::CieOvercast,
            horizontal_irradiance_rgb: [0.3, 0.35, 0.4],
        }),
        luminaires: vec![lamp()],
        emitters: false,
    }
}

pub(super) fn build(scene: &Scene, lighting: &TransferLighting, p: &TransferParams) -> Transfer {
    Transfer::build(scene, lighting, p, &AtomicBool::new(false), &|_| {}).unwrap()
}

/// A full solve of the transfer's current lighting on `scene` (fresh mesh, links and refinement).
fn resolve(scene: &Scene, t: &Transfer) -> Solution {
    solve(
        scene,
        t.light_groups(),
        &t.params().solve,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap()
}

fn assert_matches_resolve(label: &str, relit: &Solution, full: &Solution) {
    // Relight against a full re-solve: within the documented relight tolerances.
    let d = relit
        .relative_difference(full)
        .expect("same mesh, lit scene");
    assert!(d.l1_rel < RELIGHT_L1_REL_TOL, "{label}: L1 {}", d.l1_rel);
    assert!(
        d.mean_rel.abs() < RELIGHT_MEAN_REL_TOL,
        "{label}: mean {}",
        d.mean_rel
    );
    for (g, (x, y)) in relit.groups.iter().zip(&full.groups).enumerate() {
        assert_eq!(
            x.direct_irradiance_rgb, y.direct_irradiance_rgb,
            "{label}: group {g} direct term"
        );
    }
}

const STRATEGIES: [(RelightStrategy, Sweep); 4] = [
    (RelightStrategy::LinearResponses, Sweep::Shooting),
    (RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    (RelightStrategy::LinearResponses, Sweep::Jacobi),
    (RelightStrategy::WarmGaussSeidel, Sweep::GaussSeidel),
];

#[test]
fn the_initial_solution_is_the_solve() {
    let scene = yard([0.6; 3]);
    let t = build(
        &scene,
        &lighting(),
        &params(STRATEGIES[0].0, STRATEGIES[0].1),
    );
    let full = resolve(&scene, &t);
    assert_eq!(t.solution().groups, full.groups);
    assert_eq!(t.solution().interactions, full.interactions);
    assert_eq!(*t.solution().mesh, *full.mesh);
}

/// The measure the relight tests use: a solution against itself is 0; with one group's
/// radiosity doubled, the L1 difference and the mean change are that group's share of the total
/// (area-weighted luminance), computed here directly; a dark reference has no measure.
#[test]
fn relative_difference_has_its_closed_forms() {
    let scene = yard([0.6; 3]);
    let t = build(
        &scene,
        &lighting(),
        &params(STRATEGIES[0].0, STRATEGIES[0].1),
    );
    let s = t.solution();
    let same = s.relative_difference(s).unwrap();
    assert_eq!((same.l1_rel, same.mean_rel), (0.0, 0.0));
    let mut doubled = s.clone();
    for b in std::sync::Arc::make_mut(&mut doubled.groups[0].radiosity_rgb) {
        *b = b.map(|v| 2.0 * v);
    }
    let area = |e: usize| s.mesh.element_node(e).area_m2;
    let share = (0..s.mesh.elements.len())
        .map(|e| super::luminance(&s.groups[0].radiosity_rgb[e]) * area(e))
        .sum::<f64>()
        / s.total_radiosity_rgb()
            .iter()
            .enumerate()
            .map(|(e, b)| super::luminance(b) * area(e))
            .sum::<f64>();
    assert!(share > 0.1, "the sun group carries light: {share}");
    let d = doubled.relative_difference(s).unwrap();
    assert!((d.l1_rel - share).abs() < 1e-12, "{} vs {share}", d.l1_rel);
    assert!(
        (d.mean_rel - share).abs() < 1e-12,
        "{} vs {share}",
        d.mean_rel
    );
    let mut dark = s.clone();
    for g in &mut dark.groups {
        std::sync::Arc::make_mut(&mut g.radiosity_rgb)
            .iter_mut()
            .for_each(|b| *b = [0.0; 3]);
    }
    assert!(s.relative_difference(&dark).is_none());
}

#[test]
fn sun_move_sky_change_and_material_change_match_a_full_resolve() {
    for (strategy, sweep) in STRATEGIES {
        let label = format!("{strategy:?}/{sweep:?}");
        let scene = yard([0.6; 3]);
        let mut t = build(&scene, &lighting(), &params(strategy, sweep));
        // Sun move: only the sun's rays are traced again.
        let moved = t
            .relight(&LightingChange {
                sun: Some(Some(sun_at(0.9, 3.4))),
                ..LightingChange::default()
            })
            .unwrap();
        assert_matches_resolve(&format!("{label} sun"), &moved, &resolve(&scene, &t));
        // Sky type (a CIE general sky follows the sun).
        let sky = t
            .relight(&LightingChange {
                sky: Some(Some(Sky {
                    model: SkyModel::cie_general(12).unwrap(),
                    horizontal_irradiance_rgb: [0.2, 0.25, 0.35],
                })),
                ..LightingChange::default()
            })
            .unwrap();
        assert_matches_resolve(&format!("{label} sky"), &sky, &resolve(&scene, &t));
        // Material: the block turns from 0.6 to a reddish 0.8/0.3/0.2.
        let red = [0.8, 0.3, 0.2];
        let recoloured = t
            .relight(&LightingChange {
                material_reflectance: vec![("render".into(), red)],
                ..LightingChange::default()
            })
            .unwrap();
        assert_matches_resolve(
            &format!("{label} material"),
            &recoloured,
            &resolve(&yard(red), &t),
        );
        // Same links, cold start: the relight is the fixed point to the stop rule.
        let mesh = &recoloured.mesh;
        assert!(recoloured.converged(&STOP), "{label}");
        let _ = mesh;
    }
}

/// A sun step keeps the sky group when the sky's sources cannot have changed (a sky that does
/// not follow the sun); the kept group is, field for field, what clustering the sky again gives.
#[test]
fn a_kept_sky_group_is_the_clustered_one() {
    let scene = yard([0.6; 3]);
    let p = params(RelightStrategy::LinearResponses, Sweep::Shooting);
    let mut t = build(&scene, &lighting(), &p);
    let dome = crate::sky_dome::icosahedral::IcosahedralDome::new(
        &crate::sky_dome::icosahedral::IcosahedralParams::tonn_donath(),
    )
    .unwrap();
    let sky = |model| {
        Some(Some(Sky {
            model,
            horizontal_irradiance_rgb: [0.2, 0.25, 0.35],
        }))
    };
    let steps = [
        // Under the overcast sky it was built with, then a uniform one, then a CIE clear sky
        // (which follows the sun: clustered again on every step).
        (None, sun_at(0.9, 3.4)),
        (None, sun_at(0.8, 3.5)),
        (sky(SkyModel::Uniform), sun_at(0.8, 3.5)),
        (None, sun_at(0.7, 3.6)),
        (sky(SkyModel::cie_general(12).unwrap()), sun_at(0.7, 3.6)),
        (None, sun_at(0.6, 3.7)),
    ];
    for (k, (sky, sun)) in steps.into_iter().enumerate() {
        t.relight_in_place(&LightingChange {
            sun: Some(Some(sun)),
            sky,
            ..LightingChange::default()
        })
        .unwrap();
        let (clustered, _) = t.lighting().light_groups(&dome, p.sky_tolerance).unwrap();
        assert!(t.light_groups() == clustered.as_slice(), "step {k}");
    }
}

#[test]
fn relight_on_the_same_links_is_the_cold_solve() {
    for sweep in [Sweep::GaussSeidel, Sweep::Shooting] {
        relight_on_the_same_links_is_the_cold_solve_with(sweep);
    }
}

fn relight_on_the_same_links_is_the_cold_solve_with(sweep: Sweep) {
    // A relight and a cold solve on the stored links (same hierarchy) reach the same fixed point.
    let scene = yard([0.6; 3]);
    let p = params(RelightStrategy::LinearResponses, sweep);
    let mut t = build(&scene, &lighting(), &p);
    let change = LightingChange {
        sun: Some(Some(sun_at(0.4, 1.2))),
        luminaire_dimming: vec![("luminaire:lamp".into(), 0.25)],
        ..LightingChange::default()
    };
    let relit = t.relight(&change).unwrap();
    // Build a transfer directly for the new lighting with the old lighting's refinement is not
    // possible; instead solve the same b0 on the same links cold through a fresh transfer whose
    // lighting is the new one but whose links were refined for the old: relight from zero.
    let mut cold = build(&scene, &lighting(), &p);
    let dark = cold
        .relight(&LightingChange {
            sun: Some(None),
            sky: Some(None),
            luminaire_dimming: vec![("luminaire:lamp".into(), 0.0)],
            ..LightingChange::default()
        })
        .unwrap();
    assert!(dark.total_radiosity_rgb().iter().all(|b| *b == [0.0; 3]));
    let mut back = change.clone();
    back.sky = Some(lighting().sky);
    let from_dark = cold.relight(&back).unwrap();
    let rel = from_dark
        .relative_difference(&relit)
        .expect("same mesh, lit scene")
        .l1_rel;
    assert!(rel < SAME_LINKS_L1_REL_TOL, "{sweep:?}: {rel}");
}

#[test]
fn shooting_a_material_change_reads_only_that_materials_links_first() {
    // Only the block is `render`: the first shooting round reads only links whose source node
    // lies on the block (most of them: it leaves at most 5 % of the unshot power, the patches
    // with the least of it per link read), far fewer than a sweep over all links.
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::Shooting),
    );
    let links = t.solution().interactions;
    let relit = t
        .relight(&LightingChange {
            material_reflectance: vec![("render".into(), [0.8, 0.3, 0.2])],
            ..LightingChange::default()
        })
        .unwrap();
    // The links whose source node is on the block: the receivers of its radiosity.
    let block_links = t.links_from_object("block");
    for g in &relit.groups {
        let first = &g.convergence[0];
        assert!(
            first.interactions <= block_links && 2 * first.interactions >= block_links,
            "{}: {} of the block's {block_links}",
            g.name,
            first.interactions
        );
        assert!(
            first.interactions < links / 2,
            "{} of {links}",
            first.interactions
        );
    }
    assert!(relit.converged(&STOP));
}

/// A solution `relight` returned shares its values with the transfer until one changes
/// (`Arc::make_mut`): later relights of every kind (a material change shot into recycled
/// buffers, a scaling, a sun move) leave it as it was, bit for bit.
#[test]
fn a_returned_solution_keeps_its_values_through_later_relights() {
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::Shooting),
    );
    let kept = t
        .relight(&LightingChange {
            material_reflectance: vec![("brick".into(), [0.5, 0.4, 0.3])],
            ..LightingChange::default()
        })
        .unwrap();
    let copy: Vec<(Vec<Rgb>, Vec<Rgb>)> = kept
        .groups
        .iter()
        .map(|g| (g.radiosity_rgb.to_vec(), g.direct_irradiance_rgb.to_vec()))
        .collect();
    for change in [
        LightingChange {
            material_reflectance: vec![("brick".into(), [0.7, 0.6, 0.5])],
            ..LightingChange::default()
        },
        LightingChange {
            luminaire_dimming: vec![("luminaire:lamp".into(), 0.5)],
            ..LightingChange::default()
        },
        LightingChange {
            sun: Some(Some(sun_at(0.6, 2.3))),
            ..LightingChange::default()
        },
    ] {
        let now = t.relight(&change).unwrap();
        assert_ne!(now.groups, kept.groups, "the relight changed something");
    }
    for (g, (b, d)) in kept.groups.iter().zip(&copy) {
        assert_eq!(g.radiosity_rgb.as_slice(), b.as_slice(), "{}", g.name);
        assert_eq!(
            g.direct_irradiance_rgb.as_slice(),
            d.as_slice(),
            "{}",
            g.name
        );
    }
}

#[test]
fn dimming_and_weights_are_exact_scalings() {
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    );
    let before = t.solution().clone();
    let after = t
        .relight(&LightingChange {
            luminaire_dimming: vec![("luminaire:lamp".into(), 0.5)],
            sun: Some(Some(Sun {
                normal_irradiance_rgb: [1.0, 0.95, 0.85],
                ..sun_at(0.6, 2.3)
            })),
            ..LightingChange::default()
        })
        .unwrap();
    // Halving is exact in binary: bit-for-bit halves.
    for g in [0, 2] {
        for (a, b) in after.groups[g]
            .radiosity_rgb
            .iter()
            .zip(before.groups[g].radiosity_rgb.iter())
        {
            assert_eq!(*a, b.map(|v| v * 0.5), "group {g}");
        }
    }
    assert_eq!(after.groups[1], before.groups[1], "the sky is untouched");
    assert_matches_resolve("dimmed", &after, &resolve(&scene, &t));
}

#[test]
fn relights_are_bit_identical_on_one_and_two_threads() {
    let scene = yard([0.6; 3]);
    for sweep in [Sweep::Shooting, Sweep::GaussSeidel, Sweep::Jacobi] {
        let p = params(RelightStrategy::LinearResponses, sweep);
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mut t = build(&scene, &lighting(), &p);
                    let a = t
                        .relight(&LightingChange {
                            sun: Some(Some(sun_at(0.8, 3.0))),
                            ..LightingChange::default()
                        })
                        .unwrap();
                    let b = t
                        .relight(&LightingChange {
                            material_reflectance: vec![("brick".into(), [0.7, 0.6, 0.5])],
                            ..LightingChange::default()
                        })
                        .unwrap();
                    (a, b)
                })
        };
        let (one, two) = (on(1), on(2));
        let bits = |s: &Solution| -> Vec<u64> {
            s.groups
                .iter()
                .flat_map(|g| g.radiosity_rgb.iter().chain(g.direct_irradiance_rgb.iter()))
                .flat_map(|v| v.map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&one.0), bits(&two.0), "{sweep:?} sun");
        assert_eq!(bits(&one.1), bits(&two.1), "{sweep:?} material");
        assert_eq!(one.1.convergence(), two.1.convergence());
    }
}

#[test]
fn sun_below_the_horizon_and_bad_changes() {
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    );
    let night = t
        .relight(&LightingChange {
            sun: Some(Some(sun_at(-0.1, 2.0))),
            ..LightingChange::default()
        })
        .unwrap();
    assert!(
        night
            .warnings
            .iter()
            .any(|w| matches!(w, LightWarning::SunBelowHorizon { .. })),
        "{:?}",
        night.warnings
    );
    assert!(night.groups[0].radiosity_rgb.iter().all(|b| *b == [0.0; 3]));
    let before = t.solution().groups.clone();
    let err = t
        .relight(&LightingChange {
            material_reflectance: vec![("marble".into(), [0.5; 3])],
            ..LightingChange::default()
        })
        .unwrap_err();
    assert!(
        matches!(err, RadiosityError::UnknownMaterial { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("`marble`"), "{err}");
    let err = t
        .relight(&LightingChange {
            material_reflectance: vec![("render".into(), [f64::NAN, 0.5, 0.5])],
            luminaire_dimming: vec![("luminaire:lamp".into(), 0.1)],
            ..LightingChange::default()
        })
        .unwrap_err();
    assert!(err.to_string().contains("render"), "{err}");
    let err = t
        .relight(&LightingChange {
            luminaire_dimming: vec![("luminaire:nope".into(), 0.5)],
            ..LightingChange::default()
        })
        .unwrap_err();
    assert!(err.to_string().contains("luminaire:nope"), "{err}");
    let err = t
        .relight(&LightingChange {
            luminaire_dimming: vec![("luminaire:lamp".into(), -1.0)],
            ..LightingChange::default()
        })
        .unwrap_err();
    assert!(err.to_string().contains("dimming"), "{err}");
    assert_eq!(
        t.solution().groups,
        before,
        "a refused change changes nothing"
    );
    // A scene with nothing to mesh.
    let err = Transfer::build(
        &Scene::new(),
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap_err();
    assert!(matches!(err, RadiosityError::NoPatches { .. }), "{err}");
    // The solver must be hierarchical.
    let mut p = params(RelightStrategy::LinearResponses, Sweep::GaussSeidel);
    p.solve.solver = Solver::Progressive;
    let err =
        Transfer::build(&scene, &lighting(), &p, &AtomicBool::new(false), &|_| {}).unwrap_err();
    assert!(err.to_string().contains("hierarchical"), "{err}");
}

/// A vertical 4 × 3 m wall facing +y alone, no ground modelled: under a uniform sky of
/// horizontal irradiance E_h it sees half the sky (E = E_h/2) and half the ground below the
/// horizon (E = π·L_g/2 = a·E_h/2 for albedo a).
#[test]
fn vertical_wall_sees_half_sky_and_half_ground() {
    let p = Point3::new;
    let mut scene = Scene::new();
    test_scenes::add(
        &mut scene,
        "wall",
        test_scenes::quad(p(0., 0., 0.), p(0., 0., 3.), p(4., 0., 3.), p(4., 0., 0.)),
        test_scenes::grey("render", 0.5),
    );
    let normal = Vector3::new(0.0, 1.0, 0.0);
    let node = scene.triangles()[0].vertices_in_world_m;
    assert!(
        ((node[1] - node[0]).cross(&(node[2] - node[0])))
            .normalize()
            .dot(&normal)
            > 0.99
    );
    let e_h = [1.0, 0.8, 0.6];
    let albedo = [0.3, 0.2, 0.1];
    let dome = crate::sky_dome::icosahedral::IcosahedralDome::new(
        &crate::sky_dome::icosahedral::IcosahedralParams::tonn_donath(),
    )
    .unwrap();
    let sky =
        super::sources::sky_sources(&SkyModel::Uniform, &Vector3::z(), e_h, &dome, 0.02).unwrap();
    for ground in [None, Some(albedo)] {
        let solve_params = SolveParams {
            mesh: MeshParams {
                max_element_edge_m: 2.0,
                ..MeshParams::default()
            },
            ground: ground.map(|a| GroundBelowHorizon {
                albedo_rgb: a,
                cluster_tolerance: 0.02,
            }),
            ..SolveParams::default()
        };
        let s = solve(
            &scene,
            &[super::LightGroup::sky(sky.clone())],
            &solve_params,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap();
        let a = ground.unwrap_or([0.0; 3]);
        for d in s.groups[0].direct_irradiance_rgb.iter() {
            for c in 0..3 {
                let want = 0.5 * e_h[c] + 0.5 * a[c] * e_h[c];
                assert!(
                    (d[c] - want).abs() / want < CLUSTER_REL_TOL,
                    "ground {ground:?}: channel {c}: {} vs {want}",
                    d[c]
                );
            }
        }
    }
}

/// An open 8 m ground plane under a uniform sky and the sun: at every point E = E_h + E_n·sin h,
/// interpolated on the plane and gathered above it (no element there).
#[test]
fn irradiance_queries_meet_the_closed_form_on_an_open_plane() {
    let p = Point3::new;
    let mut scene = Scene::new();
    test_scenes::add(
        &mut scene,
        "ground",
        test_scenes::quad(
            p(-4., -4., 0.),
            p(4., -4., 0.),
            p(4., 4., 0.),
            p(-4., 4., 0.),
        ),
        test_scenes::grey("asphalt", 0.3),
    );
    let e_h = [0.3, 0.35, 0.4];
    let sun = sun_at(0.5, 1.0);
    let lighting = TransferLighting {
        sun: Some(sun),
        sky: Some(Sky {
            model: SkyModel::Uniform,
            horizontal_irradiance_rgb: e_h,
        }),
        luminaires: Vec::new(),
        emitters: false,
    };
    let t = build(
        &scene,
        &lighting,
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    );
    let want: Rgb = std::array::from_fn(|c| e_h[c] + sun.normal_irradiance_rgb[c] * 0.5f64.sin());
    let up = Vector3::z();
    let q = QueryParams::default();
    for point in [p(0.3, -1.7, 0.0), p(-3.9, 3.9, 0.0), p(1.0, 1.0, 0.005)] {
        let s = t.irradiance_at(&point, &up, &q).unwrap();
        assert!(s.element.is_some(), "{point}");
        for c in 0..3 {
            assert!(
                (s.total_rgb[c] - want[c]).abs() / want[c] < CLUSTER_REL_TOL,
                "{point}: {:?} vs {want:?}",
                s.total_rgb
            );
            // A lone plane reflects nothing onto itself.
            assert!(s.indirect_rgb[c].abs() < CLOSED_FORM_REL_TOL, "{s:?}");
        }
    }
    // Above the plane: no element, final gather; the plane below is not seen by an upward normal.
    let s = t.irradiance_at(&p(0.0, 0.0, 2.0), &up, &q).unwrap();
    assert_eq!(s.element, None);
    for c in 0..3 {
        assert!(
            (s.total_rgb[c] - want[c]).abs() / want[c] < CLOSED_FORM_REL_TOL,
            "{:?} vs {want:?}",
            s.total_rgb
        );
    }
    // Looking down from 2 m: the gather sees the uniformly lit plane (B = ρ·E) over most of
    // the hemisphere: E = ρ·E_plane·F, F = 1 − 1/(1 + (4/2)²)… bounded by ρ·E_plane.
    let down = -Vector3::z();
    let s = t.irradiance_at(&p(0.0, 0.0, 2.0), &down, &q).unwrap();
    for c in 0..3 {
        let bound = 0.3 * want[c];
        assert!(
            s.total_rgb[c] > 0.5 * bound && s.total_rgb[c] <= bound * 1.0001,
            "{s:?}"
        );
    }
    let err = t
        .irradiance_at(&p(0.0, 0.0, 0.0), &Vector3::new(0.0, 0.0, 2.0), &q)
        .unwrap_err();
    assert!(err.to_string().contains("unit"), "{err}");
}

#[test]
fn a_luminaire_inside_a_block_or_behind_a_wall_is_named() {
    let scene = yard([0.6; 3]);
    let inside = NamedLuminaire {
        name: "luminaire:buried".into(),
        source: PointSource {
            // Inside the 0.2 m thick wall, 0.1 m from its faces.
            position_in_world_m: Point3::new(1.6, 0.3, 1.2),
            luminaire: None,
            intensity_rgb: [1.0; 3],
        },
        dimming: 1.0,
    };
    let behind = NamedLuminaire {
        name: "luminaire:recessed".into(),
        source: PointSource {
            // 1 cm inside the wall's west face (x = 1.5, facing −x).
            position_in_world_m: Point3::new(1.51, 0.0, 1.0),
            luminaire: None,
            intensity_rgb: [1.0; 3],
        },
        dimming: 1.0,
    };
    let mut l = lighting();
    l.luminaires = vec![lamp(), inside, behind];
    let t = build(
        &scene,
        &l,
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    );
    let text: Vec<String> = t
        .solution()
        .warnings
        .iter()
        .map(ToString::to_string)
        .collect();
    assert!(
        text.iter()
            .any(|w| w.contains("`luminaire:buried`") && w.contains("inside object `wall`")),
        "{text:?}"
    );
    // The wall is 0.2 m thick: 1 cm from the west face, which faces away (a closed object too).
    assert!(
        text.iter()
            .any(|w| w.contains("`luminaire:recessed`") && w.contains("`wall`")),
        "{text:?}"
    );
    assert!(
        !text.iter().any(|w| w.contains("`luminaire:lamp`")),
        "{text:?}"
    );
    // A one-sided wall with the light 2 cm behind it.
    let p = Point3::new;
    let mut open = Scene::new();
    test_scenes::add(
        &mut open,
        "screen",
        test_scenes::quad(p(0., 0., 0.), p(0., 0., 3.), p(4., 0., 3.), p(4., 0., 0.)),
        test_scenes::grey("render", 0.5),
    );
    let mut l = lighting();
    l.luminaires[0].source.position_in_world_m = p(2.0, -0.02, 1.5);
    let t = build(
        &open,
        &l,
        &params(RelightStrategy::LinearResponses, Sweep::GaussSeidel),
    );
    let text: Vec<String> = t
        .solution()
        .warnings
        .iter()
        .map(ToString::to_string)
        .collect();
    assert!(
        text.iter()
            .any(|w| w.contains("`luminaire:lamp`")
                && w.contains("behind a surface of object `screen`")),
        "{text:?}"
    );
}
