//! Radiosity speed: form factors per second (one row of a courtyard scene) and whole solves
//! (mesh, sun and sky direct light, interreflection) with the hierarchical and the progressive
//! solver, at element sizes giving a few hundred to a few thousand elements (docs/benchmarks.md).
#![allow(clippy::unwrap_used)]

use std::hint::black_box;
use std::sync::atomic::AtomicBool;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Point3;
use photomontage::bvh::BuildQuality;
use photomontage::radiosity::form_factor::FormFactorEngine;
use photomontage::radiosity::hierarchical::HierarchicalParams;
use photomontage::radiosity::sources::sky_sources;
use photomontage::radiosity::{
    FormFactorParams, LightGroup, Mesh, MeshParams, SolveParams, Solver, StopRule, solve,
};
use photomontage::scene::{ImportedModel, Material, ObjectKind, Scene, SceneTracer};
use photomontage::sky::SkyModel;
use photomontage::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

type Tri = [Point3<f64>; 3];

fn quad(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Vec<Tri> {
    let p = |v: [f64; 3]| Point3::from(v);
    vec![[p(a), p(b), p(c)], [p(a), p(c), p(d)]]
}

fn add(scene: &mut Scene, name: &str, triangles: Vec<Tri>, albedo: f64) {
    let n = triangles.len();
    let model = ImportedModel {
        triangles_in_world_m: triangles,
        triangle_materials: vec![0; n],
        materials: vec![Material::diffuse(name, [albedo; 3])],
        warnings: Vec::new(),
    };
    scene.add_model(&model, name, ObjectKind::Natural).unwrap();
}

/// A 20 × 20 m court: ground (ρ 0.2), three 8 m walls facing in (ρ 0.4–0.7), open to the south.
fn courtyard() -> Scene {
    let mut s = Scene::new();
    add(
        &mut s,
        "ground",
        quad([0., 0., 0.], [20., 0., 0.], [20., 20., 0.], [0., 20., 0.]),
        0.2,
    );
    add(
        &mut s,
        "west",
        quad([0., 0., 0.], [0., 20., 0.], [0., 20., 8.], [0., 0., 8.]),
        0.5,
    );
    add(
        &mut s,
        "east",
        quad([20., 0., 0.], [20., 0., 8.], [20., 20., 8.], [20., 20., 0.]),
        0.7,
    );
    add(
        &mut s,
        "north",
        quad([0., 20., 0.], [20., 20., 0.], [20., 20., 8.], [0., 20., 8.]),
        0.4,
    );
    s
}

fn groups() -> Vec<LightGroup> {
    let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath()).unwrap();
    let sun = photomontage::sky::direction_from_elevation_azimuth(0.7, 2.6);
    let sky = sky_sources(
        &SkyModel::cie_general(12).unwrap(),
        &sun,
        [0.3; 3],
        &dome,
        0.1,
    )
    .unwrap();
    vec![LightGroup::sun(sun, [3.0; 3]), LightGroup::sky(sky)]
}

fn params(element_edge_m: f64, solver: Solver) -> SolveParams {
    SolveParams {
        mesh: MeshParams {
            max_patch_edge_m: 8.0,
            max_element_edge_m: element_edge_m,
            ..MeshParams::default()
        },
        solver,
        stop: StopRule::default(),
        ..SolveParams::default()
    }
}

fn bench_form_factors(c: &mut Criterion) {
    let scene = courtyard();
    let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
    let mut group = c.benchmark_group("radiosity_form_factors");
    group.sample_size(10);
    for edge in [2.0, 1.0] {
        let mesh = Mesh::build(&scene, &params(edge, Solver::Progressive).mesh).unwrap();
        let engine = FormFactorEngine::new(&mesh, &tracer, FormFactorParams::default()).unwrap();
        // A wall element near the ground: sees most of the scene.
        let sender = mesh.elements[mesh.elements.len() / 2];
        group.throughput(Throughput::Elements(mesh.elements.len() as u64));
        group.bench_with_input(
            BenchmarkId::new("row_16_samples", mesh.elements.len()),
            &mesh,
            |b, mesh| b.iter(|| black_box(engine.row(sender, &mesh.elements))),
        );
    }
    group.finish();
}

fn bench_solves(c: &mut Criterion) {
    let scene = courtyard();
    let lights = groups();
    let never = AtomicBool::new(false);
    let mut group = c.benchmark_group("radiosity_solve");
    group.sample_size(10);
    for (name, edge, solver) in [
        (
            "hierarchical",
            1.0,
            Solver::Hierarchical(HierarchicalParams::default()),
        ),
        (
            "hierarchical",
            0.5,
            Solver::Hierarchical(HierarchicalParams::default()),
        ),
        ("progressive", 2.0, Solver::Progressive),
    ] {
        let p = params(edge, solver);
        let elements = Mesh::build(&scene, &p.mesh).unwrap().elements.len();
        group.bench_with_input(BenchmarkId::new(name, elements), &p, |b, p| {
            b.iter(|| black_box(solve(&scene, &lights, p, &never, &|_| {}).unwrap()));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_form_factors, bench_solves);
criterion_main!(benches);
