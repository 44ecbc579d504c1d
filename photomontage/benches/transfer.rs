//! Precomputed transfer on a city block of ≈ 50 000 elements (16 buildings of 20 × 20 × 15 m on a
//! 200 m ground): the precompute (mesh, links, form factors, every group's first solve) timed
//! once (wall and CPU time), then relight latency on 2 threads for a sun move, a material change and a
//! luminaire dimming, with both relight strategies and every sweep (criterion medians, then a
//! summary of wall and CPU time per relight and the load average; docs/benchmarks.md). Then the
//! same relights with 32 m roots instead of 8 m (far fewer initial links), with how far that
//! solution's interreflected radiosity lies from the 8 m one.
#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};

mod common;
use common::{cpu_s, indirect_by_centroid, load_average};
use photomontage::radiosity::city_block::{
    self, RENDER_ALBEDO, city_block, city_block_lighting, city_block_params, city_block_sun,
};
use photomontage::radiosity::form_factor::FormFactorEngine;
use photomontage::radiosity::sources::direct_irradiance;
use photomontage::radiosity::{
    LightingChange, RelightStrategy, Sun, Sweep, Transfer, TransferParams,
};

/// Threads of every measurement (the target is on 2 threads).
const THREADS: usize = 2;

/// Longest patch edge (the hierarchy's roots) of the main measurements, metres.
const PATCH_EDGE_M: f64 = city_block::CITY_BLOCK_PATCH_EDGE_M;

/// Roots of the coarse-root variant, metres: 16 × fewer patches, so far fewer initial links.
const COARSE_PATCH_EDGE_M: f64 = 32.0;

fn params(strategy: RelightStrategy, sweep: Sweep) -> TransferParams {
    city_block_params(strategy, sweep)
}

fn sun(elevation: f64, azimuth: f64) -> Sun {
    city_block_sun(elevation, azimuth)
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .unwrap()
}

fn build(p: &TransferParams) -> Transfer {
    Transfer::build(
        &city_block(0, [RENDER_ALBEDO; 3]).unwrap(),
        &city_block_lighting(),
        p,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap()
}

/// L1 difference of `other`'s interreflected radiosity from `reference`'s, relative to the
/// reference's sum, and the relative difference of the means.
fn indirect_difference(
    reference: &photomontage::radiosity::Solution,
    other: &photomontage::radiosity::Solution,
) -> (f64, f64) {
    let a = indirect_by_centroid(reference);
    let b = indirect_by_centroid(other);
    let (mut l1, mut sum_a, mut sum_b) = (0.0, 0.0, 0.0);
    for (k, &(va, _)) in &a {
        let vb = b[k].0;
        l1 += (vb - va).abs();
        sum_a += va;
        sum_b += vb;
    }
    (l1 / sum_a, sum_b / sum_a - 1.0)
}

/// A relight's change, alternating between two states.
type Change = fn(bool) -> LightingChange;

fn fmt_opt(v: Option<f64>, scale: f64, unit: &str) -> String {
    v.map_or_else(|| "n/a".to_owned(), |v| format!("{:.2} {unit}", v * scale))
}

/// Wall and CPU time of `f`, seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    let (c0, t0) = (cpu_s(), Instant::now());
    let out = f();
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu_s().zip(c0).map(|(a, b)| a - b);
    (out, wall, cpu)
}

/// `runs` alternating relights: median wall and median CPU time per relight, milliseconds.
fn wall_and_cpu(
    pool: &rayon::ThreadPool,
    t: &mut Transfer,
    runs: usize,
    change: impl Fn(bool) -> LightingChange,
) -> (f64, Option<f64>) {
    let mut walls = Vec::with_capacity(runs);
    let mut cpus = Vec::with_capacity(runs);
    for i in 0..runs {
        let c = change(i % 2 == 0);
        let (_, wall, cpu) = timed(|| pool.install(|| t.relight(&c).unwrap()));
        walls.push(wall * 1e3);
        cpus.extend(cpu.map(|c| c * 1e3));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let cpu = (cpus.len() == runs).then(|| median(&mut cpus));
    (median(&mut walls), cpu)
}

fn sun_change(flip: bool) -> LightingChange {
    LightingChange {
        sun: Some(Some(if flip { sun(0.75, 2.7) } else { sun(0.7, 2.6) })),
        ..LightingChange::default()
    }
}

fn material_change(flip: bool) -> LightingChange {
    let rho = if flip { [0.7, 0.5, 0.4] } else { [0.6; 3] };
    LightingChange {
        material_reflectance: vec![("render".into(), rho)],
        ..LightingChange::default()
    }
}

fn dimming_change(flip: bool) -> LightingChange {
    LightingChange {
        luminaire_dimming: vec![("luminaire:street".into(), if flip { 0.5 } else { 1.0 })],
        ..LightingChange::default()
    }
}

/// Criterion medians of `changes` on `t` (alternating states), then a summary line each with
/// the median wall and CPU time of 6 more.
fn measure(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    pool: &rayon::ThreadPool,
    t: &mut Transfer,
    label: &str,
    changes: &[(&str, Change)],
    summary: &mut Vec<String>,
) {
    for &(what, change) in changes {
        let mut flip = false;
        group.bench_function(format!("{label}/{what}"), |b| {
            b.iter(|| {
                flip = !flip;
                let c = change(flip);
                pool.install(|| t.relight(&c).unwrap())
            });
        });
        let (wall_ms, cpu_ms) = wall_and_cpu(pool, t, 6, change);
        summary.push(format!(
            "{label}/{what}: wall {wall_ms:.2} ms, CPU {} (median of 6, load {})",
            fmt_opt(cpu_ms, 1.0, "ms"),
            fmt_opt(load_average(), 1.0, "")
        ));
    }
}

fn bench_transfer(c: &mut Criterion) {
    let pool = pool();
    println!(
        "transfer bench: {THREADS} threads, load average at start {}",
        fmt_opt(load_average(), 1.0, "")
    );
    // Precompute: timed once (criterion's minimum of 10 samples would take minutes).
    let p = params(RelightStrategy::LinearResponses, Sweep::Shooting);
    let (base, wall, cpu) = timed(|| pool.install(|| build(&p)));
    let s = base.solution();
    println!(
        "transfer precompute: {} elements, {} patches, {} links; wall {wall:.2} s, CPU {} \
         (load average now {})",
        s.mesh.elements.len(),
        s.mesh.patches.len(),
        s.interactions,
        fmt_opt(cpu, 1.0, "s"),
        fmt_opt(load_average(), 1.0, "")
    );
    let mut group = c.benchmark_group("relight_50k");
    group.sample_size(10);
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.measurement_time(std::time::Duration::from_secs(2));
    // The sun's direct term alone: one shadow ray per element sample (2 × 2) towards the sun.
    let engine = FormFactorEngine::new(&s.mesh, base.tracer(), p.solve.form_factors).unwrap();
    let moved = [photomontage::radiosity::DistantSource {
        dir_in_world: sun(0.75, 2.7).dir_in_world,
        normal_irradiance_rgb: [3.0; 3],
    }];
    group.bench_function("sun_retrace_only", |b| {
        b.iter(|| pool.install(|| direct_irradiance(&engine, &moved, 0)));
    });
    let mut summary = Vec::new();
    for (label, strategy, sweep) in [
        (
            "linear_shooting",
            RelightStrategy::LinearResponses,
            Sweep::Shooting,
        ),
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
        let changes: [(&str, Change); 3] = [
            ("sun_move", sun_change),
            ("material", material_change),
            ("dimming", dimming_change),
        ];
        measure(&mut group, &pool, &mut t, label, &changes, &mut summary);
        // Passes of one sun move and one material change (printed for the docs).
        let s = pool.install(|| t.relight(&sun_change(true)).unwrap());
        let m = pool.install(|| {
            t.relight(&LightingChange {
                material_reflectance: vec![("brick".into(), [0.5, 0.4, 0.3])],
                ..LightingChange::default()
            })
            .unwrap()
        });
        let links = |rows: &[photomontage::radiosity::ConvergenceRow]| -> u64 {
            rows.iter().map(|r| r.interactions).sum()
        };
        summary.push(format!(
            "{label}: sun move {} passes ({} link reads), material change {:?} passes per group \
             ({} link reads in all)",
            s.groups[0].convergence.len(),
            links(&s.groups[0].convergence),
            m.groups
                .iter()
                .map(|g| g.convergence.len())
                .collect::<Vec<_>>(),
            if sweep == Sweep::Shooting {
                m.groups
                    .iter()
                    .map(|g| links(&g.convergence))
                    .max()
                    .unwrap_or(0)
            } else {
                m.groups.iter().map(|g| links(&g.convergence)).sum()
            }
        ));
    }
    // The same relights on coarser roots (not the main figures: its solution differs, printed).
    let coarse_params = city_block::city_block_params_with_roots(
        RelightStrategy::LinearResponses,
        Sweep::Shooting,
        COARSE_PATCH_EDGE_M,
    );
    let (coarse, coarse_wall, coarse_cpu) = timed(|| pool.install(|| build(&coarse_params)));
    let (l1, mean) = indirect_difference(base.solution(), coarse.solution());
    summary.push(format!(
        "roots {COARSE_PATCH_EDGE_M} m: {} patches, {} links, precompute wall {coarse_wall:.2} s, \
         CPU {}; interreflected radiosity against the {PATCH_EDGE_M} m roots: L1 {:.2} %, mean \
         {:+.2} %",
        coarse.solution().mesh.patches.len(),
        coarse.solution().interactions,
        fmt_opt(coarse_cpu, 1.0, "s"),
        100.0 * l1,
        100.0 * mean
    ));
    let mut t = coarse;
    let changes: [(&str, Change); 2] = [("sun_move", sun_change), ("material", material_change)];
    measure(
        &mut group,
        &pool,
        &mut t,
        "coarse_roots",
        &changes,
        &mut summary,
    );
    group.finish();
    println!("\n== transfer summary ({THREADS} threads; wall and CPU per relight) ==");
    println!(
        "precompute: wall {wall:.2} s, CPU {}",
        fmt_opt(cpu, 1.0, "s")
    );
    for line in summary {
        println!("{line}");
    }
    println!(
        "load average at the end {}",
        fmt_opt(load_average(), 1.0, "")
    );
}

criterion_group!(benches, bench_transfer);
criterion_main!(benches);
