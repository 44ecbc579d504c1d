//! `photomontage match SITE`: tie points by SIFT feature matching (cargo feature `opencv`),
//! written into the site atomically (comments kept).

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Most SIFT keypoints per photo (the strongest).
    #[arg(long, value_name = "N", default_value_t = 4000)]
    max_features: usize,
    /// Lowe's ratio test bound (nearest / second-nearest descriptor distance).
    #[arg(long, value_name = "R", default_value_t = 0.8)]
    ratio: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[cfg(not(feature = "opencv"))]
pub fn run(args: &Args) -> anyhow::Result<()> {
    let _ = (&args.site, args.max_features, args.ratio, args.json);
    anyhow::bail!(
        "this build of photomontage has no OpenCV, and `match` needs it: install libopencv-dev, \
         clang and libclang-dev, then build with `cargo build --release --features opencv` \
         (in the photomontage crate; `--features photomontage/opencv` from the workspace root)"
    )
}

#[cfg(feature = "opencv")]
pub fn run(args: &Args) -> anyhow::Result<()> {
    use anyhow::Context;
    use photomontage::features::MatchOptions;
    use photomontage::site::SiteDocument;
    use photomontage::site::tie_matching::match_site;

    let mut doc = SiteDocument::load(&args.site)?;
    let options = MatchOptions {
        max_features: args.max_features,
        ratio: args.ratio,
        seed: doc.site.solve.seed,
        ..MatchOptions::default()
    };
    let limits = photomontage::photo::DecodeLimits::default();
    let (site, result) = match_site(&doc, &options, &limits)
        .with_context(|| format!("matching the photos of {}", args.site.display()))?;
    doc.site = site;
    doc.save()
        .with_context(|| format!("writing the tie points into {}", args.site.display()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        for p in &result.report.photos {
            println!(
                "{:<16} {:>6} keypoints (detected at 1/{:.2} scale)",
                p.id, p.keypoints, p.detection_scale
            );
        }
        for s in &result.report.pairs {
            println!(
                "{} – {}: {} pass the ratio test, {} mutual, {} verified (fundamental matrix RANSAC)",
                s.photo_a, s.photo_b, s.ratio_passed, s.mutual, s.verified
            );
        }
        println!(
            "{} tracks ({} dropped with two keypoints in one photo); {} checked in solved photos, {} rejected by reprojection",
            result.report.tracks.len(),
            result.report.conflicts_dropped,
            result.checked,
            result.rejected_by_reprojection
        );
        println!(
            "{} tie points written to {}",
            result.written,
            args.site.display()
        );
    }
    Ok(())
}
