//! `photomontage report SITE --view V [--json]`: the view geometry report of one solved photo
//! (camera position, bearing, pitch, roll, fields of view, 35 mm equivalent, sun at capture,
//! residual table, distance to the proposal, viewing distance of the sheet). The computation is
//! `photomontage::verified::geometry`; this file only prints it.

use anyhow::Context;
use photomontage::site::SiteDocument;
use photomontage::verified::{PaperSize, ViewGeometry, ViewGeometryOptions, view_geometry};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Id of the solved photo.
    #[arg(long, value_name = "PHOTO_ID")]
    view: String,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Paper of the sheet the viewing distance is computed for: A3 (default), A2 or A1.
    #[arg(long, value_name = "SIZE", default_value = "A3")]
    paper: PaperSize,
    /// Ground level below the camera (survey height, metres); default: the scene polygon below
    /// the camera.
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    ground_level_m: Option<f64>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if let Some(z) = args.ground_level_m
        && !z.is_finite()
    {
        anyhow::bail!("--ground-level-m {z}: must be a finite height in metres");
    }
    let doc = SiteDocument::load(&args.site)?;
    let options = ViewGeometryOptions {
        paper: args.paper,
        ground_level_m: args.ground_level_m,
    };
    let report = view_geometry(&doc, &args.view, &options)
        .with_context(|| format!("view geometry of photo {}", args.view))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn opt(value: Option<f64>, digits: usize, unit: &str) -> String {
    value.map_or_else(|| "unknown".to_owned(), |v| format!("{v:.digits$}{unit}"))
}

fn print_text(r: &ViewGeometry) {
    let [e, n, h] = r.camera_position_m;
    println!("view geometry of photo {} ({})", r.photo_id, r.solved_by);
    println!(
        "  camera        E {e:.3}  N {n:.3}  H {h:.3} m  ({})   σ {:.3} {:.3} {:.3} m",
        r.crs.as_deref().unwrap_or("survey CRS unnamed"),
        r.sigma_center_m[0],
        r.sigma_center_m[1],
        r.sigma_center_m[2]
    );
    println!(
        "  lat/lon       {} {}",
        opt(r.latitude_deg, 7, "°"),
        opt(r.longitude_deg, 7, "°")
    );
    println!(
        "  height        {} above ground (ground {}), {h:.3} m above datum",
        opt(r.height_above_ground_m, 3, " m"),
        opt(r.ground_level_m, 3, " m")
    );
    println!(
        "  bearing       {:.3}° true, {:.3}° grid (convergence {:.3}°{})",
        r.bearing_true_deg,
        r.bearing_grid_deg,
        r.grid_convergence_deg,
        r.crs_grid_convergence_deg
            .map_or_else(String::new, |c| format!("; CRS gives {c:.3}°"))
    );
    println!("  pitch, roll   {:.3}°, {:.3}°", r.pitch_deg, r.roll_deg);
    println!(
        "  lens          f {:.2} px = {:.1} mm (35 mm equivalent; EXIF: {} focal, {} equivalent)",
        r.focal_px,
        r.focal_35mm_equiv_mm,
        opt(r.exif_focal_length_mm, 1, " mm"),
        opt(r.exif_focal_35mm_mm, 0, " mm")
    );
    println!(
        "  field of view {:.3}° × {:.3}°   image {} × {} px   principal point ({:.2}, {:.2}) px",
        r.hfov_deg,
        r.vfov_deg,
        r.image_size_px[0],
        r.image_size_px[1],
        r.principal_point_px[0],
        r.principal_point_px[1]
    );
    let d = &r.distortion;
    println!(
        "  distortion    k1 {:.6} k2 {:.6} k3 {:.6} p1 {:.6} p2 {:.6}",
        d.k1, d.k2, d.k3, d.p1, d.p2
    );
    println!(
        "  captured      {} ({})",
        r.capture_time.as_deref().unwrap_or("unknown"),
        r.capture_time_source.unwrap_or("no source")
    );
    println!(
        "  sun           azimuth {}, elevation {}",
        opt(r.sun_azimuth_deg, 2, "°"),
        opt(r.sun_elevation_deg, 2, "°")
    );
    println!(
        "  proposal      nearest {}, centroid {} ({})",
        opt(r.distance_to_proposal_nearest_m, 2, " m"),
        opt(r.distance_to_proposal_centroid_m, 2, " m"),
        if r.proposal_models.is_empty() {
            "no visible model".to_owned()
        } else {
            r.proposal_models.join(", ")
        }
    );
    println!(
        "  sheet         {} landscape: image {:.1} mm wide, viewing distance {:.0} mm",
        r.paper.name(),
        r.printed_image_width_mm,
        r.viewing_distance_mm
    );
    println!("  RMS           {:.3} px", r.rms_px);
    println!(
        "  {:<12} {:>5} {:>10} {:>10} {:>8} {:>8} {:>6}",
        "point", "kind", "x px", "y px", "|v| px", "|v|/σ", "flag"
    );
    for row in &r.residuals {
        println!(
            "  {:<12} {:>5} {:>10.2} {:>10.2} {:>8.3} {:>8.2} {:>6}",
            row.point_id,
            row.point_kind,
            row.observed_px[0],
            row.observed_px[1],
            row.residual_norm_px,
            row.normalised,
            if row.flagged { "!" } else { "" }
        );
    }
    for note in &r.notes {
        println!("  note: {note}");
    }
}
