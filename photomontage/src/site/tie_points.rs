//! Tie points found by feature matching, in the site: writing the tracks of a match as
//! observations (ids `sift_NNNNN`, replacing those of an earlier match), listing the tracks with
//! their reprojection RMS in the stored cameras, and rejecting a track (its observations
//! disabled, so the edit is reversible and the solve leaves it out).
//!
//! Pure Rust: the studio lists and rejects tracks without the `opencv` feature; only finding
//! them needs it (`site::tie_matching`).
//!
//! # Known limitations
//! Hand-picked tie points (any other id) are listed too but never replaced by a new match.

use std::collections::BTreeMap;

use nalgebra::{Point2, Point3};

use super::{Observation, Site, stored_camera};

/// Id prefix of tie points written by a feature match.
pub const MATCHED_PREFIX: &str = "sift_";

/// One observation of a track to write: photo id, pixel, σ.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackObservation {
    pub photo: String,
    pub pixel_px: [f64; 2],
    pub sigma_px: f64,
}

/// Whether `id` names a tie point written by a feature match.
#[must_use]
pub fn is_matched(id: &str) -> bool {
    id.strip_prefix(MATCHED_PREFIX)
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// Replaces the matched tie points of `site` (observations and estimated points with
/// [`MATCHED_PREFIX`] ids) by `tracks`, numbered from 1 in the given order. Returns the ids.
pub fn replace_matched_tracks(site: &mut Site, tracks: &[Vec<TrackObservation>]) -> Vec<String> {
    site.observations.retain(|o| !is_matched(&o.point));
    site.tie_points.retain(|t| !is_matched(&t.id));
    let width = tracks.len().to_string().len().max(5);
    let mut ids = Vec::with_capacity(tracks.len());
    for (i, track) in tracks.iter().enumerate() {
        let id = format!("{MATCHED_PREFIX}{:0width$}", i + 1);
        for o in track {
            site.observations.push(Observation {
                photo: o.photo.clone(),
                point: id.clone(),
                x_px: o.pixel_px[0],
                y_px: o.pixel_px[1],
                sigma_px: o.sigma_px,
                enabled: true,
            });
        }
        ids.push(id);
    }
    ids
}

/// One tie point of the site as the Tie points panel lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackSummary {
    pub id: String,
    /// Photos with an enabled observation of it.
    pub photos: Vec<String>,
    /// RMS reprojection residual per coordinate over its enabled observations in solved photos,
    /// when the point has coordinates (after a solve).
    pub rms_px: Option<f64>,
    /// Every observation disabled (the user rejected it).
    pub rejected: bool,
}

/// The site's tie points (observed points that are not control points), in id order.
#[must_use]
pub fn track_summaries(site: &Site) -> Vec<TrackSummary> {
    let control: std::collections::HashSet<&str> =
        site.control_points.iter().map(|c| c.id.as_str()).collect();
    let mut by_id: BTreeMap<&str, Vec<&Observation>> = BTreeMap::new();
    for o in &site.observations {
        if !control.contains(o.point.as_str()) {
            by_id.entry(o.point.as_str()).or_default().push(o);
        }
    }
    let cameras: BTreeMap<&str, crate::camera::Camera> = site
        .photos
        .iter()
        .filter_map(|p| stored_camera(site, &p.id).map(|c| (p.id.as_str(), c)))
        .collect();
    by_id
        .into_iter()
        .map(|(id, obs)| {
            let enabled: Vec<&&Observation> = obs.iter().filter(|o| o.enabled).collect();
            let xyz = site
                .tie_points
                .iter()
                .find(|t| t.id == id)
                .map(|t| Point3::from(t.xyz));
            let rms_px = xyz.and_then(|x| {
                let squares: Vec<f64> = enabled
                    .iter()
                    .filter_map(|o| {
                        let p = cameras.get(o.photo.as_str())?.project(&x)?;
                        Some((p - Point2::new(o.x_px, o.y_px)).norm_squared())
                    })
                    .collect();
                (!squares.is_empty())
                    .then(|| (squares.iter().sum::<f64>() / (2.0 * squares.len() as f64)).sqrt())
            });
            TrackSummary {
                id: id.to_owned(),
                photos: enabled.iter().map(|o| o.photo.clone()).collect(),
                rms_px,
                rejected: enabled.is_empty(),
            }
        })
        .collect()
}

/// Rejects (or, with `rejected = false`, restores) a tie point: every observation of it is
/// disabled (enabled). Returns how many observations changed.
pub fn set_track_rejected(site: &mut Site, id: &str, rejected: bool) -> usize {
    let mut changed = 0;
    for o in site.observations.iter_mut().filter(|o| o.point == id) {
        if o.enabled == rejected {
            o.enabled = !rejected;
            changed += 1;
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use crate::site::{Exterior, Interior, Photo, TiePoint};

    /// Pinhole arithmetic on exact values: equal to rounding.
    const EXACT_PX: f64 = 1e-9;

    fn obs(photo: &str, x: f64, y: f64) -> TrackObservation {
        TrackObservation {
            photo: photo.into(),
            pixel_px: [x, y],
            sigma_px: 0.7,
        }
    }

    /// Photo `a` at the origin looking north (+Y) with f = 100 px on 201 × 101 px.
    fn site_with_a_solved_photo() -> Site {
        let mut site = Site::default();
        site.photos.push(Photo {
            id: "a".into(),
            file: "a.jpg".into(),
            taken_at: None,
            profile: None,
            interior: Some(Interior {
                focal_px: 100.0,
                principal_point_px: Some([100.0, 50.0]),
                distortion: crate::camera::BrownConrady::default(),
                image_size_px: Some([201, 101]),
            }),
            self_calibration: crate::site::SelfCalibrationFlags::default(),
            // Camera x = east, y = down, z = north.
            exterior: Some(Exterior {
                camera_center: [0.0, 0.0, 0.0],
                rotation_world_from_camera: [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
                rms_px: 0.0,
                sigma_center_m: [0.0; 3],
                solved_by: "resection".into(),
            }),
        });
        site
    }

    #[test]
    fn a_new_match_replaces_the_old_one_and_keeps_hand_picked_ties() {
        let mut site = site_with_a_solved_photo();
        site.observations.push(Observation {
            photo: "a".into(),
            point: "corner7".into(),
            x_px: 1.0,
            y_px: 2.0,
            sigma_px: 0.5,
            enabled: true,
        });
        let first =
            replace_matched_tracks(&mut site, &[vec![obs("a", 1.0, 1.0), obs("b", 2.0, 2.0)]]);
        assert_eq!(first, ["sift_00001"]);
        let second = replace_matched_tracks(
            &mut site,
            &[
                vec![obs("a", 3.0, 3.0), obs("b", 4.0, 4.0)],
                vec![obs("a", 5.0, 5.0), obs("b", 6.0, 6.0)],
            ],
        );
        assert_eq!(second, ["sift_00001", "sift_00002"]);
        assert_eq!(site.observations.len(), 1 + 4);
        assert!(site.observations.iter().any(|o| o.point == "corner7"));
        assert!(is_matched("sift_00002") && !is_matched("sift_") && !is_matched("sift_x1"));
    }

    #[test]
    fn summaries_give_the_reprojection_rms_and_rejection_is_reversible() {
        let mut site = site_with_a_solved_photo();
        replace_matched_tracks(
            &mut site,
            &[vec![obs("a", 103.0, 46.0), obs("b", 0.0, 0.0)]],
        );
        // 10 m north, 1 m east, 0.5 m up: projects to (110, 45); observed (103, 46).
        site.tie_points.push(TiePoint {
            id: "sift_00001".into(),
            xyz: [1.0, 10.0, 0.5],
            sigma_m: [0.0; 3],
        });
        let s = track_summaries(&site);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].photos, ["a", "b"]);
        // Only photo a is solved: residual (7, −1) → RMS per coordinate √(50/2) = 5.
        assert!(
            (s[0].rms_px.expect("solved") - 5.0).abs() < EXACT_PX,
            "{s:?}"
        );
        assert!(!s[0].rejected);
        assert_eq!(set_track_rejected(&mut site, "sift_00001", true), 2);
        let s = track_summaries(&site);
        assert!(s[0].rejected && s[0].photos.is_empty() && s[0].rms_px.is_none());
        assert_eq!(set_track_rejected(&mut site, "sift_00001", false), 2);
        assert!(!track_summaries(&site)[0].rejected);
    }
}
