//! Luminaire photometry speed: parsing an LM-63 / EULUMDAT file, integrating its flux and
//! evaluating intensity toward world directions (the renderer's hot path), for web sizes as
//! parameters (γ × C planes). Files are generated in memory, so no shared data is needed.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{Point3, Vector3};
use photomontage::luminaire::{EulumdatFile, IesFile, Luminaire};
use std::fmt::Write;
use std::hint::black_box;

/// An asymmetric LM-63-2002 file with `nv` γ angles over 0…180° and `nh` C planes over 0…360°.
fn ies_text(nv: usize, nh: usize) -> String {
    let mut s = String::from("IESNA:LM-63-2002\n[TEST] bench\nTILT=NONE\n");
    let _ = writeln!(s, "1 -1 1 {nv} {nh} 1 2 0.1 0.1 0\n1 1 10");
    for i in 0..nv {
        let _ = write!(s, "{} ", 180.0 * i as f64 / (nv - 1) as f64);
    }
    s.push('\n');
    for j in 0..nh {
        let _ = write!(s, "{} ", 360.0 * j as f64 / (nh - 1) as f64);
    }
    s.push('\n');
    for j in 0..nh {
        for i in 0..nv {
            let g = (180.0 * i as f64 / (nv - 1) as f64).to_radians();
            let _ = write!(
                s,
                "{:.2} ",
                500.0 * g.cos().max(0.0) + 20.0 + j as f64 * 0.1
            );
        }
        s.push('\n');
    }
    s
}

/// An Isym 0 EULUMDAT file with `mc` C planes and `ng` γ angles.
fn ldt_text(mc: usize, ng: usize) -> String {
    let mut l: Vec<String> = vec!["bench".into(), "1".into(), "0".into(), mc.to_string()];
    l.push(format!("{}", 360.0 / mc as f64));
    l.push(ng.to_string());
    l.push(format!("{}", 180.0 / (ng - 1) as f64));
    for t in ["r", "n", "no", "f", "d"] {
        l.push(t.into());
    }
    for v in [
        "600", "600", "50", "500", "400", "0", "0", "0", "0", "100", "100", "1", "0", "1",
    ] {
        l.push(v.into());
    }
    for v in ["1", "LED", "1000", "4000", "80", "10"] {
        l.push(v.into());
    }
    l.extend(std::iter::repeat_n("0".to_owned(), 10));
    for j in 0..mc {
        l.push(format!("{}", 360.0 * j as f64 / mc as f64));
    }
    for i in 0..ng {
        l.push(format!("{}", 180.0 * i as f64 / (ng - 1) as f64));
    }
    for _ in 0..mc {
        for i in 0..ng {
            let g = (180.0 * i as f64 / (ng - 1) as f64).to_radians();
            l.push(format!("{:.1}", 300.0 * g.cos().max(0.0) + 5.0));
        }
    }
    l.join("\r\n")
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("luminaire");
    for &(nv, nh) in &[(37usize, 25usize), (73, 73), (181, 361)] {
        let label = format!("{nv}x{nh}");
        let ies = ies_text(nv, nh);
        group.bench_with_input(BenchmarkId::new("parse_ies", &label), &ies, |b, t| {
            b.iter(|| IesFile::parse(black_box(t.as_bytes())));
        });
        let ldt = ldt_text(nh, nv);
        group.bench_with_input(BenchmarkId::new("parse_ldt", &label), &ldt, |b, t| {
            b.iter(|| EulumdatFile::parse(black_box(t.as_bytes())));
        });
        let Ok(file) = IesFile::parse(ies.as_bytes()) else {
            continue;
        };
        let Ok(web) = file.distribution() else {
            continue;
        };
        group.bench_with_input(BenchmarkId::new("total_flux", &label), &web, |b, w| {
            b.iter(|| black_box(w).total_flux_lm());
        });
        let lum = Luminaire::new(web, Point3::new(0.0, 0.0, 5.0));
        let dirs: Vec<Vector3<f64>> = (0..1024)
            .map(|k| {
                let t = k as f64 * 0.618_034;
                Vector3::new(t.sin(), (1.7 * t).cos(), -1.0).normalize()
            })
            .collect();
        group.bench_with_input(
            BenchmarkId::new("intensity_toward_1024_dirs", &label),
            &dirs,
            |b, d| {
                b.iter(|| d.iter().map(|v| lum.intensity_toward_cd(v)).sum::<f64>());
            },
        );
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
