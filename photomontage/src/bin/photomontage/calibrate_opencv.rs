//! `photomontage calibrate-opencv PHOTOS…`: lens calibration from chessboard photos with OpenCV
//! (cargo feature `opencv`); prints fx, fy, cx, cy, k1, k2, p1, p2, k3 and the RMS, and can
//! write the corners as CSV for a calibration without OpenCV.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Chessboard photos (the whole board visible in each).
    #[arg(required = true)]
    photos: Vec<PathBuf>,
    /// Inner corners per row and per column, e.g. 9x6.
    #[arg(long, value_name = "WxH", default_value = "9x6")]
    board: String,
    /// Side of one square in metres.
    #[arg(long, value_name = "M", default_value_t = 0.025)]
    square_m: f64,
    /// Keep fx = fy (OpenCV's CALIB_FIX_ASPECT_RATIO).
    #[arg(long)]
    fix_aspect_ratio: bool,
    /// Write the corners here: image,board_x,board_y,u_px,v_px.
    #[arg(long, value_name = "CSV")]
    corners_csv: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// `9x6` → [9, 6].
fn parse_board(text: &str) -> anyhow::Result<[u32; 2]> {
    let (w, h) = text
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| anyhow::anyhow!("--board {text:?}: expected WxH, e.g. 9x6"))?;
    let parse = |s: &str| -> anyhow::Result<u32> {
        let v: u32 = s
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("--board {text:?}: {s:?} is not a whole number"))?;
        anyhow::ensure!(
            v >= 2,
            "--board {text:?}: at least 2 inner corners per side"
        );
        Ok(v)
    };
    Ok([parse(w)?, parse(h)?])
}

#[cfg(not(feature = "opencv"))]
pub fn run(args: &Args) -> anyhow::Result<()> {
    parse_board(&args.board)?;
    let _ = (
        &args.photos,
        args.square_m,
        args.fix_aspect_ratio,
        &args.corners_csv,
        args.json,
    );
    anyhow::bail!(
        "this build of photomontage has no OpenCV, and `calibrate-opencv` needs it (`calibrate` works without it): install \
         libopencv-dev, clang and libclang-dev, then build with `cargo build --release --features \
         opencv` (in the photomontage crate; `--features photomontage/opencv` from the workspace root)"
    )
}

#[cfg(feature = "opencv")]
pub fn run(args: &Args) -> anyhow::Result<()> {
    use photomontage::features::calibration::{
        CalibrationFlags, Chessboard, calibrate_chessboard, corners_csv,
    };
    let board = Chessboard {
        inner_corners: parse_board(&args.board)?,
        square_m: args.square_m,
    };
    anyhow::ensure!(
        args.square_m.is_finite() && args.square_m > 0.0,
        "--square-m {}: a positive length in metres",
        args.square_m
    );
    let c = calibrate_chessboard(
        &args.photos,
        board,
        CalibrationFlags {
            fix_aspect_ratio: args.fix_aspect_ratio,
        },
    )?;
    if let Some(path) = &args.corners_csv {
        photomontage::atomic_file::write_atomically(path, corners_csv(&c.views).as_bytes())?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        let d = c.distortion;
        println!(
            "{} photos, {} corners each; image {}×{} px",
            c.views.len(),
            c.views.first().map_or(0, |v| v.corners.len()),
            c.image_size_px[0],
            c.image_size_px[1]
        );
        println!(
            "fx {:.4} px  fy {:.4} px  cx {:.4} px  cy {:.4} px",
            c.fx_px, c.fy_px, c.cx_px, c.cy_px
        );
        println!(
            "k1 {:.6}  k2 {:.6}  p1 {:.6}  p2 {:.6}  k3 {:.6}",
            d.k1, d.k2, d.p1, d.p2, d.k3
        );
        println!("RMS reprojection error {:.4} px", c.rms_px);
        if let Some(path) = &args.corners_csv {
            println!("corners written to {}", path.display());
        }
    }
    Ok(())
}
