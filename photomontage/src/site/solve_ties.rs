//! Photos that cannot be resected from their own control, placed by tie points
//! ([`crate::photogrammetry::block_start`]) before the bundle adjustment refines them.
//!
//! A photo whose control observations contain a mislabelled pair (two plane points on one
//! pixel, [`PhotogrammetryError::CoincidentObservations`]) enters the block without both; after
//! the adjustment the warning of [`which_label_fits`] says which label the adjusted camera
//! supports.

use std::collections::{HashMap, HashSet};

use super::{PhotoSolution, PhotoSolveError, Prepared};
use crate::photogrammetry::block_start::{StartPhoto, start_block};
use crate::photogrammetry::{ControlPoint, PhotogrammetryError};
use crate::site::Site;

/// `solved_by` of a photo placed by tie points and not (yet) adjusted.
pub(super) const SOLVED_BY_TIES: &str = "tie_points";

/// What placing by tie points achieved.
pub(super) struct Placed {
    /// The newly placed photos' preparations (their solutions are pushed to the list).
    pub prepared: HashMap<String, Prepared>,
    /// Why a photo stayed unplaced.
    pub unplaced: HashMap<String, String>,
    pub rejected_ties: HashSet<String>,
    /// (photo, first, second) of mislabelled pairs left out.
    pub mislabelled: Vec<(String, String, String)>,
}

/// The relative orientation the build has (the five-point solver needs OpenCV).
#[cfg(feature = "opencv")]
fn relative() -> Option<crate::photogrammetry::block_start::RelativeOrientation<'static>> {
    Some(&crate::features::relative_orientation)
}
#[cfg(not(feature = "opencv"))]
fn relative() -> Option<crate::photogrammetry::block_start::RelativeOrientation<'static>> {
    None
}

/// Places the `unresected` photos by tie points when the site has any (see the module doc).
pub(super) fn place_by_tie_points(
    site: &Site,
    control: &[ControlPoint],
    photos: &mut Vec<PhotoSolution>,
    prepared_by_id: &HashMap<String, Prepared>,
    unresected: Vec<(Prepared, PhotoSolveError)>,
    warnings: &mut Vec<String>,
) -> Placed {
    let mut placed = Placed {
        prepared: HashMap::new(),
        unplaced: HashMap::new(),
        rejected_ties: HashSet::new(),
        mislabelled: Vec::new(),
    };
    let control_ids: HashSet<&str> = control.iter().map(|c| c.id.as_str()).collect();
    let has_ties = unresected.iter().any(|(p, _)| {
        p.observations
            .iter()
            .any(|o| !control_ids.contains(o.point_id.as_str()))
    });
    if !has_ties {
        return placed;
    }
    let mut start_photos = Vec::new();
    for s in photos.iter() {
        let Some(prep) = prepared_by_id.get(&s.id) else {
            continue;
        };
        let outliers: HashSet<&str> = s.outliers.iter().map(String::as_str).collect();
        start_photos.push(StartPhoto {
            id: s.id.clone(),
            intrinsics: s.camera.intrinsics,
            camera: Some(s.camera),
            observations: prep
                .observations
                .iter()
                .filter(|o| !outliers.contains(o.point_id.as_str()))
                .cloned()
                .collect(),
        });
    }
    let mut errors = HashMap::new();
    let mut excluded: HashMap<String, Vec<String>> = HashMap::new();
    for (prep, error) in &unresected {
        let mut left_out = Vec::new();
        if let PhotoSolveError::Solver(PhotogrammetryError::CoincidentObservations {
            first,
            second,
            ..
        }) = error
        {
            warnings.push(format!(
                "photo {}: {error}; both left out of its solution by tie points",
                prep.id
            ));
            placed
                .mislabelled
                .push((prep.id.clone(), first.clone(), second.clone()));
            left_out = vec![first.clone(), second.clone()];
        }
        start_photos.push(StartPhoto {
            id: prep.id.clone(),
            intrinsics: prep.intrinsics,
            camera: None,
            observations: prep
                .observations
                .iter()
                .filter(|o| !left_out.contains(&o.point_id))
                .cloned()
                .collect(),
        });
        errors.insert(prep.id.clone(), error.to_string());
        excluded.insert(prep.id.clone(), left_out);
    }
    let start = match start_block(&start_photos, control, relative(), site.solve.seed) {
        Ok(start) => start,
        Err(e) => {
            #[cfg(feature = "opencv")]
            for (prep, _) in &unresected {
                placed.unplaced.insert(
                    prep.id.clone(),
                    format!("its tie points could not place it either: {e}"),
                );
            }
            #[cfg(not(feature = "opencv"))]
            let _ = e;
            return placed;
        }
    };
    warnings.extend(start.warnings.iter().cloned());
    if !start.rejected_ties.is_empty() {
        warnings.push(format!(
            "{} tie points left out: their rays do not meet within {} σ",
            start.rejected_ties.len(),
            crate::photogrammetry::block_start::TIE_GATE_SIGMA
        ));
    }
    if let Some((a, b)) = &start.model_pair {
        warnings.push(format!(
            "photos placed by tie points: relative orientation of {a} and {b}, {} tie points intersected",
            start.tie_points
        ));
    }
    for (id, reason) in &start.unplaced {
        placed
            .unplaced
            .insert(id.clone(), format!("not placed by tie points: it {reason}"));
    }
    for (prep, _) in unresected {
        let index = start_photos.iter().position(|p| p.id == prep.id);
        let Some(camera) = index.and_then(|i| start.cameras[i]) else {
            continue;
        };
        let outliers = excluded.remove(&prep.id).unwrap_or_default();
        let used = prep
            .observations
            .iter()
            .filter(|o| {
                !outliers.contains(&o.point_id) && !start.rejected_ties.contains(&o.point_id)
            })
            .count();
        photos.push(PhotoSolution {
            id: prep.id.clone(),
            camera,
            rms_px: f64::NAN,
            redundancy: 2 * i64::try_from(used).unwrap_or(i64::MAX / 4) - 6,
            sigma_center_m: [f64::NAN; 3],
            sigma_angles_deg: [f64::NAN; 3],
            sigma_focal_px: None,
            residuals: Vec::new(),
            outliers,
            warnings: vec![format!(
                "placed by tie points: resection from its control alone failed ({})",
                errors.get(&prep.id).map_or("", String::as_str)
            )],
            // What the user asked to estimate: the bundle adjustment frees what the block supports.
            estimated: prep.self_calibration,
            solved_by: SOLVED_BY_TIES,
            focal_source: prep.focal_source,
            radial_pattern: None,
            opencv_check: None,
        });
        placed.prepared.insert(prep.id.clone(), prep);
    }
    placed.rejected_ties = start.rejected_ties;
    placed
}

/// Which of a mislabelled pair the adjusted camera supports: its residual rows (kept for left-out
/// observations) compared.
pub(super) fn which_label_fits(s: &PhotoSolution, a: &str, b: &str) -> String {
    let residual = |id: &str| {
        s.residuals
            .iter()
            .find(|r| r.point_id == id)
            .map(|r| r.residual_px[0].hypot(r.residual_px[1]))
    };
    match (residual(a), residual(b)) {
        (Some(ra), Some(rb)) => {
            let (fits, fr, wrong, wr) = if ra <= rb {
                (a, ra, b, rb)
            } else {
                (b, rb, a, ra)
            };
            format!(
                "photo {}: of the pair left out, {fits} fits the adjusted camera ({fr:.1} px) and {wrong} does not ({wr:.1} px): the label {wrong} is wrong",
                s.id
            )
        }
        _ => format!(
            "photo {}: observations of {a} and {b} lie on one pixel; one label is wrong",
            s.id
        ),
    }
}
