//! Render speed of the differential renderer on the Mitsuba peer scene (issue 4 acceptance
//! "Render speed"; `docs/benchmarks.md`), side by side with the peers' own figures.
//!
//! The 1024-spp `without_box` render is the photo; the box is rendered into it at 1280 × 720 with
//! the scene, camera and lights of [`photomontage::peer_scene::mitsuba_pair_scene`] (the same as
//! the accuracy test) for each rays-per-pixel setting (adaptive `min–max` and fixed `n–n`) and
//! thread count. Printed per setting: the median wall time of `--reps` renders (the tracer's BVH
//! setup timed separately), the median CPU seconds of a render (all threads; on a shared machine
//! CPU s / threads is what the wall clock would show on idle cores), the rays per pixel traced,
//! the pixels changed, and the RMSE against the 1024-spp `with_box` truth. Then the peers' render
//! times and RMSE of the same scene read from `peers/results/{mitsuba,blender}_*.json`.
//!
//! `--lighting radiosity` renders in the radiosity lighting mode instead of the sky facets and
//! photo-bounce gathers: the pair's solutions with and without the box
//! ([`photomontage::peer_scene::radiosity::mitsuba_pair_radiosity`], as the accuracy test
//! `render_mitsuba_radiosity.rs`) are solved at every rep and timed as the precompute, printed
//! beside the render; each render gets a fresh renderer light, so its vertex gathers are traced
//! within the render time, as in a first render.
//!
//! Usage: `render_bench [BENCH_DIR] [--reps N] [--threads 1,2] [--spp 4-4,4-8,...]
//! [--cache on,off] [--lighting facets,radiosity]`.
//! `BENCH_DIR` (or `PHOTOMONTAGE_BENCH_DATA`) is the shared bench folder holding
//! `data/mitsuba/`; without it the program prints a notice and exits 0.
//!
//! Known limitations: our renderer traces only the pixels the box can change (the rest is the
//! photo, bit for bit), while the peers render every pixel of the scene from scratch; the times
//! answer "how long does a montage take", not "how fast is the path tracer".

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Parser;
use photomontage::peer_scene::radiosity::mitsuba_pair_radiosity;
use photomontage::peer_scene::{MAX_DEPTH, mitsuba_pair_scene};
use photomontage::render::{DifferentialTracer, RenderSettings, render_view};
use serde_json::Value;

#[derive(Parser)]
#[command(about = "Time the differential renderer on the Mitsuba peer scene")]
struct Args {
    /// Bench folder (holding data/mitsuba/scene.json); default $PHOTOMONTAGE_BENCH_DATA.
    bench_dir: Option<PathBuf>,
    /// Timed renders per setting (the median is reported; at least 3).
    #[arg(long, default_value_t = 3)]
    reps: usize,
    /// Thread counts, comma-separated.
    #[arg(long, default_value = "1,2", value_delimiter = ',')]
    threads: Vec<usize>,
    /// Rays per pixel as MIN-MAX (multiples of 4), comma-separated.
    #[arg(long, default_value = "4-4,4-8,8-8,4-16,16-16", value_delimiter = ',')]
    spp: Vec<String>,
    /// Irradiance cache of the gathers, comma-separated `on` / `off` (off: every ray sample
    /// gathers afresh, the renderer before the cache).
    #[arg(long, default_value = "on", value_delimiter = ',')]
    cache: Vec<String>,
    /// Lighting modes, comma-separated: `facets` (sky facets and photo-bounce gathers) and / or
    /// `radiosity` (the radiosity solutions, precompute timed beside the render).
    #[arg(long, default_value = "facets", value_delimiter = ',')]
    lighting: Vec<String>,
    /// Folder with the peers' results JSON (default: BENCH_DIR/peers/results).
    #[arg(long)]
    peer_results: Option<PathBuf>,
}

/// CPU seconds used by this process so far (all threads; user + system), from `/proc/self/stat`
/// at the kernel's 100 Hz tick (as in `bvh_bench`). `None` where that file does not exist.
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

fn load_linear(path: &Path) -> Result<image::Rgb32FImage> {
    Ok(photomontage::photo::load(path)
        .with_context(|| format!("reading {}", path.display()))?
        .pixels)
}

fn rmse(rgba: &[[f32; 4]], truth: &image::Rgb32FImage) -> f64 {
    let sq: f64 = rgba
        .iter()
        .zip(truth.pixels())
        .map(|(o, t)| {
            (0..3)
                .map(|k| (f64::from(o[k]) - f64::from(t.0[k])).powi(2))
                .sum::<f64>()
        })
        .sum();
    #[allow(clippy::cast_precision_loss)]
    let n = (3 * rgba.len()) as f64;
    (sq / n).sqrt()
}

fn parse_spp(s: &str) -> Result<(u32, u32)> {
    let (a, b) = s.split_once('-').unwrap_or((s, s));
    let (min, max): (u32, u32) = (a.trim().parse()?, b.trim().parse()?);
    if min == 0 || min % 4 != 0 || max % 4 != 0 || max < min {
        bail!("--spp {s}: need multiples of 4 with 4 ≤ min ≤ max");
    }
    Ok((min, max))
}

fn json(path: &Path) -> Option<Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// One line per peer results file with a `with_box` render: threads, spp, time, RMSE.
fn print_peers(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        println!("NOTICE: no peer results folder {}", dir.display());
        return;
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("mitsuba_") || n.starts_with("blender_"))
        })
        .collect();
    files.sort();
    println!(
        "\npeers (with_box render of the whole scene, from {}):",
        dir.display()
    );
    println!(
        "{:<44} {:>7} {:>5} {:>10} {:>10}",
        "results file", "threads", "spp", "render s", "RMSE"
    );
    for path in files {
        let Some(v) = json(&path) else { continue };
        let r = &v["renders"]["with_box"];
        let time = r["render_s_warm_median"]
            .as_f64()
            .or_else(|| r["render_s_median"].as_f64());
        let err = r["rmse_vs_llvm_1024spp"]
            .as_f64()
            .or_else(|| r["rmse_vs_mitsuba_1024spp"].as_f64());
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("?");
        let fmt =
            |x: Option<f64>, p: usize| x.map_or_else(|| "-".to_owned(), |x| format!("{x:.p$}"));
        println!(
            "{name:<44} {:>7} {:>5} {:>10} {:>10}",
            v["threads"].as_u64().unwrap_or(0),
            v["spp"].as_u64().unwrap_or(0),
            fmt(time, 3),
            fmt(err, 5)
        );
    }
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
    let data = bench.join("data/mitsuba");
    let spec_path = data.join("scene.json");
    if !spec_path.is_file() {
        println!("NOTICE: {} is absent; nothing to do", spec_path.display());
        return Ok(());
    }
    if args.reps < 3 {
        bail!("--reps must be at least 3 (a median of fewer runs says little)");
    }
    let spec: Value = serde_json::from_str(&std::fs::read_to_string(&spec_path)?)?;
    let photo = load_linear(&data.join("llvm_ad_rgb_1024spp_without_box.exr"))?;
    let truth = load_linear(&data.join("llvm_ad_rgb_1024spp_with_box.exr"))?;
    if photo.dimensions() != truth.dimensions() {
        bail!("photo and truth differ in size");
    }
    let size_px = [photo.width(), photo.height()];
    let peer = mitsuba_pair_scene(&spec, size_px)?;
    let spps = args
        .spp
        .iter()
        .map(|s| parse_spp(s))
        .collect::<Result<Vec<_>>>()?;
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "render_bench: Mitsuba pair {}x{}, {} reps, load average at start: {}",
        size_px[0],
        size_px[1],
        args.reps,
        load.trim()
    );
    println!(
        "RMSE of the photo itself vs truth: {:.5}",
        rmse(
            &photo
                .pixels()
                .map(|p| [p.0[0], p.0[1], p.0[2], 0.0])
                .collect::<Vec<_>>(),
            &truth
        )
    );
    println!(
        "{:>9} {:>5} {:>7} {:>7} {:>12} {:>9} {:>10} {:>12} {:>9} {:>11} {:>9}",
        "lighting",
        "cache",
        "threads",
        "spp",
        "precompute s",
        "setup s",
        "render s",
        "render CPU s",
        "rays/px",
        "changed px",
        "RMSE"
    );
    let caches = args
        .cache
        .iter()
        .map(|c| match c.trim() {
            "on" => Ok(true),
            "off" => Ok(false),
            other => bail!("--cache {other}: on or off"),
        })
        .collect::<Result<Vec<bool>>>()?;
    let radiosity_modes = args
        .lighting
        .iter()
        .map(|l| match l.trim() {
            "facets" => Ok(false),
            "radiosity" => Ok(true),
            other => bail!("--lighting {other}: facets or radiosity"),
        })
        .collect::<Result<Vec<bool>>>()?;
    for ((&threads, &cache), &radiosity) in args
        .threads
        .iter()
        .flat_map(|t| caches.iter().map(move |c| (t, c)))
        .flat_map(|tc| radiosity_modes.iter().map(move |r| (tc, r)))
    {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        for &(min, max) in &spps {
            let settings = RenderSettings {
                min_rays_per_pixel: min,
                max_rays_per_pixel: max,
                max_depth: MAX_DEPTH,
                ..RenderSettings::default()
            };
            let (mut precompute_s, mut setup_s, mut render_s, mut cpu_s, mut last) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new(), None);
            // Radiosity mode: a second render with the vertex gathers the first one traced (the
            // studio's renders after a relight), wall and CPU seconds.
            let (mut warm_s, mut warm_cpu_s) = (Vec::new(), Vec::new());
            for _ in 0..args.reps {
                let mut lighting = peer.lighting.clone();
                if radiosity {
                    let t = Instant::now();
                    let solutions = pool.install(|| mitsuba_pair_radiosity(&peer))?;
                    precompute_s.push(t.elapsed().as_secs_f64());
                    lighting.radiosity = Some(std::sync::Arc::new(solutions.light()?));
                }
                let t0 = Instant::now();
                let mut cpu0 = None;
                let out = pool.install(|| -> Result<_> {
                    let mut tracer = DifferentialTracer::new(
                        &peer.scene,
                        &lighting,
                        &peer.camera,
                        &photo,
                        MAX_DEPTH,
                    )?;
                    if !cache {
                        tracer.set_irradiance_cache(None);
                    }
                    let t1 = Instant::now();
                    cpu0 = process_cpu_s();
                    let out = render_view(&tracer, &settings, &|_| {}, &AtomicBool::new(false))?;
                    let t1_end = Instant::now();
                    let cpu1 = process_cpu_s();
                    if radiosity {
                        let warm =
                            render_view(&tracer, &settings, &|_| {}, &AtomicBool::new(false))?;
                        warm_s.push(t1_end.elapsed().as_secs_f64());
                        if let (Some(a), Some(b)) = (cpu1, process_cpu_s()) {
                            warm_cpu_s.push(b - a);
                        }
                        if warm.rgba != out.rgba {
                            bail!("the warm render differs from the first");
                        }
                    }
                    Ok((t1, t1_end, cpu1, out))
                })?;
                let (t1, t1_end, cpu1, image) = out;
                setup_s.push((t1 - t0).as_secs_f64());
                render_s.push((t1_end - t1).as_secs_f64());
                if let (Some(a), Some(b)) = (cpu0, cpu1) {
                    cpu_s.push(b - a);
                }
                last = Some(image);
            }
            let Some(image) = last else { continue };
            #[allow(clippy::cast_precision_loss)]
            let rays_per_px =
                image.primary_rays as f64 / (f64::from(size_px[0]) * f64::from(size_px[1]));
            println!(
                "{:>9} {:>5} {threads:>7} {:>7} {:>12} {:>9.3} {:>10.3} {:>12} {rays_per_px:>9.2} {:>11} {:>9.5}",
                if radiosity { "radiosity" } else { "facets" },
                if cache { "on" } else { "off" },
                format!("{min}-{max}"),
                if precompute_s.is_empty() {
                    "-".to_owned()
                } else {
                    format!("{:.3}", median(precompute_s))
                },
                median(setup_s),
                median(render_s),
                if cpu_s.is_empty() {
                    "-".to_owned()
                } else {
                    format!("{:.3}", median(cpu_s))
                },
                image.changed_pixels,
                rmse(&image.rgba, &truth)
            );
            if !warm_s.is_empty() {
                println!(
                    "{:>9} {:>5} {threads:>7} {:>7} {:>12} {:>9} {:>10.3} {:>12} (the same render with the gathers already traced)",
                    "  warm",
                    "",
                    format!("{min}-{max}"),
                    "",
                    "",
                    median(warm_s),
                    if warm_cpu_s.is_empty() {
                        "-".to_owned()
                    } else {
                        format!("{:.3}", median(warm_cpu_s))
                    },
                );
            }
        }
    }
    print_peers(
        &args
            .peer_results
            .unwrap_or_else(|| bench.join("peers/results")),
    );
    Ok(())
}
