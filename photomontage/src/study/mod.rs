//! Sun and shadow studies: one view rendered at several dates × local clock times, as planning
//! authorities ask for (typically the equinoxes and solstices, 08:00–18:00).
//!
//! Each frame is the site with `lighting.time` set to the frame's instant (and any
//! `lighting.sun_manual` dropped), rendered through the one render entry point
//! ([`crate::site::render_photo::RenderPlan`]); so a frame is exactly the `photomontage render` of
//! that time, with the same seed. The sun of every frame is the NREL SPA (Reda & Andreas 2008) at
//! `[location]`, as `photomontage sun` computes it. Clock times are read in the site's
//! `location.time_zone` (IANA; daylight saving time applied, see [`crate::time_zone`]) unless they
//! carry their own UTC offset.
//!
//! Frames whose sun is at or below the horizon (SPA elevation with refraction ≤ 0°) are skipped; a
//! study with no daylight frame is an error.
//!
//! With the frames come plan-view shadow maps ([`shadow_map`]): the site from above, each cell
//! lit, in existing shadow, in shadow added by the proposal, or under the proposal.
//!
//! [`series::run_study`] makes a whole study (with an observer for progress and previews) and
//! [`series::StudyResult::write`] writes it; the CLI and the studio both use them.
//!
//! Known limitations: the frames of a study are rendered one after the other, each loading the
//! view again (the scene is small next to the tracing).

pub mod contact_sheet;
pub mod series;
pub mod shadow_map;

use std::sync::atomic::AtomicBool;

use chrono::{DateTime, FixedOffset, NaiveDate, NaiveTime, SecondsFormat};

use crate::render::TileProgress;
use crate::site::SiteDocument;
use crate::site::render_error::SiteRenderError;
use crate::site::render_photo::{RenderPlan, RenderRequest, RenderedPhoto};
use crate::site::site_time::{site_solar_position, site_time_zone};
use crate::time_zone::TimeZoneError;

/// Most frames one study may hold (dates × times), so a typo cannot queue days of rendering.
pub const MAX_FRAMES: usize = 500;

/// What can go wrong planning or rendering a study.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("--dates: `{text}` is not a date YYYY-MM-DD")]
    BadDate { text: String },
    #[error("--times: `{text}` is not a clock time HH:MM (optionally with a UTC offset, +02:00)")]
    BadTime { text: String },
    #[error("--{field}: empty list")]
    Empty { field: &'static str },
    #[error("{frames} frames (dates × times) is more than the {max} a study may hold")]
    TooManyFrames { frames: usize, max: usize },
    #[error(
        "--times {time}: no UTC offset and the site names no location.time_zone; set \
         location.time_zone (e.g. \"Europe/Zurich\") or give the offset (e.g. {time}+01:00)"
    )]
    NoTimeZone { time: String },
    #[error("{date} {time}: {source}")]
    LocalTime {
        date: NaiveDate,
        time: String,
        source: TimeZoneError,
    },
    #[error(
        "no daylight frame: the sun is at or below the horizon at every date and time asked \
         ({asked} frames); nothing written"
    )]
    NoDaylight { asked: usize },
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    #[error(
        "no shadow map: the site has no polygons or natural models with an extent in plan \
         (the ground)"
    )]
    NoGround,
    #[error("shadow map: {0}")]
    Scene(crate::scene::SceneError),
    #[error("study cancelled: nothing written")]
    Cancelled,
    #[error("nothing to make: ask for montages, shadow maps or both")]
    NothingToMake,
    #[error("shadow map cell {cell_m} m: must be a positive number of metres")]
    BadCell { cell_m: f64 },
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
}

/// A clock time of the study, with its own UTC offset when one was given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StudyTime {
    pub clock: NaiveTime,
    pub offset: Option<FixedOffset>,
}

/// Parses `2026-03-20,2026-06-21`.
///
/// # Errors
/// [`StudyError::BadDate`] naming the entry, [`StudyError::Empty`].
pub fn parse_dates(text: &str) -> Result<Vec<NaiveDate>, StudyError> {
    let dates = text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            NaiveDate::parse_from_str(s, "%Y-%m-%d")
                .map_err(|_| StudyError::BadDate { text: s.to_owned() })
        })
        .collect::<Result<Vec<_>, _>>()?;
    if dates.is_empty() {
        return Err(StudyError::Empty { field: "dates" });
    }
    Ok(dates)
}

/// Parses `09:00,12:00,15:30` (each optionally `HH:MM:SS`, optionally with `Z` or `±HH:MM`).
///
/// # Errors
/// [`StudyError::BadTime`] naming the entry, [`StudyError::Empty`].
pub fn parse_times(text: &str) -> Result<Vec<StudyTime>, StudyError> {
    let times = text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(parse_time)
        .collect::<Result<Vec<_>, _>>()?;
    if times.is_empty() {
        return Err(StudyError::Empty { field: "times" });
    }
    Ok(times)
}

fn parse_time(text: &str) -> Result<StudyTime, StudyError> {
    let bad = || StudyError::BadTime {
        text: text.to_owned(),
    };
    let (clock_text, offset) = if let Some(clock) = text.strip_suffix(['Z', 'z']) {
        (clock, Some(FixedOffset::east_opt(0).ok_or_else(bad)?))
    } else if let Some(k) = text.rfind(['+', '-']) {
        let offset = DateTime::parse_from_rfc3339(&format!("2000-01-01T00:00:00{}", &text[k..]))
            .map_err(|_| bad())?
            .offset()
            .to_owned();
        (&text[..k], Some(offset))
    } else {
        (text, None)
    };
    let clock = NaiveTime::parse_from_str(clock_text, "%H:%M")
        .or_else(|_| NaiveTime::parse_from_str(clock_text, "%H:%M:%S"))
        .map_err(|_| bad())?;
    Ok(StudyTime { clock, offset })
}

/// What a study asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRequest {
    /// The photo id.
    pub view: String,
    pub dates: Vec<NaiveDate>,
    pub times: Vec<StudyTime>,
    /// Fewest / most rays per pixel and seed; `None` takes the site's `[render]` value.
    pub spp_min: Option<u32>,
    pub spp_max: Option<u32>,
    pub seed: Option<u64>,
}

/// One date × time of a study and its sun.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyFrame {
    pub date: NaiveDate,
    pub clock: NaiveTime,
    /// The instant, with the offset in force at the site then.
    pub time: DateTime<FixedOffset>,
    /// SPA azimuth from true north, degrees clockwise.
    pub sun_azimuth_deg: f64,
    /// SPA topocentric elevation with refraction, degrees.
    pub sun_elevation_deg: f64,
}

impl StudyFrame {
    /// Whether the sun is above the horizon.
    #[must_use]
    pub fn is_daylight(&self) -> bool {
        self.sun_elevation_deg > 0.0
    }

    /// `<view>_<YYYY-MM-DD>_<HHMM>` (the file stem of the frame).
    #[must_use]
    pub fn stem(&self, view: &str) -> String {
        format!(
            "{view}_{}_{}",
            self.date.format("%Y-%m-%d"),
            self.clock.format("%H%M")
        )
    }

    /// The instant as RFC 3339 with its offset.
    #[must_use]
    pub fn time_rfc3339(&self) -> String {
        self.time.to_rfc3339_opts(SecondsFormat::Secs, false)
    }

    /// The label drawn on the contact sheet.
    #[must_use]
    pub fn label(&self) -> String {
        format!(
            "{} {} az {:.1} el {:.1}",
            self.date.format("%Y-%m-%d"),
            self.clock.format("%H:%M"),
            self.sun_azimuth_deg,
            self.sun_elevation_deg
        )
    }

    /// The site as it is rendered for this frame: `lighting.time` is the frame's instant, the
    /// manual sun is dropped.
    #[must_use]
    pub fn document(&self, doc: &SiteDocument) -> SiteDocument {
        let mut frame_doc = doc.clone();
        frame_doc.site.lighting.time = Some(self.time_rfc3339());
        frame_doc.site.lighting.sun_manual = None;
        frame_doc
    }
}

/// The frames of a study in date-major order, daylight or not, each with its SPA sun.
///
/// # Errors
/// [`StudyError::TooManyFrames`], [`StudyError::NoTimeZone`], [`StudyError::LocalTime`] for a
/// skipped or ambiguous local time, [`StudyError::Site`] without `[location]` or for an unknown
/// zone, [`StudyError::NoDaylight`] when no frame has the sun up.
pub fn plan_frames(
    doc: &SiteDocument,
    request: &StudyRequest,
) -> Result<Vec<StudyFrame>, StudyError> {
    let count = request.dates.len() * request.times.len();
    if count > MAX_FRAMES {
        return Err(StudyError::TooManyFrames {
            frames: count,
            max: MAX_FRAMES,
        });
    }
    let zone = site_time_zone(&doc.site)?;
    let mut frames = Vec::with_capacity(count);
    for &date in &request.dates {
        for t in &request.times {
            let local = date.and_time(t.clock);
            let time = match (t.offset, zone.as_ref()) {
                (Some(offset), _) => {
                    local.and_local_timezone(offset).single().ok_or_else(|| {
                        StudyError::BadTime {
                            text: t.clock.to_string(),
                        }
                    })?
                }
                (None, Some(zone)) => {
                    zone.resolve(local)
                        .map_err(|source| StudyError::LocalTime {
                            date,
                            time: t.clock.format("%H:%M").to_string(),
                            source,
                        })?
                }
                (None, None) => {
                    return Err(StudyError::NoTimeZone {
                        time: t.clock.format("%H:%M").to_string(),
                    });
                }
            };
            let pos = site_solar_position(&doc.site, &time, &request.view)?;
            frames.push(StudyFrame {
                date,
                clock: t.clock,
                time,
                sun_azimuth_deg: pos.azimuth_deg,
                sun_elevation_deg: pos.elevation_deg,
            });
        }
    }
    if !frames.iter().any(StudyFrame::is_daylight) {
        return Err(StudyError::NoDaylight { asked: count });
    }
    Ok(frames)
}

/// The render plan of `frame` (the same as `photomontage render` of the frame's site).
///
/// # Errors
/// As [`RenderPlan::new`].
pub fn frame_plan(
    frame_doc: &SiteDocument,
    request: &StudyRequest,
) -> Result<RenderPlan, StudyError> {
    let render_request = RenderRequest {
        spp_min: request.spp_min,
        spp_max: request.spp_max,
        seed: request.seed,
        ..RenderRequest::view(&request.view)
    };
    Ok(RenderPlan::new(frame_doc, &render_request)?)
}

/// Renders one frame through [`RenderPlan::render`].
///
/// # Errors
/// As [`RenderPlan::new`] and [`RenderPlan::render`].
pub fn render_frame(
    doc: &SiteDocument,
    frame: &StudyFrame,
    request: &StudyRequest,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<(RenderPlan, RenderedPhoto), StudyError> {
    let frame_doc = frame.document(doc);
    let plan = frame_plan(&frame_doc, request)?;
    let rendered = plan.render(&frame_doc, on_tile, cancel)?;
    Ok((plan, rendered))
}

/// The plan-view shadow map of `frame` (see [`shadow_map`]): the site's scene with the frame's
/// sun as the renderer places it for `request.view`.
///
/// # Errors
/// As [`crate::site::site_scene::site_scene`], [`crate::site::render::site_sun_dir`] and
/// [`shadow_map::shadow_map`].
pub fn frame_shadow_map(
    doc: &SiteDocument,
    frame: &StudyFrame,
    view: &str,
    cell_m: f64,
) -> Result<shadow_map::ShadowMap, StudyError> {
    let frame_doc = frame.document(doc);
    let sun_dir_in_world = crate::site::render::site_sun_dir(&frame_doc, view)?;
    let scene = crate::site::site_scene::site_scene(&frame_doc)?;
    shadow_map::shadow_map(&scene.scene, &sun_dir_in_world, cell_m)
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
