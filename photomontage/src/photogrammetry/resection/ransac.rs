//! Robust start of the resection: RANSAC (Fischler & Bolles 1981) over minimal P3P samples
//! ([`crate::photogrammetry::p3p`]) with the MSAC score (Torr & Zisserman 2000) and a local least-squares
//! optimisation of the best candidates (LO-RANSAC, Chum, Matas & Kittler 2003). Small point
//! sets are enumerated exhaustively, larger ones sampled with a seeded `ChaCha8Rng`.
//!
//! Cheirality (Hartley & Zisserman 2004 §21.1): a pose counts a point as an inlier only when
//! the point lies in front of it (depth > 0), and a P3P pose that puts one of its own three
//! points behind the camera is dropped. When the best such pose leaves half the points or more
//! unexplained, the same search with [`Side::Behind`] (bearings reversed, depth < 0 required)
//! tells whether the data are rather those of points behind the camera, so the caller can name
//! them instead of returning a camera fitted to a chance handful of points.
//!
//! # Known limitations
//! The focal length is taken from the initial intrinsics; with a focal error of tens of percent
//! the consensus relies on the wide gate used during self-calibration.

use nalgebra::{Unit, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{MIN_POINTS, Obs, Problem, ResectionOptions};
use crate::camera::{Camera, Intrinsics, Pose};
use crate::photogrammetry::least_squares::levenberg_marquardt;
use crate::photogrammetry::p3p;
use crate::photogrammetry::{ImageObservation, PhotogrammetryError, SelfCalibration};

/// Samples drawn even when the adaptive stop says fewer suffice: with every point an inlier the
/// adaptive count is 0, and a few extra samples guard against a lucky first consensus.
const MIN_RANSAC_ITERATIONS: usize = 3;
/// Number of best RANSAC poses given a local least-squares optimisation.
const LOCAL_OPTIMISATION_CANDIDATES: usize = 5;
/// Below this many triples (8 points) every triple is tried: deterministic and as cheap as
/// sampling.
const EXHAUSTIVE_MAX_TRIPLES: usize = 56;
/// Up to this many points the best candidates get the local optimisation; with more points
/// the best MSAC pose is reliably in the right basin and the refinement that follows
/// ([`super`]) does the same job.
const FEW_POINTS: usize = 8;

/// Which side of the camera the points are required on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Side {
    /// Depth > 0: the physical case, the only one a solution may have.
    Front,
    /// Depth < 0: the mirrored hypothesis, used only to diagnose input whose points lie
    /// behind the camera.
    Behind,
}

impl Side {
    fn sign(self) -> f64 {
        match self {
            Self::Front => 1.0,
            Self::Behind => -1.0,
        }
    }
}

/// Squared normalised reprojection error of `o` for a camera, using σ_px and the control σ
/// scaled by focal/depth (isotropic approximation, good enough for scoring). `None` for a
/// point behind the camera.
pub(super) fn normalised_error_sq(camera: &Camera, o: &Obs) -> Option<f64> {
    error_sq_on_side(camera, o, Side::Front)
}

/// [`normalised_error_sq`] for a point required on `side` of the camera.
pub(super) fn error_sq_on_side(camera: &Camera, o: &Obs, side: Side) -> Option<f64> {
    let pc = camera.pose.camera_from_world(&o.point);
    if pc.z * side.sign() <= 0.0 {
        return None;
    }
    let pixel = camera
        .intrinsics
        .pixel_from_normalised(nalgebra::Point2::new(pc.x / pc.z, pc.y / pc.z));
    let sigma_ctrl = o.control_sigma_m.iter().fold(0.0_f64, |m, s| m.max(*s));
    let sigma_sq =
        o.sigma_px * o.sigma_px + (camera.intrinsics.focal_px * sigma_ctrl / pc.z.abs()).powi(2);
    Some((pixel - o.pixel).norm_squared() / sigma_sq)
}

/// RANSAC over P3P samples; returns the pose with the best MSAC score among those with every
/// inlier on `side` of the camera, and its number of inliers, if that is at least
/// [`MIN_POINTS`].
pub(super) fn ransac(
    all: &[Obs],
    intrinsics: &Intrinsics,
    options: &ResectionOptions,
    gate_px: f64,
    side: Side,
) -> Option<(Pose, usize)> {
    let n = all.len();
    // Reversed bearings make P3P place its three points behind the camera.
    let bearings: Vec<Unit<Vector3<f64>>> = all
        .iter()
        .map(|o| {
            let p = intrinsics.normalised_from_pixel(o.pixel);
            Unit::new_normalize(Vector3::new(p.x, p.y, 1.0) * side.sign())
        })
        .collect();
    let threshold = options.outlier_threshold_sigma;
    let score = |pose: &Pose| -> (f64, usize) {
        let camera = Camera {
            intrinsics: *intrinsics,
            pose: *pose,
        };
        let mut cost = 0.0;
        let mut inliers = 0;
        for o in all {
            let cap = if gate_px > 0.0 {
                (gate_px / o.sigma_px).max(threshold).powi(2)
            } else {
                threshold * threshold
            };
            let e2 = error_sq_on_side(&camera, o, side).unwrap_or(f64::INFINITY);
            if e2 < cap {
                inliers += 1;
                cost += e2;
            } else {
                cost += cap;
            }
        }
        (cost, inliers)
    };
    let mut top: Vec<(f64, usize, Pose)> = Vec::with_capacity(LOCAL_OPTIMISATION_CANDIDATES + 1);
    let try_triple = |t: [usize; 3], top: &mut Vec<(f64, usize, Pose)>| {
        let b = [bearings[t[0]], bearings[t[1]], bearings[t[2]]];
        let p = [all[t[0]].point, all[t[1]].point, all[t[2]].point];
        for pose in p3p::p3p(&b, &p) {
            // Cheirality of the sample itself (P3P's positive distances already imply it; a
            // near-degenerate triple can still flip a point through rounding).
            if p.iter()
                .any(|x| pose.camera_from_world(x).z * side.sign() <= 0.0)
            {
                continue;
            }
            let (cost, inliers) = score(&pose);
            if top.len() < LOCAL_OPTIMISATION_CANDIDATES
                || top.last().is_some_and(|(c, _, _)| cost < *c)
            {
                let at = top.partition_point(|(c, _, _)| *c <= cost);
                top.insert(at, (cost, inliers, pose));
                top.truncate(LOCAL_OPTIMISATION_CANDIDATES);
            }
        }
    };
    let triples = n * (n - 1) * (n - 2) / 6;
    if triples <= EXHAUSTIVE_MAX_TRIPLES.min(options.max_ransac_iterations) {
        for a in 0..n {
            for b in a + 1..n {
                for c in b + 1..n {
                    try_triple([a, b, c], &mut top);
                }
            }
        }
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let mut needed = options.max_ransac_iterations;
        let mut iteration = 0;
        while iteration < needed.max(MIN_RANSAC_ITERATIONS)
            && iteration < options.max_ransac_iterations
        {
            iteration += 1;
            let a = rng.random_range(0..n);
            let mut b = rng.random_range(0..n - 1);
            if b >= a {
                b += 1;
            }
            let mut c = rng.random_range(0..n - 2);
            for lo in [a.min(b), a.max(b)] {
                if c >= lo {
                    c += 1;
                }
            }
            try_triple([a, b, c], &mut top);
            if let Some((_, inliers, _)) = top.first() {
                let w = *inliers as f64 / n as f64;
                let miss = 1.0 - w.powi(3);
                needed = if miss <= 1e-12 {
                    0
                } else {
                    ((1.0 - options.ransac_confidence).ln() / miss.ln())
                        .ceil()
                        .max(0.0) as usize
                };
            }
        }
    }
    let (_, best_inliers, _) = *top.first()?;
    if best_inliers == n {
        return top.first().map(|t| (t.2, t.1));
    }
    // Local optimisation (Chum, Matas & Kittler 2003): a P3P pose from three noisy rays can miss
    // the other points by many σ (tele lenses, small sets). Refine the best candidates on their
    // closest points and score again.
    let mut best = top[0];
    // The least-squares refinement works in front of the camera only.
    let candidates = if n <= FEW_POINTS && side == Side::Front {
        top.len()
    } else {
        0
    };
    for &(_, inliers, pose) in &top[..candidates] {
        let camera = Camera {
            intrinsics: *intrinsics,
            pose,
        };
        let mut ranked: Vec<(f64, &Obs)> = all
            .iter()
            .filter_map(|o| normalised_error_sq(&camera, o).map(|e| (e, o)))
            .collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let keep = inliers.max(MIN_POINTS);
        if ranked.len() < keep {
            continue;
        }
        let subset: Vec<Obs> = ranked[..keep].iter().map(|(_, o)| (*o).clone()).collect();
        let problem = Problem::new(&subset, &camera, SelfCalibration::default());
        if let Some(sol) = levenberg_marquardt(&problem, camera) {
            let (cost, inliers) = score(&sol.state.pose);
            if cost < best.0 {
                best = (cost, inliers, sol.state.pose);
            }
        }
    }
    (best.1 >= MIN_POINTS).then_some((best.2, best.1))
}

/// When the best pose with the points in front leaves some unexplained, whether a pose with the
/// points behind explains more than its `front_inliers`: then the error names the points it
/// puts behind the camera (cheirality), never a camera.
pub(super) fn behind_the_camera(
    all: &[Obs],
    observations: &[ImageObservation],
    intrinsics: &Intrinsics,
    options: &ResectionOptions,
    gate_px: f64,
    front_inliers: usize,
) -> Option<PhotogrammetryError> {
    let (pose, _) = ransac(all, intrinsics, options, gate_px, Side::Behind)?;
    let camera = Camera {
        intrinsics: *intrinsics,
        pose,
    };
    let threshold = options.outlier_threshold_sigma;
    let cap = |o: &Obs| {
        if gate_px > 0.0 {
            (gate_px / o.sigma_px).max(threshold).powi(2)
        } else {
            threshold * threshold
        }
    };
    let point_ids: Vec<String> = all
        .iter()
        .filter(|o| error_sq_on_side(&camera, o, Side::Behind).is_some_and(|e| e < cap(o)))
        .map(|o| observations[o.index].point_id.clone())
        .collect();
    (point_ids.len() >= MIN_POINTS && point_ids.len() > front_inliers).then_some(
        PhotogrammetryError::PointsBehindCamera {
            photo: None,
            point_ids,
        },
    )
}
