//! Single-photo resection: exterior (and optionally interior) orientation of one photo from
//! control points (Durisch 1992 §4.1; collinearity adjustment as in Wolf & Dewitt, *Elements of
//! Photogrammetry*, 3rd ed., §11.6; robust start by RANSAC, Fischler & Bolles 1981, over P3P
//! samples, [`super::p3p`]; outliers by data snooping, Baarda 1968; support of self-calibration
//! by the multiple correlation of each parameter, Förstner & Wrobel 2016 §4.6).
//!
//! Steps:
//! 1. validate the input (finite values, σ > 0, unique ids, every observed point is control,
//!    not all collinear, no two plane points imaged onto the same pixel);
//! 2. RANSAC over P3P (exhaustive when the number of triples is small), MSAC score on all points
//!    with each point's σ including its control σ projected into the image; only points in
//!    front of a pose count as its inliers (cheirality). When the best such pose leaves at least
//!    half the points unexplained and a pose with the points behind the camera explains more, the
//!    error [`PhotogrammetryError::PointsBehindCamera`] names those points;
//! 3. Levenberg–Marquardt on the consensus set, reclassification of all points, repeated;
//! 4. self-calibration: the requested parameters are freed only if their multiple correlation
//!    with the other unknowns is below [`ResectionOptions::max_correlation`] and the redundancy
//!    is enough; otherwise they stay fixed and a warning says why;
//! 5. data snooping: the observation with the largest w = v/(σ √r) above the threshold is
//!    removed and the adjustment repeated;
//! 6. covariance σ₀² N⁻¹ with σ₀ = max(1, σ̂₀).
//!
//! All computation happens in world coordinates reduced to the centroid of the control points
//! (survey coordinates of 10⁵–10⁶ m would otherwise cost 6 digits); results are reported in the
//! original coordinates.
//!
//! Angles: `sigma_angles_deg` are the standard deviations of small rotations about the world X,
//! Y and Z axes (for a level camera: tilt about X/Y and swing/heading about Z).
//!
//! # Known limitations
//! At least four control points are needed (three give up to four poses). The initial focal
//! length must be within a few tens of percent when it is to be estimated. Observations of two
//! points on one ray are accepted for non-planar control (they can be genuine). With planar
//! control, points that lie behind the camera (e.g. mirrored through its centre) are explained
//! exactly by the camera mirrored across the control plane, with every point in front: the data
//! cannot tell the two apart, so that camera is returned (the solution in front is preferred;
//! only a prior on the camera position, which [`resect`] does not take, could reject it).

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector, Matrix2, Point2, Point3, SMatrix, SVector, Vector2, Vector3};
use serde::Serialize;

use super::least_squares::{
    NormalEquations, levenberg_marquardt, multiple_correlation, spd_inverse,
};
use super::projection::{
    apply_intrinsics_increment, apply_pose_increment, intrinsic_indices, project_with_jacobian,
};
mod ransac;

use super::radial_pattern::{RadialPattern, radial_pattern};
use super::{
    ControlPoint, ImageObservation, PhotogrammetryError, SelfCalibration, validate_control,
    validate_intrinsics, validate_observations,
};
use crate::camera::{Camera, Intrinsics};
use ransac::{Side, behind_the_camera, normalised_error_sq, ransac};

/// Tunables of [`resect`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResectionOptions {
    /// Interior orientation to start from (and keep, unless self-calibration frees a part).
    pub initial_intrinsics: Intrinsics,
    /// Parameters the user asks to estimate.
    pub self_calibration: SelfCalibration,
    /// Normalised residual above which an observation is an outlier (3.5: false-alarm rate
    /// ≈ 5·10⁻⁴ per coordinate for Gaussian errors).
    pub outlier_threshold_sigma: f64,
    /// Seed of the RANSAC sampler.
    pub seed: u64,
    /// Upper bound on RANSAC samples.
    pub max_ransac_iterations: usize,
    /// Probability of drawing at least one all-inlier sample, for the adaptive stop.
    pub ransac_confidence: f64,
    /// A requested intrinsic parameter whose multiple correlation with the other unknowns
    /// exceeds this stays fixed.
    pub max_correlation: f64,
}

impl ResectionOptions {
    /// Defaults: fixed intrinsics, threshold 3.5 σ, seed 0, 1000 RANSAC samples at 99.9 %,
    /// correlation bound 0.999.
    #[must_use]
    pub fn new(initial_intrinsics: Intrinsics) -> Self {
        Self {
            initial_intrinsics,
            self_calibration: SelfCalibration::default(),
            outlier_threshold_sigma: 3.5,
            seed: 0,
            max_ransac_iterations: 1000,
            ransac_confidence: 0.999,
            max_correlation: 0.999,
        }
    }
}

/// Residual of one observation at the solution.
#[derive(Debug, Clone, Serialize)]
pub struct ObservationResidual {
    pub point_id: String,
    /// Projected minus observed pixel position.
    pub residual_px: [f64; 2],
    /// Residual whitened by its σ (σ_px and projected control σ).
    pub normalised: [f64; 2],
    /// Excluded from the adjustment as a gross error.
    pub outlier: bool,
}

/// The solved camera of one photo with its quality measures.
#[derive(Debug, Clone, Serialize)]
pub struct Resection {
    pub camera: Camera,
    /// One entry per observation, in input order.
    pub residuals: Vec<ObservationResidual>,
    /// RMS of the inlier residuals per coordinate.
    pub rms_px: f64,
    /// Observations minus unknowns (2 × inliers − 6 − freed intrinsics).
    pub redundancy: i64,
    /// A-posteriori σ₀ (1 when the stated σ are right).
    pub sigma0: f64,
    /// σ of the camera centre along world X, Y, Z (metres).
    pub sigma_center_m: [f64; 3],
    /// σ of small rotations about world X, Y, Z (degrees).
    pub sigma_angles_deg: [f64; 3],
    pub sigma_focal_px: Option<f64>,
    pub sigma_principal_point_px: Option<[f64; 2]>,
    pub sigma_k1: Option<f64>,
    pub sigma_k2: Option<f64>,
    /// Ids of the observations flagged as gross errors.
    pub outliers: Vec<String>,
    pub warnings: Vec<String>,
    /// The intrinsic parameters that were actually estimated.
    pub estimated: SelfCalibration,
    /// Whether the final adjustment met its convergence test.
    pub converged: bool,
    /// Radial residual pattern over all observations (see [`super::radial_pattern`]); when k1
    /// was not estimated and the pattern is significant, `warnings` names it.
    pub radial_pattern: Option<RadialPattern>,
}

/// Minimum number of control points for a unique pose.
pub const MIN_POINTS: usize = 4;
/// Required redundancy per freed intrinsic parameter before it may be estimated.
const MIN_REDUNDANCY_PER_INTRINSIC: i64 = 3;
/// While intrinsics are being estimated from a rough start, RANSAC and the first
/// reclassification accept residuals up to this fraction of the image diagonal: a 10 % focal
/// error or uncorrected barrel distortion displaces image corners by ~100 px on a 6000 px image.
const SELF_CALIBRATION_GATE_FRACTION: f64 = 0.05;
/// Two observations in one photo closer than this many combined σ are "the same pixel".
const COINCIDENT_SIGMA: f64 = 3.0;
/// Control points are planar when the smallest principal extent is below this fraction of the
/// largest.
const PLANARITY_RATIO: f64 = 1e-3;
/// Collinear when the second principal extent is below this fraction of the largest.
const COLLINEARITY_RATIO: f64 = 1e-6;
const MAX_REFINE_ROUNDS: usize = 5;

/// One active observation inside the adjustment.
#[derive(Clone)]
pub(super) struct Obs {
    pub(super) index: usize,
    pub(super) point: Point3<f64>,
    pub(super) pixel: Point2<f64>,
    pub(super) sigma_px: f64,
    pub(super) control_sigma_m: [f64; 3],
}

/// Pose (6) + all intrinsics (focal, ppx, ppy, k1, k2).
const MAX_UNKNOWNS: usize = 11;
type Rows = SMatrix<f64, 2, MAX_UNKNOWNS>;

pub(super) struct Problem<'a> {
    obs: &'a [Obs],
    /// Whitening matrices C⁻¹ with C Cᵀ = Σ of each observation.
    whitening: Vec<Matrix2<f64>>,
    free: SelfCalibration,
    intrinsic_columns: Vec<usize>,
}

impl<'a> Problem<'a> {
    pub(super) fn new(obs: &'a [Obs], camera: &Camera, free: SelfCalibration) -> Self {
        let whitening = obs.iter().map(|o| whitening_matrix(o, camera)).collect();
        Self {
            obs,
            whitening,
            free,
            intrinsic_columns: intrinsic_indices(&free),
        }
    }

    /// Whitened residual and Jacobian rows of observation `k`.
    /// Columns beyond `unknowns()` are zero (fixed size: no allocation in the hot loop).
    fn rows(&self, camera: &Camera, k: usize) -> Option<(Vector2<f64>, Rows)> {
        let o = &self.obs[k];
        let pj = project_with_jacobian(camera, &o.point)?;
        let l = self.whitening[k];
        let r = l * (pj.pixel - o.pixel);
        let mut j = Rows::zeros();
        j.fixed_view_mut::<2, 6>(0, 0).copy_from(&(l * pj.d_pose));
        for (c, &col) in self.intrinsic_columns.iter().enumerate() {
            let d = l * pj.d_intrinsics.column(col);
            j[(0, 6 + c)] = d.x;
            j[(1, 6 + c)] = d.y;
        }
        Some((r, j))
    }
}

impl NormalEquations for Problem<'_> {
    type State = Camera;
    type Normal = DMatrix<f64>;
    fn unknowns(&self) -> usize {
        6 + self.intrinsic_columns.len()
    }
    fn cost(&self, camera: &Camera) -> Option<f64> {
        let mut cost = 0.0;
        for (o, l) in self.obs.iter().zip(&self.whitening) {
            let pixel = camera.project(&o.point)?;
            cost += (l * (pixel - o.pixel)).norm_squared();
        }
        Some(cost)
    }
    fn normal_equations(&self, camera: &Camera) -> Option<(DMatrix<f64>, DVector<f64>, f64)> {
        let m = self.unknowns();
        let mut n = SMatrix::<f64, MAX_UNKNOWNS, MAX_UNKNOWNS>::zeros();
        let mut g = SVector::<f64, MAX_UNKNOWNS>::zeros();
        let mut cost = 0.0;
        for k in 0..self.obs.len() {
            let (r, j) = self.rows(camera, k)?;
            n += j.transpose() * j;
            g += j.transpose() * r;
            cost += r.norm_squared();
        }
        Some((
            DMatrix::from_fn(m, m, |a, b| n[(a, b)]),
            DVector::from_fn(m, |a, _| g[a]),
            cost,
        ))
    }
    fn update(&self, camera: &Camera, delta: &DVector<f64>) -> Camera {
        let d = delta.as_slice();
        Camera {
            pose: apply_pose_increment(&camera.pose, &d[..6]),
            intrinsics: apply_intrinsics_increment(&camera.intrinsics, &self.free, &d[6..]),
        }
    }
}

/// C⁻¹ where C Cᵀ = σ_px² I + J_X Σ_X J_Xᵀ (control σ projected into the image).
fn whitening_matrix(o: &Obs, camera: &Camera) -> Matrix2<f64> {
    let mut cov = Matrix2::identity() * (o.sigma_px * o.sigma_px);
    if o.control_sigma_m.iter().any(|s| *s > 0.0)
        && let Some(pj) = project_with_jacobian(camera, &o.point)
    {
        let s = Vector3::from(o.control_sigma_m.map(|s| s * s));
        cov += pj.d_point * nalgebra::Matrix3::from_diagonal(&s) * pj.d_point.transpose();
    }
    cov.cholesky()
        .and_then(|c| c.l().try_inverse())
        .unwrap_or_else(|| Matrix2::identity() / o.sigma_px)
}

/// Solves the pose (and supported requested intrinsics) of one photo from control points.
///
/// # Errors
/// Invalid input ([`PhotogrammetryError::NonFinite`], `InvalidSigma`, `DuplicateId`,
/// `UnknownPoint`), too few points (`NotEnoughPoints`, required 4), `Collinear` control,
/// `CoincidentObservations` that leave too few points, or `Degenerate` when no pose explains
/// at least four observations.
pub fn resect(
    control: &[ControlPoint],
    observations: &[ImageObservation],
    options: &ResectionOptions,
) -> Result<Resection, PhotogrammetryError> {
    validate_intrinsics(&options.initial_intrinsics)?;
    validate_control(control)?;
    validate_observations(observations)?;
    if !(options.outlier_threshold_sigma.is_finite() && options.outlier_threshold_sigma > 0.0) {
        return Err(PhotogrammetryError::InvalidSigma {
            what: "outlier threshold".to_owned(),
            value: options.outlier_threshold_sigma,
        });
    }
    let by_id: HashMap<&str, &ControlPoint> = control.iter().map(|c| (c.id.as_str(), c)).collect();
    let mut matched = Vec::with_capacity(observations.len());
    for o in observations {
        let c =
            by_id
                .get(o.point_id.as_str())
                .ok_or_else(|| PhotogrammetryError::UnknownPoint {
                    id: o.point_id.clone(),
                })?;
        matched.push(*c);
    }
    let n = observations.len();
    if n < 3 {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: MIN_POINTS,
            found: n,
        });
    }
    // Reduce to the centroid for conditioning.
    let origin = matched
        .iter()
        .fold(Vector3::zeros(), |a, c| a + c.point_in_world.coords)
        / n as f64;
    let all: Vec<Obs> = observations
        .iter()
        .zip(&matched)
        .enumerate()
        .map(|(index, (o, c))| Obs {
            index,
            point: Point3::from(c.point_in_world.coords - origin),
            pixel: o.pixel,
            sigma_px: o.sigma_px,
            control_sigma_m: c.sigma_m,
        })
        .collect();
    let extents = principal_extents(&all.iter().map(|o| o.point).collect::<Vec<_>>());
    if extents[1] <= COLLINEARITY_RATIO * extents[0] {
        return Err(PhotogrammetryError::Collinear);
    }
    let planar = extents[2] <= PLANARITY_RATIO * extents[0];
    let mut warnings = Vec::new();
    if planar && let Some((a, b, dp, dw)) = coincident_pair(&all) {
        if n - 1 < MIN_POINTS {
            return Err(PhotogrammetryError::CoincidentObservations {
                first: observations[a].point_id.clone(),
                second: observations[b].point_id.clone(),
                pixel_distance_px: dp,
                world_distance_m: dw,
            });
        }
        warnings.push(format!(
            "observations of {} and {} are {dp:.2} px apart but the points are {dw:.2} m apart on a plane: one label is wrong",
            observations[a].point_id, observations[b].point_id
        ));
    }
    if n < MIN_POINTS {
        return Err(PhotogrammetryError::NotEnoughPoints {
            required: MIN_POINTS,
            found: n,
        });
    }

    let intrinsics = options.initial_intrinsics;
    let threshold = options.outlier_threshold_sigma;
    let diagonal_px =
        f64::from(intrinsics.image_size_px[0]).hypot(f64::from(intrinsics.image_size_px[1]));
    let gate_px = if options.self_calibration.any() {
        SELF_CALIBRATION_GATE_FRACTION * diagonal_px
    } else {
        0.0
    };

    // Step 2: robust start.
    let front = ransac(&all, &intrinsics, options, gate_px, Side::Front);
    let front_inliers = front.map_or(0, |(_, inliers)| inliers);
    // A pose behind can explain more points only when the front one leaves at least half
    // unexplained (a point rarely fits both); checking only then keeps the second search off
    // the ordinary photo with a few gross errors.
    if 2 * front_inliers <= n
        && let Some(e) = behind_the_camera(
            &all,
            observations,
            &intrinsics,
            options,
            gate_px,
            front_inliers,
        )
    {
        return Err(e);
    }
    let Some((start_pose, _)) = front else {
        return Err(PhotogrammetryError::Degenerate {
            reason: "no pose from any three control points explains a fourth".to_owned(),
        });
    };
    let mut camera = Camera {
        intrinsics,
        pose: start_pose,
    };

    // Step 3: refine with fixed intrinsics, reclassify.
    let fixed = SelfCalibration::default();
    let (mut active, mut solved) = refine_and_reclassify(&all, camera, fixed, threshold, gate_px)?;
    camera = solved.0;

    // Step 4: self-calibration.
    let mut free = SelfCalibration::default();
    if options.self_calibration.any() {
        free = supported_intrinsics(&active, &camera, options, &mut warnings);
        if free.any() {
            (active, solved) = refine_and_reclassify(&all, camera, free, threshold, gate_px)?;
            camera = solved.0;
        }
    }
    if gate_px > 0.0 {
        // Final classification with the strict threshold.
        (active, solved) = refine_and_reclassify(&all, camera, free, threshold, 0.0)?;
        camera = solved.0;
    }
    let mut converged = solved.1;

    // Step 5: data snooping.
    let unknowns = 6 + intrinsic_indices(&free).len();
    loop {
        let redundancy = 2 * active.len() as i64 - unknowns as i64;
        if redundancy < 3 {
            break;
        }
        let problem = Problem::new(&active, &camera, free);
        let Some(worst) = worst_normalised(&problem, &camera) else {
            break;
        };
        if worst.1 <= threshold {
            break;
        }
        active.remove(worst.0);
        let problem = Problem::new(&active, &camera, free);
        let sol =
            levenberg_marquardt(&problem, camera).ok_or(PhotogrammetryError::NoConvergence)?;
        camera = sol.state;
        converged = sol.converged;
    }
    if active.len() < MIN_POINTS {
        return Err(PhotogrammetryError::Degenerate {
            reason: format!("only {} observations are consistent", active.len()),
        });
    }

    // Step 6: statistics.
    let problem = Problem::new(&active, &camera, free);
    let (normal, _, cost) = problem
        .normal_equations(&camera)
        .ok_or(PhotogrammetryError::NoConvergence)?;
    let redundancy = 2 * active.len() as i64 - unknowns as i64;
    let sigma0 = if redundancy > 0 {
        (cost / redundancy as f64).sqrt()
    } else {
        1.0
    };
    let covariance = spd_inverse(&normal).ok_or_else(|| PhotogrammetryError::Degenerate {
        reason: "normal matrix is singular at the solution".to_owned(),
    })? * sigma0.max(1.0).powi(2);
    let rotation = camera.pose.rotation_world_from_camera.matrix();
    let cov_theta_world = rotation * covariance.fixed_view::<3, 3>(3, 3) * rotation.transpose();
    let sd = |i: usize| covariance[(i, i)].max(0.0).sqrt();
    let mut col = 6;
    let mut next = |flag: bool, count: usize| {
        if flag {
            let c = col;
            col += count;
            Some(c)
        } else {
            None
        }
    };
    let focal_col = next(free.focal, 1);
    let pp_col = next(free.principal_point, 2);
    let k1_col = next(free.k1, 1);
    let k2_col = next(free.k2, 1);

    let active_set: std::collections::HashSet<usize> = active.iter().map(|o| o.index).collect();
    let mut residuals = Vec::with_capacity(n);
    let mut outliers = Vec::new();
    let mut sum_sq = 0.0;
    for o in &all {
        let id = observations[o.index].point_id.clone();
        let outlier = !active_set.contains(&o.index);
        let (residual_px, normalised) = match camera.project(&o.point) {
            Some(p) => {
                let v = p - o.pixel;
                let w = whitening_matrix(o, &camera) * v;
                ([v.x, v.y], [w.x, w.y])
            }
            None => {
                warnings.push(format!("point {id} lies behind the solved camera"));
                ([f64::NAN; 2], [f64::NAN; 2])
            }
        };
        if outlier {
            outliers.push(id.clone());
        } else {
            sum_sq += residual_px[0].powi(2) + residual_px[1].powi(2);
        }
        residuals.push(ObservationResidual {
            point_id: id,
            residual_px,
            normalised,
            outlier,
        });
    }
    if !converged {
        warnings.push("the adjustment stopped before meeting its convergence test".to_owned());
    }
    if redundancy < 4 {
        warnings.push(format!(
            "low redundancy ({redundancy}): gross errors may go undetected"
        ));
    }
    let observed_px: Vec<Point2<f64>> = observations.iter().map(|o| o.pixel).collect();
    let residual_px: Vec<[f64; 2]> = residuals.iter().map(|r| r.residual_px).collect();
    let pattern = radial_pattern(&camera.intrinsics, &observed_px, &residual_px);
    if !free.k1
        && let Some(p) = pattern.filter(RadialPattern::is_significant)
    {
        warnings.push(p.warning());
    }
    camera.pose.camera_center_in_world += origin;
    Ok(Resection {
        camera,
        residuals,
        rms_px: (sum_sq / (2 * active.len()) as f64).sqrt(),
        redundancy,
        sigma0,
        sigma_center_m: [sd(0), sd(1), sd(2)],
        sigma_angles_deg: [0, 1, 2].map(|i| cov_theta_world[(i, i)].max(0.0).sqrt().to_degrees()),
        sigma_focal_px: focal_col.map(sd),
        sigma_principal_point_px: pp_col.map(|c| [sd(c), sd(c + 1)]),
        sigma_k1: k1_col.map(sd),
        sigma_k2: k2_col.map(sd),
        outliers,
        warnings,
        estimated: free,
        converged,
        radial_pattern: pattern,
    })
}

/// Square roots of the eigenvalues of the scatter matrix (descending).
fn principal_extents(points: &[Point3<f64>]) -> [f64; 3] {
    let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / points.len().max(1) as f64;
    let mut scatter = nalgebra::Matrix3::zeros();
    for p in points {
        let d = p.coords - c;
        scatter += d * d.transpose();
    }
    let mut e: Vec<f64> = scatter
        .symmetric_eigenvalues()
        .iter()
        .map(|v| v.max(0.0).sqrt())
        .collect();
    e.sort_by(|a, b| b.total_cmp(a));
    [e[0], e[1], e[2]]
}

/// First pair of observations imaging two distinct plane points onto the same pixel.
fn coincident_pair(all: &[Obs]) -> Option<(usize, usize, f64, f64)> {
    for a in 0..all.len() {
        for b in a + 1..all.len() {
            let (oa, ob) = (&all[a], &all[b]);
            let dp = (oa.pixel - ob.pixel).norm();
            let dw = (oa.point - ob.point).norm();
            let sigma_world = oa
                .control_sigma_m
                .iter()
                .chain(&ob.control_sigma_m)
                .fold(0.0_f64, |m, s| m.max(*s));
            if dp <= COINCIDENT_SIGMA * oa.sigma_px.hypot(ob.sigma_px)
                && dw > 10.0 * sigma_world.max(1e-6)
            {
                return Some((oa.index, ob.index, dp, dw));
            }
        }
    }
    None
}

/// Whether `o` is consistent with `camera`: within `threshold` σ or within the gate (pixels).
fn is_inlier(camera: &Camera, o: &Obs, threshold: f64, gate_px: f64) -> bool {
    normalised_error_sq(camera, o)
        .is_some_and(|e2| e2 <= threshold * threshold || e2.sqrt() * o.sigma_px <= gate_px)
}

/// Alternates LM on the current inliers with reclassification of every observation until the
/// inlier set is stable. Returns the inliers and (camera, converged).
fn refine_and_reclassify(
    all: &[Obs],
    start: Camera,
    free: SelfCalibration,
    threshold: f64,
    gate_px: f64,
) -> Result<(Vec<Obs>, (Camera, bool)), PhotogrammetryError> {
    let mut camera = start;
    let mut active: Vec<Obs> = all
        .iter()
        .filter(|o| is_inlier(&camera, o, threshold, gate_px))
        .cloned()
        .collect();
    let mut converged = false;
    for _ in 0..MAX_REFINE_ROUNDS {
        if active.len() < MIN_POINTS {
            return Err(PhotogrammetryError::Degenerate {
                reason: format!("only {} observations are consistent", active.len()),
            });
        }
        let problem = Problem::new(&active, &camera, free);
        let sol =
            levenberg_marquardt(&problem, camera).ok_or(PhotogrammetryError::NoConvergence)?;
        camera = sol.state;
        converged = sol.converged;
        let next: Vec<Obs> = all
            .iter()
            .filter(|o| is_inlier(&camera, o, threshold, gate_px))
            .cloned()
            .collect();
        let same =
            next.len() == active.len() && next.iter().zip(&active).all(|(a, b)| a.index == b.index);
        if same || next.len() < MIN_POINTS {
            break;
        }
        active = next;
    }
    Ok((active, (camera, converged)))
}

/// Index (into the problem's observations) and value of the largest normalised residual
/// w = r / √(redundancy number), maximised over the two coordinates of each observation.
fn worst_normalised(problem: &Problem<'_>, camera: &Camera) -> Option<(usize, f64)> {
    let (normal, _, _) = problem.normal_equations(camera)?;
    let inverse_dyn = spd_inverse(&normal)?;
    let m = inverse_dyn.nrows();
    let inverse = SMatrix::<f64, MAX_UNKNOWNS, MAX_UNKNOWNS>::from_fn(|a, b| {
        if a < m && b < m {
            inverse_dyn[(a, b)]
        } else {
            0.0
        }
    });
    let mut worst: Option<(usize, f64)> = None;
    for k in 0..problem.obs.len() {
        let (r, j) = problem.rows(camera, k)?;
        let h = j * inverse * j.transpose();
        for c in 0..2 {
            let redundancy_number = 1.0 - h[(c, c)];
            if redundancy_number <= 1e-6 {
                continue;
            }
            let w = r[c].abs() / redundancy_number.sqrt();
            if worst.is_none_or(|(_, v)| w > v) {
                worst = Some((k, w));
            }
        }
    }
    worst
}

/// Which requested intrinsics the geometry supports; warnings name the others.
fn supported_intrinsics(
    active: &[Obs],
    camera: &Camera,
    options: &ResectionOptions,
    warnings: &mut Vec<String>,
) -> SelfCalibration {
    let mut free = options.self_calibration;
    let names = [
        ("focal", 0usize),
        ("principal_point", 1),
        ("k1", 3),
        ("k2", 4),
    ];
    loop {
        let k = intrinsic_indices(&free).len();
        if k == 0 {
            return free;
        }
        let redundancy = 2 * active.len() as i64 - 6 - k as i64;
        if redundancy < MIN_REDUNDANCY_PER_INTRINSIC * k as i64 {
            warnings.push(format!(
                "self-calibration of {} not attempted: redundancy {redundancy} is below {} for {k} intrinsic parameters",
                names
                    .iter()
                    .filter(|(name, _)| requested(&free, name))
                    .map(|(name, _)| *name)
                    .collect::<Vec<_>>()
                    .join(", "),
                MIN_REDUNDANCY_PER_INTRINSIC * k as i64
            ));
            return SelfCalibration::default();
        }
        let problem = Problem::new(active, camera, free);
        let Some((normal, _, _)) = problem.normal_equations(camera) else {
            return SelfCalibration::default();
        };
        let columns = intrinsic_indices(&free);
        let Some(inverse) = spd_inverse(&normal) else {
            // Singular: drop the last requested parameter and retry.
            let name = names
                .iter()
                .rev()
                .find(|(name, _)| requested(&free, name))
                .map_or("", |n| n.0);
            warnings.push(format!(
                "{name} kept fixed: the normal matrix is singular with it free"
            ));
            set(&mut free, name, false);
            continue;
        };
        // The worst-correlated parameter above the bound is dropped, then the rest re-checked.
        let mut worst: Option<(&str, f64)> = None;
        for (name, first_col) in names {
            if !requested(&free, name) {
                continue;
            }
            let rho = columns
                .iter()
                .enumerate()
                .filter(|(_, c)| **c == first_col || (first_col == 1 && **c == 2))
                .map(|(pos, _)| multiple_correlation(&normal, &inverse, 6 + pos))
                .fold(0.0_f64, f64::max);
            if rho > options.max_correlation && worst.is_none_or(|(_, r)| rho > r) {
                worst = Some((name, rho));
            }
        }
        match worst {
            None => return free,
            Some((name, rho)) => {
                warnings.push(format!(
                    "{name} kept fixed: the control geometry cannot separate it from the other unknowns (multiple correlation {rho:.5} > {})",
                    options.max_correlation
                ));
                set(&mut free, name, false);
            }
        }
    }
}

fn requested(free: &SelfCalibration, name: &str) -> bool {
    match name {
        "focal" => free.focal,
        "principal_point" => free.principal_point,
        "k1" => free.k1,
        _ => free.k2,
    }
}

fn set(free: &mut SelfCalibration, name: &str, value: bool) {
    match name {
        "focal" => free.focal = value,
        "principal_point" => free.principal_point = value,
        "k1" => free.k1 = value,
        _ => free.k2 = value,
    }
}

#[cfg(test)]
mod tests;
