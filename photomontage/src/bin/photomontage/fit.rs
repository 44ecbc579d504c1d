//! `photomontage fit SITE`: the lighting fits of Durisch 1992 §4.2–4.3 on a site's samples,
//! the sun cross-check, and the atomic write-back into `[lighting]` and `[fit]`.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context;
use photomontage::fit::site::{SiteFitOptions, SiteFitReport, apply_fit, fit_site};
use photomontage::fit::{FitIteration, FitObserver, FitStage};
use photomontage::site::SiteDocument;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Fit and report without writing anything.
    #[arg(long)]
    no_write: bool,
}

/// Prints one progress line per solver iteration on stderr.
struct ProgressLine;

impl FitObserver for ProgressLine {
    fn on_iteration(&self, e: &FitIteration) {
        let stage = match e.stage {
            FitStage::Atmosphere => "atmosphere (eq. 7)",
            FitStage::Daylight => "daylight (eq. 9)",
        };
        let channel = ["red", "green", "blue"].get(e.channel).unwrap_or(&"?");
        eprint!(
            "\r{stage} {channel:<5} iteration {:>3}  ‖r‖ = {:.3e}   ",
            e.iteration, e.cost
        );
        let _ = std::io::stderr().flush();
    }
}

fn rgb(v: [f64; 3]) -> String {
    format!("{:.5} {:.5} {:.5}", v[0], v[1], v[2])
}

fn sigma(v: Option<[Option<f64>; 3]>) -> String {
    v.map_or_else(String::new, |s| {
        let parts: Vec<String> = s
            .iter()
            .map(|x| x.map_or_else(|| "—".into(), |x| format!("{x:.5}")))
            .collect();
        format!("   σ {}", parts.join(" "))
    })
}

fn print_text(r: &SiteFitReport) {
    match r.transmittance {
        Some(t) => println!(
            "transmittance τₐ over {:.0} m  {}{}",
            r.reference_distance_m,
            rgb(t),
            sigma(r.transmittance_sigma)
        ),
        None => println!("transmittance  not fitted (kept from the site)"),
    }
    println!("horizon colour L∞            {}", rgb(r.horizon_colour));
    for (name, w, s) in [
        ("sun weight k_s    ", r.sun_weight, r.sun_weight_sigma),
        (
            "ambient weight k_u",
            r.ambient_weight,
            r.ambient_weight_sigma,
        ),
        ("sky weight k_h    ", r.sky_weight, r.sky_weight_sigma),
    ] {
        match w {
            Some(w) => println!("{name}           {}{}", rgb(w), sigma(s)),
            None => println!("{name}           not fitted (kept from the site)"),
        }
    }
    if r.weights_relative {
        println!("(weights relative: the material's reflectance is not in the library)");
    }
    if !r.residuals.is_empty() {
        println!("residuals (model − photo, linear):");
        for res in &r.residuals {
            println!(
                "  {:<12} {:<10} {}{}",
                res.sample,
                res.fit,
                rgb(res.residual_rgb),
                if res.flagged { "   OUTLIER" } else { "" }
            );
        }
    }
    for c in &r.sun_checks {
        println!(
            "sun check {}: {:.2}° between shadow and SPA sun (elevation {:.2}°, azimuth {:.2}°)",
            c.pair, c.check.angle_deg, c.check.spa_elevation_deg, c.check.spa_azimuth_deg
        );
    }
    for w in &r.warnings {
        println!("warning: {w}");
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut doc = SiteDocument::load(&args.site)?;
    let observer: Option<Arc<dyn FitObserver>> = if args.json {
        None
    } else {
        Some(Arc::new(ProgressLine))
    };
    let report = fit_site(&doc, &SiteFitOptions::default(), observer)
        .with_context(|| format!("fitting the lighting of {}", args.site.display()))?;
    if !args.json {
        eprintln!();
    }
    let written_to = if args.no_write {
        None
    } else {
        let now = chrono::Utc::now().to_rfc3339_opts(chrono::SecondsFormat::Secs, true);
        apply_fit(&mut doc.site, &report, &now);
        doc.save()
            .with_context(|| format!("saving the fitted site to {}", args.site.display()))?;
        Some(args.site.display().to_string())
    };
    if args.json {
        let mut value = serde_json::to_value(&report)?;
        if let Some(obj) = value.as_object_mut() {
            obj.insert("written_to".into(), serde_json::json!(written_to));
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        print_text(&report);
        if let Some(path) = &written_to {
            println!("written to {path}");
        }
    }
    Ok(())
}
