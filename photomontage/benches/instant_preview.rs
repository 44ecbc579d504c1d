//! The studio's instant image in the radiosity mode (issue 17: "the montage preview updates
//! within a frame for the radiosity part"): on the street sample (solved here, `[render]
//! radiosity = true`), the preview records of view V1 are traced once
//! ([`photomontage::render::preview::PreviewRecords::record`], the studio's
//! `INSTANT_SAMPLES` budget), then each step is a material colour edit of the planned building
//! (alternating two colours): the site's transfers relit (`SiteTransfers::update`, timed
//! apart) and the records replayed under the relit solutions and the new materials
//! ([`photomontage::render::preview::PreviewRecords::replay`], timed by criterion: the first
//! replay after each relight, which reads the relit solutions' vertex values for the first
//! time, as the studio's does). Then the full-resolution linear image the studio tone-maps
//! ([`photomontage::render::preview::PreviewImage::linear_at`]) and the tracing of the records.
//! 2 threads.
//!
//! `cargo bench -p photomontage --bench instant_preview` (release profile).
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};

use photomontage::render::preview::{PreviewRecords, stride_for};
use photomontage::site::SiteDocument;
use photomontage::site::live_relight::SiteTransfers;
use photomontage::site::render::{ViewJob, prepare_view};
use photomontage::site::solve::{apply_solution, solve_site};

/// Threads of every measurement.
const THREADS: usize = 2;
/// The studio's sample budget of the instant image (`app/src/render_panel/instant.rs`).
const INSTANT_SAMPLES: u64 = 150_000;
/// The two colours a step alternates the planned building's material between.
const COLOURS: [[f64; 3]; 2] = [[0.7, 0.35, 0.2], [0.35, 0.45, 0.6]];

fn street() -> SiteDocument {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/street/site.toml");
    let mut doc = SiteDocument::load(&path).unwrap();
    let solution = solve_site(&doc);
    apply_solution(&mut doc.site, &solution);
    doc.site.render.radiosity = true;
    doc
}

/// The site with the planned building's first material in `colour`.
fn coloured(doc: &SiteDocument, colour: [f64; 3]) -> SiteDocument {
    let mut doc = doc.clone();
    let job = prepare_view(&doc, "V1").unwrap();
    let scene = &job.scene.scene;
    let planned = scene
        .triangles()
        .iter()
        .find(|t| {
            scene.objects()[t.object.0 as usize].kind == photomontage::scene::ObjectKind::Artificial
        })
        .unwrap();
    let mut material = scene.materials()[planned.material.0 as usize].clone();
    material.diffuse_rgb = colour;
    doc.site
        .materials
        .retain(|m| m.material.name != material.name);
    doc.site.materials.push(photomontage::site::SiteMaterial {
        material,
        colour: None,
    });
    doc
}

/// The view of `doc` with the kept transfers relit to it; the update's wall time.
fn relit_view(doc: &SiteDocument, slot: &mut Option<SiteTransfers>) -> (ViewJob, Duration) {
    let mut job = prepare_view(doc, "V1").unwrap();
    let t = Instant::now();
    let (light, _) = SiteTransfers::update(
        slot,
        doc,
        &job.scene.scene,
        "V1",
        None,
        &AtomicBool::new(false),
    )
    .unwrap();
    let relight = t.elapsed();
    job.lighting.radiosity = Some(light);
    (job, relight)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench_instant_preview(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(THREADS)
        .build()
        .unwrap();
    let base = street();
    let docs = COLOURS.map(|colour| coloured(&base, colour));
    let mut slot = None;
    let (job, _) = pool.install(|| relit_view(&docs[0], &mut slot));
    let photo = &job.photo_linear;
    let stride = stride_for([photo.width(), photo.height()], INSTANT_SAMPLES);
    let tracer = job.tracer().unwrap();
    let mut record_ms = Vec::new();
    let mut records = None;
    for _ in 0..3 {
        let t = Instant::now();
        records = Some(
            pool.install(|| PreviewRecords::record(&tracer, stride, &AtomicBool::new(false)))
                .unwrap(),
        );
        record_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let records = records.unwrap();
    println!(
        "instant preview: street V1 {}×{} px, 1 sample per {stride}×{stride} px = {} samples; \
         tracing them: median {:.1} ms of 3 ({THREADS} threads)",
        photo.width(),
        photo.height(),
        records.samples().len(),
        median(record_ms)
    );

    let mut step = 0_usize;
    let mut relight_ms = Vec::new();
    c.bench_function("instant_preview/replay_after_colour_relight", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                step += 1;
                let (view, relight) = pool.install(|| relit_view(&docs[step % 2], &mut slot));
                relight_ms.push(relight.as_secs_f64() * 1e3);
                let t = Instant::now();
                let image = pool.install(|| {
                    records
                        .replay(&view.scene.scene, &view.lighting, &view.camera)
                        .unwrap()
                });
                total += t.elapsed();
                std::hint::black_box(image);
            }
            total
        });
    });
    if !relight_ms.is_empty() {
        println!(
            "transfers relit before each replay: median {:.1} ms of {}",
            median(relight_ms),
            step
        );
    }

    // Again under the same light: the solutions' vertex values read, the replay alone.
    let (view, _) = pool.install(|| relit_view(&docs[step % 2], &mut slot));
    c.bench_function("instant_preview/replay_again", |b| {
        b.iter(|| {
            pool.install(|| {
                records
                    .replay(&view.scene.scene, &view.lighting, &view.camera)
                    .unwrap()
            })
        });
    });

    let image = records
        .replay(&job.scene.scene, &job.lighting, &job.camera)
        .unwrap();
    c.bench_function("instant_preview/full_resolution_linear", |b| {
        b.iter(|| {
            let mut sum = 0.0_f32;
            for y in 0..photo.height() {
                for x in 0..photo.width() {
                    sum += image.linear_at(x, y, photo)[1];
                }
            }
            sum
        });
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(Duration::from_secs(10));
    targets = bench_instant_preview
}
criterion_main!(benches);
