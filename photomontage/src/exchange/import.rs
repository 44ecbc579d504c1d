//! Imported cameras as initial values for a site's photos.
//!
//! An imported image is matched to a photo by the photo's `file` as the site writes it, then by
//! its file name, then by the photo id. The matched photo's interior (focal length, principal
//! point, distortion, image size) is replaced, so `solve` starts from it; with `with_poses` the
//! exterior is written too (`solved_by = "import:<format>"`), which is only right when the
//! reconstruction is in the site's world frame. Without it a previously solved exterior is
//! removed (it belonged to the old interior) and the photo must be solved again.
//!
//! # Known limitations
//! Names are matched exactly (after the folder is dropped); no fuzzy matching.

use std::path::Path;

use nalgebra::Rotation3;
use serde::Serialize;

use super::ExchangeError;
use super::colmap::ImportedCamera;
use crate::site::{Exterior, Interior, Site};

/// What an import changed.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ImportReport {
    /// (photo id, imported image name) of each updated photo.
    pub matched: Vec<(String, String)>,
    /// Imported images that match no photo.
    pub unmatched_images: Vec<String>,
    /// Photos no imported image matches (left unchanged).
    pub photos_without_camera: Vec<String>,
    /// Photos whose solved exterior was removed because their interior changed.
    pub exteriors_cleared: Vec<String>,
    pub with_poses: bool,
}

fn file_name(s: &str) -> &str {
    Path::new(s)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(s)
}

/// Writes the imported cameras into `site`. Nothing changes when an error is returned.
///
/// # Errors
/// [`ExchangeError::SizeMismatch`] when a photo states another image size than the import.
pub fn apply_imported(
    site: &mut Site,
    cameras: &[ImportedCamera],
    format: &str,
    with_poses: bool,
) -> Result<ImportReport, ExchangeError> {
    let mut report = ImportReport {
        with_poses,
        ..ImportReport::default()
    };
    let mut updates: Vec<(usize, &ImportedCamera)> = Vec::new();
    for c in cameras {
        let found = site
            .photos
            .iter()
            .position(|p| p.file == c.image_name)
            .or_else(|| {
                site.photos
                    .iter()
                    .position(|p| file_name(&p.file) == file_name(&c.image_name))
            })
            .or_else(|| site.photos.iter().position(|p| p.id == c.image_name));
        match found {
            Some(k) => {
                let p = &site.photos[k];
                if let Some(stated) = p.interior.as_ref().and_then(|i| i.image_size_px)
                    && stated != c.camera.intrinsics.image_size_px
                {
                    return Err(ExchangeError::SizeMismatch {
                        photo: p.id.clone(),
                        imported: c.camera.intrinsics.image_size_px,
                        stated,
                    });
                }
                updates.push((k, c));
            }
            None => report.unmatched_images.push(c.image_name.clone()),
        }
    }
    for (k, c) in updates {
        let p = &mut site.photos[k];
        let intr = c.camera.intrinsics;
        p.interior = Some(Interior {
            focal_px: intr.focal_px,
            principal_point_px: Some(intr.principal_point_px),
            distortion: intr.distortion,
            image_size_px: Some(intr.image_size_px),
        });
        if with_poses {
            let r: Rotation3<f64> = c.camera.pose.rotation_world_from_camera;
            let m = r.matrix();
            p.exterior = Some(Exterior {
                camera_center: c.camera.pose.camera_center_in_world.coords.into(),
                rotation_world_from_camera: [0, 1, 2].map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]),
                rms_px: 0.0,
                sigma_center_m: [0.0; 3],
                solved_by: format!("import:{format}"),
            });
        } else if p.exterior.take().is_some() {
            report.exteriors_cleared.push(p.id.clone());
        }
        report.matched.push((p.id.clone(), c.image_name.clone()));
    }
    report.photos_without_camera = site
        .photos
        .iter()
        .filter(|p| !report.matched.iter().any(|(id, _)| id == &p.id))
        .map(|p| p.id.clone())
        .collect();
    Ok(report)
}
