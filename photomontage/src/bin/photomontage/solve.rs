//! `photomontage solve SITE`: solve every photo of a site and write the result back.

use crate::report::{PhotoRecord, print_photo, rotation_rows};
use anyhow::Context;
use photomontage::site::{SiteDocument, apply_solution, solve_site};
use serde::Serialize;
use std::path::PathBuf;

/// Tie points listed in the text report.
const MAX_TIE_LINES: usize = 30;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Write the solved site here instead of over SITE (relative paths are rebased).
    #[arg(long, value_name = "PATH")]
    out: Option<PathBuf>,
    /// Solve and report without writing anything.
    #[arg(long, conflicts_with = "out")]
    no_write: bool,
}

#[derive(Serialize)]
struct Output<'a> {
    photos: Vec<PhotoRecord<'a>>,
    /// Per solved photo, OpenCV's solvePnP compared (null without the `opencv` feature).
    opencv_checks: Vec<Option<photomontage::site::solve::PoseCheck>>,
    failures: &'a [photomontage::site::solve::PhotoFailure],
    tie_points: Vec<&'a photomontage::photogrammetry::BundlePointReport>,
    bundle_rms_px: Option<f64>,
    warnings: &'a [String],
    written_to: Option<String>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut doc = SiteDocument::load(&args.site)?;
    let solution = solve_site(&doc);
    apply_solution(&mut doc.site, &solution);
    let written_to = if args.no_write {
        None
    } else {
        let target = args.out.clone().unwrap_or_else(|| args.site.clone());
        doc.save_as(&target)
            .with_context(|| format!("saving the solved site to {}", target.display()))?;
        Some(target.display().to_string())
    };
    let records: Vec<PhotoRecord<'_>> = solution
        .photos
        .iter()
        .map(|s| {
            let intr = s.camera.intrinsics;
            PhotoRecord {
                id: &s.id,
                camera_center: s.camera.pose.camera_center_in_world.coords.into(),
                rotation_world_from_camera: rotation_rows(&s.camera),
                focal_px: intr.focal_px,
                principal_point_px: intr.principal_point_px,
                distortion: intr.distortion,
                image_size_px: intr.image_size_px,
                rms_px: s.rms_px,
                redundancy: s.redundancy,
                sigma_center_m: s.sigma_center_m,
                sigma_angles_deg: s.sigma_angles_deg,
                sigma_focal_px: s.sigma_focal_px,
                outliers: &s.outliers,
                warnings: &s.warnings,
                residuals: &s.residuals,
                control_crs: None,
                site_location: None,
                radial_pattern: s.radial_pattern,
                solved_by: s.solved_by,
            }
        })
        .collect();
    let ties: Vec<_> = solution.points.iter().filter(|p| !p.is_control).collect();
    if args.json {
        let out = Output {
            photos: records,
            opencv_checks: solution.photos.iter().map(|s| s.opencv_check).collect(),
            failures: &solution.failures,
            tie_points: ties,
            bundle_rms_px: solution.bundle_rms_px,
            warnings: &solution.warnings,
            written_to,
        };
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        for (r, s) in records.iter().zip(&solution.photos) {
            print_photo(r);
            if let Some(c) = &s.opencv_check {
                println!(
                    "  OpenCV solvePnP check ({} points): centre differs by {:.3e} m, rotation by {:.3e}°",
                    c.points, c.center_difference_m, c.rotation_difference_deg
                );
            }
            println!();
        }
        if !ties.is_empty() {
            println!("tie points:");
            // Matched tie points come by the thousand: the first ones and a count in text, all
            // of them in --json.
            for t in ties.iter().take(MAX_TIE_LINES) {
                println!(
                    "  {:<12} X {:.4}  Y {:.4}  Z {:.4}   σ {:.4} {:.4} {:.4} m  ({} rays, RMS {:.2} px)",
                    t.id,
                    t.point_in_world.x,
                    t.point_in_world.y,
                    t.point_in_world.z,
                    t.sigma_m[0],
                    t.sigma_m[1],
                    t.sigma_m[2],
                    t.rays,
                    t.rms_px
                );
            }
            if ties.len() > MAX_TIE_LINES {
                println!(
                    "  … and {} more (all in --json)",
                    ties.len() - MAX_TIE_LINES
                );
            }
        }
        if let Some(rms) = solution.bundle_rms_px {
            println!("bundle adjustment RMS {rms:.3} px");
        }
        for w in &solution.warnings {
            println!("warning: {w}");
        }
        for f in &solution.failures {
            println!("NOT SOLVED {}: {}", f.id, f.error);
        }
        if let Some(path) = &written_to {
            println!("written to {path}");
        }
    }
    if !solution.failures.is_empty() {
        anyhow::bail!(
            "{} of {} photos could not be solved",
            solution.failures.len(),
            doc.site.photos.len()
        );
    }
    Ok(())
}
