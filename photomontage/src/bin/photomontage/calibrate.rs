//! `photomontage calibrate IMAGES… --board 9x6 --square-mm S --out profile.toml`: lens
//! calibration from chessboard photos (own corner detector and Zhang 2000), saved as a camera
//! profile that sites reuse.

use anyhow::{Context, bail};
use photomontage::calibration::chessboard::{GrayImage, find_chessboard};
use photomontage::calibration::profile::{CameraProfile, MAX_ASPECT_DEVIATION};
use photomontage::calibration::{Board, BoardView, CalibrationOptions, calibrate};
use photomontage::site::write_atomically;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Photos of the chessboard (at least 3, all the same size, the whole board in each).
    #[arg(required = true)]
    images: Vec<PathBuf>,
    /// Inner corners per row and per column, e.g. 9x6.
    #[arg(long)]
    board: String,
    /// Side of one square in millimetres.
    #[arg(long)]
    square_mm: f64,
    /// Profile file to write (TOML).
    #[arg(long)]
    out: PathBuf,
    /// Keep the tangential distortion p1, p2 at zero.
    #[arg(long)]
    no_tangential: bool,
    /// Camera make and model to record in the profile.
    #[arg(long)]
    make: Option<String>,
    #[arg(long)]
    model: Option<String>,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let board = Board::parse(&args.board, args.square_mm)?;
    let mut views = Vec::new();
    let mut size: Option<[u32; 2]> = None;
    for path in &args.images {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let image = GrayImage::load(path).with_context(|| format!("reading {}", path.display()))?;
        #[allow(clippy::cast_possible_truncation)] // decoded sizes are u32
        let this = [image.width as u32, image.height as u32];
        if let Some(s) = size
            && s != this
        {
            bail!(
                "photo {name} is {}×{} px but the first photo is {}×{} px: calibrate one image size at a time",
                this[0],
                this[1],
                s[0],
                s[1]
            );
        }
        size = Some(this);
        let corners = find_chessboard(&image, &name, board.columns, board.rows)?;
        views.push(BoardView {
            photo: name,
            corners_px: corners,
        });
    }
    let Some(size) = size else {
        bail!("no photos given")
    };
    let options = CalibrationOptions {
        tangential: !args.no_tangential,
    };
    let c = calibrate(&board, &views, size, &options)?;
    let mut profile = CameraProfile::from_calibration(
        &c,
        "Zhang 2000 (own chessboard corners, photomontage)",
        views.iter().map(|v| v.photo.clone()).collect(),
    );
    profile.make.clone_from(&args.make);
    profile.model.clone_from(&args.model);
    profile.board = Some(args.board.clone());
    profile.square_mm = Some(args.square_mm);
    let text = profile.to_toml()?;
    write_atomically(&args.out, text.as_bytes())
        .with_context(|| format!("writing {}", args.out.display()))?;
    let mut warnings = Vec::new();
    if profile.aspect_deviation().abs() > MAX_ASPECT_DEVIATION {
        warnings.push(format!(
            "fx/fy − 1 = {:.2e}: sites use square pixels with f = √(fx·fy)",
            profile.aspect_deviation()
        ));
    }
    if args.json {
        let out = serde_json::json!({
            "profile": args.out.display().to_string(),
            "calibration": c,
            "warnings": warnings,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{} photos, {} corners each",
            views.len(),
            board.columns * board.rows
        );
        println!(
            "fx {:.3} ± {:.3} px   fy {:.3} ± {:.3} px",
            c.fx_px, c.sigma[0], c.fy_px, c.sigma[1]
        );
        println!(
            "cx {:.3} ± {:.3} px   cy {:.3} ± {:.3} px",
            c.principal_point_px[0], c.sigma[2], c.principal_point_px[1], c.sigma[3]
        );
        println!(
            "k1 {:.5}  k2 {:.5}  p1 {:.6}  p2 {:.6}",
            c.k1, c.k2, c.p1, c.p2
        );
        println!("RMS {:.4} px", c.rms_px);
        for (photo, rms) in &c.view_rms_px {
            println!("  {photo}: {rms:.4} px");
        }
        for w in &warnings {
            println!("warning: {w}");
        }
        println!("profile written to {}", args.out.display());
    }
    Ok(())
}
