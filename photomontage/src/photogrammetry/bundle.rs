//! Bundle adjustment: all photos, control points (weighted by their σ) and tie points in one
//! least-squares adjustment of the collinearity equations (Durisch 1992 §4.1; Triggs,
//! McLauchlan, Hartley & Fitzgibbon, *Bundle adjustment — a modern synthesis*, 2000, §6.1 for
//! the reduced camera system; Förstner & Wrobel 2016 §15.4 for control as weighted observations).
//!
//! Unknowns: per photo the pose (δC, δθ) and the requested, supported intrinsics; per point its
//! world position, except control points with σ = 0 on every axis, which are fixed. Control
//! with σ > 0 adds the pseudo-observations X − X_surveyed with weight 1/σ² (an axis with σ = 0
//! among others gets σ = [`FIXED_AXIS_SIGMA_M`]). Tie points (ids observed in ≥ 2 photos and
//! not control) start from [`super::intersect`] with the initial cameras.
//!
//! The normal equations are stored sparsely, as the camera blocks, the 3×3 point blocks and one
//! camera–point block per observation, and solved through the reduced camera system (Schur
//! complement of the point blocks, module [`normal`]): memory grows with photos² + observations,
//! a step costs O(observations · rays · k²) + O((k · photos)³) for k unknowns per photo.
//! Covariances of the cameras come from the inverse of the reduced system; those of the points
//! only when [`BundleOptions::point_covariance`] asks for them.
//!
//! Cheirality: a photo cannot see a point behind it. When the start cameras or the adjusted
//! ones put an observed point at depth ≤ 0 in a photo observing it, the adjustment fails with
//! [`PhotogrammetryError::PointsBehindCamera`] naming the photo and the points, rather than
//! returning a camera.
//!
//! Outliers: after convergence the observation with the largest whitened residual is removed
//! when it exceeds the threshold, and the adjustment repeated (at most
//! [`BundleOptions::max_outlier_rounds`] times); a tie point left with one ray is dropped.
//! Without redundancy numbers this test is conservative (residuals are shrunk by √r).
//!
//! # Known limitations
//! The reduced camera system is dense and factored by Cholesky: fine for hundreds of photos, not
//! thousands (measured: 20 photos × 5000 points, 10⁵ observations, in `docs/benchmarks.md`).
//! The datum comes from the control only (at least three non-collinear control points are
//! needed); no free-network adjustment. Outliers are tested without redundancy numbers.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::least_squares::{
    LinearSystem, NormalEquations, correlation_from_diagonals, levenberg_marquardt,
};
use super::projection::intrinsic_indices;
use super::resection::ObservationResidual;
use super::{
    ControlPoint, ImageObservation, PhotogrammetryError, SelfCalibration, intersect,
    validate_control, validate_intrinsics, validate_observations,
};
use crate::camera::Camera;
use normal::{Assembly, Obs, PointRef, Problem, State};

#[path = "bundle_normal.rs"]
mod normal;

#[cfg(test)]
#[path = "bundle_dense.rs"]
mod dense;

/// σ used for an axis given as 0 on a control point whose other axes are free (metres).
pub const FIXED_AXIS_SIGMA_M: f64 = 1e-6;

/// One photo entering the adjustment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BundlePhoto {
    pub id: String,
    /// Initial camera (e.g. from [`super::resect`]).
    pub camera: Camera,
    pub observations: Vec<ImageObservation>,
    pub self_calibration: SelfCalibration,
}

/// Tunables of [`bundle_adjust`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BundleOptions {
    /// Whitened residual above which an observation is an outlier.
    pub outlier_threshold_sigma: f64,
    /// Rounds of outlier removal (0 = none).
    pub max_outlier_rounds: usize,
    /// Requested intrinsics whose multiple correlation exceeds this stay fixed.
    pub max_correlation: f64,
    /// Compute the 3×3 covariance of every unknown point (for [`BundlePointReport::sigma_m`]).
    /// Off by default: without it `sigma_m` of unknown points is NaN (fixed control: 0).
    pub point_covariance: bool,
}

impl Default for BundleOptions {
    fn default() -> Self {
        Self {
            outlier_threshold_sigma: 3.5,
            max_outlier_rounds: 20,
            max_correlation: 0.999,
            point_covariance: false,
        }
    }
}

/// Per-photo results.
#[derive(Debug, Clone, Serialize)]
pub struct BundlePhotoReport {
    pub id: String,
    pub camera: Camera,
    pub rms_px: f64,
    pub sigma_center_m: [f64; 3],
    /// σ of small rotations about world X, Y, Z (degrees).
    pub sigma_angles_deg: [f64; 3],
    pub sigma_focal_px: Option<f64>,
    pub residuals: Vec<ObservationResidual>,
    pub outliers: Vec<String>,
    pub warnings: Vec<String>,
    pub estimated: SelfCalibration,
}

/// Per-point results.
#[derive(Debug, Clone, Serialize)]
pub struct BundlePointReport {
    pub id: String,
    pub point_in_world: Point3<f64>,
    /// σ along world X, Y, Z (0 for fixed control; NaN unless
    /// [`BundleOptions::point_covariance`] was set, and for dropped tie points).
    pub sigma_m: [f64; 3],
    /// RMS of its image residuals per coordinate.
    pub rms_px: f64,
    pub is_control: bool,
    /// Number of photos whose observation of it was used.
    pub rays: usize,
}

/// The adjustment's results.
#[derive(Debug, Clone, Serialize)]
pub struct BundleReport {
    pub photos: Vec<BundlePhotoReport>,
    pub points: Vec<BundlePointReport>,
    /// RMS of all used image residuals per coordinate.
    pub rms_px: f64,
    /// A-posteriori σ₀.
    pub sigma0: f64,
    pub redundancy: i64,
    pub warnings: Vec<String>,
    pub converged: bool,
}

/// Adjusts all photos, points and requested intrinsics together.
///
/// # Errors
/// Invalid input (non-finite values, duplicate ids, σ ≤ 0), `NotEnoughPoints` when fewer than
/// two photos or no usable observations, `Degenerate` when the control does not fix the datum,
/// `PointsBehindCamera` when an observed point lies at depth ≤ 0 in a photo observing it, at
/// the start or after the adjustment (tie points that cannot be initialised in front of their
/// cameras are left out with a warning).
pub fn bundle_adjust(
    photos: &[BundlePhoto],
    control: &[ControlPoint],
    options: &BundleOptions,
) -> Result<BundleReport, PhotogrammetryError> {
    adjust(photos, control, options, Assembly::Sparse)
}

/// [`bundle_adjust`] on the dense normal equations the sparse ones replaced (memory
/// O(points²)): the reference of the tests.
#[cfg(test)]
pub(crate) fn bundle_adjust_dense_reference(
    photos: &[BundlePhoto],
    control: &[ControlPoint],
    options: &BundleOptions,
) -> Result<BundleReport, PhotogrammetryError> {
    adjust(photos, control, options, Assembly::DenseReference)
}

/// Observations (active or flagged) of points still in the solution that lie at depth ≤ 0 in
/// the photo observing them, as the error naming the first such photo and its points.
fn cheirality(
    photos: &[BundlePhoto],
    problem: &Problem,
    state: &State,
) -> Option<PhotogrammetryError> {
    let mut behind: Vec<Vec<String>> = vec![Vec::new(); photos.len()];
    for o in &problem.observations {
        if matches!(o.point, PointRef::Unknown(q) if problem.dropped[q]) {
            continue;
        }
        let x = Problem::point_position(state, o.point);
        let depth_m = state.cameras[o.photo].pose.camera_from_world(&x).z;
        if depth_m.is_nan() || depth_m <= 0.0 {
            behind[o.photo].push(o.observation.point_id.clone());
        }
    }
    let (photo, point_ids) = behind
        .into_iter()
        .enumerate()
        .find(|(_, b)| !b.is_empty())?;
    Some(PhotogrammetryError::PointsBehindCamera {
        photo: Some(photos[photo].id.clone()),
        point_ids,
    })
}

fn adjust(
    photos: &[BundlePhoto],
    control: &[ControlPoint],
    options: &BundleOptions,
    assembly: Assembly,
) -> Result<BundleReport, PhotogrammetryError> {
    validate_control(control)?;
    let mut ids = std::collections::HashSet::new();
    for p in photos {
        validate_intrinsics(&p.camera.intrinsics)?;
        let pose = &p.camera.pose;
        if !(pose.camera_center_in_world.iter().all(|v| v.is_finite())
            && pose
                .rotation_world_from_camera
                .matrix()
                .iter()
                .all(|v| v.is_finite()))
        {
            return Err(PhotogrammetryError::NonFinite {
                what: format!("start pose of photo {}", p.id),
            });
        }
        validate_observations(&p.observations)?;
        if !ids.insert(p.id.as_str()) {
            return Err(PhotogrammetryError::DuplicateId { id: p.id.clone() });
        }
    }
    if photos.is_empty() {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: 1,
            found: 0,
        });
    }
    let mut warnings = Vec::new();
    let control_by_id: HashMap<&str, &ControlPoint> =
        control.iter().map(|c| (c.id.as_str(), c)).collect();
    let origin = if control.is_empty() {
        Vector3::zeros()
    } else {
        control
            .iter()
            .fold(Vector3::zeros(), |a, c| a + c.point_in_world.coords)
            / control.len() as f64
    };
    let reduced_cameras: Vec<Camera> = photos
        .iter()
        .map(|p| {
            let mut c = p.camera;
            c.pose.camera_center_in_world -= origin;
            c
        })
        .collect();

    // Count rays per id to find tie points.
    let mut rays: HashMap<&str, Vec<(usize, &ImageObservation)>> = HashMap::new();
    for (pi, p) in photos.iter().enumerate() {
        for o in &p.observations {
            rays.entry(o.point_id.as_str()).or_default().push((pi, o));
        }
    }
    let mut point_ids: Vec<String> = Vec::new();
    let mut point_index: HashMap<String, PointRef> = HashMap::new();
    let mut start_points = Vec::new();
    let mut priors = Vec::new();
    let mut is_control = Vec::new();
    let mut sorted_ids: Vec<&str> = rays.keys().copied().collect();
    sorted_ids.sort_unstable();
    for id in sorted_ids {
        let obs = &rays[id];
        if let Some(c) = control_by_id.get(id) {
            let reduced = Point3::from(c.point_in_world.coords - origin);
            if c.sigma_m.iter().all(|s| *s == 0.0) {
                point_index.insert(id.to_owned(), PointRef::Fixed(reduced));
            } else {
                let sigma = c
                    .sigma_m
                    .map(|s| if s > 0.0 { s } else { FIXED_AXIS_SIGMA_M });
                point_index.insert(id.to_owned(), PointRef::Unknown(start_points.len()));
                start_points.push(reduced);
                priors.push(Some((reduced, sigma)));
                is_control.push(true);
                point_ids.push(id.to_owned());
            }
            continue;
        }
        if obs.len() < 2 {
            warnings.push(format!(
                "{id} is neither control nor seen in two photos: ignored"
            ));
            continue;
        }
        let ray_list: Vec<(Camera, ImageObservation)> = obs
            .iter()
            .map(|(pi, o)| (reduced_cameras[*pi], (*o).clone()))
            .collect();
        match intersect(&ray_list) {
            Ok(x) => {
                point_index.insert(id.to_owned(), PointRef::Unknown(start_points.len()));
                start_points.push(x.point_in_world);
                priors.push(None);
                is_control.push(false);
                point_ids.push(id.to_owned());
            }
            Err(e) => warnings.push(format!("tie point {id} not initialised ({e}): ignored")),
        }
    }
    let mut observations = Vec::new();
    for (pi, p) in photos.iter().enumerate() {
        for o in &p.observations {
            if let Some(r) = point_index.get(&o.point_id) {
                observations.push(Obs {
                    photo: pi,
                    point: *r,
                    observation: o.clone(),
                    active: true,
                });
            }
        }
    }
    let mut free: Vec<SelfCalibration> = photos.iter().map(|p| p.self_calibration).collect();
    let mut state = State {
        cameras: reduced_cameras,
        points: start_points,
    };
    let build = |free: &[SelfCalibration], observations: Vec<Obs>| {
        Problem::new(free, observations, priors.clone(), assembly)
    };
    let mut problem = build(&free, observations);
    let unsolvable = || {
        PhotogrammetryError::Degenerate {
        reason: "the adjustment is singular: control does not fix every photo and point (datum, or too few rays)".to_owned(),
    }
    };

    // Solve; drop unsupported intrinsics; then outlier rounds.
    if let Some(e) = cheirality(photos, &problem, &state) {
        return Err(e);
    }
    let mut solution =
        levenberg_marquardt(&problem, state.clone()).ok_or(PhotogrammetryError::NoConvergence)?;
    if free.iter().any(SelfCalibration::any) {
        let s_inv = solution
            .normal
            .covariances(false)
            .ok_or_else(unsolvable)?
            .cameras;
        let diagonal = solution.normal.diagonal();
        let mut changed = false;
        for (p, f) in free.iter_mut().enumerate() {
            let cols = intrinsic_indices(f);
            let o = problem.offsets[p];
            for (name, index) in [("focal", 0), ("principal_point", 1), ("k1", 3), ("k2", 4)] {
                let Some(pos) = cols.iter().position(|c| *c == index) else {
                    continue;
                };
                let i = o + 6 + pos;
                let rho = correlation_from_diagonals(diagonal[i], s_inv[(i, i)]);
                if rho > options.max_correlation {
                    warnings.push(format!(
                        "photo {}: {name} kept fixed (multiple correlation {rho:.5} > {})",
                        photos[p].id, options.max_correlation
                    ));
                    match index {
                        0 => f.focal = false,
                        1 => f.principal_point = false,
                        3 => f.k1 = false,
                        _ => f.k2 = false,
                    }
                    changed = true;
                }
            }
        }
        if changed {
            problem = build(&free, problem.observations);
            solution = levenberg_marquardt(&problem, state.clone())
                .ok_or(PhotogrammetryError::NoConvergence)?;
        }
    }
    state = solution.state.clone();
    for _ in 0..options.max_outlier_rounds {
        let mut worst: Option<(usize, f64)> = None;
        for (k, o) in problem
            .observations
            .iter()
            .enumerate()
            .filter(|(_, o)| o.active)
        {
            let x = Problem::point_position(&state, o.point);
            let w = state.cameras[o.photo]
                .project(&x)
                .map_or(f64::INFINITY, |p| {
                    let v = (p - o.observation.pixel) / o.observation.sigma_px;
                    v.x.abs().max(v.y.abs())
                });
            if w > options.outlier_threshold_sigma && worst.is_none_or(|(_, b)| w > b) {
                worst = Some((k, w));
            }
        }
        let Some((k, _)) = worst else {
            break;
        };
        problem.observations[k].active = false;
        if let PointRef::Unknown(q) = problem.observations[k].point {
            let rays = problem
                .observations
                .iter()
                .filter(|o| o.active && matches!(o.point, PointRef::Unknown(r) if r == q))
                .count();
            if rays < 2 && problem.priors[q].is_none() {
                problem.dropped[q] = true;
                for o in &mut problem.observations {
                    if matches!(o.point, PointRef::Unknown(r) if r == q) {
                        o.active = false;
                    }
                }
                warnings.push(format!(
                    "tie point {} dropped: fewer than two consistent rays",
                    point_ids[q]
                ));
            }
        }
        solution =
            levenberg_marquardt(&problem, state).ok_or(PhotogrammetryError::NoConvergence)?;
        state = solution.state.clone();
    }

    if let Some(e) = cheirality(photos, &problem, &state) {
        return Err(e);
    }

    // Statistics.
    let covariances = solution
        .normal
        .covariances(options.point_covariance)
        .ok_or_else(unsolvable)?;
    let s_inv = covariances.cameras;
    let active = problem.observations.iter().filter(|o| o.active).count();
    let prior_rows: usize = problem.priors.iter().flatten().count() * 3;
    let redundancy = (2 * active + prior_rows) as i64 - problem.unknowns() as i64;
    let sigma0 = if redundancy > 0 {
        (solution.cost / redundancy as f64).sqrt()
    } else {
        1.0
    };
    let variance = sigma0.max(1.0).powi(2);
    let mut photo_reports = Vec::with_capacity(photos.len());
    let mut point_sq = vec![(0.0, 0usize); problem.priors.len()];
    let mut fixed_sq: HashMap<String, (f64, usize)> = HashMap::new();
    let mut total_sq = 0.0;
    for (p, photo) in photos.iter().enumerate() {
        let camera = state.cameras[p];
        let mut residuals = Vec::new();
        let mut outliers = Vec::new();
        let mut sum_sq = 0.0;
        let mut used = 0usize;
        let mut photo_warnings = Vec::new();
        for o in problem.observations.iter().filter(|o| o.photo == p) {
            let x = Problem::point_position(&state, o.point);
            let (v, w) = match camera.project(&x) {
                Some(px) => {
                    let v = px - o.observation.pixel;
                    (v, v / o.observation.sigma_px)
                }
                None => {
                    photo_warnings.push(format!(
                        "{} lies behind the adjusted camera",
                        o.observation.point_id
                    ));
                    (
                        nalgebra::Vector2::repeat(f64::NAN),
                        nalgebra::Vector2::repeat(f64::NAN),
                    )
                }
            };
            if o.active {
                sum_sq += v.norm_squared();
                used += 1;
                match o.point {
                    PointRef::Unknown(q) => {
                        point_sq[q].0 += v.norm_squared();
                        point_sq[q].1 += 1;
                    }
                    PointRef::Fixed(_) => {
                        let e = fixed_sq
                            .entry(o.observation.point_id.clone())
                            .or_insert((0.0, 0));
                        e.0 += v.norm_squared();
                        e.1 += 1;
                    }
                }
            } else {
                outliers.push(o.observation.point_id.clone());
            }
            residuals.push(ObservationResidual {
                point_id: o.observation.point_id.clone(),
                residual_px: [v.x, v.y],
                normalised: [w.x, w.y],
                outlier: !o.active,
            });
        }
        for o in &photo.observations {
            if !point_index.contains_key(&o.point_id) {
                photo_warnings.push(format!("observation of {} not used", o.point_id));
            }
        }
        total_sq += sum_sq;
        let off = problem.offsets[p];
        let sd = |i: usize| (s_inv[(off + i, off + i)] * variance).max(0.0).sqrt();
        let rot = camera.pose.rotation_world_from_camera.matrix();
        let cov_theta =
            rot * s_inv.fixed_view::<3, 3>(off + 3, off + 3) * rot.transpose() * variance;
        let focal_col = intrinsic_indices(&free[p]).iter().position(|c| *c == 0);
        let mut camera_out = camera;
        camera_out.pose.camera_center_in_world += origin;
        photo_reports.push(BundlePhotoReport {
            id: photo.id.clone(),
            camera: camera_out,
            rms_px: if used > 0 {
                (sum_sq / (2 * used) as f64).sqrt()
            } else {
                f64::NAN
            },
            sigma_center_m: [sd(0), sd(1), sd(2)],
            sigma_angles_deg: [0, 1, 2].map(|i| cov_theta[(i, i)].max(0.0).sqrt().to_degrees()),
            sigma_focal_px: focal_col.map(|c| sd(6 + c)),
            residuals,
            outliers,
            warnings: photo_warnings,
            estimated: free[p],
        });
    }
    let mut points = Vec::new();
    for (q, id) in point_ids.iter().enumerate() {
        let sigma_m = match &covariances.points {
            Some(point_cov) if !problem.dropped[q] => {
                let cov = point_cov[q] * variance;
                [0, 1, 2].map(|i| cov[(i, i)].max(0.0).sqrt())
            }
            _ => [f64::NAN; 3],
        };
        points.push(BundlePointReport {
            id: id.clone(),
            point_in_world: state.points[q] + origin,
            sigma_m,
            rms_px: if point_sq[q].1 > 0 {
                (point_sq[q].0 / (2 * point_sq[q].1) as f64).sqrt()
            } else {
                f64::NAN
            },
            is_control: is_control[q],
            rays: point_sq[q].1,
        });
    }
    for (id, r) in &point_index {
        if let PointRef::Fixed(x) = r {
            let (sq, rays) = fixed_sq.get(id).copied().unwrap_or((0.0, 0));
            points.push(BundlePointReport {
                id: id.clone(),
                point_in_world: x + origin,
                sigma_m: [0.0; 3],
                rms_px: if rays > 0 {
                    (sq / (2 * rays) as f64).sqrt()
                } else {
                    f64::NAN
                },
                is_control: true,
                rays,
            });
        }
    }
    points.sort_by(|a, b| a.id.cmp(&b.id));
    if !solution.converged {
        warnings.push("the adjustment stopped before meeting its convergence test".to_owned());
    }
    Ok(BundleReport {
        photos: photo_reports,
        points,
        rms_px: if active > 0 {
            (total_sq / (2 * active) as f64).sqrt()
        } else {
            f64::NAN
        },
        sigma0,
        redundancy,
        warnings,
        converged: solution.converged,
    })
}

#[cfg(test)]
#[path = "bundle_tests.rs"]
mod tests;
