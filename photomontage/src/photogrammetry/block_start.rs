//! Starting cameras for photos that cannot be resected from their own control: the classical
//! sequence of analytical photogrammetry (Wolf & Dewitt, *Elements of Photogrammetry*, ch. 11
//! and 17; Snavely et al., *Photo tourism*, 2006, §4.2 for the incremental order):
//!
//! 1. when fewer than two photos are solved in the world already, the **relative orientation**
//!    of the pair sharing the most tie points defines a model frame (camera a at the origin,
//!    baseline 1); the relative orientation itself is supplied by the caller (the `opencv`
//!    feature brings Nistér's five-point solver, `features::relative_orientation`);
//! 2. tie points seen by two or more placed photos are **intersected** ([`super::intersect`]);
//!    those whose reprojection residual exceeds [`TIE_GATE_SIGMA`] σ are rejected;
//! 3. the unplaced photo seeing the most intersected tie points is **resected** from them
//!    ([`super::resect`], P3P RANSAC and least squares), and steps 2–3 repeat;
//! 4. in a model frame, control points seen in two or more photos are intersected and the
//!    model is moved onto the world by **absolute orientation** ([`super::absolute`]): from three
//!    such points, or from two and the rays of control seen in one photo only.
//!
//! The result only starts the bundle adjustment, which then weighs all observations.
//!
//! # Known limitations
//! One model is built (the largest connected set of photos from the best pair); photos linked
//! to it by fewer than [`MIN_RESECTION_TIES`] intersected tie points stay unplaced. The datum
//! needs at least two control points intersected in the model plus one more control ray.

use std::collections::{HashMap, HashSet};

use nalgebra::{Point2, Point3, Rotation3, Vector3};

use super::absolute::{
    ControlRay, Similarity, similarity_from_points, similarity_from_two_points_and_rays,
};
use super::{ControlPoint, ImageObservation, PhotogrammetryError, ResectionOptions, intersect};
use crate::camera::{Camera, Intrinsics, Pose};

/// A tie point whose intersection leaves a residual above this many σ in a photo is rejected
/// (gross mismatches pass the epipolar test when they lie along the epipolar line).
pub const TIE_GATE_SIGMA: f64 = 4.0;
/// A pair needs this many shared tie points for its relative orientation (5-point RANSAC wants
/// a margin well above its minimal 5).
pub const MIN_RELATIVE_TIES: usize = 15;
/// A photo is resected from at least this many intersected tie points (P3P RANSAC plus
/// redundancy for the outlier test).
pub const MIN_RESECTION_TIES: usize = 8;

/// Relative orientation of photo b with respect to photo a: a point's camera-b coordinates are
/// `rotation_b_from_a · x_a + translation_b_from_a`, with |translation| = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativePose {
    pub rotation_b_from_a: Rotation3<f64>,
    pub translation_b_from_a: Vector3<f64>,
}

/// Computes the relative orientation of photo b with respect to photo a from their matched
/// pixels (a, b).
pub type RelativeOrientation<'a> = &'a dyn Fn(
    &StartPhoto,
    &StartPhoto,
    &[(Point2<f64>, Point2<f64>)],
) -> Result<RelativePose, PhotogrammetryError>;

/// One photo of the block.
#[derive(Debug, Clone)]
pub struct StartPhoto {
    pub id: String,
    pub intrinsics: Intrinsics,
    /// Its camera when already solved in the world (e.g. resected from control).
    pub camera: Option<Camera>,
    /// Control and tie observations (control observations found wrong left out by the caller).
    pub observations: Vec<ImageObservation>,
}

/// What [`start_block`] found.
#[derive(Debug, Clone)]
pub struct BlockStart {
    /// Per input photo, its world camera (the given one, or the one placed here).
    pub cameras: Vec<Option<Camera>>,
    /// Tie points rejected by the intersection gate (leave them out of the adjustment).
    pub rejected_ties: HashSet<String>,
    /// Per input photo left unplaced, why.
    pub unplaced: Vec<(String, String)>,
    /// Tie points intersected at the end, and the photos' pair used for the model (if any).
    pub tie_points: usize,
    pub model_pair: Option<(String, String)>,
    pub warnings: Vec<String>,
}

/// Places the photos of a block by relative orientation, intersection, resection and absolute
/// orientation (see the module doc). `relative` is needed only when fewer than two photos come
/// with a world camera.
///
/// # Errors
/// `NotEnoughPoints` when no pair shares [`MIN_RELATIVE_TIES`] tie points or the control does
/// not fix the datum; errors of the relative orientation.
pub fn start_block(
    photos: &[StartPhoto],
    control: &[ControlPoint],
    relative: Option<RelativeOrientation<'_>>,
    seed: u64,
) -> Result<BlockStart, PhotogrammetryError> {
    let control_by_id: HashMap<&str, &ControlPoint> =
        control.iter().map(|c| (c.id.as_str(), c)).collect();
    let mut seen_in: HashMap<&str, usize> = HashMap::new();
    for p in photos {
        for o in &p.observations {
            if !control_by_id.contains_key(o.point_id.as_str()) {
                *seen_in.entry(o.point_id.as_str()).or_default() += 1;
            }
        }
    }
    let is_tie = |id: &str| seen_in.get(id).is_some_and(|&n| n >= 2);
    let mut warnings = Vec::new();
    let world_solved = photos.iter().filter(|p| p.camera.is_some()).count();
    let in_world = world_solved >= 2;
    let mut cameras: Vec<Option<Camera>> = vec![None; photos.len()];
    let mut model_pair = None;
    if in_world {
        for (slot, p) in cameras.iter_mut().zip(photos) {
            *slot = p.camera;
        }
    } else {
        let relative = relative.ok_or(PhotogrammetryError::NotEnoughPoints {
            required: 2,
            found: world_solved,
        })?;
        let (a, b, shared) =
            best_pair(photos, &is_tie).ok_or(PhotogrammetryError::NotEnoughPoints {
                required: MIN_RELATIVE_TIES,
                found: 0,
            })?;
        if shared.len() < MIN_RELATIVE_TIES {
            return Err(PhotogrammetryError::NotEnoughPoints {
                required: MIN_RELATIVE_TIES,
                found: shared.len(),
            });
        }
        let pa = &photos[a];
        let pb = &photos[b];
        let rel = relative(pa, pb, &shared)?;
        cameras[a] = Some(Camera {
            intrinsics: pa.intrinsics,
            pose: Pose {
                rotation_world_from_camera: Rotation3::identity(),
                camera_center_in_world: Point3::origin(),
            },
        });
        let r_model_from_b = rel.rotation_b_from_a.inverse();
        cameras[b] = Some(Camera {
            intrinsics: pb.intrinsics,
            pose: Pose {
                rotation_world_from_camera: r_model_from_b,
                camera_center_in_world: Point3::from(-(r_model_from_b * rel.translation_b_from_a)),
            },
        });
        model_pair = Some((pa.id.clone(), pb.id.clone()));
    }

    // Grow: intersect, resect the best-connected unplaced photo, repeat.
    let mut rejected_ties = HashSet::new();
    let mut points;
    loop {
        points = intersect_ties(photos, &cameras, &is_tie, &mut rejected_ties);
        let next = photos
            .iter()
            .enumerate()
            .filter(|(i, _)| cameras[*i].is_none())
            .map(|(i, p)| {
                let n = p
                    .observations
                    .iter()
                    .filter(|o| points.contains_key(o.point_id.as_str()))
                    .count();
                (i, n)
            })
            .max_by_key(|&(i, n)| (n, std::cmp::Reverse(i)));
        let Some((i, n)) = next.filter(|&(_, n)| n >= MIN_RESECTION_TIES) else {
            break;
        };
        let p = &photos[i];
        let as_control: Vec<ControlPoint> = p
            .observations
            .iter()
            .filter_map(|o| {
                points.get(o.point_id.as_str()).map(|x| ControlPoint {
                    id: o.point_id.clone(),
                    point_in_world: *x,
                    sigma_m: [0.0; 3],
                })
            })
            .collect();
        let obs: Vec<ImageObservation> = p
            .observations
            .iter()
            .filter(|o| points.contains_key(o.point_id.as_str()))
            .cloned()
            .collect();
        let mut options = ResectionOptions::new(p.intrinsics);
        options.seed = seed;
        match super::resect(&as_control, &obs, &options) {
            Ok(r) => cameras[i] = Some(r.camera),
            Err(e) => {
                warnings.push(format!(
                    "photo {}: resection from {n} tie points failed: {e}",
                    p.id
                ));
                break;
            }
        }
    }

    if !in_world {
        let similarity = absolute_orientation(photos, &cameras, control)?;
        for c in cameras.iter_mut().flatten() {
            *c = similarity.camera_in_world(c);
        }
    }
    let unplaced = photos
        .iter()
        .zip(&cameras)
        .filter(|(_, c)| c.is_none())
        .map(|(p, _)| {
            let n = p
                .observations
                .iter()
                .filter(|o| points.contains_key(o.point_id.as_str()))
                .count();
            (
                p.id.clone(),
                format!(
                    "sees {n} tie points intersected in the block ({MIN_RESECTION_TIES} needed)"
                ),
            )
        })
        .collect();
    Ok(BlockStart {
        cameras,
        rejected_ties,
        unplaced,
        tie_points: points.len(),
        model_pair,
        warnings,
    })
}

/// Pixels of the tie points two photos share: (in a, in b).
type SharedPixels = Vec<(Point2<f64>, Point2<f64>)>;

/// The pair of photos sharing the most tie points, with the shared pixels (a, b).
fn best_pair(
    photos: &[StartPhoto],
    is_tie: &dyn Fn(&str) -> bool,
) -> Option<(usize, usize, SharedPixels)> {
    let mut best: Option<(usize, usize, SharedPixels)> = None;
    for a in 0..photos.len() {
        let by_id: HashMap<&str, Point2<f64>> = photos[a]
            .observations
            .iter()
            .filter(|o| is_tie(&o.point_id))
            .map(|o| (o.point_id.as_str(), o.pixel))
            .collect();
        for b in a + 1..photos.len() {
            let shared: Vec<_> = photos[b]
                .observations
                .iter()
                .filter_map(|o| by_id.get(o.point_id.as_str()).map(|pa| (*pa, o.pixel)))
                .collect();
            if best.as_ref().is_none_or(|(_, _, s)| shared.len() > s.len()) {
                best = Some((a, b, shared));
            }
        }
    }
    best
}

/// Intersects every tie point seen by two or more placed photos; rejects those over the gate.
fn intersect_ties<'p>(
    photos: &'p [StartPhoto],
    cameras: &[Option<Camera>],
    is_tie: &dyn Fn(&str) -> bool,
    rejected: &mut HashSet<String>,
) -> HashMap<&'p str, Point3<f64>> {
    let mut rays: HashMap<&str, Vec<(Camera, ImageObservation)>> = HashMap::new();
    for (p, c) in photos.iter().zip(cameras) {
        let Some(c) = c else { continue };
        for o in &p.observations {
            if is_tie(&o.point_id) && !rejected.contains(&o.point_id) {
                rays.entry(o.point_id.as_str())
                    .or_default()
                    .push((*c, o.clone()));
            }
        }
    }
    let mut points = HashMap::new();
    let mut ids: Vec<&str> = rays.keys().copied().collect();
    ids.sort_unstable();
    for id in ids {
        let r = &rays[id];
        if r.len() < 2 {
            continue;
        }
        match intersect(r) {
            Ok(x)
                if x.residuals_px
                    .iter()
                    .zip(r)
                    .all(|(v, (_, o))| v[0].hypot(v[1]) <= TIE_GATE_SIGMA * o.sigma_px) =>
            {
                points.insert(id, x.point_in_world);
            }
            _ => {
                rejected.insert(id.to_owned());
            }
        }
    }
    points
}

/// The similarity from the model onto the world, from the control seen in the placed photos.
fn absolute_orientation(
    photos: &[StartPhoto],
    cameras: &[Option<Camera>],
    control: &[ControlPoint],
) -> Result<Similarity, PhotogrammetryError> {
    let mut pairs = Vec::new();
    let mut pair_ids = Vec::new();
    let mut single = Vec::new();
    for c in control {
        let rays: Vec<(Camera, ImageObservation)> = photos
            .iter()
            .zip(cameras)
            .filter_map(|(p, cam)| {
                let cam = cam.as_ref()?;
                let o = p.observations.iter().find(|o| o.point_id == c.id)?;
                Some((*cam, o.clone()))
            })
            .collect();
        match rays.len() {
            0 => {}
            1 => single.push((c, rays[0].clone())),
            _ => {
                if let Ok(x) = intersect(&rays) {
                    pairs.push((x.point_in_world, c.point_in_world));
                    pair_ids.push(c.id.as_str());
                }
            }
        }
    }
    let datum = |what: String| PhotogrammetryError::Degenerate {
        reason: format!(
            "the control cannot fix the block's position, scale and rotation: {what}; a third \
             control point seen in two placed photos, or one more control point seen in one, is needed"
        ),
    };
    match pairs.len() {
        n if n >= 3 => similarity_from_points(&pairs),
        2 if !single.is_empty() => {
            let rays: Vec<ControlRay> = single
                .iter()
                .map(|(c, (cam, o))| ControlRay {
                    origin_in_model: cam.pose.camera_center_in_world,
                    dir_in_model: cam.ray_dir_in_world(o.pixel),
                    point_in_world: c.point_in_world,
                })
                .collect();
            similarity_from_two_points_and_rays([pairs[0], pairs[1]], &rays)
        }
        2 => Err(datum(format!(
            "only {} and {} are seen in the placed photos, and the block can turn about their line",
            pair_ids[0], pair_ids[1]
        ))),
        _ => Err(datum(format!(
            "{} control point(s) seen in two placed photos ({}), {} in one",
            pairs.len(),
            pair_ids.join(", "),
            single.len()
        ))),
    }
}

#[cfg(test)]
#[path = "block_start_tests.rs"]
mod tests;
