//! Solar position throughput: µs per NREL SPA evaluation (compare pvlib `spa_python` numpy,
//! 3.2 µs per position in `bench/peers/results/pvlib.json`).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use photomontage::sun::{SpaParams, solar_position_at_jd};
use std::hint::black_box;

fn bench_spa(c: &mut Criterion) {
    let params = SpaParams {
        elevation_m: 408.0,
        pressure_mbar: 965.19,
        ..SpaParams::at(47.37, 8.54)
    };
    // 2025-01-01 00:00 UTC, then 8760 hourly instants (as pvlib's Zurich benchmark).
    let jd0 = 2_460_676.5;
    let mut group = c.benchmark_group("spa");
    group.bench_function("one_position", |b| {
        b.iter(|| solar_position_at_jd(black_box(jd0 + 0.3), black_box(&params)));
    });
    group.throughput(Throughput::Elements(8760));
    group.bench_function("year_hourly_8760", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for h in 0..8760 {
                acc += solar_position_at_jd(jd0 + f64::from(h) / 24.0, &params).zenith_deg;
            }
            black_box(acc)
        });
    });
    group.finish();
}

criterion_group!(benches, bench_spa);
criterion_main!(benches);
