//! Bundle adjustment speed on seeded synthetic blocks (cameras on a ring of 60 m around a
//! 40 × 40 × 10 m volume, [`block`]), initial cameras perturbed by 0.5 m and 0.6°:
//! - `30_photos_300_points`: ~1080 unknowns, ~9000 image observations;
//! - `20_photos_5000_points`: ~15 000 unknowns, ~10⁵ image observations (issue 16: the size the
//!   dense normal equations could not hold).
//!
//! Each iteration is a full adjustment with outlier rounds and camera covariances (no point
//! covariances, the default). Figures and peak memory in `docs/benchmarks.md`; run one size
//! with `cargo bench -p photomontage --bench bundle -- 20_photos`.

use criterion::{Criterion, criterion_group, criterion_main};
use photomontage::photogrammetry::synthetic::{BlockSpec, block};
use photomontage::photogrammetry::{BundleOptions, BundlePhoto, SelfCalibration, bundle_adjust};
use std::hint::black_box;

fn photos(b: &photomontage::photogrammetry::synthetic::SyntheticBlock) -> Vec<BundlePhoto> {
    b.initial_cameras
        .iter()
        .zip(&b.observations)
        .enumerate()
        .map(|(i, (camera, o))| BundlePhoto {
            id: format!("photo{i:02}"),
            camera: *camera,
            observations: o.clone(),
            self_calibration: SelfCalibration::default(),
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let options = BundleOptions::default();
    let mut group = c.benchmark_group("bundle_adjust");
    group.sample_size(10);
    for (photo_count, points, control) in [(30, 300, 12), (20, 5000, 12)] {
        let b = block(&BlockSpec {
            photos: photo_count,
            points,
            control,
            control_sigma_m: 0.005,
            sigma_px: 0.5,
            initial_center_error_m: 0.5,
            initial_rotation_error: 0.01,
            seed: 12,
        });
        let input = photos(&b);
        let observations: usize = b.observations.iter().map(Vec::len).sum();
        eprintln!("{photo_count} photos × {points} points: {observations} observations");
        group.bench_function(format!("{photo_count}_photos_{points}_points"), |bch| {
            bch.iter(|| {
                bundle_adjust(
                    black_box(&input),
                    black_box(&b.control),
                    black_box(&options),
                )
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
