//! Precomputed transfer on a city block of ≈ 50 000 elements (16 buildings of 20 × 20 × 15 m on a
//! 200 m ground): the precompute (mesh, links, form factors, every group's first solve) timed
//! three times, then relight latency on 2 threads for a sun move, a material change and a
//! luminaire dimming, with both relight strategies and both sweeps (docs/benchmarks.md).
#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use photomontage::radiosity::form_factor::FormFactorEngine;
use photomontage::radiosity::hierarchical::HierarchicalParams;
use photomontage::radiosity::sources::direct_irradiance;
use photomontage::radiosity::{
    FormFactorParams, LightingChange, MeshParams, NamedLuminaire, PointSource, RelightStrategy,
    Sky, SolveParams, Solver, Sun, Sweep, Transfer, TransferLighting, TransferParams,
};
use photomontage::scene::{ImportedModel, Material, ObjectKind, Scene};
use photomontage::sky::{SkyModel, direction_from_elevation_azimuth};

type Tri = [Point3<f64>; 3];

/// Threads of every measurement (the target is on 2 threads).
const THREADS: usize = 2;

fn quad(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Vec<Tri> {
    let p = |v: [f64; 3]| Point3::from(v);
    vec![[p(a), p(b), p(c)], [p(a), p(c), p(d)]]
}

fn add(scene: &mut Scene, name: &str, triangles: Vec<Tri>, material: &str, albedo: f64) {
    let n = triangles.len();
    let model = ImportedModel {
        triangles_in_world_m: triangles,
        triangle_materials: vec![0; n],
        materials: vec![Material::diffuse(material, [albedo; 3])],
        warnings: Vec::new(),
    };
    scene.add_model(&model, name, ObjectKind::Natural).unwrap();
}

/// Walls and roof of a box (outward), no floor.
fn building(x: f64, y: f64, w: f64, h: f64) -> Vec<Tri> {
    let (x1, y1) = (x + w, y + w);
    let mut t = Vec::new();
    t.extend(quad([x, y, 0.], [x1, y, 0.], [x1, y, h], [x, y, h]));
    t.extend(quad([x1, y, 0.], [x1, y1, 0.], [x1, y1, h], [x1, y, h]));
    t.extend(quad([x1, y1, 0.], [x, y1, 0.], [x, y1, h], [x1, y1, h]));
    t.extend(quad([x, y1, 0.], [x, y, 0.], [x, y, h], [x, y1, h]));
    t.extend(quad([x, y, h], [x1, y, h], [x1, y1, h], [x, y1, h]));
    t
}

/// 16 buildings (4 × 4, 20 m wide, 15 m high, 40 m apart) on a 200 m ground.
fn city_block() -> Scene {
    let mut s = Scene::new();
    add(
        &mut s,
        "ground",
        quad(
            [-100., -100., 0.],
            [100., -100., 0.],
            [100., 100., 0.],
            [-100., 100., 0.],
        ),
        "asphalt",
        0.2,
    );
    let mut k = 0;
    for i in 0..4 {
        for j in 0..4 {
            let (x, y) = (-70.0 + 40.0 * f64::from(i), -70.0 + 40.0 * f64::from(j));
            let material = if k % 2 == 0 { "render" } else { "brick" };
            add(
                &mut s,
                &format!("building{k}"),
                building(x, y, 20.0, 15.0),
                material,
                if k % 2 == 0 { 0.6 } else { 0.35 },
            );
            k += 1;
        }
    }
    s
}

fn params(strategy: RelightStrategy, sweep: Sweep) -> TransferParams {
    let mut object_element_edge_m = std::collections::BTreeMap::new();
    object_element_edge_m.insert("ground".to_owned(), 8.0);
    TransferParams {
        solve: SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: 8.0,
                max_element_edge_m: 2.0,
                object_element_edge_m,
                ..MeshParams::default()
            },
            form_factors: FormFactorParams {
                samples_per_axis: 2,
                seed: 0,
                visibility: true,
            },
            solver: Solver::Hierarchical(HierarchicalParams::default()),
            ..SolveParams::default()
        },
        sky_tolerance: 0.1,
        strategy,
        sweep,
    }
}

fn sun(elevation: f64, azimuth: f64) -> Sun {
    Sun {
        dir_in_world: direction_from_elevation_azimuth(elevation, azimuth),
        normal_irradiance_rgb: [3.0, 2.9, 2.7],
    }
}

fn lighting() -> TransferLighting {
    TransferLighting {
        sun: Some(sun(0.7, 2.6)),
        sky: Some(Sky {
            model: SkyModel::CieOvercast,
            horizontal_irradiance_rgb: [0.4, 0.45, 0.5],
        }),
        luminaires: vec![NamedLuminaire {
            name: "luminaire:street".into(),
            source: PointSource {
                position_in_world_m: Point3::new(0.0, 0.0, 6.0),
                luminaire: None,
                intensity_rgb: [500.0; 3],
            },
            dimming: 1.0,
        }],
        emitters: false,
    }
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .unwrap()
}

fn build(p: &TransferParams) -> Transfer {
    Transfer::build(
        &city_block(),
        &lighting(),
        p,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap()
}

fn bench_transfer(c: &mut Criterion) {
    let pool = pool();
    // Precompute: three timed builds (criterion's minimum of 10 samples would take minutes).
    let p = params(RelightStrategy::LinearResponses, Sweep::GaussSeidel);
    let mut times = Vec::new();
    let mut transfer = None;
    for _ in 0..3 {
        let t0 = Instant::now();
        let t = pool.install(|| build(&p));
        times.push(t0.elapsed().as_secs_f64());
        transfer = Some(t);
    }
    times.sort_by(f64::total_cmp);
    let base = transfer.unwrap();
    let s = base.solution();
    println!(
        "transfer precompute: {} elements, {} patches, {} links; builds {:.2} / {:.2} / {:.2} s (median {:.2} s)",
        s.mesh.elements.len(),
        s.mesh.patches.len(),
        s.interactions,
        times[0],
        times[1],
        times[2],
        times[1]
    );
    let mut group = c.benchmark_group("relight_50k");
    group.sample_size(20);
    group.warm_up_time(std::time::Duration::from_secs(1));
    group.measurement_time(std::time::Duration::from_secs(3));
    // The sun's direct term alone: one shadow ray per element sample (2 × 2) towards the sun.
    let engine = FormFactorEngine::new(&s.mesh, base.tracer(), p.solve.form_factors).unwrap();
    let moved = [photomontage::radiosity::DistantSource {
        dir_in_world: sun(0.75, 2.7).dir_in_world,
        normal_irradiance_rgb: [3.0; 3],
    }];
    group.bench_function("sun_retrace_only", |b| {
        b.iter(|| pool.install(|| direct_irradiance(&engine, &moved, 0)));
    });
    for (label, strategy, sweep) in [
        (
            "linear_gauss_seidel",
            RelightStrategy::LinearResponses,
            Sweep::GaussSeidel,
        ),
        (
            "linear_jacobi",
            RelightStrategy::LinearResponses,
            Sweep::Jacobi,
        ),
        (
            "warm_gauss_seidel",
            RelightStrategy::WarmGaussSeidel,
            Sweep::GaussSeidel,
        ),
    ] {
        let mut t = base.clone().with_strategy(strategy, sweep);
        let mut flip = false;
        group.bench_function(format!("{label}/sun_move"), |b| {
            b.iter(|| {
                flip = !flip;
                let s = if flip { sun(0.75, 2.7) } else { sun(0.7, 2.6) };
                pool.install(|| {
                    t.relight(&LightingChange {
                        sun: Some(Some(s)),
                        ..LightingChange::default()
                    })
                    .unwrap()
                })
            });
        });
        group.bench_function(format!("{label}/material"), |b| {
            b.iter(|| {
                flip = !flip;
                let rho = if flip { [0.7, 0.5, 0.4] } else { [0.6; 3] };
                pool.install(|| {
                    t.relight(&LightingChange {
                        material_reflectance: vec![("render".into(), rho)],
                        ..LightingChange::default()
                    })
                    .unwrap()
                })
            });
        });
        group.bench_function(format!("{label}/dimming"), |b| {
            b.iter(|| {
                flip = !flip;
                let d = if flip { 0.5 } else { 1.0 };
                pool.install(|| {
                    t.relight(&LightingChange {
                        luminaire_dimming: vec![("luminaire:street".into(), d)],
                        ..LightingChange::default()
                    })
                    .unwrap()
                })
            });
        });
        // Passes of one sun move and one material change (printed for the docs).
        let s = pool.install(|| {
            t.relight(&LightingChange {
                sun: Some(Some(sun(0.8, 2.8))),
                ..LightingChange::default()
            })
            .unwrap()
        });
        let m = pool.install(|| {
            t.relight(&LightingChange {
                material_reflectance: vec![("brick".into(), [0.5, 0.4, 0.3])],
                ..LightingChange::default()
            })
            .unwrap()
        });
        println!(
            "{label}: sun move {} passes, material change {:?} passes per group",
            s.groups[0].convergence.len(),
            m.groups
                .iter()
                .map(|g| g.convergence.len())
                .collect::<Vec<_>>()
        );
    }
    group.finish();
}

criterion_group!(benches, bench_transfer);
criterion_main!(benches);
