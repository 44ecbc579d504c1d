//! `photomontage radiosity SITE`: mesh the site's scene, light it by the sun, the sky, each
//! enabled luminaire and the emitting materials as separate groups and solve the interreflection; report patches, links,
//! passes, time and residual, and optionally write the mesh (PLY), the convergence record (CSV)
//! and a JSON report. Ctrl-C cancels between passes; nothing is written then.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use photomontage::atomic_file::{probe_writable, write_atomically};
use photomontage::radiosity::convergence::csv;
use photomontage::radiosity::hierarchical::HierarchicalParams;
use photomontage::radiosity::{SolveParams, Solver, StopRule, luminance, solve};
use photomontage::site::SiteDocument;
use photomontage::site::radiosity_lighting::{site_ground_below_horizon, site_light_groups};
use photomontage::site::render::site_scene;
use photomontage::site::solve_options::SolveOptions;

use crate::render::{install_cancel, with_threads};

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum SolverArg {
    /// Hierarchical radiosity with BF refinement (Hanrahan et al. 1991).
    Hierarchical,
    /// Progressive refinement: shoot the largest unshot power (Cohen et al. 1988).
    Progressive,
    /// Gauss–Seidel on the full element matrix (small scenes).
    Direct,
}

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Solver.
    #[arg(long, value_enum, default_value_t = SolverArg::Hierarchical)]
    solver: SolverArg,
    #[command(flatten)]
    solve: SolveArgs,
    /// Write the elements with their radiosity colours as PLY.
    #[arg(long, value_name = "FILE.ply")]
    mesh_out: Option<PathBuf>,
    /// Write the convergence record (every pass of every group) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    convergence: Option<PathBuf>,
    /// Plot the convergence record (log residual and mean change per pass and group) as PNG.
    #[arg(long, value_name = "FILE.png")]
    convergence_plot: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Meshing, quadrature, stop rule and lighting options shared by `radiosity` and `irradiance`.
#[derive(clap::Args)]
pub struct SolveArgs {
    /// Photo whose capture time places the sun (default: the first photo; not needed with
    /// `sun_manual`).
    #[arg(long, value_name = "PHOTO_ID")]
    pub view: Option<String>,
    /// Longest patch edge in metres (the global size).
    #[arg(long, default_value_t = SolveOptions::default().patch_edge_m)]
    pub patch_edge_m: f64,
    /// Longest element edge in metres, unless the object has its own.
    #[arg(long, default_value_t = SolveOptions::default().element_edge_m)]
    pub element_edge_m: f64,
    /// Element size of one object, `NAME=METRES` (repeatable; object names as `info` lists
    /// polygons and models).
    #[arg(long, value_name = "NAME=METRES")]
    pub object_element_edge: Vec<String>,
    /// Split elements that face another surface closer than their own size (the feet of walls,
    /// inner corners, under overhangs) down to this edge, metres: irradiance read off the
    /// elements there follows the fall-off instead of an element's mean (docs/methodology.md).
    #[arg(long, value_name = "METRES")]
    pub corner_element_m: Option<f64>,
    /// Form-factor samples per axis (n² per pair).
    #[arg(long, default_value_t = SolveOptions::default().samples_per_axis)]
    pub samples: u32,
    /// Random seed of the form factors and shadow rays.
    #[arg(long, default_value_t = SolveOptions::default().seed)]
    pub seed: u64,
    /// HR BF tolerance (fraction of the mean brightness).
    #[arg(long, default_value_t = SolveOptions::default().bf_tolerance)]
    pub bf_tolerance: f64,
    /// Sky clustering tolerance of the icosahedral dome.
    #[arg(long, default_value_t = SolveOptions::default().sky_tolerance)]
    pub sky_tolerance: f64,
    /// Stop when the mean brightness changes by less than this between passes (Üncü & Kayakuş: 0.01).
    #[arg(long, default_value_t = SolveOptions::default().mean_change)]
    pub mean_change: f64,
    /// ... and the relative residual is below this.
    #[arg(long, default_value_t = SolveOptions::default().residual)]
    pub residual: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

impl SolveArgs {
    /// The photo that places the sun.
    pub fn view_id(&self, doc: &SiteDocument) -> String {
        self.view
            .clone()
            .or_else(|| doc.site.photos.first().map(|p| p.id.clone()))
            .unwrap_or_default()
    }

    /// The options as the library's one set ([`SolveOptions`]).
    pub fn options(&self) -> anyhow::Result<SolveOptions> {
        Ok(SolveOptions {
            patch_edge_m: self.patch_edge_m,
            element_edge_m: self.element_edge_m,
            object_element_edge_m: object_sizes(&self.object_element_edge)?,
            samples_per_axis: self.samples,
            seed: self.seed,
            bf_tolerance: self.bf_tolerance,
            sky_tolerance: self.sky_tolerance,
            mean_change: self.mean_change,
            residual: self.residual,
            corner_element_m: self.corner_element_m,
        })
    }

    /// Solve parameters with `solver`, and the ground below the horizon of the site.
    pub fn params(
        &self,
        solver: Solver,
        ground: Option<photomontage::radiosity::GroundBelowHorizon>,
    ) -> anyhow::Result<SolveParams> {
        Ok(self.options()?.solve_params(solver, ground))
    }

    /// The stop rule.
    pub fn stop(&self) -> StopRule {
        StopRule {
            mean_change: self.mean_change,
            residual: self.residual,
            ..StopRule::default()
        }
    }
}

pub fn object_sizes(specs: &[String]) -> anyhow::Result<BTreeMap<String, f64>> {
    specs
        .iter()
        .map(|s| {
            let (name, size) = s
                .rsplit_once('=')
                .with_context(|| format!("--object-element-edge `{s}` is not NAME=METRES"))?;
            let size: f64 = size.parse().with_context(|| {
                format!("--object-element-edge `{s}`: `{size}` is not a number")
            })?;
            Ok((name.to_owned(), size))
        })
        .collect()
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    for path in args
        .mesh_out
        .iter()
        .chain(&args.convergence)
        .chain(&args.convergence_plot)
    {
        probe_writable(path).with_context(|| format!("cannot write {}", path.display()))?;
    }
    let doc = SiteDocument::load(&args.site)?;
    let site = site_scene(&doc)?;
    for w in &site.warnings {
        eprintln!("warning: {w}");
    }
    // The one builder of a site's light groups (shared with `irradiance` and the transfer).
    let lights = site_light_groups(
        &doc,
        &site.scene,
        &args.solve.view_id(&doc),
        args.solve.sky_tolerance,
    )?;
    for w in &lights.warnings {
        eprintln!("warning: {w}");
    }
    for n in &lights.notes {
        eprintln!("note: {n}");
    }
    let groups = &lights.groups;
    if groups.is_empty() {
        bail!(
            "nothing lights {}: sun_weight and sky_weight are zero (or the sun is down), no \
             luminaire is enabled and no material emits",
            args.site.display()
        );
    }
    let stop = args.solve.stop();
    let ground = site_ground_below_horizon(&doc, &site.scene)?;
    if let Some(g) = &ground {
        eprintln!(
            "note: the site models no ground: the lower hemisphere is a uniform ground of albedo {:?}",
            g.albedo_rgb
        );
    }
    let mut params = args.solve.params(
        match args.solver {
            SolverArg::Hierarchical => Solver::Hierarchical(HierarchicalParams {
                bf_tolerance: args.solve.bf_tolerance,
                ..HierarchicalParams::default()
            }),
            SolverArg::Progressive => Solver::Progressive,
            SolverArg::Direct => Solver::Direct,
        },
        ground,
    )?;
    let (mesh, notes) = params.mesh.sized_for(&site.scene);
    params.mesh = mesh;
    for n in notes {
        eprintln!("note: {n}");
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    bar.set_message("meshing and lighting (Ctrl-C cancels)");
    let cancel = install_cancel()?;
    eprintln!(
        "solving radiosity: {} light group(s) (Ctrl-C cancels)",
        groups.len()
    );
    let start = Instant::now();
    let result = with_threads(args.solve.threads, || {
        Ok(solve(&site.scene, groups, &params, cancel, &|row| {
            bar.set_message(format!(
                "{} pass {}: residual {:.2e}, mean change {:.2e}, {} interactions",
                row.group, row.pass, row.residual, row.mean_change, row.interactions
            ));
        })?)
    });
    bar.finish_and_clear();
    if cancel.load(Ordering::SeqCst) {
        bail!("cancelled (Ctrl-C): nothing written");
    }
    let solution = result?;
    let elapsed_s = start.elapsed().as_secs_f64();
    for w in &solution.mesh.warnings {
        eprintln!("warning: {w}");
    }
    for w in &solution.warnings {
        eprintln!("warning: {w}");
    }
    let total = solution.total_radiosity_rgb();
    if let Some(path) = &args.mesh_out {
        let white = total.iter().map(luminance).fold(0.0, f64::max);
        solution.mesh.write_ply(path, Some(&total), white)?;
    }
    let rows = solution.convergence();
    if let Some(path) = &args.convergence {
        write_atomically(path, csv(&rows).as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.convergence_plot {
        photomontage::radiosity::convergence_plot::write_png(path, &rows, &stop)?;
    }
    let converged = solution.converged(&stop);
    let groups_json: Vec<serde_json::Value> = solution
        .groups
        .iter()
        .map(|g| {
            let last = g.convergence.last();
            serde_json::json!({
                "name": g.name,
                "passes": g.convergence.len(),
                "residual": last.map_or(0.0, |r| r.residual),
                "mean_change": last.map_or(0.0, |r| r.mean_change),
                "mean_radiosity_luminance": last.map_or(0.0, |r| r.mean_brightness),
            })
        })
        .collect();
    let report = serde_json::json!({
        "solver": format!("{:?}", args.solver).to_lowercase(),
        "patches": solution.mesh.patches.len(),
        "elements": solution.mesh.elements.len(),
        "interactions": solution.interactions,
        "refinement_passes": solution.refinement.len(),
        "groups": groups_json,
        "converged": converged,
        "time_s": elapsed_s,
        "warnings": solution
            .mesh
            .warnings
            .iter()
            .map(ToString::to_string)
            .chain(solution.warnings.iter().map(ToString::to_string))
            .chain(lights.warnings.iter().map(ToString::to_string))
            .collect::<Vec<_>>(),
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "{} patches, {} elements, {} {} in {elapsed_s:.2} s{}",
            solution.mesh.patches.len(),
            solution.mesh.elements.len(),
            solution.interactions,
            match args.solver {
                SolverArg::Hierarchical => "links",
                SolverArg::Progressive => "form factors",
                SolverArg::Direct => "matrix entries",
            },
            if converged { "" } else { " (NOT converged)" }
        );
        for g in &solution.groups {
            if let Some(r) = g.convergence.last() {
                println!(
                    "  {:<9} {} passes, residual {:.2e}, mean change {:.2e}, mean radiosity {:.4}",
                    g.name,
                    g.convergence.len(),
                    r.residual,
                    r.mean_change,
                    r.mean_brightness
                );
            }
        }
    }
    Ok(())
}
