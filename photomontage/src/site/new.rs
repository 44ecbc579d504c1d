//! A new site from a set of photographs (the studio's File → New site…): one `[[photos]]` entry
//! per file with an id from its file name, the image size read from the file, the interior
//! orientation started from EXIF (CIPA DC-008 "Exif 2.3" via [`crate::photo::exif`]: focal
//! length in mm with the focal-plane resolution or a known sensor size, else the 35 mm equivalent
//! focal length → focal length in pixels), the capture time ([`crate::photo::capture_time`]:
//! EXIF `DateTimeOriginal` + `OffsetTimeOriginal`, else GPS time, else Mapillary
//! `MAPCaptureTime`), and file paths relative to the site file. This is the "image data" step
//! of Durisch 1992 §4.1 before any control point is measured.
//!
//! When EXIF gives no focal length the photo still gets an interior orientation with the stated
//! fallback [`FALLBACK_FOCAL_PER_DIAGONAL`] × the image diagonal (a "normal" lens: 53° across the
//! diagonal, the 43 mm-equivalent focal length) with `self_calibration.focal = true`, so the solve
//! estimates it from the control points, and a [`NewSiteWarning::NoFocalLength`] says so.
//!
//! # Known limitations
//! EXIF GPS positions are not turned into the site's `[location]` (the survey frame is unknown
//! here); a capture time without a UTC offset is left out of `taken_at` (renders read it in the
//! site's `location.time_zone` when one is set, see [`super::site_time`]). The
//! site file's folder must exist. Photo ids are file stems made unique with `_2`, `_3`, … in the
//! order given.

use std::collections::HashSet;
use std::fmt;
use std::path::{Component, Path, PathBuf};

use super::{Interior, Photo, SelfCalibrationFlags, Site, SiteDocument, SiteError};
use crate::photo::{self, FocalSource, PhotoError};

/// Fallback focal length when EXIF has none, as a multiple of the image diagonal in pixels: 1.0
/// gives a 2·atan(1/2) = 53.1° diagonal field of view, that of a 43.3 mm lens on 36 × 24 mm
/// (the "normal" lens whose focal length equals the frame diagonal). Typical site photos are
/// taken with 24–50 mm equivalent lenses, so this start is within a factor of two of the truth,
/// inside the resection's convergence range; the solve then estimates the focal length.
pub const FALLBACK_FOCAL_PER_DIAGONAL: f64 = 1.0;

/// Most photos one new site takes (a bound on the work one click can start).
pub const MAX_PHOTOS: usize = 10_000;

/// What can go wrong creating a site from photos.
#[derive(Debug, thiserror::Error)]
pub enum NewSiteError {
    #[error("no photos chosen: a new site needs at least one photo")]
    NoPhotos,
    #[error("{count} photos chosen; a new site takes at most {max}")]
    TooManyPhotos { count: usize, max: usize },
    #[error("site file {path} already exists: choose another name (nothing was overwritten)")]
    SiteFileExists { path: PathBuf },
    #[error("the folder of the site file {path} does not exist")]
    NoSiteFolder { path: PathBuf },
    #[error("photo {path} is chosen twice")]
    DuplicatePhoto { path: PathBuf },
    #[error(
        "the path of photo {} is not valid UTF-8 and a site file (TOML text) cannot hold it; \
         rename the file or folder",
        path.display()
    )]
    NonUtf8Path { path: PathBuf },
    #[error(transparent)]
    Photo(#[from] PhotoError),
    #[error(transparent)]
    Site(#[from] SiteError),
}

/// Something the user should know about the new site that did not stop it.
#[derive(Debug, Clone, PartialEq)]
pub enum NewSiteWarning {
    /// The photo has no readable EXIF block.
    NoExif { photo: String, reason: String },
    /// EXIF gives no focal length; the fallback was used and the solve will estimate it.
    NoFocalLength {
        photo: String,
        fallback_focal_px: f64,
    },
    /// EXIF has a capture time without a UTC offset; `taken_at` was left out.
    TimeWithoutOffset { photo: String, date_time: String },
}

impl fmt::Display for NewSiteWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoExif { photo, reason } => write!(f, "photo `{photo}`: no EXIF ({reason})"),
            Self::NoFocalLength {
                photo,
                fallback_focal_px,
            } => write!(
                f,
                "photo `{photo}`: EXIF gives no focal length; started at {fallback_focal_px:.1} px \
                 (the image diagonal, a 53° diagonal field of view) and set to be estimated by \
                 the solve. Enter the focal length in the photo's camera settings if you know it."
            ),
            Self::TimeWithoutOffset { photo, date_time } => write!(
                f,
                "photo `{photo}`: EXIF time {date_time} has no UTC offset, so taken_at is not \
                 set (set location.time_zone to read it as local time there, or lighting.time or \
                 the photo's taken_at for the sun position)"
            ),
        }
    }
}

/// Where a new photo's focal length came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FocalOrigin {
    /// From EXIF, by this rule.
    Exif(FocalSource),
    /// [`FALLBACK_FOCAL_PER_DIAGONAL`] × the image diagonal.
    Fallback,
}

/// A site built from photos, not yet saved.
#[derive(Debug, Clone)]
pub struct NewSite {
    /// The site with its path (the file does not exist yet).
    pub document: SiteDocument,
    /// Per photo (in order), where its focal length came from.
    pub focal_origins: Vec<FocalOrigin>,
    /// What the user should be told.
    pub warnings: Vec<NewSiteWarning>,
}

impl NewSite {
    /// Saves the site atomically ([`Site::save`]); refuses to overwrite an existing file.
    ///
    /// # Errors
    /// [`NewSiteError::SiteFileExists`], or [`NewSiteError::Site`] when writing fails.
    pub fn save_new(&self) -> Result<(), NewSiteError> {
        let path = &self.document.path;
        if path.exists() {
            return Err(NewSiteError::SiteFileExists { path: path.clone() });
        }
        self.document.save()?;
        Ok(())
    }
}

/// The path of `target` relative to the folder `base` (both absolute and canonical), with `..`
/// where needed; `target` itself when they share no root (another drive).
#[must_use]
pub fn relative_path(base: &Path, target: &Path) -> PathBuf {
    let b: Vec<Component> = base.components().collect();
    let t: Vec<Component> = target.components().collect();
    if b.first() != t.first() {
        return target.to_path_buf();
    }
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c.as_os_str());
    }
    out
}

/// A photo id from a file name: its stem with whitespace trimmed (`photo` when empty), made
/// unique against `taken` with `_2`, `_3`, ….
fn unique_id(path: &Path, taken: &HashSet<String>) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().trim().to_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "photo".into());
    (1..)
        .map(|n| {
            if n == 1 {
                stem.clone()
            } else {
                format!("{stem}_{n}")
            }
        })
        .find(|id| !taken.contains(id))
        .unwrap_or(stem)
}

/// Builds a site at `site_path` holding `photo_paths` (see the module doc). Reads each photo's
/// size and EXIF; writes nothing.
///
/// # Errors
/// [`NewSiteError`]: no photos, too many, a site file that already exists, a missing site folder,
/// the same photo twice, or a photo that is missing or cannot be decoded.
pub fn site_from_photos(
    site_path: &Path,
    photo_paths: &[PathBuf],
) -> Result<NewSite, NewSiteError> {
    if photo_paths.is_empty() {
        return Err(NewSiteError::NoPhotos);
    }
    if photo_paths.len() > MAX_PHOTOS {
        return Err(NewSiteError::TooManyPhotos {
            count: photo_paths.len(),
            max: MAX_PHOTOS,
        });
    }
    if site_path.exists() {
        return Err(NewSiteError::SiteFileExists {
            path: site_path.to_path_buf(),
        });
    }
    let folder = site_path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let folder = std::fs::canonicalize(folder).map_err(|_| NewSiteError::NoSiteFolder {
        path: site_path.to_path_buf(),
    })?;

    let mut site = Site {
        name: site_path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        ..Site::default()
    };
    let mut seen_files = HashSet::new();
    let mut ids = HashSet::new();
    let mut focal_origins = Vec::with_capacity(photo_paths.len());
    let mut warnings = Vec::new();
    for path in photo_paths {
        let size_px = photo::size_px(path)?;
        let absolute =
            std::fs::canonicalize(path).map_err(|_| PhotoError::Missing { path: path.clone() })?;
        if !seen_files.insert(absolute.clone()) {
            return Err(NewSiteError::DuplicatePhoto { path: path.clone() });
        }
        let id = unique_id(path, &ids);
        ids.insert(id.clone());

        let exif = photo::read_exif(path);
        if let Err(e) = &exif {
            let reason = match e {
                PhotoError::Exif { message, .. } => message.clone(),
                other => other.to_string(),
            };
            warnings.push(NewSiteWarning::NoExif {
                photo: id.clone(),
                reason,
            });
        }
        let estimate = exif
            .as_ref()
            .ok()
            .and_then(|e| photo::initial_focal_px(e, size_px));
        let (focal_px, origin) = match estimate {
            Some(e) => (e.focal_px, FocalOrigin::Exif(e.source)),
            None => {
                let diagonal = f64::from(size_px[0]).hypot(f64::from(size_px[1]));
                let fallback = FALLBACK_FOCAL_PER_DIAGONAL * diagonal;
                warnings.push(NewSiteWarning::NoFocalLength {
                    photo: id.clone(),
                    fallback_focal_px: fallback,
                });
                (fallback, FocalOrigin::Fallback)
            }
        };
        let taken_at = exif.as_ref().ok().and_then(|e| {
            let t = e.taken_at_rfc3339();
            if t.is_none()
                && let Some(dt) = &e.date_time_original
            {
                warnings.push(NewSiteWarning::TimeWithoutOffset {
                    photo: id.clone(),
                    date_time: dt.clone(),
                });
            }
            t
        });
        site.photos.push(Photo {
            id,
            file: relative_path(&folder, &absolute)
                .to_str()
                .ok_or_else(|| NewSiteError::NonUtf8Path {
                    path: absolute.clone(),
                })?
                .to_owned(),
            taken_at,
            profile: None,
            interior: Some(Interior {
                focal_px,
                principal_point_px: None,
                distortion: crate::camera::BrownConrady::default(),
                image_size_px: Some(size_px),
            }),
            self_calibration: SelfCalibrationFlags {
                focal: origin == FocalOrigin::Fallback,
                ..SelfCalibrationFlags::default()
            },
            exterior: None,
        });
        focal_origins.push(origin);
    }
    // The same checks as loading: what is saved here must open again.
    if let Some(issue) = site.validate().into_iter().next() {
        return Err(NewSiteError::Site(SiteError::Invalid {
            path: site_path.to_path_buf(),
            line: 0,
            field: issue.field,
            message: issue.message,
        }));
    }
    Ok(NewSite {
        document: SiteDocument {
            path: site_path.to_path_buf(),
            site,
        },
        focal_origins,
        warnings,
    })
}

/// [`site_from_photos`], then [`NewSite::save_new`]: the site file is written atomically and
/// never over an existing one.
///
/// # Errors
/// As [`site_from_photos`] and [`NewSite::save_new`].
pub fn create_site(site_path: &Path, photo_paths: &[PathBuf]) -> Result<NewSite, NewSiteError> {
    let new = site_from_photos(site_path, photo_paths)?;
    new.save_new()?;
    Ok(new)
}

#[cfg(test)]
#[path = "new_tests.rs"]
mod tests;
