//! The job list: every unit of work of a set of views cut into bands, with its output path, in
//! one JSON file that any scheduler can index (a Slurm array task id, a Kubernetes completion
//! index, a Flamenco task). A job renders one band and writes its part; a merge puts a view's
//! parts together. Running a job whose part already exists with the same identity does nothing,
//! so a requeued or repeated task is harmless; parts are written atomically, so a part that
//! exists is complete.
//!
//! Paths in the list are relative to the list's own folder, so the folder (with the site at the
//! same relative place) can be mounted anywhere on the nodes.
//!
//! # Known limitations
//! The list covers views × bands. Design variants and sun studies are not in the site format
//! yet, so they cannot be listed.

use std::path::{Component, Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::render::output::{LayerSet, OutputFormat, write_object_table};
use crate::render::partial::{PartError, merge_parts, read_part_info, write_part};
use crate::render::{Band, TileProgress};
use crate::site::SiteDocument;
use crate::site::render::SiteRenderError;
use crate::site::render_photo::{RenderPlan, RenderRequest, site_content_sha256};
use crate::verified::ViewMetadata;
use crate::verified::image_metadata::{view_metadata, write_render};

/// The `format` of a job list this version writes and reads.
pub const JOBS_FORMAT: &str = "photomontage-jobs/1";

/// Render settings every job of a list shares (the CLI's `render` overrides).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JobRender {
    /// Fewest rays per pixel; `None`: the site's.
    pub spp_min: Option<u32>,
    /// Most rays per pixel; `None`: the site's.
    pub spp_max: Option<u32>,
    /// Seed; `None`: the site's.
    pub seed: Option<u64>,
    /// Spectral mode.
    pub spectral: bool,
    /// Extra EXR layers, comma-separated.
    pub layers: String,
    /// Exposure for 8-bit output; `None`: the site's.
    pub exposure: Option<f64>,
}

/// One unit of work: a band of a view.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Job {
    /// 0-based position in the list (the scheduler's array index).
    pub index: usize,
    /// The view (photo id).
    pub view: String,
    /// The band, `I/N`.
    pub tile: String,
    /// The part file, relative to the list's folder.
    pub output: String,
}

/// The merge of one view's parts.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Merge {
    /// The view.
    pub view: String,
    /// Its parts, relative to the list's folder.
    pub parts: Vec<String>,
    /// The merged image, relative to the list's folder.
    pub output: String,
}

/// A job list (see the module documentation).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JobList {
    /// [`JOBS_FORMAT`].
    pub format: String,
    /// The site file, relative to the list's folder.
    pub site: String,
    /// SHA-256 of the site's content when the list was made; jobs refuse a changed site.
    pub site_sha256: String,
    /// Bands per view.
    pub tiles: u32,
    /// Shared render settings.
    pub render: JobRender,
    /// Whole-image size of each view, `[view, width, height]`, for resource estimates.
    pub views: Vec<(String, [u32; 2])>,
    /// The band jobs.
    pub jobs: Vec<Job>,
    /// One merge per view.
    pub merges: Vec<Merge>,
}

/// What can go wrong making or running jobs.
#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// A check of the site or a view failed.
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    /// The site file cannot be read.
    #[error(transparent)]
    SiteFile(#[from] crate::site::SiteError),
    /// A bad argument.
    #[error("{0}")]
    Argument(String),
    /// The job list cannot be read.
    #[error("job list {path}: {message}")]
    List {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The site changed after the list was made.
    #[error(
        "the site {site} changed after the job list {list} was made (content hash {now} ≠ {then}); \
         make the job list again so that no part mixes old and new settings"
    )]
    SiteChanged {
        /// The site file.
        site: PathBuf,
        /// The job list.
        list: PathBuf,
        /// Hash now.
        now: String,
        /// Hash in the list.
        then: String,
    },
    /// A part or merge failed.
    #[error(transparent)]
    Part(#[from] PartError),
    /// Writing failed.
    #[error(transparent)]
    Output(#[from] crate::render::OutputError),
    /// Writing an 8-bit image with its EXIF failed.
    #[error(transparent)]
    Metadata(#[from] crate::verified::image_metadata::ImageMetadataError),
    /// A folder could not be made or written.
    #[error("cannot write in {path}: {message}")]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// Options of [`JobList::build`].
#[derive(Debug, Clone, PartialEq)]
pub struct JobOptions {
    /// Views to render; empty: every solved photo of the site.
    pub views: Vec<String>,
    /// Bands per view.
    pub tiles: u32,
    /// Shared render settings.
    pub render: JobRender,
    /// Extension of the merged images: exr, png, jpg, tif.
    pub image_format: String,
}

/// `path` relative to `base` (both made absolute first); falls back to the absolute path when
/// they share no prefix (another drive).
#[must_use]
pub fn relative_to(path: &Path, base: &Path) -> PathBuf {
    let abs = |p: &Path| -> PathBuf {
        let p = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let mut out = PathBuf::new();
        for c in p.components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::CurDir => {}
                other => out.push(other),
            }
        }
        out
    };
    let (path, base) = (abs(path), abs(base));
    let p: Vec<_> = path.components().collect();
    let b: Vec<_> = base.components().collect();
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    if common == 0 {
        return path;
    }
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    out
}

fn utf8(path: &Path) -> Result<String, FarmError> {
    path.to_str().map(str::to_owned).ok_or_else(|| {
        FarmError::Argument(format!(
            "{} is not valid UTF-8; a job list (JSON) cannot hold it",
            path.display()
        ))
    })
}

impl JobRender {
    fn request(&self, view: &str, band: Band) -> Result<RenderRequest, FarmError> {
        Ok(RenderRequest {
            view: view.to_owned(),
            spp_min: self.spp_min,
            spp_max: self.spp_max,
            seed: self.seed,
            spectral: self.spectral,
            radiosity: false,
            layers: LayerSet::parse(&self.layers)
                .map_err(|e| FarmError::Argument(e.to_string()))?,
            exposure: self.exposure,
            band,
        })
    }
}

/// A file name part for a view id: letters, digits, `-`, `_`, `.` kept; others become `_`.
fn file_stem(view: &str) -> String {
    view.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

impl JobList {
    /// Lists the jobs for `doc` (loaded from `site_path`), to be written as `list_path`. Every
    /// view's band is checked here ([`RenderPlan::new`]), so a bad view, setting or tile count
    /// fails before any job runs.
    ///
    /// # Errors
    /// [`FarmError::Argument`] for no views, a zero tile count, an unknown image format or two
    /// views with the same file name; [`FarmError::Site`] for a view that cannot be rendered as
    /// asked.
    pub fn build(
        doc: &SiteDocument,
        site_path: &Path,
        list_path: &Path,
        options: &JobOptions,
    ) -> Result<Self, FarmError> {
        if options.tiles == 0 {
            return Err(FarmError::Argument("--tiles must be at least 1".into()));
        }
        let ext = options.image_format.to_ascii_lowercase();
        let format = OutputFormat::from_path(Path::new(&format!("x.{ext}")))
            .map_err(|e| FarmError::Argument(e.to_string()))?;
        let layers = LayerSet::parse(&options.render.layers)
            .map_err(|e| FarmError::Argument(e.to_string()))?;
        if format != OutputFormat::Exr && !layers.is_empty() {
            return Err(FarmError::Argument(format!(
                "layers {} need exr images, not {ext}",
                layers.names()
            )));
        }
        let views: Vec<String> = if options.views.is_empty() {
            doc.site
                .photos
                .iter()
                .filter(|p| p.exterior.is_some())
                .map(|p| p.id.clone())
                .collect()
        } else {
            options.views.clone()
        };
        if views.is_empty() {
            return Err(FarmError::Argument(
                "the site has no solved photo to render; run `photomontage solve` first".into(),
            ));
        }
        let list_dir = list_path.parent().unwrap_or(Path::new("."));
        let mut stems = std::collections::HashSet::new();
        let (mut jobs, mut merges, mut sizes) = (Vec::new(), Vec::new(), Vec::new());
        for view in &views {
            let stem = file_stem(view);
            if !stems.insert(stem.clone()) {
                return Err(FarmError::Argument(format!(
                    "view `{view}` is listed twice (or two views share the file name `{stem}`)"
                )));
            }
            let mut parts = Vec::new();
            for i in 1..=options.tiles {
                let band =
                    Band::new(i, options.tiles).map_err(|e| FarmError::Argument(e.to_string()))?;
                let plan = RenderPlan::new(doc, &options.render.request(view, band)?)?;
                if i == 1 {
                    sizes.push((view.clone(), plan.full_size_px));
                }
                let output = format!("parts/{stem}.tile-{i}-of-{}.exr", options.tiles);
                jobs.push(Job {
                    index: jobs.len(),
                    view: view.clone(),
                    tile: band.to_string(),
                    output: output.clone(),
                });
                parts.push(output);
            }
            merges.push(Merge {
                view: view.clone(),
                parts,
                output: format!("{stem}.{ext}"),
            });
        }
        Ok(Self {
            format: JOBS_FORMAT.to_owned(),
            site: utf8(&relative_to(site_path, list_dir))?,
            site_sha256: site_content_sha256(doc)?,
            tiles: options.tiles,
            render: options.render.clone(),
            views: sizes,
            jobs,
            merges,
        })
    }

    /// Writes the list as pretty JSON (atomically), creating its folder and `parts/`.
    ///
    /// # Errors
    /// [`FarmError::Folder`].
    pub fn write(&self, list_path: &Path) -> Result<(), FarmError> {
        let dir = list_path.parent().unwrap_or(Path::new("."));
        let folder = |e: &dyn std::fmt::Display| FarmError::Folder {
            path: dir.to_path_buf(),
            message: e.to_string(),
        };
        std::fs::create_dir_all(dir.join("parts")).map_err(|e| folder(&e))?;
        let text = serde_json::to_string_pretty(self).map_err(|e| folder(&e))?;
        crate::atomic_file::write_atomically(list_path, text.as_bytes()).map_err(|e| folder(&e))
    }

    /// Reads a list.
    ///
    /// # Errors
    /// [`FarmError::List`].
    pub fn read(list_path: &Path) -> Result<Self, FarmError> {
        let err = |message: String| FarmError::List {
            path: list_path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(list_path).map_err(|e| err(e.to_string()))?;
        let list: Self = serde_json::from_str(&text).map_err(|e| err(e.to_string()))?;
        if list.format != JOBS_FORMAT {
            return Err(err(format!(
                "format `{}`, this version reads `{JOBS_FORMAT}`",
                list.format
            )));
        }
        for (k, job) in list.jobs.iter().enumerate() {
            if job.index != k {
                return Err(err(format!("job {k} says it is index {}", job.index)));
            }
        }
        Ok(list)
    }
}

/// What running one job did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JobOutcome {
    /// The part was rendered and written.
    Rendered {
        /// The part file.
        output: PathBuf,
        /// Changed pixels in the band.
        changed_pixels: usize,
    },
    /// A complete part of the same identity was already there.
    AlreadyDone {
        /// The part file.
        output: PathBuf,
    },
}

fn load_site(list: &JobList, list_path: &Path) -> Result<(SiteDocument, PathBuf), FarmError> {
    let dir = list_path.parent().unwrap_or(Path::new("."));
    let site_path = dir.join(&list.site);
    let doc = SiteDocument::load(&site_path)?;
    let now = site_content_sha256(&doc)?;
    if now != list.site_sha256 {
        return Err(FarmError::SiteChanged {
            site: site_path,
            list: list_path.to_path_buf(),
            now,
            then: list.site_sha256.clone(),
        });
    }
    Ok((doc, dir.to_path_buf()))
}

/// Runs job `index` of the list at `list_path`: renders its band and writes its part, unless a
/// part of the same identity is already there. Stale temporaries of killed runs are removed.
///
/// # Errors
/// [`FarmError::Argument`] for an index outside the list, [`FarmError::SiteChanged`], any render
/// or write error.
pub fn run_job(
    list_path: &Path,
    index: usize,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<JobOutcome, FarmError> {
    let list = JobList::read(list_path)?;
    let job = list.jobs.get(index).ok_or_else(|| {
        FarmError::Argument(format!(
            "job index {index} is out of range: {} has jobs 0 to {}",
            list_path.display(),
            list.jobs.len().saturating_sub(1)
        ))
    })?;
    let (doc, dir) = load_site(&list, list_path)?;
    let band = Band::parse(&job.tile).map_err(|e| FarmError::Argument(e.to_string()))?;
    let plan = RenderPlan::new(&doc, &list.render.request(&job.view, band)?)?;
    let output = dir.join(&job.output);
    crate::atomic_file::remove_stale_temporaries(&output);
    if let Ok(info) = read_part_info(&output)
        && info.identity == plan.identity
        && info.tile == job.tile
    {
        return Ok(JobOutcome::AlreadyDone { output });
    }
    // The part's folder must take the file before the render starts, not after.
    let folder = |e: std::io::Error| FarmError::Folder {
        path: output.parent().unwrap_or(Path::new(".")).to_path_buf(),
        message: e.to_string(),
    };
    if let Some(parent) = output.parent() {
        std::fs::create_dir_all(parent).map_err(folder)?;
    }
    crate::atomic_file::probe_writable(&output).map_err(folder)?;
    let rendered = plan.render(&doc, on_tile, cancel)?;
    let mut info = plan.part_info(&rendered);
    // 8-bit merges carry the view geometry as EXIF, as a whole-image `render` writes it.
    info.view_json = view_metadata(&doc, &job.view)
        .ok()
        .map(|m| m.to_ascii_json());
    write_part(&output, &rendered.image, &rendered.layers, &info)?;
    Ok(JobOutcome::Rendered {
        output,
        changed_pixels: rendered.image.changed_pixels,
    })
}

/// Merges the parts of `view` (or of every view for `None`) into their images; returns the
/// images written.
///
/// # Errors
/// [`FarmError::Argument`] for an unknown view, any [`PartError`] (missing, duplicate or foreign
/// parts named), write errors.
pub fn run_merges(list_path: &Path, view: Option<&str>) -> Result<Vec<PathBuf>, FarmError> {
    let list = JobList::read(list_path)?;
    let dir = list_path.parent().unwrap_or(Path::new("."));
    let merges: Vec<&Merge> = list
        .merges
        .iter()
        .filter(|m| view.is_none_or(|v| m.view == v))
        .collect();
    if let (Some(v), true) = (view, merges.is_empty()) {
        return Err(FarmError::Argument(format!(
            "no view `{v}` in {}; it lists {}",
            list_path.display(),
            list.merges
                .iter()
                .map(|m| m.view.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let mut written = Vec::new();
    for merge in merges {
        let parts: Vec<PathBuf> = merge.parts.iter().map(|p| dir.join(p)).collect();
        // Parts are listed in band order; name every band whose part is not there yet.
        let missing: Vec<u32> = (1..)
            .zip(&parts)
            .filter(|(_, p)| !p.exists())
            .map(|(i, _)| i)
            .collect();
        if !missing.is_empty() {
            return Err(PartError::Missing {
                missing,
                count: list.tiles,
            }
            .into());
        }
        let out = dir.join(&merge.output);
        crate::atomic_file::probe_writable(&out).map_err(|e| FarmError::Folder {
            path: out.parent().unwrap_or(Path::new(".")).to_path_buf(),
            message: e.to_string(),
        })?;
        merge_to_file(&parts, &out)?;
        written.push(out);
    }
    Ok(written)
}

/// Merges `parts` (one view's complete set) into `out` (format by extension; 8-bit outputs use
/// the parts' exposure) and writes the object table beside an EXR with an `object_id` layer.
///
/// # Errors
/// Any [`PartError`], write errors.
pub fn merge_to_file(
    parts: &[PathBuf],
    out: &Path,
) -> Result<crate::render::partial::Merged, FarmError> {
    let merged = merge_parts(parts)?;
    let tone_map = crate::colour::ToneMap::clamp_with_exposure(merged.info.exposure);
    let format = OutputFormat::from_path(out).map_err(|e| FarmError::Argument(e.to_string()))?;
    // The view the whole render would carry: EXIF and XMP in 8-bit images, attributes in EXR.
    let view: Option<ViewMetadata> = merged
        .info
        .view_json
        .as_deref()
        .and_then(|j| serde_json::from_str(j).ok());
    if format == OutputFormat::Exr {
        write_render(out, &merged.image, &merged.layers, &tone_map, view.as_ref())?;
        if let (Some(names), Some(_)) = (&merged.info.object_names, &merged.layers.object_id) {
            write_object_table(out, names)?;
        }
    } else {
        // 8-bit images drop the layers and carry the view, as `render` writes them.
        write_render(
            out,
            &merged.image,
            &crate::render::output::OutputLayers::default(),
            &tone_map,
            view.as_ref(),
        )?;
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_and_descend() {
        assert_eq!(
            relative_to(Path::new("/a/b/site.toml"), Path::new("/a/c/d")),
            PathBuf::from("../../b/site.toml")
        );
        assert_eq!(
            relative_to(Path::new("/a/b/site.toml"), Path::new("/a/b")),
            PathBuf::from("site.toml")
        );
        assert_eq!(
            relative_to(Path::new("/a/./b/../b/x"), Path::new("/a")),
            PathBuf::from("b/x")
        );
    }

    #[test]
    fn view_ids_become_safe_file_names() {
        assert_eq!(file_stem("V1"), "V1");
        assert_eq!(file_stem("north/east view"), "north_east_view");
    }
}
