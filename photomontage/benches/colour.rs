//! Per-pixel cost of the colour and atmosphere paths the renderer calls: RGB → spectrum
//! (Durisch Appendix A), spectrum → RGB, Schachter forward and second inversion, 8-bit display
//! encoding; and the one-off Appendix A basis search at 1 nm.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use photomontage::atmosphere::SchachterAtmosphere;
use photomontage::colour::{
    Colour, ColourMode, ColourSystem, RgbColourSpace, RgbToSpectrum, SampleSet, SpectralSampling,
    ToneMap, encode_srgb8,
};

/// Pixels per iteration: a 64×64 tile.
const TILE_PX: usize = 64 * 64;

fn tile() -> Vec<[f32; 3]> {
    (0..TILE_PX)
        .map(|i| {
            let f = i as f32 / TILE_PX as f32;
            [f, (f * 7.0).fract(), (f * 13.0).fract()]
        })
        .collect()
}

fn per_pixel(c: &mut Criterion) {
    let pixels = tile();
    let mut group = c.benchmark_group("colour_per_pixel");
    group.throughput(Throughput::Elements(TILE_PX as u64));
    for (name, mode) in [
        ("rgb", ColourMode::Rgb),
        ("durisch9", ColourMode::Spectral(SampleSet::Durisch9)),
        ("meyer4", ColourMode::Spectral(SampleSet::Meyer4)),
    ] {
        let Ok(system) = ColourSystem::new(mode, RgbColourSpace::srgb()) else {
            return;
        };
        group.bench_function(format!("from_linear_rgb/{name}"), |b| {
            b.iter(|| {
                let mut acc = Colour::BLACK;
                for p in &pixels {
                    acc += system.from_linear_rgb(black_box(*p));
                }
                acc
            });
        });
        let colours: Vec<Colour> = pixels.iter().map(|p| system.from_linear_rgb(*p)).collect();
        group.bench_function(format!("to_linear_rgb/{name}"), |b| {
            b.iter(|| {
                let mut acc = 0.0_f32;
                for c in &colours {
                    acc += system.to_linear_rgb(black_box(c))[1];
                }
                acc
            });
        });
    }
    let colours: Vec<Colour> = pixels.iter().map(|p| Colour::from_slice(p)).collect();
    let Ok(atm) = SchachterAtmosphere::new(
        Colour::from_slice(&[0.85, 0.8, 0.7]),
        Colour::from_slice(&[0.7, 0.75, 0.9]),
        1000.0,
        3,
    ) else {
        return;
    };
    group.bench_function("schachter_apparent/rgb", |b| {
        b.iter(|| {
            let mut acc = Colour::BLACK;
            for (i, c) in colours.iter().enumerate() {
                acc += atm.apparent(black_box(c), 10.0 * i as f64);
            }
            acc
        });
    });
    group.bench_function("schachter_true_colour/rgb", |b| {
        b.iter(|| {
            let mut acc = Colour::BLACK;
            for (i, c) in colours.iter().enumerate() {
                if let Ok(t) = atm.true_colour(black_box(c), 0.5 * i as f64) {
                    acc += t;
                }
            }
            acc
        });
    });
    let tm = ToneMap::aces(0.0);
    group.bench_function("encode_srgb8/aces", |b| {
        b.iter(|| {
            let mut acc = 0_u32;
            for p in &pixels {
                acc += u32::from(encode_srgb8(black_box(*p), &tm)[0]);
            }
            acc
        });
    });
    group.finish();
}

fn basis_search(c: &mut Criterion) {
    let mut group = c.benchmark_group("appendix_a_basis_search");
    group.sample_size(10);
    group.bench_function("srgb/durisch9", |b| {
        b.iter(|| RgbToSpectrum::for_sample_set(RgbColourSpace::srgb(), SampleSet::Durisch9));
    });
    group.bench_function("srgb/cie_1nm_380_780", |b| {
        b.iter(|| {
            SpectralSampling::cie_1nm(380, 780)
                .and_then(|s| RgbToSpectrum::new(RgbColourSpace::srgb(), s))
        });
    });
    group.finish();
}

criterion_group!(benches, per_pixel, basis_search);
criterion_main!(benches);
