//! Lighting-fit cost (Durisch 1992 §4.2–4.3): the eq. 7 atmosphere fit per channel (argmin
//! Gauss–Newton), the unit irradiance components of one sample (1 sun + 256 sky-facet shadow
//! rays), and the eq. 9 daylight fit of 30 samples with robust refits.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Point3, Vector3};
use photomontage::atmosphere::schachter::apparent_radiance;
use photomontage::bvh::BuildQuality;
use photomontage::fit::atmosphere::solve_eq7;
use photomontage::fit::daylight::{
    DaylightFitOptions, DaylightSample, fit_daylight, irradiance_components, normalised_sky_facets,
};
use photomontage::scene::{Material, ObjectKind, Scene, SceneObject, SceneTracer};
use photomontage::sky::{SkyModel, direction_from_elevation_azimuth};
use photomontage::sky_dome::durisch_facets::durisch_dome;
use std::hint::black_box;

#[allow(clippy::unwrap_used)]
fn bench_fit(c: &mut Criterion) {
    let mut group = c.benchmark_group("fit");
    let samples: Vec<(f64, f64)> = [120.0, 480.0, 900.0, 1700.0, 2600.0, 3300.0, 4000.0]
        .iter()
        .map(|&d| (d, apparent_radiance(0.12, 0.85, 0.62, d, 1000.0)))
        .collect();
    group.bench_function("eq7_one_channel_7_samples", |b| {
        b.iter(|| solve_eq7(black_box(0.85), black_box(&samples), 1000.0, None));
    });

    // Ground, a wall and a box, as in the unit tests.
    let mut scene = Scene::new();
    let obj = scene
        .add_object(SceneObject {
            name: "site".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .unwrap();
    let mat = scene
        .add_material(Material::diffuse("stone", [0.5; 3]))
        .unwrap();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    for poly in [
        vec![
            p(-50.0, -50.0, 0.0),
            p(400.0, -50.0, 0.0),
            p(400.0, 50.0, 0.0),
            p(-50.0, 50.0, 0.0),
        ],
        vec![
            p(-30.0, 20.0, 0.0),
            p(-30.0, 20.0, 8.0),
            p(40.0, 20.0, 8.0),
            p(40.0, 20.0, 0.0),
        ],
        vec![
            p(8.0, 8.0, 0.0),
            p(12.0, 8.0, 0.0),
            p(12.0, 8.0, 4.0),
            p(8.0, 8.0, 4.0),
        ],
        vec![
            p(8.0, 8.0, 4.0),
            p(12.0, 8.0, 4.0),
            p(12.0, 12.0, 4.0),
            p(8.0, 12.0, 4.0),
        ],
    ] {
        scene.add_polygon(&poly, mat, obj).unwrap();
    }
    let tracer = SceneTracer::new(&scene, BuildQuality::default()).unwrap();
    let sun = direction_from_elevation_azimuth(35_f64.to_radians(), 110_f64.to_radians());
    let sky = normalised_sky_facets(
        &durisch_dome(8).unwrap(),
        &SkyModel::cie_general(12).unwrap(),
        &sun,
    )
    .unwrap();
    group.bench_function("irradiance_components_256_facets", |b| {
        b.iter(|| {
            irradiance_components(
                &tracer,
                black_box(&Point3::new(5.0, 12.0, 0.0)),
                &Vector3::z(),
                Some(&sun),
                &sky,
            )
        });
    });
    let day: Vec<DaylightSample> = (0..30)
        .map(|i| {
            let f = f64::from(i);
            let (pt, n) = if i % 2 == 0 {
                (Point3::new(f * 0.5, 5.0 + f * 0.4, 0.0), Vector3::z())
            } else {
                (
                    Point3::new(-25.0 + f * 2.0, 20.0, 0.5 + f * 0.2),
                    -Vector3::y(),
                )
            };
            let e = irradiance_components(&tracer, &pt, &n, Some(&sun), &sky);
            let l = [0.9 * e.sun + 0.03 * e.ambient + 0.2 * e.sky; 3];
            DaylightSample {
                id: format!("s{i}"),
                true_colour_rgb: l,
                components: e,
                normal_in_world: n,
                diffuse_reflectance_rgb: None,
                interreflection_rgb: [0.0; 3],
            }
        })
        .collect();
    group.bench_function("eq9_30_samples", |b| {
        b.iter(|| fit_daylight(black_box(&day), &DaylightFitOptions::default(), None));
    });
    group.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
