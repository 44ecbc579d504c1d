//! `photomontage irradiance SITE --points POINTS.csv [--json]`: solve the site's radiosity
//! (hierarchical, as a precomputed transfer) and print, for each row `id,X,Y,Z,nx,ny,nz` (world
//! metres, outward unit normal), the irradiance from sun, sky, luminaires and interreflection in
//! the site's linear units: `{"points":[{"id":…,"irradiance_rgb":[…],"direct_rgb":[…],
//! "indirect_rgb":[…]}]}`. Bad rows are refused by line before any work; Ctrl-C cancels and
//! prints nothing.

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Duration;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use photomontage::radiosity::hierarchical::HierarchicalParams;
use photomontage::radiosity::{QueryParams, Solver, Transfer, TransferParams, parse_query_points};
use photomontage::site::SiteDocument;
use photomontage::site::radiosity_lighting::{site_ground_below_horizon, site_transfer_lighting};
use photomontage::site::render::site_scene;
use rayon::prelude::*;

use crate::radiosity::SolveArgs;
use crate::render::{install_cancel, with_threads};

/// Gather rays per point by default: 16 × the library's default, since a CLI query is a few
/// points, not a render.
const POINT_GATHER_RAYS: u32 = 4096;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// The points: CSV rows `id,X,Y,Z,nx,ny,nz` (world metres, outward unit normal; an `id,…`
    /// header line is allowed).
    #[arg(long, value_name = "POINTS.csv")]
    points: PathBuf,
    #[command(flatten)]
    solve: SolveArgs,
    /// Interpolate on elements no longer than this, metres; coarser elements (and points on
    /// no element) are final-gathered. Default 0: every point is gathered, which gives the
    /// solution's value at the point (within 2.2 % of Radiance's `rtrace -I` on the courtyard,
    /// where element values were up to 5.7 % off at the feet of walls; docs/benchmarks.md).
    #[arg(long, default_value_t = 0.0)]
    max_interpolation_edge_m: f64,
    /// Rays of a final gather (the interreflected part's standard error falls as 1/√rays).
    #[arg(long, default_value_t = POINT_GATHER_RAYS)]
    gather_rays: u32,
    /// Print JSON (else one CSV row per point: id, irradiance, direct and indirect RGB).
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.points)
        .with_context(|| format!("reading {}", args.points.display()))?;
    let points = parse_query_points(&text).with_context(|| args.points.display().to_string())?;
    if points.is_empty() {
        bail!("{}: no points", args.points.display());
    }
    let doc = SiteDocument::load(&args.site)?;
    let site = site_scene(&doc)?;
    for w in &site.warnings {
        eprintln!("warning: {w}");
    }
    let (lighting, notes) = site_transfer_lighting(&doc, &site.scene, &args.solve.view_id(&doc))?;
    for n in notes {
        eprintln!("note: {n}");
    }
    let ground = site_ground_below_horizon(&doc, &site.scene)?;
    let mut params = TransferParams {
        solve: args.solve.params(
            Solver::Hierarchical(HierarchicalParams {
                bf_tolerance: args.solve.bf_tolerance,
                ..HierarchicalParams::default()
            }),
            ground,
        )?,
        sky_tolerance: args.solve.sky_tolerance,
        ..TransferParams::default()
    };
    let (mesh, notes) = params.solve.mesh.sized_for(&site.scene);
    params.solve.mesh = mesh;
    for n in notes {
        eprintln!("note: {n}");
    }
    let query = QueryParams {
        max_interpolation_edge_m: args.max_interpolation_edge_m,
        gather_rays: args.gather_rays,
    };
    let cancel = install_cancel()?;
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    bar.set_message("meshing, lighting and solving (Ctrl-C cancels)");
    eprintln!(
        "solving radiosity for {} point(s) (Ctrl-C cancels)",
        points.len()
    );
    let result = with_threads(args.solve.threads, || {
        let transfer = Transfer::build(&site.scene, &lighting, &params, cancel, &|row| {
            bar.set_message(format!(
                "{} pass {}: residual {:.2e}, mean change {:.2e}",
                row.group, row.pass, row.residual, row.mean_change
            ));
        })?;
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} points {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_length(points.len() as u64);
        let samples: Vec<_> = points
            .par_iter()
            .map(|p| {
                if cancel.load(Ordering::Relaxed) {
                    return Err(anyhow::anyhow!("cancelled"));
                }
                let s = transfer
                    .irradiance_at(&p.point_in_world_m, &p.normal_in_world, &query)
                    .with_context(|| format!("point `{}`", p.id))?;
                bar.inc(1);
                Ok(s)
            })
            .collect::<anyhow::Result<_>>()?;
        Ok((transfer.solution().warnings.clone(), samples))
    });
    bar.finish_and_clear();
    if cancel.load(Ordering::SeqCst) {
        bail!("cancelled (Ctrl-C): nothing written");
    }
    let (warnings, samples) = result?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if args.json {
        let rows: Vec<serde_json::Value> = points
            .iter()
            .zip(&samples)
            .map(|(p, s)| {
                serde_json::json!({
                    "id": p.id,
                    "irradiance_rgb": s.total_rgb,
                    "direct_rgb": s.direct_rgb,
                    "indirect_rgb": s.indirect_rgb,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "points": rows }))?
        );
    } else {
        println!(
            "id,irradiance_r,irradiance_g,irradiance_b,direct_r,direct_g,direct_b,indirect_r,indirect_g,indirect_b"
        );
        for (p, s) in points.iter().zip(&samples) {
            let v: Vec<String> = s
                .total_rgb
                .iter()
                .chain(&s.direct_rgb)
                .chain(&s.indirect_rgb)
                .map(|x| format!("{x:e}"))
                .collect();
            println!("{},{}", p.id, v.join(","));
        }
    }
    Ok(())
}
