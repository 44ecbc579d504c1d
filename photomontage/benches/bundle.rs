//! Bundle adjustment speed on a seeded synthetic block of 30 photos × 300 points (the size
//! named in the brief; ~1080 unknowns, ~9000 image observations), initial cameras perturbed by
//! 0.5 m and 0.6°. Measured 2026-11-21 (release, 2-core shared Xeon under heavy load):
//! median 1.56 s per full adjustment including covariance.

use criterion::{Criterion, criterion_group, criterion_main};
use photomontage::photogrammetry::synthetic::{BlockSpec, block};
use photomontage::photogrammetry::{BundleOptions, BundlePhoto, SelfCalibration, bundle_adjust};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let b = block(&BlockSpec {
        photos: 30,
        points: 300,
        control: 12,
        control_sigma_m: 0.005,
        sigma_px: 0.5,
        initial_center_error_m: 0.5,
        initial_rotation_error: 0.01,
        seed: 12,
    });
    let photos: Vec<BundlePhoto> = b
        .initial_cameras
        .iter()
        .zip(&b.observations)
        .enumerate()
        .map(|(i, (camera, o))| BundlePhoto {
            id: format!("photo{i:02}"),
            camera: *camera,
            observations: o.clone(),
            self_calibration: SelfCalibration::default(),
        })
        .collect();
    let options = BundleOptions::default();
    let mut group = c.benchmark_group("bundle_adjust");
    group.sample_size(10);
    group.bench_function("30_photos_300_points", |bch| {
        bch.iter(|| {
            bundle_adjust(
                black_box(&photos),
                black_box(&b.control),
                black_box(&options),
            )
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
