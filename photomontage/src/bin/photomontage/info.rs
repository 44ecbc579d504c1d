//! `photomontage info SITE`: what a site holds.

use anyhow::Context;
use photomontage::{photo, site::SiteDocument};
use serde::Serialize;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct PhotoInfo {
    id: String,
    file: String,
    exists: bool,
    size_px: Option<[u32; 2]>,
    solved: bool,
    observations: usize,
    rms_px: Option<f64>,
}

#[derive(Serialize)]
struct PointInfo {
    id: String,
    xyz: [f64; 3],
    sigma_m: [f64; 3],
    kind: &'static str,
}

#[derive(Serialize)]
struct Info {
    name: String,
    photos: Vec<PhotoInfo>,
    control_points: Vec<PointInfo>,
    tie_points: Vec<PointInfo>,
    observations: usize,
    polygons: Vec<String>,
    models: Vec<String>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let doc = SiteDocument::load(&args.site)?;
    let site = &doc.site;
    let photos = site
        .photos
        .iter()
        .map(|p| {
            let path = doc.resolve(&p.file);
            let size_px = photo::size_px(&path)
                .ok()
                .or_else(|| p.interior.as_ref().and_then(|i| i.image_size_px));
            PhotoInfo {
                id: p.id.clone(),
                file: p.file.clone(),
                exists: path.exists(),
                size_px,
                solved: p.exterior.is_some(),
                observations: site.observations.iter().filter(|o| o.photo == p.id).count(),
                rms_px: p.exterior.as_ref().map(|e| e.rms_px),
            }
        })
        .collect();
    let info = Info {
        name: site.name.clone(),
        photos,
        control_points: site
            .control_points
            .iter()
            .map(|c| PointInfo {
                id: c.id.clone(),
                xyz: c.xyz,
                sigma_m: c.sigma_m,
                kind: "control",
            })
            .collect(),
        tie_points: site
            .tie_points
            .iter()
            .map(|t| PointInfo {
                id: t.id.clone(),
                xyz: t.xyz,
                sigma_m: t.sigma_m,
                kind: "tie",
            })
            .collect(),
        observations: site.observations.len(),
        polygons: site.polygons.iter().map(|p| p.id.clone()).collect(),
        models: site.models.iter().map(|m| m.id.clone()).collect(),
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&info).context("JSON output")?
        );
        return Ok(());
    }
    println!("site: {} ({})", info.name, args.site.display());
    println!("photos ({}):", info.photos.len());
    for p in &info.photos {
        let size = p
            .size_px
            .map_or_else(|| "size unknown".into(), |[w, h]| format!("{w}×{h} px"));
        let state = match (p.exists, p.solved) {
            (false, _) => "MISSING FILE".to_string(),
            (true, true) => format!("solved, RMS {:.2} px", p.rms_px.unwrap_or(f64::NAN)),
            (true, false) => "not solved".into(),
        };
        println!(
            "  {:<10} {:<28} {:>14}  {:>3} observations  {state}",
            p.id, p.file, size, p.observations
        );
    }
    println!(
        "control points: {}   tie points: {}   observations: {}",
        info.control_points.len(),
        info.tie_points.len(),
        info.observations
    );
    println!(
        "polygons ({}): {}",
        info.polygons.len(),
        info.polygons.join(", ")
    );
    println!("models ({}): {}", info.models.len(), info.models.join(", "));
    Ok(())
}
