//! Relight latency of the studio's live preview in the radiosity mode (issue 17: "Relight
//! latency in the studio (sun slider, material colour) measured in a bench with the 50 000-patch
//! scene of the radiosity issue: median ≤ 16 ms for the radiosity update").
//!
//! The scene is the city block of `benches/transfer.rs` ([`photomontage::radiosity::city_block`])
//! with its first building planned (artificial), so the studio keeps two transfers (with and
//! without the planned building) as `photomontage::site::live_relight::SiteTransfers` does. Each
//! step is the studio's path after the site has been read: the site's lighting and materials →
//! [`photomontage::site::live_relight::lighting_change`] (geometry fingerprint, change) →
//! `Transfer::relight` on both transfers side by side → the renderer's `RadiosityLight` (the
//! traced groups' direct light taken out). A sun slider step moves the sun by 1° of azimuth
//! back and forth; a sun drag step moves it on by 1° along a sweep of ±30° (a user dragging the
//! slider); a material colour step changes the "render" material's colour, which the planned building
//! shares with seven existing ones, so both transfers relight (the worst case). A proposal
//! colour step changes the colour of a planned building that has its own material
//! ([`photomontage::radiosity::city_block::city_block_with_proposal`], as a design imported from
//! CAD brings its own), so only the transfer with the planned building relights. 2 threads;
//! criterion medians, then medians of 8 alternating steps (wall and CPU time, with the load
//! average). A colour step after the first edit of that material reads the material's table
//! (`Transfer::relight_material`); the first edit, which builds the table, is timed on its own.
//!
//! `cargo bench -p photomontage --bench relight_latency` (release profile).
#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};

mod common;
use common::{cpu_s, load_average};
use photomontage::radiosity::TransferParams;
use photomontage::radiosity::city_block::{
    RENDER_ALBEDO, city_block, city_block_lighting, city_block_params, city_block_sun,
    city_block_with_proposal,
};
use photomontage::radiosity::{RelightStrategy, Sweep, TransferLighting};
use photomontage::radiosity::{Solution, luminance};
use photomontage::scene::Scene;
use photomontage::site::live_relight::{SiteTransfers, TransferUpdate};
use photomontage::sky::SkyModel;

/// Threads of every measurement (the target is on 2 threads).
const THREADS: usize = 2;
/// Sun slider step: 1° of azimuth.
const SUN_STEP_RAD: f64 = 1.0_f64 * std::f64::consts::PI / 180.0;
/// Half the sweep of the sun drag, in 1° steps.
const DRAG_HALF_DEG: usize = 30;
/// Steps of the drag summary (one sweep from one end to the other and back).
const DRAG_STEPS: usize = 4 * DRAG_HALF_DEG;
/// The material colour step: "render" between its albedo and this colour.
const RENDER_COLOUR: [f64; 3] = [0.7, 0.5, 0.4];
/// The proposal colour step: "proposal" between the render albedo and this colour.
const PROPOSAL_COLOUR: [f64; 3] = [0.45, 0.55, 0.7];

fn sun_lighting(flip: bool) -> TransferLighting {
    let mut l = city_block_lighting();
    l.sun = Some(city_block_sun(
        0.7,
        2.6 + if flip { SUN_STEP_RAD } else { 0.0 },
    ));
    l
}

/// Sun slider drag: the `i`-th of 1° azimuth steps swept back and forth over ±[`DRAG_HALF_DEG`]
/// around the base sun (a triangle wave), as a user drags the slider across an afternoon.
fn drag_lighting(i: usize) -> TransferLighting {
    let period = 4 * DRAG_HALF_DEG;
    let k = i % period;
    let offset_deg = if k <= 2 * DRAG_HALF_DEG {
        k as f64 - DRAG_HALF_DEG as f64
    } else {
        (period - k) as f64 - DRAG_HALF_DEG as f64
    };
    let mut l = city_block_lighting();
    l.sun = Some(city_block_sun(0.7, 2.6 + offset_deg * SUN_STEP_RAD));
    l
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Wall time of one call of `f`, milliseconds.
fn once(f: &mut dyn FnMut()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64() * 1e3
}

/// Median wall and median CPU time (both threads) of 8 calls of `f(i)`, milliseconds.
fn timed(f: &mut dyn FnMut(usize)) -> (f64, f64) {
    let (mut wall, mut cpu): (Vec<f64>, Vec<f64>) = (0..8)
        .map(|i| {
            let (c, t) = (cpu_s(), Instant::now());
            f(i);
            let wall = t.elapsed().as_secs_f64() * 1e3;
            (
                wall,
                cpu_s().zip(c).map_or(f64::NAN, |(a, b)| (a - b) * 1e3),
            )
        })
        .unzip();
    (median(&mut wall), median(&mut cpu))
}

/// The studio's two transfers and what relights them.
struct StudioTransfers<'a> {
    pool: &'a rayon::ThreadPool,
    params: &'a TransferParams,
    transfers: SiteTransfers,
}

impl<'a> StudioTransfers<'a> {
    /// The transfers for `scene` lit by `lighting`; prints the build.
    fn build(
        pool: &'a rayon::ThreadPool,
        params: &'a TransferParams,
        scene: &Scene,
        lighting: &TransferLighting,
    ) -> Self {
        let t0 = Instant::now();
        let transfers = pool.install(|| {
            SiteTransfers::build_for(scene, lighting, params, &AtomicBool::new(false)).unwrap()
        });
        println!(
            "relight latency: {} + {} elements (with / without the planned building), built in \
             {:.1} s on {THREADS} threads",
            transfers.with_artificial().mesh.elements.len(),
            transfers.without_artificial().mesh.elements.len(),
            t0.elapsed().as_secs_f64()
        );
        Self {
            pool,
            params,
            transfers,
        }
    }

    /// One studio step, as the live preview makes it: relight both transfers to `scene` and
    /// `lighting` (never a build).
    fn step(&mut self, scene: &Scene, lighting: &TransferLighting) {
        let (transfers, params) = (&mut self.transfers, self.params);
        let update = self
            .pool
            .install(|| transfers.relight_for(scene, lighting, params).unwrap());
        // Never a build: a step is a relight (or nothing, when it goes back to where it is).
        assert!(matches!(
            update,
            Some(TransferUpdate::Relit | TransferUpdate::Unchanged)
        ));
        drop(transfers.light());
    }
}

/// One sun drag ([`DRAG_STEPS`] steps of [`drag_lighting`]).
struct Drag {
    /// Median and slowest step, milliseconds.
    median_ms: f64,
    slowest_ms: f64,
    /// The sun group of the natural transfer at the drag's end against a cold shooting of the
    /// same sun (from a dark sun, the sun's axis responses shot from nothing): area-weighted L1
    /// of luminance over the cold one's.
    drift_l1: f64,
}

/// The sun group: area-weighted L1 of `a` − `b` over `b`'s.
fn sun_l1(a: &Solution, b: &Solution) -> f64 {
    let lum = |v: [f64; 3]| luminance(&v.map(f64::abs));
    let (mut d, mut n) = (0.0, 0.0);
    for (e, (x, y)) in a.groups[0]
        .radiosity_rgb
        .iter()
        .zip(b.groups[0].radiosity_rgb.iter())
        .enumerate()
    {
        let w = b.mesh.element_node(e).area_m2;
        d += lum(std::array::from_fn(|c| x[c] - y[c])) * w;
        n += lum(*y) * w;
    }
    d / n
}

/// A whole drag from the start of the sweep, then its end against a cold shooting.
fn sun_drag(studio: &mut StudioTransfers<'_>, scene: &Scene) -> Drag {
    studio.step(scene, &drag_lighting(0));
    let mut steps: Vec<f64> = (1..=DRAG_STEPS)
        .map(|i| once(&mut || studio.step(scene, &drag_lighting(i))))
        .collect();
    let slowest_ms = steps.iter().copied().fold(0.0, f64::max);
    let dragged = studio.transfers.without_artificial().clone();
    // The reference shoots the sun cold: from a dark sun, its axis responses from nothing.
    studio.transfers.drop_sun_axes();
    let mut dark = drag_lighting(DRAG_STEPS);
    dark.sun = None;
    studio.step(scene, &dark);
    studio.step(scene, &drag_lighting(DRAG_STEPS));
    Drag {
        median_ms: median(&mut steps),
        slowest_ms,
        drift_l1: sun_l1(&dragged, studio.transfers.without_artificial()),
    }
}

fn bench_relight_latency(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .unwrap();
    let params = city_block_params(RelightStrategy::LinearResponses, Sweep::Shooting);
    let scenes: [Scene; 2] = [
        city_block(1, [RENDER_ALBEDO; 3]).unwrap(),
        city_block(1, RENDER_COLOUR).unwrap(),
    ];
    let mut studio = StudioTransfers::build(&pool, &params, &scenes[0], &city_block_lighting());
    let mut group = c.benchmark_group("studio_relight_50k");
    group.sample_size(10);
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.measurement_time(std::time::Duration::from_secs(2));
    let mut flip = false;
    group.bench_function("sun_slider_step", |b| {
        b.iter(|| {
            flip = !flip;
            studio.step(&scenes[0], &sun_lighting(flip));
        });
    });
    let mut drag = 0;
    group.bench_function("sun_drag_step", |b| {
        b.iter(|| {
            drag += 1;
            studio.step(&scenes[0], &drag_lighting(drag));
        });
    });
    // Back to the base sun, then colour steps: the first edit of the material builds its table
    // (`Transfer::relight_material`), the steps read it.
    studio.step(&scenes[0], &sun_lighting(false));
    studio.step(&scenes[1], &sun_lighting(false));
    let mut k = 1;
    group.bench_function("material_colour_step", |b| {
        b.iter(|| {
            k = 1 - k;
            studio.step(&scenes[k], &sun_lighting(false));
        });
    });
    if k == 1 {
        studio.step(&scenes[0], &sun_lighting(false));
    }
    let load_before = load_average();
    let (sun_ms, sun_cpu_ms) = timed(&mut |i| {
        studio.step(&scenes[0], &sun_lighting(i % 2 == 0));
    });
    // One whole drag, step by step (from the start of the sweep): the median and the slowest.
    let drag = sun_drag(&mut studio, &scenes[0]);
    studio.step(&scenes[0], &sun_lighting(false));
    let colour_first_ms = once(&mut || studio.step(&scenes[1], &sun_lighting(false)));
    let (colour_ms, colour_cpu_ms) = timed(&mut |i| {
        studio.step(&scenes[i % 2], &sun_lighting(false));
    });
    // The first sun step after a colour edit shoots the sun's axis responses from nothing (a
    // reflectance change drops them, `radiosity::transfer` sun_basis.rs).
    let sun_after_colour_ms = once(&mut || studio.step(&scenes[1], &sun_lighting(true)));
    drop(studio);
    // The planned building in its own material.
    let proposal: [Scene; 2] = [
        city_block_with_proposal([RENDER_ALBEDO; 3], [RENDER_ALBEDO; 3]).unwrap(),
        city_block_with_proposal([RENDER_ALBEDO; 3], PROPOSAL_COLOUR).unwrap(),
    ];
    let mut studio = StudioTransfers::build(&pool, &params, &proposal[0], &city_block_lighting());
    let proposal_first_ms = once(&mut || studio.step(&proposal[1], &sun_lighting(false)));
    let mut k = 1;
    group.bench_function("proposal_colour_step", |b| {
        b.iter(|| {
            k = 1 - k;
            studio.step(&proposal[k], &sun_lighting(false));
        });
    });
    group.finish();
    if k == 1 {
        studio.step(&proposal[0], &sun_lighting(false));
    }
    let (proposal_ms, proposal_cpu_ms) = timed(&mut |i| {
        studio.step(&proposal[(i + 1) % 2], &sun_lighting(false));
    });
    // A sun step drops the tables; the first colour edit after it builds one again.
    studio.step(&proposal[0], &sun_lighting(true));
    let proposal_after_sun_ms = once(&mut || studio.step(&proposal[1], &sun_lighting(true)));
    drop(studio);
    // The sun step again under a CIE clear sky (type 12), which follows the sun: its direct
    // light is summed again from the sky transfer's facets at every step (report only, no
    // criterion group).
    let clear = |flip: bool| {
        let mut l = sun_lighting(flip);
        if let Some(sky) = l.sky.as_mut() {
            sky.model = SkyModel::cie_general(12).unwrap();
        }
        l
    };
    let mut studio = StudioTransfers::build(&pool, &params, &scenes[0], &clear(false));
    studio.step(&scenes[0], &clear(true));
    let (clear_ms, clear_cpu_ms) = timed(&mut |i| {
        studio.step(&scenes[0], &clear(i % 2 == 1));
    });
    println!("\n== studio relight ({THREADS} threads, median of 8 steps, wall / CPU) ==");
    println!("sun slider step (1° azimuth): {sun_ms:.1} ms / {sun_cpu_ms:.1} ms CPU");
    println!(
        "sun slider drag ({DRAG_STEPS} steps of 1° azimuth over ±{DRAG_HALF_DEG}°): median \
         {:.1} ms, slowest {:.1} ms; its end against a cold shooting of the same sun: L1 {:.1e}",
        drag.median_ms, drag.slowest_ms, drag.drift_l1
    );
    println!(
        "material colour step (shared by planned and existing buildings): {colour_ms:.1} ms / \
         {colour_cpu_ms:.1} ms CPU"
    );
    println!(
        "proposal colour step (the planned building's own material): {proposal_ms:.1} ms / \
         {proposal_cpu_ms:.1} ms CPU"
    );
    println!(
        "first colour edit of a material (builds its table, one step): shared material \
         {colour_first_ms:.0} ms, proposal {proposal_first_ms:.0} ms, proposal after a sun step \
         {proposal_after_sun_ms:.0} ms"
    );
    println!(
        "first sun step after a colour edit (builds the sun's axis responses): \
         {sun_after_colour_ms:.0} ms"
    );
    println!(
        "sun slider step under a CIE clear sky (type 12, which follows the sun): \
         {clear_ms:.1} ms / {clear_cpu_ms:.1} ms CPU"
    );
    println!(
        "load average (1 min) before / after: {:?} / {:?}",
        load_before,
        load_average()
    );
}

criterion_group!(benches, bench_relight_latency);
criterion_main!(benches);
