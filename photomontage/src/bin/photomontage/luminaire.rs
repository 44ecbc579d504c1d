//! `photomontage luminaire FILE [--json] [--plot OUT.png]`: read an IES LM-63 or EULUMDAT file
//! and report its format, total flux, maximum intensity, symmetry and parse warnings.

use anyhow::Context;
use clap::Args;
use photomontage::luminaire::PhotometricFile;
use photomontage::luminaire::polar_plot::{PolarPlotOptions, save_polar_plot_png};
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `photomontage luminaire`.
#[derive(Args)]
pub struct LuminaireArgs {
    /// An IES LM-63 (.ies) or EULUMDAT (.ldt) file.
    file: PathBuf,
    /// Print a JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Write a polar intensity plot (PNG) here.
    #[arg(long, value_name = "OUT.png")]
    plot: Option<PathBuf>,
}

#[derive(Serialize)]
struct Report {
    format: String,
    total_flux_lm: f64,
    max_intensity_cd: f64,
    symmetry: &'static str,
    warnings: Vec<String>,
}

/// Runs the subcommand.
pub fn run(args: &LuminaireArgs) -> anyhow::Result<()> {
    let file = PhotometricFile::read(&args.file)
        .with_context(|| format!("reading {}", args.file.display()))?;
    let web = file.distribution()?;
    let report = Report {
        format: file.format_label(),
        total_flux_lm: web.total_flux_lm(),
        max_intensity_cd: web.max_intensity_cd(),
        symmetry: web.symmetry().label(),
        warnings: file.warnings().to_vec(),
    };
    if let Some(out) = &args.plot {
        save_polar_plot_png(&web, &PolarPlotOptions::default(), out)?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("format:           {}", report.format);
        println!("total flux:       {:.2} lm", report.total_flux_lm);
        println!("max intensity:    {:.2} cd", report.max_intensity_cd);
        println!("symmetry:         {}", report.symmetry);
        for w in &report.warnings {
            println!("warning:          {w}");
        }
    }
    Ok(())
}
