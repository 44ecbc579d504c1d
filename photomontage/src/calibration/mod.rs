//! Lens calibration from photos of a chessboard, without OpenCV: our own corner detector
//! ([`chessboard`]), Zhang's closed-form start ([`zhang`]) and the nonlinear refinement of the
//! intrinsics, distortion and every view's pose ([`refine`]); the result is a camera profile
//! ([`profile`]) that sites reuse.
//!
//! Method: Z. Zhang, "A flexible new technique for camera calibration", IEEE Transactions on
//! Pattern Analysis and Machine Intelligence 22(11):1330–1334, 2000 — homographies by the
//! normalised DLT (Hartley & Zisserman 2004 §4.4), intrinsics in closed form from B = K⁻ᵀK⁻¹
//! (zero skew imposed), extrinsics per view, then maximum-likelihood refinement of fx, fy, cx,
//! cy, k1, k2 (p1, p2 optional) and all poses. The distortion model is OpenCV's (k3 fixed at 0),
//! so the numbers compare with `cv2.calibrateCamera(…, flags=CALIB_FIX_K3)`.
//!
//! # Known limitations
//! Board corners are the inner corners of a plain chessboard (no ChArUco/markers); the board
//! must be seen whole in every photo. fx and fy are fitted separately; a site camera has square
//! pixels, so a profile gives sites √(fx·fy) (the profile keeps both and warns when they differ
//! by more than [`profile::MAX_ASPECT_DEVIATION`]).

pub mod chessboard;
pub mod profile;
pub mod refine;
pub mod zhang;

use nalgebra::{Matrix3, Point2, Rotation3, Vector3};
use serde::Serialize;

/// Everything that can go wrong in a calibration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    #[error("{found} board view(s): at least 3 are needed for fx, fy, cx, cy")]
    TooFewViews { found: usize },
    #[error("degenerate calibration: {reason}")]
    Degenerate { reason: String },
    #[error("photo {photo}: {count} corners given, the {columns}×{rows} board has {expected}")]
    CornerCount {
        photo: String,
        count: usize,
        columns: usize,
        rows: usize,
        expected: usize,
    },
    #[error("photo {photo}: no plane-to-image homography (corners collinear or repeated)")]
    NoHomography { photo: String },
    #[error("the refinement did not start (non-finite reprojection at the closed-form start)")]
    NoConvergence,
    #[error("board `{text}`: expected COLUMNSxROWS of inner corners, e.g. 9x6, each at least 2")]
    BoardSpec { text: String },
}

/// A chessboard: inner corners per row (`columns`) and per column (`rows`), square size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Board {
    pub columns: usize,
    pub rows: usize,
    pub square_m: f64,
}

impl Board {
    /// Parses `9x6` (inner corners) with the square size in millimetres.
    ///
    /// # Errors
    /// [`CalibrationError::BoardSpec`].
    pub fn parse(text: &str, square_mm: f64) -> Result<Self, CalibrationError> {
        let err = || CalibrationError::BoardSpec {
            text: text.to_owned(),
        };
        let (c, r) = text.trim().split_once(['x', 'X', '×']).ok_or_else(err)?;
        let columns: usize = c.trim().parse().map_err(|_| err())?;
        let rows: usize = r.trim().parse().map_err(|_| err())?;
        if columns < 2
            || rows < 2
            || columns * rows > 10_000
            || !(square_mm.is_finite() && square_mm > 0.0)
        {
            return Err(err());
        }
        Ok(Self {
            columns,
            rows,
            square_m: square_mm / 1000.0,
        })
    }

    /// The corners on the board plane (metres), row by row: index = row · columns + column.
    #[must_use]
    pub fn plane_points(&self) -> Vec<Point2<f64>> {
        (0..self.rows)
            .flat_map(|j| {
                (0..self.columns)
                    .map(move |i| Point2::new(self.square_m * i as f64, self.square_m * j as f64))
            })
            .collect()
    }
}

/// The corners of one photo in board order.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardView {
    pub photo: String,
    pub corners_px: Vec<Point2<f64>>,
}

/// Tunables of [`calibrate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CalibrationOptions {
    /// Fit the tangential terms p1, p2 (else they stay 0).
    pub tangential: bool,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        Self { tangential: true }
    }
}

/// The calibrated camera.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    pub image_size_px: [u32; 2],
    pub fx_px: f64,
    pub fy_px: f64,
    pub principal_point_px: [f64; 2],
    pub k1: f64,
    pub k2: f64,
    pub p1: f64,
    pub p2: f64,
    /// σ of fx, fy, cx, cy, k1, k2, p1, p2 (σ₀-scaled; 0 when fixed).
    pub sigma: [f64; 8],
    /// sqrt(Σ|residual|² / corners) (OpenCV's definition).
    pub rms_px: f64,
    /// (photo, RMS) per view.
    pub view_rms_px: Vec<(String, f64)>,
    /// The closed-form start (Zhang §3.1): fx, fy, cx, cy.
    pub closed_form: [f64; 4],
    pub converged: bool,
    /// Board-to-camera poses (rotation vector, translation in metres) per view.
    #[serde(skip)]
    pub poses: Vec<(Rotation3<f64>, Vector3<f64>)>,
}

/// Calibrates from the corners of ≥ 3 views of `board` in photos of `image_size_px`.
///
/// # Errors
/// [`CalibrationError`] naming the photo whose corners are unusable, or the degeneracy.
pub fn calibrate(
    board: &Board,
    views: &[BoardView],
    image_size_px: [u32; 2],
    options: &CalibrationOptions,
) -> Result<Calibration, CalibrationError> {
    if views.len() < 3 {
        return Err(CalibrationError::TooFewViews { found: views.len() });
    }
    let plane = board.plane_points();
    let [w, h] = image_size_px.map(f64::from);
    let s = w.max(h);
    // Image coordinates scaled to ~[−0.5, 0.5] for conditioning (see `zhang`).
    let n = Matrix3::new(
        1.0 / s,
        0.0,
        -w / 2.0 / s,
        0.0,
        1.0 / s,
        -h / 2.0 / s,
        0.0,
        0.0,
        1.0,
    );
    let mut homographies = Vec::with_capacity(views.len());
    for v in views {
        if v.corners_px.len() != plane.len() {
            return Err(CalibrationError::CornerCount {
                photo: v.photo.clone(),
                count: v.corners_px.len(),
                columns: board.columns,
                rows: board.rows,
                expected: plane.len(),
            });
        }
        let scaled: Vec<Point2<f64>> = v
            .corners_px
            .iter()
            .map(|p| Point2::new((p.x - w / 2.0) / s, (p.y - h / 2.0) / s))
            .collect();
        let hm =
            zhang::homography(&plane, &scaled).ok_or_else(|| CalibrationError::NoHomography {
                photo: v.photo.clone(),
            })?;
        homographies.push(hm);
    }
    let k_scaled = zhang::intrinsics_from_homographies(&homographies)?;
    let n_inv = n.try_inverse().ok_or(CalibrationError::NoConvergence)?;
    let k = n_inv * k_scaled;
    let poses: Vec<(Rotation3<f64>, Vector3<f64>)> = homographies
        .iter()
        .zip(views)
        .map(|(hm, v)| {
            zhang::pose_from_homography(&k_scaled, hm).ok_or_else(|| {
                CalibrationError::NoHomography {
                    photo: v.photo.clone(),
                }
            })
        })
        .collect::<Result<_, _>>()?;
    let start = [
        k[(0, 0)],
        k[(1, 1)],
        k[(0, 2)],
        k[(1, 2)],
        0.0,
        0.0,
        0.0,
        0.0,
    ];
    let corners: Vec<Vec<Point2<f64>>> = views.iter().map(|v| v.corners_px.clone()).collect();
    let r = refine::refine(&plane, &corners, start, &poses, options.tangential)
        .ok_or(CalibrationError::NoConvergence)?;
    let [fx, fy, cx, cy, k1, k2, p1, p2] = r.intrinsics;
    Ok(Calibration {
        image_size_px,
        fx_px: fx,
        fy_px: fy,
        principal_point_px: [cx, cy],
        k1,
        k2,
        p1,
        p2,
        sigma: r.sigma,
        rms_px: r.rms_px,
        view_rms_px: views
            .iter()
            .map(|v| v.photo.clone())
            .zip(r.view_rms_px.iter().copied())
            .collect(),
        closed_form: start[..4].try_into().unwrap_or([0.0; 4]),
        converged: r.converged,
        poses: r.poses,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::BrownConrady;

    /// Noise-free synthetic corners: the refinement recovers the generating camera to the LM
    /// stopping tolerance.
    const EXACT_RELATIVE: f64 = 1e-7;
    const EXACT_DISTORTION: f64 = 1e-7;

    #[test]
    fn calibration_recovers_a_synthetic_camera_with_distortion() {
        let board = Board::parse("9x6", 30.0).unwrap();
        let (fx, fy, cx, cy) = (810.0, 806.0, 331.0, 247.0);
        let d = BrownConrady {
            k1: -0.21,
            k2: 0.06,
            k3: 0.0,
            p1: 0.0012,
            p2: -0.0007,
        };
        let poses = [
            (
                Vector3::new(0.3, -0.2, 0.1),
                Vector3::new(-0.12, -0.08, 0.6),
            ),
            (
                Vector3::new(-0.25, 0.35, -0.05),
                Vector3::new(-0.1, -0.1, 0.7),
            ),
            (
                Vector3::new(0.1, 0.2, 0.4),
                Vector3::new(-0.15, -0.05, 0.55),
            ),
            (
                Vector3::new(-0.4, -0.1, 0.2),
                Vector3::new(-0.1, -0.06, 0.65),
            ),
            (
                Vector3::new(0.05, 0.45, -0.3),
                Vector3::new(-0.13, -0.09, 0.6),
            ),
        ];
        let views: Vec<BoardView> = poses
            .iter()
            .enumerate()
            .map(|(k, (w, t))| BoardView {
                photo: format!("v{k}"),
                corners_px: board
                    .plane_points()
                    .iter()
                    .map(|p| refine::project(&[fx, fy, cx, cy, d.k1, d.k2, d.p1, d.p2], w, t, p))
                    .collect(),
            })
            .collect();
        let c = calibrate(&board, &views, [640, 480], &CalibrationOptions::default()).unwrap();
        assert!(c.converged);
        assert!((c.fx_px / fx - 1.0).abs() < EXACT_RELATIVE, "{c:?}");
        assert!((c.fy_px / fy - 1.0).abs() < EXACT_RELATIVE, "{c:?}");
        assert!((c.principal_point_px[0] - cx).abs() < EXACT_RELATIVE * fx);
        assert!((c.principal_point_px[1] - cy).abs() < EXACT_RELATIVE * fy);
        for (got, want) in [(c.k1, d.k1), (c.k2, d.k2), (c.p1, d.p1), (c.p2, d.p2)] {
            assert!((got - want).abs() < EXACT_DISTORTION, "{got} vs {want}");
        }
        assert!(c.rms_px < 1e-6);
    }

    #[test]
    fn too_few_views_and_wrong_corner_counts_are_named() {
        let board = Board::parse("9x6", 30.0).unwrap();
        let one = BoardView {
            photo: "a.jpg".into(),
            corners_px: vec![Point2::new(0.0, 0.0); 10],
        };
        assert_eq!(
            calibrate(
                &board,
                std::slice::from_ref(&one),
                [640, 480],
                &CalibrationOptions::default()
            )
            .unwrap_err(),
            CalibrationError::TooFewViews { found: 1 }
        );
        let err = calibrate(
            &board,
            &[one.clone(), one.clone(), one],
            [640, 480],
            &CalibrationOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("a.jpg") && err.contains("10 corners"), "{err}");
        assert!(Board::parse("9by6", 25.0).is_err());
        assert!(Board::parse("1x6", 25.0).is_err());
        assert!(Board::parse("9x6", 0.0).is_err());
    }
}
