//! BVH speed and correctness against Embree on the shared peer benchmark's data
//! (`bench/data/embree/`, formats in its `manifest.json`; see `docs/benchmarks.md`).
//!
//! For each scene (city_10k, terrain_1m), ray set (incoherent 2M, primary 1M), query (closest,
//! any-hit) and thread count (1, 2): median Mrays/s over `--reps` runs, the ratio to Embree's
//! `peers/results/embree_threads{N}.json`, and the fraction of rays whose closest hit differs
//! from Embree's hit file (separating float ties: same `t`, different triangle).
//!
//! Usage: `bvh_bench [BENCH_DIR] [--reps N] [--threads 1,2] [--scenes city_10k,terrain_1m]`.
//! `BENCH_DIR` (or `PHOTOMONTAGE_BENCH_DATA`) is the bench folder holding `data/embree/` with the
//! regenerated rays and hits; without it the program prints a notice and exits 0.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Parser;
use glam::Vec3A;
use photomontage::bvh::{BuildQuality, BvhHit, Ray};
use photomontage::scene::{ImportOptions, ObjectKind, Scene, SceneTracer, obj::load_obj};
use serde_json::Value;

/// Relative `t` difference under which two different triangles count as a float tie (shared
/// edges and vertices: both hits are right to single precision).
const TIE_REL_T: f32 = 1e-4;

#[derive(Parser)]
#[command(about = "Trace the Embree peer benchmark's rays with the photomontage BVH")]
struct Args {
    /// Bench folder (holding data/embree/manifest.json); default $PHOTOMONTAGE_BENCH_DATA.
    bench_dir: Option<PathBuf>,
    /// Timed repetitions per configuration (the median is reported).
    #[arg(long, default_value_t = 5)]
    reps: usize,
    /// Thread counts, comma-separated.
    #[arg(long, default_value = "1,2", value_delimiter = ',')]
    threads: Vec<usize>,
    /// Scenes, comma-separated.
    #[arg(long, default_value = "city_10k,terrain_1m", value_delimiter = ',')]
    scenes: Vec<String>,
    /// Ray sets, comma-separated.
    #[arg(
        long,
        default_value = "incoherent_2m,primary_1m",
        value_delimiter = ','
    )]
    sets: Vec<String>,
    /// BVH build quality: fast, medium or high.
    #[arg(long, default_value = "medium")]
    quality: String,
    /// Folder with embree_threads{N}.json (default: BENCH_DIR/peers/results).
    #[arg(long)]
    peer_results: Option<PathBuf>,
}

fn read_f32s(path: &Path) -> Result<Vec<f32>> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if bytes.len() % 4 != 0 {
        bail!("{} is not a whole number of f32 values", path.display());
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

fn read_rays(path: &Path, origin_offset: Vec3A) -> Result<Vec<Ray>> {
    let v = read_f32s(path)?;
    if v.len() % 6 != 0 {
        bail!("{} is not a whole number of rays", path.display());
    }
    Ok(v.chunks_exact(6)
        .map(|r| {
            Ray::new_inf(
                Vec3A::new(r[0], r[1], r[2]) - origin_offset,
                Vec3A::new(r[3], r[4], r[5]),
            )
        })
        .collect())
}

/// Embree's hit file: per ray (t, primID), primID u32::MAX for a miss.
fn read_hits(path: &Path) -> Result<Vec<(f32, u32)>> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if bytes.len() % 8 != 0 {
        bail!("{} is not a whole number of hit records", path.display());
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|b| {
            (
                f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                u32::from_le_bytes([b[4], b[5], b[6], b[7]]),
            )
        })
        .collect())
}

/// CPU seconds used by this process so far (all threads; user + system), from `/proc/self/stat`
/// at the kernel's 100 Hz tick. `None` where that file does not exist.
fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[derive(Default, Debug)]
struct Agreement {
    mismatches: usize,
    ties: usize,
}

fn compare_closest(ours: &[Option<BvhHit>], embree: &[(f32, u32)]) -> Agreement {
    let mut a = Agreement::default();
    for (o, &(t, prim)) in ours.iter().zip(embree) {
        match o {
            None if prim == u32::MAX => {}
            Some(h) if h.triangle_id == prim => {}
            Some(h) if prim != u32::MAX && (h.t - t).abs() <= TIE_REL_T * t.max(1.0) => a.ties += 1,
            _ => a.mismatches += 1,
        }
    }
    a
}

fn compare_any(ours: &[bool], embree: &[(f32, u32)]) -> usize {
    ours.iter()
        .zip(embree)
        .filter(|(o, (_, prim))| **o != (*prim != u32::MAX))
        .count()
}

fn embree_mrays(peer: Option<&Value>, scene: &str, set: &str, query: &str) -> Option<f64> {
    peer?["scenes"][scene]["trace"][set][query]["mrays_per_s"].as_f64()
}

fn main() -> Result<()> {
    let args = Args::parse();
    let Some(bench) = args
        .bench_dir
        .clone()
        .or_else(|| std::env::var_os("PHOTOMONTAGE_BENCH_DATA").map(PathBuf::from))
    else {
        println!(
            "NOTICE: no bench folder given (argument or PHOTOMONTAGE_BENCH_DATA); nothing to do"
        );
        return Ok(());
    };
    let quality = match args.quality.as_str() {
        "fast" => BuildQuality::Fast,
        "medium" => BuildQuality::Medium,
        "high" => BuildQuality::High,
        other => bail!("unknown --quality {other} (fast, medium, high)"),
    };
    let manifest_path = bench.join("data/embree/manifest.json");
    if !manifest_path.exists() {
        println!(
            "NOTICE: {} is absent; nothing to do",
            manifest_path.display()
        );
        return Ok(());
    }
    let manifest: Value = serde_json::from_str(&std::fs::read_to_string(&manifest_path)?)?;
    let results_dir = args
        .peer_results
        .clone()
        .unwrap_or_else(|| bench.join("peers/results"));
    let peers: Vec<(usize, Option<Value>)> = args
        .threads
        .iter()
        .map(|&n| {
            let p = results_dir.join(format!("embree_threads{n}.json"));
            let v = std::fs::read_to_string(&p)
                .ok()
                .and_then(|s| serde_json::from_str(&s).ok());
            (n, v)
        })
        .collect();

    println!(
        "Mrays/s: ours by wall clock (wall) and by CPU time per thread (cpu); Embree from its \
         results JSON; r_ = ours / Embree; mismatch and ties are fractions of rays"
    );
    println!(
        "scene       set            query     thr      wall       cpu    embree  r_wall  r_cpu   mismatch     ties"
    );
    for scene_name in &args.scenes {
        let sc = &manifest["scenes"][scene_name.as_str()];
        let file = |key: &str| -> Result<PathBuf> {
            let rel = sc["files"][key]
                .as_str()
                .with_context(|| format!("manifest lacks {scene_name}.files.{key}"))?;
            Ok(bench.join(rel))
        };
        let t0 = Instant::now();
        let model = load_obj(&file("obj")?, &ImportOptions::default())?;
        let load_s = t0.elapsed().as_secs_f64();
        let mut scene = Scene::new();
        scene.add_model(&model, scene_name, ObjectKind::Natural)?;
        drop(model);
        for (threads, _) in &peers {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(*threads)
                .build()?;
            let mut build_s = Vec::new();
            for _ in 0..3 {
                let t = Instant::now();
                let tracer = pool.install(|| SceneTracer::new(&scene, quality))?;
                build_s.push(t.elapsed().as_secs_f64());
                drop(tracer);
            }
            println!(
                "{scene_name}: {} triangles, OBJ read {load_s:.2} s, BVH build {:.3} s median ({threads} thr)",
                scene.triangles().len(),
                median(build_s)
            );
        }
        let tracer = SceneTracer::new(&scene, quality)?;
        println!("{scene_name}: {:?}", tracer.bvh());
        let o = tracer.local_origin_in_world_m();
        #[allow(clippy::cast_possible_truncation)]
        let offset = Vec3A::new(o.x as f32, o.y as f32, o.z as f32);
        for set in args.sets.iter().map(String::as_str) {
            let rays = read_rays(&file(set)?, offset)?;
            let hits_path =
                bench.join(format!("data/embree/generated/hits_{scene_name}_{set}.bin"));
            let embree_hits = read_hits(&hits_path).ok().filter(|h| h.len() == rays.len());
            let mut closest = vec![None; rays.len()];
            let mut any = vec![false; rays.len()];
            for (threads, peer) in &peers {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(*threads)
                    .build()?;
                for query in ["closest", "occluded"] {
                    let mut times = Vec::new();
                    let mut cpu_times = Vec::new();
                    for rep in 0..=args.reps {
                        let cpu0 = process_cpu_s();
                        let t = Instant::now();
                        pool.install(|| {
                            if query == "closest" {
                                tracer.bvh().closest_hits_into(&rays, &mut closest);
                            } else {
                                tracer.bvh().any_hits_into(&rays, &mut any);
                            }
                        });
                        if rep > 0 {
                            times.push(t.elapsed().as_secs_f64()); // rep 0 warms caches
                            if let (Some(a), Some(b)) = (cpu0, process_cpu_s()) {
                                cpu_times.push(b - a);
                            }
                        }
                    }
                    #[allow(clippy::cast_precision_loss)]
                    let n_times = times.len();
                    let ours = rays.len() as f64 / median(times) / 1e6;
                    // Throughput per busy thread from CPU time: what the wall clock would show on
                    // an otherwise idle machine (other processes steal cores, not CPU seconds).
                    #[allow(clippy::cast_precision_loss)]
                    let ours_cpu = (cpu_times.len() == n_times).then(|| {
                        rays.len() as f64 * *threads as f64 / median(cpu_times).max(1e-2) / 1e6
                    });
                    let theirs = embree_mrays(peer.as_ref(), scene_name, set, query);
                    let (mismatch, ties) = match (&embree_hits, query) {
                        (Some(h), "closest") => {
                            let a = compare_closest(&closest, h);
                            (Some(a.mismatches), Some(a.ties))
                        }
                        (Some(h), _) => (Some(compare_any(&any, h)), None),
                        (None, _) => (None, None),
                    };
                    #[allow(clippy::cast_precision_loss)]
                    let frac = |n: Option<usize>| {
                        n.map_or_else(
                            || "n/a".to_owned(),
                            |n| format!("{:.2e}", n as f64 / rays.len() as f64),
                        )
                    };
                    let ratio = |x: Option<f64>| match (x, theirs) {
                        (Some(x), Some(e)) => format!("{:.2}", x / e),
                        _ => "n/a".to_owned(),
                    };
                    println!(
                        "{scene_name:<11} {set:<14} {query:<9} {threads:>3} {ours:>9.2} {:>9} {:>9} {:>6} {:>6} {:>10} {:>8}",
                        ours_cpu.map_or_else(|| "n/a".to_owned(), |c| format!("{c:.2}")),
                        theirs.map_or_else(|| "n/a".to_owned(), |e| format!("{e:.2}")),
                        ratio(Some(ours)),
                        ratio(ours_cpu),
                        frac(mismatch),
                        frac(ties),
                    );
                }
            }
        }
    }
    Ok(())
}
