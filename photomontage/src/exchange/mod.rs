//! Camera exchange with other programs: solved cameras out to Blender (a Python script), COLMAP
//! (text model) and OpenCV (`cv::FileStorage` YAML); cameras in from COLMAP text models and
//! OpenSfM `reconstruction.json` as initial values for a site's photos.
//!
//! Each format has its own module with its conventions in its doc comment. What they share:
//! - our camera frame is OpenCV's (x right, y down, z forward), so OpenCV, COLMAP and OpenSfM
//!   rotations are ours transposed (they store camera-from-world); Blender's camera looks down
//!   −Z with +Y up, i.e. our frame turned half a turn about x;
//! - our pixel (0, 0) is the *centre* of the top-left pixel, as in OpenCV and OpenSfM; COLMAP puts
//!   that centre at (0.5, 0.5) and Blender measures the image from its corner, so both shift the
//!   principal point by half a pixel;
//! - our distortion is Brown–Conrady with OpenCV's coefficient order (k1 k2 p1 p2 k3). A format
//!   or a chosen model that cannot carry a non-zero term is refused naming the term and the
//!   photo, never written without it ([`ExchangeError::TermNotCarried`]).
//!
//! Sources: COLMAP documentation, "Output format" and "Camera models" (colmap.github.io,
//! `src/colmap/sensor/models.h`); OpenCV `calib3d` and `persistence` documentation; OpenSfM
//! documentation "Reconstruction file format" and `opensfm/features.py`
//! (`normalized_image_coordinates`); Blender Python API `bpy.types.Camera`,
//! `bpy.types.MovieTrackingCamera` and `BKE_camera_params_compute_viewplane` for the meaning
//! of `shift_x`/`shift_y`.
//!
//! # Known limitations
//! Blender's camera object itself is a pinhole: the script puts the distortion on a movie clip
//! of the photo (tracking camera, Brown model) for the compositor's Movie Distortion node; the
//! script was checked by parsing its numbers back, not by running Blender. Imported poses are
//! only meaningful when the reconstruction is in the site's world frame (COLMAP after
//! `model_aligner`, OpenSfM with its topocentric frame converted): by default only the interior
//! orientation is imported.

pub mod blender;
pub mod colmap;
pub mod import;
pub mod opencv_yaml;
pub mod opensfm;

use std::collections::HashMap;
use std::path::PathBuf;

use nalgebra::{Point2, Point3};

use crate::camera::Camera;
use crate::site::{SiteDocument, stored_camera};

/// Everything that can go wrong reading or writing an exchange file.
#[derive(Debug, thiserror::Error)]
pub enum ExchangeError {
    #[error("{format} cannot carry {term} = {value} of photo {photo}{hint}")]
    TermNotCarried {
        format: String,
        photo: String,
        term: &'static str,
        value: f64,
        hint: String,
    },
    #[error("{file} line {line}: {message}")]
    Parse {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}: camera {camera}: the {model} model is not supported ({reason})")]
    UnsupportedModel {
        file: String,
        camera: String,
        model: String,
        reason: String,
    },
    #[error(
        "{file}: camera {camera} has fx = {fx_px} px and fy = {fy_px} px; the photomontage camera has square pixels"
    )]
    NonSquarePixels {
        file: String,
        camera: String,
        fx_px: f64,
        fy_px: f64,
    },
    #[error(
        "{file}: camera {camera} has {term} = {value}, which the photomontage camera model (Brown–Conrady k1 k2 k3 p1 p2) lacks"
    )]
    TermNotModelled {
        file: String,
        camera: String,
        term: &'static str,
        value: f64,
    },
    #[error("{file}: image {image} refers to camera {camera}, which is not defined")]
    UnknownCamera {
        file: String,
        image: String,
        camera: String,
    },
    #[error(
        "photo {photo}: the imported image is {imported:?} px but the site states {stated:?} px"
    )]
    SizeMismatch {
        photo: String,
        imported: [u32; 2],
        stated: [u32; 2],
    },
    #[error("the site has no solved photo to export (run `photomontage solve` first)")]
    NothingSolved,
    #[error("reading {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("writing {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// One solved photo to export.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportCamera {
    /// The photo's id in the site.
    pub id: String,
    /// The photo file as the site names it (relative to the site file).
    pub image_name: String,
    /// The photo file resolved against the site's folder.
    pub image_path: PathBuf,
    pub camera: Camera,
}

/// One point with its observations in the exported photos.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportPoint {
    pub id: String,
    pub point_in_world: Point3<f64>,
    /// (index into the exported cameras, pixel in our convention).
    pub observations: Vec<(usize, Point2<f64>)>,
}

/// The solved cameras of a site and the control and tie points they observe.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSet {
    pub site_name: String,
    pub cameras: Vec<ExportCamera>,
    pub points: Vec<ExportPoint>,
}

impl ExportSet {
    /// Collects the solved photos (interior and exterior stored) of a site, with the enabled
    /// control points and the tie points that any of them observes (enabled observations).
    ///
    /// # Errors
    /// [`ExchangeError::NothingSolved`] when no photo is solved.
    pub fn from_site(doc: &SiteDocument) -> Result<Self, ExchangeError> {
        let site = &doc.site;
        let cameras: Vec<ExportCamera> = site
            .photos
            .iter()
            .filter_map(|p| {
                stored_camera(site, &p.id).map(|camera| ExportCamera {
                    id: p.id.clone(),
                    image_name: p.file.clone(),
                    image_path: doc.resolve(&p.file),
                    camera,
                })
            })
            .collect();
        if cameras.is_empty() {
            return Err(ExchangeError::NothingSolved);
        }
        let camera_index: HashMap<&str, usize> = cameras
            .iter()
            .enumerate()
            .map(|(k, c)| (c.id.as_str(), k))
            .collect();
        let mut world: Vec<(String, Point3<f64>)> = site
            .control_points
            .iter()
            .filter(|c| c.enabled)
            .map(|c| (c.id.clone(), Point3::from(c.xyz)))
            .collect();
        world.extend(
            site.tie_points
                .iter()
                .map(|t| (t.id.clone(), Point3::from(t.xyz))),
        );
        let mut points = Vec::new();
        for (id, point_in_world) in world {
            let observations: Vec<(usize, Point2<f64>)> = site
                .observations
                .iter()
                .filter(|o| o.enabled && o.point == id)
                .filter_map(|o| {
                    camera_index
                        .get(o.photo.as_str())
                        .map(|&k| (k, Point2::new(o.x_px, o.y_px)))
                })
                .collect();
            if !observations.is_empty() {
                points.push(ExportPoint {
                    id,
                    point_in_world,
                    observations,
                });
            }
        }
        Ok(Self {
            site_name: site.name.clone(),
            cameras,
            points,
        })
    }
}

/// A number as Rust's shortest round-trip text (always with a `.` or an exponent, so Python,
/// YAML and COLMAP read it as a float).
pub(crate) fn num(x: f64) -> String {
    format!("{x:?}")
}

/// Writes `text` to `dir/name` atomically.
pub(crate) fn write_file(
    dir: &std::path::Path,
    name: &str,
    text: &str,
) -> Result<PathBuf, ExchangeError> {
    let path = dir.join(name);
    crate::atomic_file::write_atomically(&path, text.as_bytes()).map_err(|source| {
        ExchangeError::Write {
            path: path.clone(),
            source,
        }
    })?;
    Ok(path)
}
