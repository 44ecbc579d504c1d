//! Resection speed with 12 and 50 control points, robust start (RANSAC over P3P) included,
//! statistics and data snooping included. Peers (OpenCV 5.0, same data, 1 thread, from
//! `shared/bench/peers/results/opencv.json`): SQPnP 14.6 µs, ITERATIVE 68 µs (12 points).
//!
//! Measured 2026-11-21 (release, 2-core shared Xeon, load ≈ 3): median 59 µs (12 points) and
//! 148 µs (50 points), i.e. 0.87× and 1.7× OpenCV ITERATIVE (68 / 86 µs), 4.1× and 9.9×
//! SQPnP (14.6 / 15.0 µs). Our time includes the RANSAC start, covariance and data snooping.
//!
//! Data: `shared/bench/data/opencv/pnp_{12,50}.json` (set `PHOTOMONTAGE_SHARED` or keep the
//! shared folder beside the checkout), else seeded synthetic scenes of the same geometry.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Point2, Point3};
use photomontage::camera::Intrinsics;
use photomontage::photogrammetry::synthetic::{Layout, SceneSpec, single_photo};
use photomontage::photogrammetry::{ControlPoint, ImageObservation, ResectionOptions, resect};
use std::hint::black_box;
use std::path::PathBuf;

type Data = (Vec<ControlPoint>, Vec<ImageObservation>, Intrinsics);

fn shared_dir() -> PathBuf {
    std::env::var_os("PHOTOMONTAGE_SHARED").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared"),
        PathBuf::from,
    )
}

fn from_json(n: usize) -> Option<Data> {
    let path = shared_dir().join(format!("bench/data/opencv/pnp_{n}.json"));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    let k = &v["K"];
    let f = |x: &serde_json::Value| x.as_f64();
    let mut intrinsics = Intrinsics::centred(f(&k[0][0])?, [6000, 4000]);
    intrinsics.principal_point_px = [f(&k[0][2])?, f(&k[1][2])?];
    let mut control = Vec::new();
    let mut obs = Vec::new();
    for (i, (x, p)) in v["object_points"]
        .as_array()?
        .iter()
        .zip(v["image_points_observed"].as_array()?)
        .enumerate()
    {
        control.push(ControlPoint {
            id: format!("p{i}"),
            point_in_world: Point3::new(f(&x[0])?, f(&x[1])?, f(&x[2])?),
            sigma_m: [0.0; 3],
        });
        obs.push(ImageObservation {
            point_id: format!("p{i}"),
            pixel: Point2::new(f(&p[0])?, f(&p[1])?),
            sigma_px: 0.5,
        });
    }
    Some((control, obs, intrinsics))
}

fn synthetic(n: usize) -> Data {
    let s = single_photo(&SceneSpec {
        focal_px: 4500.0,
        image_size_px: [6000, 4000],
        distance_m: 80.0,
        points: n,
        layout: Layout::Volume {
            depth_fraction: 0.3,
        },
        sigma_px: 0.5,
        outlier_fraction: 0.0,
        seed: 20_240_601,
    });
    (s.control, s.observations, s.camera.intrinsics)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("resection");
    for n in [12, 50] {
        let (control, obs, intrinsics) = from_json(n).unwrap_or_else(|| {
            eprintln!("pnp_{n}.json not found: using seeded synthetic data");
            synthetic(n)
        });
        let options = ResectionOptions::new(intrinsics);
        group.bench_function(format!("{n}_points"), |b| {
            b.iter(|| resect(black_box(&control), black_box(&obs), black_box(&options)));
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
