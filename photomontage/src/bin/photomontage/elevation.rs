//! `photomontage elevation SITE --model ID --out FILE.png [--irradiance] [--json]`: the unfolded
//! elevation of one CAD model (Tonn & Donath): its façades side by side with their current
//! colours (site `[[materials]]` included), or with the irradiance of the site's radiosity
//! solution in false colour. `--json` prints each façade's azimuth, width and, with
//! `--irradiance`, the irradiance at its centre. Ctrl-C during the solve writes nothing.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use anyhow::{Context, bail};
use photomontage::design::unfolded::UnfoldParams;
use photomontage::site::SiteDocument;
use photomontage::site::elevation::{ElevationLighting, site_elevation};

use crate::radiosity::SolveArgs;
use crate::render::{install_cancel, with_threads};

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// The CAD model (its `[[models]] id`).
    #[arg(long)]
    model: String,
    /// The PNG to write.
    #[arg(long, value_name = "FILE.png")]
    out: PathBuf,
    /// Show the irradiance of a radiosity solve instead of the colours.
    #[arg(long)]
    irradiance: bool,
    /// Pixels per metre.
    #[arg(long, default_value_t = UnfoldParams::default().px_per_m)]
    px_per_m: f64,
    /// Print the façades as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    solve: SolveArgs,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let doc = SiteDocument::load(&args.site)?;
    let params = UnfoldParams {
        px_per_m: args.px_per_m,
        ..UnfoldParams::default()
    };
    let cancel = install_cancel()?;
    let lighting = if args.irradiance {
        eprintln!("solving radiosity (Ctrl-C cancels)");
        Some(ElevationLighting {
            params: args.solve.options()?.elevation_transfer_params(),
            view: args.solve.view_id(&doc),
            cancel,
        })
    } else {
        None
    };
    let result = with_threads(args.solve.threads, || {
        Ok(site_elevation(&doc, &args.model, &params, lighting)?)
    });
    if cancel.load(Ordering::SeqCst) {
        bail!("cancelled (Ctrl-C): nothing written");
    }
    let elevation = result?;
    for w in &elevation.warnings {
        eprintln!("warning: {w}");
    }
    let bytes = elevation.png_bytes().context("encoding PNG")?;
    photomontage::site::write_atomically(&args.out, &bytes)
        .with_context(|| format!("writing {}", args.out.display()))?;
    if args.json {
        let report = serde_json::json!({
            "model": args.model,
            "px_per_m": args.px_per_m,
            "image_size_px": elevation.layout.image_size_px,
            "panel_y0_px": elevation.layout.y0_px,
            "panel_height_px": elevation.layout.height_px,
            "max_irradiance_y": elevation.image.max_irradiance_y,
            "facades": elevation.facades,
        });
        println!("{report}");
    } else {
        for f in &elevation.facades {
            println!(
                "façade az {:.1}°: {:.2} m, {} px{}",
                f.azimuth_deg,
                f.width_m,
                f.width_px,
                f.centre_irradiance_y
                    .map(|y| format!(", irradiance Y at centre {y:.4}"))
                    .unwrap_or_default()
            );
        }
        eprintln!("wrote {}", args.out.display());
    }
    Ok(())
}
