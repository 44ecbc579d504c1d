//! Camera profiles: the result of a calibration saved as TOML, reused by sites
//! (`[[photos]] profile = "lens.toml"`, read by `solve` when the photo has no `[photos.interior]`).
//!
//! ```toml
//! make = "Canon"
//! model = "EOS 5D"
//! image_size_px = [640, 480]
//! fx_px = 536.46
//! fy_px = 536.41
//! principal_point_px = [342.37, 235.55]
//! rms_px = 0.41
//! board = "9x6"
//! square_mm = 25.0
//! method = "Zhang 2000, own chessboard corners"
//! source_images = ["left01.jpg", "left02.jpg"]
//!
//! [distortion]  # Brown–Conrady, OpenCV order and signs
//! k1 = -0.279
//! k2 = 0.067
//! p1 = 0.0018
//! p2 = -0.00034
//! ```
//!
//! # Known limitations
//! A profile belongs to one lens at one focus and zoom setting and one image size; it is refused
//! for photos of another size rather than scaled.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::Calibration;
use crate::camera::{BrownConrady, Intrinsics};

/// fx/fy − 1 above which the square-pixel site camera is a poor fit of the profile.
pub const MAX_ASPECT_DEVIATION: f64 = 1e-3;

/// A saved calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraProfile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub make: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    pub image_size_px: [u32; 2],
    pub fx_px: f64,
    pub fy_px: f64,
    pub principal_point_px: [f64; 2],
    #[serde(default)]
    pub distortion: BrownConrady,
    /// Reprojection RMS of the calibration (pixels).
    pub rms_px: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub board: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub square_mm: Option<f64>,
    #[serde(default)]
    pub method: String,
    #[serde(default)]
    pub source_images: Vec<String>,
}

/// Errors reading or using a profile.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    #[error("reading camera profile {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("camera profile {path}: {message}")]
    Parse { path: PathBuf, message: String },
    #[error(
        "camera profile {path} is for {profile:?} px images, but photo {photo} is {photo_size:?} px"
    )]
    SizeMismatch {
        path: PathBuf,
        photo: String,
        profile: [u32; 2],
        photo_size: [u32; 2],
    },
}

impl CameraProfile {
    /// A profile from a calibration.
    #[must_use]
    pub fn from_calibration(c: &Calibration, method: &str, source_images: Vec<String>) -> Self {
        Self {
            make: None,
            model: None,
            image_size_px: c.image_size_px,
            fx_px: c.fx_px,
            fy_px: c.fy_px,
            principal_point_px: c.principal_point_px,
            distortion: BrownConrady {
                k1: c.k1,
                k2: c.k2,
                k3: 0.0,
                p1: c.p1,
                p2: c.p2,
            },
            rms_px: c.rms_px,
            board: None,
            square_mm: None,
            method: method.to_owned(),
            source_images,
        }
    }

    /// Reads a profile file; errors name the file and, for TOML errors, the line.
    ///
    /// # Errors
    /// [`ProfileError::Read`] or [`ProfileError::Parse`].
    pub fn load(path: &Path) -> Result<Self, ProfileError> {
        let text = std::fs::read_to_string(path).map_err(|source| ProfileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let p: Self = toml::from_str(&text).map_err(|e| ProfileError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let finite = [
            p.fx_px,
            p.fy_px,
            p.principal_point_px[0],
            p.principal_point_px[1],
        ];
        if finite.iter().any(|v| !v.is_finite()) || p.fx_px <= 0.0 || p.fy_px <= 0.0 {
            return Err(ProfileError::Parse {
                path: path.to_path_buf(),
                message: "fx_px, fy_px must be positive and the principal point finite".to_owned(),
            });
        }
        Ok(p)
    }

    /// The TOML text.
    ///
    /// # Errors
    /// When serialisation fails (it does not for finite numbers).
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string_pretty(self)
    }

    /// The square-pixel site camera: focal √(fx·fy).
    #[must_use]
    pub fn intrinsics(&self) -> Intrinsics {
        Intrinsics {
            focal_px: (self.fx_px * self.fy_px).sqrt(),
            principal_point_px: self.principal_point_px,
            distortion: self.distortion,
            image_size_px: self.image_size_px,
        }
    }

    /// fx/fy − 1.
    #[must_use]
    pub fn aspect_deviation(&self) -> f64 {
        self.fx_px / self.fy_px - 1.0
    }

    /// The intrinsics for a photo of `photo_size`, refused when the sizes differ.
    ///
    /// # Errors
    /// [`ProfileError::SizeMismatch`].
    pub fn intrinsics_for(
        &self,
        path: &Path,
        photo: &str,
        photo_size: [u32; 2],
    ) -> Result<Intrinsics, ProfileError> {
        if photo_size != self.image_size_px {
            return Err(ProfileError::SizeMismatch {
                path: path.to_path_buf(),
                photo: photo.to_owned(),
                profile: self.image_size_px,
                photo_size,
            });
        }
        Ok(self.intrinsics())
    }
}
