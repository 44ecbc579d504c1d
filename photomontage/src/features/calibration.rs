//! Lens calibration from chessboard photos with OpenCV (Zhang, *A flexible new technique for
//! camera calibration*, IEEE PAMI 22(11) 2000, as implemented by `calibrateCamera` with Brown's
//! distortion k1, k2, p1, p2, k3): inner corners by `findChessboardCorners`, refined by
//! `cornerSubPix` (11 × 11 window, 30 iterations or 0.001 px, OpenCV's calibration sample
//! settings), then the calibration.
//!
//! The corners are also returned, and written as CSV (`image,board_x,board_y,u_px,v_px`, one row
//! per corner, board coordinates in squares), so a calibration without OpenCV can start from
//! exactly the same measurements.
//!
//! # Known limitations
//! Only the chessboard pattern (no circle grids, no ChArUco); every photo must show the whole
//! board. Photos are decoded by our loader and converted to 8-bit luma.

use std::path::{Path, PathBuf};

use nalgebra::Point2;
use opencv::calib3d;
use opencv::core::{self, Mat, Point2f, Point3f, Size, TermCriteria, Vector};
use opencv::imgproc;
use opencv::prelude::*;
use serde::Serialize;

use super::FeatureError;
use crate::camera::BrownConrady;
use crate::photo;

/// The board: inner corners per row and column, and the square size (metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Chessboard {
    pub inner_corners: [u32; 2],
    pub square_m: f64,
}

/// Corners found in one photo, row by row as OpenCV orders them.
#[derive(Debug, Clone, Serialize)]
pub struct BoardCorners {
    pub image: String,
    /// (board x, board y) in squares, and the pixel (pixel-centre convention).
    pub corners: Vec<([u32; 2], Point2<f64>)>,
}

/// OpenCV's calibration result.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    pub fx_px: f64,
    pub fy_px: f64,
    pub cx_px: f64,
    pub cy_px: f64,
    pub distortion: BrownConrady,
    /// RMS reprojection error over all corners (OpenCV's return value).
    pub rms_px: f64,
    pub image_size_px: [u32; 2],
    pub views: Vec<BoardCorners>,
}

/// Options of [`calibrate_chessboard`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CalibrationFlags {
    /// Keep fx/fy at their initial ratio 1 (`CALIB_FIX_ASPECT_RATIO`).
    pub fix_aspect_ratio: bool,
}

/// Finds the corners in each photo and calibrates.
///
/// # Errors
/// [`FeatureError::ChessboardNotFound`] naming the first photo without the whole board,
/// photos of different sizes ([`FeatureError::Geometry`]), decoding or OpenCV failures.
pub fn calibrate_chessboard(
    photos: &[PathBuf],
    board: Chessboard,
    flags: CalibrationFlags,
) -> Result<Calibration, FeatureError> {
    let [bw, bh] = board.inner_corners;
    let pattern = Size::new(
        i32::try_from(bw).unwrap_or(0),
        i32::try_from(bh).unwrap_or(0),
    );
    let mut object_points = Vector::<Vector<Point3f>>::new();
    let mut image_points = Vector::<Vector<Point2f>>::new();
    let mut views = Vec::new();
    let mut size: Option<[u32; 2]> = None;
    #[allow(clippy::cast_possible_truncation)]
    let square = board.square_m as f32;
    let object: Vector<Point3f> = (0..bh)
        .flat_map(|y| (0..bw).map(move |x| (x, y)))
        .map(|(x, y)| Point3f::new(x as f32 * square, y as f32 * square, 0.0))
        .collect();
    for path in photos {
        let name = file_name(path);
        let gray = gray_mat(path)?;
        let this = [
            u32::try_from(gray.cols()).unwrap_or(0),
            u32::try_from(gray.rows()).unwrap_or(0),
        ];
        match size {
            None => size = Some(this),
            Some(s) if s != this => {
                return Err(FeatureError::Geometry(format!(
                    "{name} is {}×{} px but the first photo is {}×{} px",
                    this[0], this[1], s[0], s[1]
                )));
            }
            Some(_) => {}
        }
        let mut corners = Vector::<Point2f>::new();
        let found = calib3d::find_chessboard_corners(
            &gray,
            pattern,
            &mut corners,
            calib3d::CALIB_CB_ADAPTIVE_THRESH | calib3d::CALIB_CB_NORMALIZE_IMAGE,
        )?;
        if !found {
            return Err(FeatureError::ChessboardNotFound {
                image: name,
                width: bw,
                height: bh,
            });
        }
        imgproc::corner_sub_pix(
            &gray,
            &mut corners,
            Size::new(11, 11),
            Size::new(-1, -1),
            TermCriteria::new(core::TermCriteria_COUNT + core::TermCriteria_EPS, 30, 0.001)?,
        )?;
        let list = corners
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let i = u32::try_from(i).unwrap_or(0);
                (
                    [i % bw, i / bw],
                    Point2::new(f64::from(p.x), f64::from(p.y)),
                )
            })
            .collect();
        views.push(BoardCorners {
            image: name,
            corners: list,
        });
        object_points.push(object.clone());
        image_points.push(corners);
    }
    let Some([w, h]) = size else {
        return Err(FeatureError::Geometry("no calibration photos given".into()));
    };
    let mut k = Mat::eye(3, 3, core::CV_64F)?.to_mat()?;
    let mut dist = Mat::default();
    let mut rvecs = Vector::<Mat>::new();
    let mut tvecs = Vector::<Mat>::new();
    let cv_flags = if flags.fix_aspect_ratio {
        calib3d::CALIB_FIX_ASPECT_RATIO
    } else {
        0
    };
    let rms = calib3d::calibrate_camera(
        &object_points,
        &image_points,
        Size::new(i32::try_from(w).unwrap_or(0), i32::try_from(h).unwrap_or(0)),
        &mut k,
        &mut dist,
        &mut rvecs,
        &mut tvecs,
        cv_flags,
        TermCriteria::new(
            core::TermCriteria_COUNT + core::TermCriteria_EPS,
            30,
            f64::EPSILON,
        )?,
    )?;
    let at = |r: i32, c: i32| -> Result<f64, FeatureError> { Ok(*k.at_2d::<f64>(r, c)?) };
    let d = |i: i32| -> Result<f64, FeatureError> { Ok(*dist.at::<f64>(i)?) };
    Ok(Calibration {
        fx_px: at(0, 0)?,
        fy_px: at(1, 1)?,
        cx_px: at(0, 2)?,
        cy_px: at(1, 2)?,
        distortion: BrownConrady {
            k1: d(0)?,
            k2: d(1)?,
            p1: d(2)?,
            p2: d(3)?,
            k3: d(4)?,
        },
        rms_px: rms,
        image_size_px: [w, h],
        views,
    })
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The photo as an 8-bit luma Mat (BT.601 weights on the sRGB-encoded values).
fn gray_mat(path: &Path) -> Result<Mat, FeatureError> {
    let image = photo::load(path)?;
    let [w, h] = image.size_px();
    let mut bytes = Vec::with_capacity(w as usize * h as usize);
    for p in image.pixels.pixels() {
        let luma = 0.299 * p.0[0] + 0.587 * p.0[1] + 0.114 * p.0[2];
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        bytes.push((luma * 255.0).round().clamp(0.0, 255.0) as u8);
    }
    let rows = i32::try_from(h).map_err(|_| FeatureError::Geometry("image too tall".into()))?;
    Ok(Mat::from_slice(&bytes)?.reshape(1, rows)?.try_clone()?)
}

/// The corners as CSV: `image,board_x,board_y,u_px,v_px`, one row per corner.
#[must_use]
pub fn corners_csv(views: &[BoardCorners]) -> String {
    let mut out = String::from("image,board_x,board_y,u_px,v_px\n");
    for v in views {
        for ([x, y], p) in &v.corners {
            out.push_str(&format!("{},{x},{y},{:.4},{:.4}\n", v.image, p.x, p.y));
        }
    }
    out
}
