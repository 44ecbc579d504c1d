//! Tie points by feature matching, chessboard calibration and an independent pose check, with
//! OpenCV (cargo feature `opencv`, off by default; needs libopencv-dev ≥ 4.4, clang and
//! libclang-dev). Below `site`: it knows photos and cameras, not site files.
//!
//! # Method
//! 1. **Keypoints**: SIFT (Lowe, *Distinctive image features from scale-invariant keypoints*,
//!    IJCV 60(2) 2004) on the photo decoded by our own loader ([`crate::photo`], EXIF orientation
//!    applied), converted to 8-bit luma (ITU-R BT.601 weights, as OpenCV's `cvtColor`) and
//!    downscaled so its longer side is at most [`MatchOptions::max_image_side_px`] (SIFT's
//!    scale space makes keypoints repeatable across the change; positions are mapped back to
//!    full-resolution pixels).
//! 2. **Matching**: exact nearest neighbours (brute force, L2), **ratio test** (Lowe 2004 §7.1:
//!    reject when the nearest distance exceeds 0.8 × the second nearest, which "eliminates 90 %
//!    of the false matches while discarding less than 5 % of the correct ones"), and a **mutual**
//!    check (a's best in b must have a as its best in a).
//! 3. **Geometric verification** per pair: the fundamental matrix by RANSAC (Fischler & Bolles
//!    1981; Hartley & Zisserman, *Multiple View Geometry*, 2nd ed. 2004, §11.6), inliers within
//!    [`MatchOptions::epipolar_threshold_px`] of their epipolar line.
//! 4. **Tracks** across photos by union-find, dropping tracks with two keypoints in one photo
//!    (module [`tracks`], pure Rust).
//!
//! Triangulation of the tracks (our [`crate::photogrammetry::intersect`]) and their use in the
//! bundle adjustment happen in `site` (`site::tie_matching`, `site::solve`).
//!
//! Also here: the relative orientation of two photos by Nistér's five-point algorithm (OpenCV
//! `findEssentialMat` + `recoverPose`, [`relative_orientation`]), which starts a block whose
//! photos see too few control points; OpenCV's `solvePnP` as an independent check of a solved
//! camera ([`pnp`]); and chessboard corners with OpenCV's calibration ([`calibration`]).
//!
//! # Known limitations
//! Brute-force matching costs O(n_a·n_b) per pair and all pairs are tried (fine for tens of
//! photos with a few thousand keypoints each, not for hundreds). OpenCV's RANSAC draws from its
//! own generator; it is seeded ([`MatchOptions::seed`]) so a run is repeatable on one OpenCV
//! version, but another version may choose other inliers.

pub mod tracks;

#[cfg(feature = "opencv")]
pub mod calibration;
#[cfg(feature = "opencv")]
mod matching;
#[cfg(feature = "opencv")]
pub mod pnp;
#[cfg(feature = "opencv")]
mod relative;

#[cfg(feature = "opencv")]
pub use matching::{MatchInput, MatchReport, PairStats, PhotoFeatures, Track, match_photos};
#[cfg(feature = "opencv")]
pub use relative::relative_orientation;

use serde::Serialize;

/// Lowe's ratio (2004 §7.1): the nearest neighbour must be closer than this fraction of the
/// second nearest.
pub const LOWE_RATIO: f64 = 0.8;

/// Tunables of the matching.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MatchOptions {
    /// Most keypoints kept per photo (the strongest by SIFT response).
    pub max_features: usize,
    /// Lowe's ratio test bound, in (0, 1].
    pub ratio: f64,
    /// Photos are downscaled for detection so their longer side is at most this (pixels).
    pub max_image_side_px: u32,
    /// RANSAC inlier bound: distance to the epipolar line in full-resolution pixels.
    pub epipolar_threshold_px: f64,
    /// A pair with fewer verified matches is treated as not overlapping.
    pub min_pair_matches: usize,
    /// Seed of OpenCV's random generator (RANSAC).
    pub seed: u64,
}

impl Default for MatchOptions {
    fn default() -> Self {
        Self {
            max_features: 4000,
            ratio: LOWE_RATIO,
            max_image_side_px: 3000,
            epipolar_threshold_px: 2.0,
            min_pair_matches: 20,
            seed: 0,
        }
    }
}

/// What can go wrong finding features.
#[derive(Debug, thiserror::Error)]
pub enum FeatureError {
    #[error(transparent)]
    Photo(#[from] crate::photo::PhotoError),
    #[error("{field} = {value} is invalid: {reason}")]
    InvalidOption {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("at least two photos are needed to match features, {found} given")]
    TooFewPhotos { found: usize },
    #[error(
        "photo {photo} shares no verified features with any other photo (best: {best_matches} matches with {best_other}, {required} needed)"
    )]
    NoOverlap {
        photo: String,
        best_other: String,
        best_matches: usize,
        required: usize,
    },
    #[error("no SIFT keypoints found in photo {photo} (a blank or very small image?)")]
    NoKeypoints { photo: String },
    #[error(transparent)]
    Tracks(#[from] tracks::TrackError),
    #[error("chessboard {width}×{height} inner corners not found in {image}")]
    ChessboardNotFound {
        image: String,
        width: u32,
        height: u32,
    },
    #[error("{0}")]
    Geometry(String),
    #[cfg(feature = "opencv")]
    #[error("OpenCV: {0}")]
    OpenCv(#[from] opencv::Error),
}

impl MatchOptions {
    /// Checks the ranges of the options.
    ///
    /// # Errors
    /// [`FeatureError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), FeatureError> {
        if !(self.ratio > 0.0 && self.ratio <= 1.0) {
            return Err(FeatureError::InvalidOption {
                field: "ratio",
                value: self.ratio,
                reason: "Lowe's ratio must lie in (0, 1]",
            });
        }
        if self.max_features == 0 {
            return Err(FeatureError::InvalidOption {
                field: "max_features",
                value: 0.0,
                reason: "at least one keypoint per photo",
            });
        }
        if self.max_image_side_px < 64 {
            return Err(FeatureError::InvalidOption {
                field: "max_image_side_px",
                value: f64::from(self.max_image_side_px),
                reason: "SIFT needs at least 64 px",
            });
        }
        if !(self.epipolar_threshold_px.is_finite() && self.epipolar_threshold_px > 0.0) {
            return Err(FeatureError::InvalidOption {
                field: "epipolar_threshold_px",
                value: self.epipolar_threshold_px,
                reason: "a positive distance in pixels",
            });
        }
        Ok(())
    }
}
