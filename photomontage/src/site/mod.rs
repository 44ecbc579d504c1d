//! The site file: the project a user saves (TOML, versioned schema). Every field is documented
//! in `docs/site-format.md`; this module is the schema, its validation and atomic saving.
//!
//! A site holds the photos (file, interior orientation, exterior orientation once solved), the
//! surveyed control points, the pixel observations of points in photos, the scene polygons
//! (Durisch 1992 §4.1: vertices, material attribute, image attribute), lighting and atmosphere
//! parameters, CAD models with their placement and the render settings. Paths are relative to the
//! site file.
//!
//! # Known limitations
//! Line numbers of semantic errors (a duplicate id, an unknown photo) are found by locating the
//! `[[table]]` header and key in the text, which works for the array-of-tables layout that
//! [`Site::save`] writes; for hand-written inline tables the error names the field but may give
//! the line of the enclosing table.

pub mod control_location;
pub mod elevation;
pub mod live_relight;
mod locate;
pub mod luminaires;
pub mod material_pick;
pub mod models;
pub mod new;
pub mod other_photos;
pub mod photo_points;
pub mod photo_reflectance;
#[cfg(test)]
mod photo_reflectance_tests;
mod photo_views;
pub mod radiosity_lighting;
pub mod render;
pub mod render_error;
pub mod render_photo;
pub mod render_radiosity;
mod schema;
pub mod site_materials;
pub mod site_scene;
pub mod site_time;
pub mod solve;
pub mod solve_options;
pub mod spectral_radiosity;
pub mod sun_path;
#[cfg(feature = "opencv")]
pub mod tie_matching;
pub mod tie_points;
pub mod toml_merge;
mod validate;
pub mod variant_renders;
pub mod variants;

pub use schema::*;
pub use solve::{SiteSolution, apply_solution, solve_site, stored_camera};
pub use validate::SiteIssue;

use std::path::{Path, PathBuf};

/// The schema version this build reads and writes.
pub const SCHEMA_VERSION: u32 = 1;

/// What can go wrong loading or saving a site file.
#[derive(Debug, thiserror::Error)]
pub enum SiteError {
    #[error("cannot read site file {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{path}:{line}: field `{field}`: {message}")]
    Invalid {
        path: PathBuf,
        line: usize,
        field: String,
        message: String,
    },
    #[error(
        "{path}: schema_version {found} is not supported (this build reads version {supported})"
    )]
    UnsupportedVersion {
        path: PathBuf,
        found: u32,
        supported: u32,
    },
    #[error("cannot serialise site: {0}")]
    Serialise(String),
    #[error(
        "the path {} is not valid UTF-8 and a site file (TOML text) cannot hold it; rename \
         the folder or file, or save the site beside the original so its paths stay relative",
        path.display()
    )]
    NonUtf8Path { path: PathBuf },
    #[error("cannot write site file {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// A site file loaded from disk, with the folder its relative paths are resolved against.
#[derive(Debug, Clone, PartialEq)]
pub struct SiteDocument {
    /// The site file's own path.
    pub path: PathBuf,
    /// The schema content.
    pub site: Site,
}

impl SiteDocument {
    /// Reads, parses and validates a site file.
    ///
    /// # Errors
    /// [`SiteError`] naming the file, line and field of the first problem.
    pub fn load(path: &Path) -> Result<Self, SiteError> {
        let text = std::fs::read_to_string(path).map_err(|source| SiteError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let site = Site::from_toml(&text, path)?;
        Ok(Self {
            path: path.to_path_buf(),
            site,
        })
    }

    /// The folder relative paths in the site are resolved against.
    #[must_use]
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or_else(|| Path::new("."))
    }

    /// Resolves a path written in the site file (relative to the site file) to a usable path.
    #[must_use]
    pub fn resolve(&self, relative: &str) -> PathBuf {
        self.base_dir().join(relative)
    }

    /// Saves atomically to `path` and makes it the document's path. When the new file is in
    /// another folder, relative photo, model, luminaire and material-library paths are rewritten as absolute
    /// paths so they still point at the same files.
    ///
    /// # Errors
    /// [`SiteError::Write`] or [`SiteError::Serialise`]; nothing changes in memory then.
    pub fn save_as(&mut self, path: &Path) -> Result<(), SiteError> {
        let new_dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let same_dir = match (
            std::fs::canonicalize(self.base_dir()),
            std::fs::canonicalize(new_dir),
        ) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        let mut site = self.site.clone();
        if !same_dir {
            let rebase = |p: &mut String| -> Result<(), SiteError> {
                if Path::new(p.as_str()).is_relative() {
                    let joined = self.resolve(p);
                    let abs = std::fs::canonicalize(&joined).unwrap_or(joined);
                    // A TOML site holds text: a path that is not UTF-8 cannot be written
                    // without changing it, so it is refused rather than rewritten.
                    *p = abs
                        .to_str()
                        .ok_or_else(|| SiteError::NonUtf8Path { path: abs.clone() })?
                        .to_owned();
                }
                Ok(())
            };
            for ph in &mut site.photos {
                rebase(&mut ph.file)?;
            }
            for m in &mut site.models {
                rebase(&mut m.file)?;
            }
            for l in &mut site.luminaires {
                rebase(&mut l.file)?;
            }
            if let Some(lib) = site.lighting.material_library.as_mut() {
                rebase(lib)?;
            }
        }
        let template = std::fs::read_to_string(&self.path).ok();
        site.save_over(path, template.as_deref())?;
        self.site = site;
        self.path = path.to_path_buf();
        Ok(())
    }

    /// Saves atomically to the document's own path.
    ///
    /// # Errors
    /// [`SiteError::Write`] or [`SiteError::Serialise`]; the file on disk is then unchanged.
    pub fn save(&self) -> Result<(), SiteError> {
        self.site.save(&self.path)
    }
}

impl Site {
    /// Parses and validates site TOML text. `path` is only used in error messages.
    ///
    /// # Errors
    /// [`SiteError::Syntax`] for TOML or type errors, [`SiteError::Invalid`] for semantic errors,
    /// [`SiteError::UnsupportedVersion`] for another schema version.
    pub fn from_toml(text: &str, path: &Path) -> Result<Self, SiteError> {
        // The version is checked first so that a newer file gets a version message, not a
        // confusing unknown-field one.
        if let Ok(probe) = toml::from_str::<VersionProbe>(text)
            && probe.schema_version != SCHEMA_VERSION
        {
            return Err(SiteError::UnsupportedVersion {
                path: path.to_path_buf(),
                found: probe.schema_version,
                supported: SCHEMA_VERSION,
            });
        }
        let site: Self = toml::from_str(text).map_err(|e| {
            let (line, column) = e
                .span()
                .map_or((0, 0), |span| locate::line_column(text, span.start));
            SiteError::Syntax {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().to_string(),
            }
        })?;
        if let Some(issue) = site.validate().into_iter().next() {
            return Err(SiteError::Invalid {
                path: path.to_path_buf(),
                line: locate::field_line(text, &issue.field),
                field: issue.field,
                message: issue.message,
            });
        }
        Ok(site)
    }

    /// The site as TOML text, in the layout `load` reads back to an equal value.
    ///
    /// # Errors
    /// [`SiteError::Serialise`] if a value cannot be represented (e.g. a non-finite float).
    pub fn to_toml(&self) -> Result<String, SiteError> {
        toml::to_string_pretty(self).map_err(|e| SiteError::Serialise(e.to_string()))
    }

    /// Saves atomically: writes a temporary file beside `path`, flushes it to disk, then renames it
    /// over `path`, so a crash leaves either the old or the new file, never a torn one. When
    /// `path` already holds a site, its comments, blank lines and key order are kept
    /// ([`toml_merge`]).
    ///
    /// # Errors
    /// [`SiteError::Write`] or [`SiteError::Serialise`].
    pub fn save(&self, path: &Path) -> Result<(), SiteError> {
        let template = std::fs::read_to_string(path).ok();
        self.save_over(path, template.as_deref())
    }

    /// The site as TOML laid into `template`'s comments and order ([`toml_merge`]) when that
    /// reads back to this very site, else the plain serialisation.
    ///
    /// # Errors
    /// [`SiteError::Serialise`].
    pub fn to_toml_over(&self, template: Option<&str>) -> Result<String, SiteError> {
        let fresh = self.to_toml()?;
        let merged = template
            .and_then(|t| {
                toml_merge::merge_into_template(t, &fresh, |candidate| {
                    Self::from_toml(candidate, Path::new("merged"))
                        .ok()?
                        .to_toml()
                        .ok()
                })
            })
            .filter(|m| Self::from_toml(m, Path::new("merged")).is_ok_and(|back| back == *self));
        Ok(merged.unwrap_or(fresh))
    }

    /// [`Self::save`] with the previous text given (e.g. the file a document was loaded from).
    ///
    /// # Errors
    /// [`SiteError::Write`] or [`SiteError::Serialise`].
    pub fn save_over(&self, path: &Path, template: Option<&str>) -> Result<(), SiteError> {
        let text = self.to_toml_over(template)?;
        write_atomically(path, text.as_bytes()).map_err(|source| SiteError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

pub use crate::atomic_file::write_atomically;

#[derive(serde::Deserialize)]
struct VersionProbe {
    schema_version: u32,
}

#[cfg(test)]
mod tests;
