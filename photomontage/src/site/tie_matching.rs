//! `match`: tie points of a site by SIFT feature matching ([`crate::features`], cargo feature
//! `opencv`) written into the site as observations ([`super::tie_points`]).
//!
//! Tracks seen by two or more photos that are already solved are intersected with the stored
//! cameras ([`crate::photogrammetry::intersect`]) and dropped when a residual exceeds
//! [`crate::photogrammetry::block_start::TIE_GATE_SIGMA`] σ; the others are checked the same way
//! when `solve` places their photos.
//!
//! # Known limitations
//! All photos of the site are matched against each other (no pair selection by position).

use nalgebra::Point2;

use super::tie_points::{TrackObservation, replace_matched_tracks};
use super::{Site, SiteDocument, stored_camera};
use crate::features::{FeatureError, MatchInput, MatchOptions, MatchReport, match_photos};
use crate::photo::DecodeLimits;
use crate::photogrammetry::block_start::TIE_GATE_SIGMA;
use crate::photogrammetry::{ImageObservation, intersect};

/// σ of a SIFT keypoint position in detection pixels (sub-pixel refined extremum; Lowe 2004
/// §4); multiplied by the detection scale for full-resolution pixels.
pub const KEYPOINT_SIGMA_PX: f64 = 0.5;

/// What a match did to the site.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SiteMatch {
    pub report: MatchReport,
    /// Tie points written.
    pub written: usize,
    /// Tracks intersected in already solved photos, and of those dropped by the gate.
    pub checked: usize,
    pub rejected_by_reprojection: usize,
}

/// Matches the photos of `doc` and returns the site with the new tie-point observations (earlier
/// matched tie points replaced).
///
/// # Errors
/// [`FeatureError`] from the matching (a photo missing or undecodable, photos sharing no
/// features, …); nothing is returned then, so the site stays unchanged.
pub fn match_site(
    doc: &SiteDocument,
    options: &MatchOptions,
    limits: &DecodeLimits,
) -> Result<(Site, SiteMatch), FeatureError> {
    let site = &doc.site;
    let inputs: Vec<MatchInput> = site
        .photos
        .iter()
        .map(|p| MatchInput {
            id: p.id.clone(),
            path: doc.resolve(&p.file),
        })
        .collect();
    let report = match_photos(&inputs, options, limits)?;
    let cameras: Vec<_> = site
        .photos
        .iter()
        .map(|p| stored_camera(site, &p.id))
        .collect();
    let mut tracks = Vec::new();
    let (mut checked, mut rejected) = (0, 0);
    for t in &report.tracks {
        let obs: Vec<TrackObservation> = t
            .observations
            .iter()
            .map(|(photo, px)| TrackObservation {
                photo: site.photos[*photo].id.clone(),
                pixel_px: [px.x, px.y],
                sigma_px: KEYPOINT_SIGMA_PX * report.photos[*photo].detection_scale,
            })
            .collect();
        let rays: Vec<_> = t
            .observations
            .iter()
            .zip(&obs)
            .filter_map(|((photo, px), o)| {
                cameras[*photo].map(|c| {
                    (
                        c,
                        ImageObservation {
                            point_id: "track".into(),
                            pixel: Point2::new(px.x, px.y),
                            sigma_px: o.sigma_px,
                        },
                    )
                })
            })
            .collect();
        if rays.len() >= 2 {
            checked += 1;
            let ok = intersect(&rays).is_ok_and(|x| {
                x.residuals_px
                    .iter()
                    .zip(&rays)
                    .all(|(v, (_, o))| v[0].hypot(v[1]) <= TIE_GATE_SIGMA * o.sigma_px)
            });
            if !ok {
                rejected += 1;
                continue;
            }
        }
        tracks.push(obs);
    }
    let mut out = site.clone();
    let ids = replace_matched_tracks(&mut out, &tracks);
    Ok((
        out,
        SiteMatch {
            report,
            written: ids.len(),
            checked,
            rejected_by_reprojection: rejected,
        },
    ))
}
