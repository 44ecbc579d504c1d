//! A whole sun study run and written: every daylight frame of [`super::plan_frames`] rendered
//! through [`super::render_frame`] (the one render entry point, `RenderPlan`) and/or mapped in
//! plan view ([`super::frame_shadow_map`]), reported frame by frame to an observer (the CLI's
//! progress bar, the studio's animated preview), then written to a folder with the contact
//! sheet ([`super::contact_sheet`]). Both `photomontage study` and the studio's Study tab run
//! this, so their files are the same.
//!
//! Writing is all-or-nothing where the file system allows it: a folder that does not exist yet
//! is filled under a temporary sibling name and renamed into place at the end (POSIX `rename`
//! of a directory is atomic); into an existing folder every file is written through a temporary
//! file and a rename ([`crate::site::write_atomically`]).
//!
//! Known limitations: frames are rendered one after the other and kept in memory until written
//! (a study of many large frames needs their linear RGBA in memory); into an existing folder a
//! failure part-way leaves the files written before it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use image::RgbImage;

use super::contact_sheet::{SheetCell, contact_sheet};
use super::shadow_map::{DEFAULT_CELL_M, shadow_map_image};
use super::{
    StudyError, StudyFrame, StudyRequest, frame_plan, frame_shadow_map, plan_frames, render_frame,
};
use crate::colour::{ToneMap, encode_srgb8};
use crate::render::output::OutputLayers;
use crate::render::{RenderError, TileProgress};
use crate::site::SiteDocument;
use crate::site::render_error::SiteRenderError;
use crate::site::render_photo::RenderedPhoto;
use crate::verified::ViewMetadata;
use crate::verified::image_metadata::{view_metadata, write_render};

/// What a study makes besides the frames' sun angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StudyOptions {
    /// Render a montage per daylight frame.
    pub montages: bool,
    /// Map the shadows in plan view per daylight frame.
    pub shadow_maps: bool,
    /// Cell edge of the shadow maps, metres.
    pub cell_m: f64,
}

impl Default for StudyOptions {
    fn default() -> Self {
        Self {
            montages: true,
            shadow_maps: false,
            cell_m: DEFAULT_CELL_M,
        }
    }
}

/// A daylight frame's montage.
pub struct FrameMontage {
    /// The render, linear.
    pub photo: RenderedPhoto,
    /// The tone map of its 8-bit output (the site's exposure, clamped).
    pub tone_map: ToneMap,
    /// The render as 8-bit sRGB through `tone_map` (what the PNG holds).
    pub srgb: RgbImage,
    /// The frame's view geometry for the files' metadata (its sun is the frame's).
    pub metadata: Option<ViewMetadata>,
}

/// One daylight frame made.
pub struct FrameOutput {
    pub frame: StudyFrame,
    pub montage: Option<FrameMontage>,
    /// The plan-view shadow map drawn with its legend and the frame's label.
    pub shadow_map: Option<RgbImage>,
    /// Render warnings and why the view metadata is missing, as text.
    pub warnings: Vec<String>,
}

impl FrameOutput {
    /// The image that stands for the frame on the contact sheet and in a preview: the montage,
    /// else the shadow map.
    #[must_use]
    pub fn picture(&self) -> Option<&RgbImage> {
        self.montage
            .as_ref()
            .map(|m| &m.srgb)
            .or(self.shadow_map.as_ref())
    }
}

/// What the observer of [`run_study`] hears, in this order: `Planned` once, then per daylight
/// frame `FrameStarted`, its tiles (from the render's worker threads), `FrameDone`.
pub enum StudyEvent<'a> {
    /// The frames are planned: all of them (night ones included), and how many tiles the
    /// montages will take in all (0 without montages).
    Planned {
        frames: &'a [StudyFrame],
        daylight: usize,
        tiles_total: u64,
    },
    /// Daylight frame `index` (of `count`) starts.
    FrameStarted {
        index: usize,
        count: usize,
        frame: &'a StudyFrame,
    },
    /// A tile of the current frame's montage is finished.
    Tile(TileProgress),
    /// Daylight frame `index` (of `count`) is made.
    FrameDone {
        index: usize,
        count: usize,
        output: &'a FrameOutput,
    },
}

/// A study made, not yet written.
pub struct StudyResult {
    /// The photo id.
    pub view: String,
    /// Every frame asked for, date-major, night ones included.
    pub frames: Vec<StudyFrame>,
    /// The daylight frames made, in the same order.
    pub outputs: Vec<FrameOutput>,
    /// Columns of the contact sheet (the number of clock times).
    pub columns: usize,
    /// What was made.
    pub options: StudyOptions,
}

/// A frame's files, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenFrame {
    pub frame: StudyFrame,
    /// The montage (`<stem>.png`).
    pub file: Option<PathBuf>,
    /// The montage as linear EXR (`<stem>.exr`).
    pub exr: Option<PathBuf>,
    /// The plan-view shadow map (`<stem>_shadow.png`).
    pub shadow_map: Option<PathBuf>,
}

/// The files of a study, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenStudy {
    pub frames: Vec<WrittenFrame>,
    /// `<view>_contact_sheet.png`.
    pub contact_sheet: PathBuf,
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

impl WrittenStudy {
    /// `{"frames":[{"time","sun_azimuth_deg","sun_elevation_deg","file"[,"shadow_map"]}],
    /// "contact_sheet"}` with file names relative to the folder (issue 17's format).
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        let frames: Vec<serde_json::Value> = self
            .frames
            .iter()
            .map(|w| {
                let mut entry = serde_json::json!({
                    "time": w.frame.time_rfc3339(),
                    "sun_azimuth_deg": w.frame.sun_azimuth_deg,
                    "sun_elevation_deg": w.frame.sun_elevation_deg,
                });
                if let Some(f) = &w.file {
                    entry["file"] = file_name(f).into();
                }
                if let Some(f) = &w.shadow_map {
                    entry["shadow_map"] = file_name(f).into();
                }
                entry
            })
            .collect();
        serde_json::json!({
            "frames": frames,
            "contact_sheet": file_name(&self.contact_sheet),
        })
    }
}

fn cancelled(cancel: &AtomicBool) -> Result<(), StudyError> {
    if cancel.load(Ordering::SeqCst) {
        Err(StudyError::Cancelled)
    } else {
        Ok(())
    }
}

/// Plans `request` and makes every daylight frame (montage and/or shadow map per `options`),
/// telling `on_event` as it goes. Raising `cancel` stops at the next tile or frame.
///
/// # Errors
/// Any error of [`plan_frames`], [`render_frame`] and [`frame_shadow_map`];
/// [`StudyError::NothingToMake`] when `options` asks for neither montages nor shadow maps;
/// [`StudyError::Cancelled`].
pub fn run_study(
    doc: &SiteDocument,
    request: &StudyRequest,
    options: StudyOptions,
    on_event: &(dyn Fn(StudyEvent<'_>) + Sync),
    cancel: &AtomicBool,
) -> Result<StudyResult, StudyError> {
    if !options.montages && !options.shadow_maps {
        return Err(StudyError::NothingToMake);
    }
    if !(options.cell_m.is_finite() && options.cell_m > 0.0) {
        return Err(StudyError::BadCell {
            cell_m: options.cell_m,
        });
    }
    let frames = plan_frames(doc, request)?;
    let daylight: Vec<&StudyFrame> = frames.iter().filter(|f| f.is_daylight()).collect();
    let tiles_total = if options.montages {
        frame_plan(&daylight[0].document(doc), request)?.tile_count() * daylight.len() as u64
    } else {
        0
    };
    on_event(StudyEvent::Planned {
        frames: &frames,
        daylight: daylight.len(),
        tiles_total,
    });
    let count = daylight.len();
    let mut outputs = Vec::with_capacity(count);
    for (index, frame) in daylight.into_iter().enumerate() {
        cancelled(cancel)?;
        on_event(StudyEvent::FrameStarted {
            index,
            count,
            frame,
        });
        let mut warnings = Vec::new();
        let montage = if options.montages {
            let on_tile = |t: TileProgress| on_event(StudyEvent::Tile(t));
            let (plan, photo) = match render_frame(doc, frame, request, &on_tile, cancel) {
                Err(StudyError::Site(SiteRenderError::Render(RenderError::Cancelled))) => {
                    return Err(StudyError::Cancelled);
                }
                other => other?,
            };
            warnings.extend(photo.warnings.iter().map(ToString::to_string));
            let tone_map = plan.tone_map();
            let [w, h] = photo.image.size_px;
            let srgb = RgbImage::from_fn(w, h, |x, y| {
                let p = photo.image.rgba[(y * w + x) as usize];
                image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone_map))
            });
            let metadata = match view_metadata(&frame.document(doc), &request.view) {
                Ok(m) => Some(m),
                Err(e) => {
                    warnings.push(format!("no view geometry in the image's metadata: {e}"));
                    None
                }
            };
            Some(FrameMontage {
                photo,
                tone_map,
                srgb,
                metadata,
            })
        } else {
            None
        };
        cancelled(cancel)?;
        let shadow_map = if options.shadow_maps {
            let map = frame_shadow_map(doc, frame, &request.view, options.cell_m)?;
            Some(shadow_map_image(&map, &frame.label()))
        } else {
            None
        };
        outputs.push(FrameOutput {
            frame: frame.clone(),
            montage,
            shadow_map,
            warnings,
        });
        if let Some(output) = outputs.last() {
            on_event(StudyEvent::FrameDone {
                index,
                count,
                output,
            });
        }
    }
    Ok(StudyResult {
        view: request.view.clone(),
        frames,
        outputs,
        columns: request.times.len(),
        options,
    })
}

/// Encodes `img` as PNG and writes it through a temporary file and a rename.
fn write_png(path: &Path, img: &RgbImage) -> Result<(), StudyError> {
    let fail = |message: String| StudyError::Write {
        path: path.display().to_string(),
        message,
    };
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| fail(e.to_string()))?;
    crate::site::write_atomically(path, &bytes).map_err(|e| fail(e.to_string()))
}

impl StudyResult {
    /// The contact sheet: one row per date, one column per time, night frames grey.
    #[must_use]
    pub fn contact_sheet(&self) -> RgbImage {
        let mut made = self.outputs.iter();
        let cells: Vec<SheetCell<'_>> = self
            .frames
            .iter()
            .map(|f| {
                if f.is_daylight() {
                    SheetCell {
                        image: made.next().and_then(FrameOutput::picture),
                        label: f.label(),
                    }
                } else {
                    SheetCell {
                        image: None,
                        label: format!("{} {} night", f.date, f.clock.format("%H:%M")),
                    }
                }
            })
            .collect();
        contact_sheet(&cells, self.columns)
    }

    /// Writes the frames (`<view>_<date>_<HHMM>.png`, with `exr` also `.exr`;
    /// `<…>_shadow.png`) and `<view>_contact_sheet.png` into `dir` (see the module doc for
    /// how this is atomic).
    ///
    /// # Errors
    /// [`StudyError::Write`] naming the file or folder.
    pub fn write(&self, dir: &Path, exr: bool) -> Result<WrittenStudy, StudyError> {
        let fail = |path: &Path, e: &dyn std::fmt::Display| StudyError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        if dir.exists() {
            if !dir.is_dir() {
                return Err(fail(dir, &"exists and is not a folder"));
            }
            return self.write_into(dir, dir, exr);
        }
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|e| fail(&parent, &e))?;
        let staging = parent.join(format!(
            ".{}.partial-{}",
            file_name(dir),
            std::process::id()
        ));
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|e| fail(&staging, &e))?;
        }
        std::fs::create_dir(&staging).map_err(|e| fail(&staging, &e))?;
        let written = self.write_into(&staging, dir, exr).and_then(|w| {
            std::fs::rename(&staging, dir)
                .map(|()| w)
                .map_err(|e| fail(dir, &e))
        });
        if written.is_err() {
            // Best effort: the staging folder is ours and holds nothing the user had.
            let _ = std::fs::remove_dir_all(&staging);
        }
        written
    }

    /// Writes into `into`, naming the files as they will be in `dir`.
    fn write_into(&self, into: &Path, dir: &Path, exr: bool) -> Result<WrittenStudy, StudyError> {
        let mut frames = Vec::with_capacity(self.outputs.len());
        for out in &self.outputs {
            let stem = out.frame.stem(&self.view);
            let mut written = WrittenFrame {
                frame: out.frame.clone(),
                file: None,
                exr: None,
                shadow_map: None,
            };
            if let Some(m) = &out.montage {
                let png = format!("{stem}.png");
                write_render(
                    &into.join(&png),
                    &m.photo.image,
                    &OutputLayers::default(),
                    &m.tone_map,
                    m.metadata.as_ref(),
                )
                .map_err(|e| fail_write(&into.join(&png), &e))?;
                written.file = Some(dir.join(png));
                if exr {
                    let name = format!("{stem}.exr");
                    write_render(
                        &into.join(&name),
                        &m.photo.image,
                        &m.photo.layers,
                        &m.tone_map,
                        m.metadata.as_ref(),
                    )
                    .map_err(|e| fail_write(&into.join(&name), &e))?;
                    written.exr = Some(dir.join(name));
                }
            }
            if let Some(map) = &out.shadow_map {
                let name = format!("{stem}_shadow.png");
                write_png(&into.join(&name), map)?;
                written.shadow_map = Some(dir.join(name));
            }
            frames.push(written);
        }
        let sheet = format!("{}_contact_sheet.png", self.view);
        write_png(&into.join(&sheet), &self.contact_sheet())?;
        Ok(WrittenStudy {
            frames,
            contact_sheet: dir.join(sheet),
        })
    }
}

fn fail_write(path: &Path, e: &dyn std::fmt::Display) -> StudyError {
    StudyError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}
