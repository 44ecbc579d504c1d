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
//! The normal equations are assembled densely but solved by eliminating the 3×3 point blocks
//! (Schur complement), so a step costs O(points · cameras²) + O(cameras³).
//!
//! Outliers: after convergence the observation with the largest whitened residual is removed
//! when it exceeds the threshold, and the adjustment repeated (at most
//! [`BundleOptions::max_outlier_rounds`] times); a tie point left with one ray is dropped.
//! Without redundancy numbers this test is conservative (residuals are shrunk by √r).
//!
//! # Known limitations
//! Dense camera block: fine for tens of photos, not thousands. The datum comes from the
//! control only (at least three non-collinear control points are needed); no free-network
//! adjustment.

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector, Matrix3, Point3, Vector3};
use serde::Serialize;

use super::least_squares::{NormalEquations, levenberg_marquardt, multiple_correlation};
use super::projection::{
    apply_intrinsics_increment, apply_pose_increment, intrinsic_indices, project_with_jacobian,
};
use super::resection::ObservationResidual;
use super::{
    ControlPoint, ImageObservation, PhotogrammetryError, SelfCalibration, intersect,
    validate_control, validate_intrinsics, validate_observations,
};
use crate::camera::Camera;

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
}

impl Default for BundleOptions {
    fn default() -> Self {
        Self {
            outlier_threshold_sigma: 3.5,
            max_outlier_rounds: 20,
            max_correlation: 0.999,
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
    /// σ along world X, Y, Z (0 for fixed control).
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

#[derive(Clone)]
struct State {
    cameras: Vec<Camera>,
    /// Reduced coordinates of the unknown points.
    points: Vec<Point3<f64>>,
}

struct Obs {
    photo: usize,
    /// Index of an unknown point, or the fixed point in reduced coordinates.
    point: PointRef,
    observation: ImageObservation,
    active: bool,
}

#[derive(Clone, Copy)]
enum PointRef {
    Unknown(usize),
    Fixed(Point3<f64>),
}

struct Problem {
    observations: Vec<Obs>,
    /// Per unknown point: surveyed position (reduced) and σ, for weighted control.
    priors: Vec<Option<(Point3<f64>, [f64; 3])>>,
    /// Tie points left with fewer than two rays after outlier removal: kept in the system
    /// with an identity block (zero step) and reported without σ.
    dropped: Vec<bool>,
    free: Vec<SelfCalibration>,
    /// First column of each photo's block.
    offsets: Vec<usize>,
    camera_columns: usize,
}

impl Problem {
    fn camera_block(&self, photo: usize) -> usize {
        6 + intrinsic_indices(&self.free[photo]).len()
    }

    fn point_position(state: &State, r: PointRef) -> Point3<f64> {
        match r {
            PointRef::Unknown(q) => state.points[q],
            PointRef::Fixed(p) => p,
        }
    }
}

impl NormalEquations for Problem {
    type State = State;
    fn unknowns(&self) -> usize {
        self.camera_columns + 3 * self.priors.len()
    }
    fn cost(&self, s: &State) -> Option<f64> {
        let mut cost = 0.0;
        for o in self.observations.iter().filter(|o| o.active) {
            let p = s.cameras[o.photo].project(&Self::point_position(s, o.point))?;
            cost += ((p - o.observation.pixel) / o.observation.sigma_px).norm_squared();
        }
        for (q, prior) in self.priors.iter().enumerate() {
            if let Some((x0, sigma)) = prior {
                let d = s.points[q] - x0;
                cost += (0..3).map(|i| (d[i] / sigma[i]).powi(2)).sum::<f64>();
            }
        }
        Some(cost)
    }
    fn normal_equations(&self, s: &State) -> Option<(DMatrix<f64>, DVector<f64>, f64)> {
        let m = self.unknowns();
        let mut n = DMatrix::zeros(m, m);
        let mut g = DVector::zeros(m);
        let mut cost = 0.0;
        for o in self.observations.iter().filter(|o| o.active) {
            let camera = &s.cameras[o.photo];
            let pj = project_with_jacobian(camera, &Self::point_position(s, o.point))?;
            let w = 1.0 / o.observation.sigma_px;
            let r = (pj.pixel - o.observation.pixel) * w;
            cost += r.norm_squared();
            let cols = intrinsic_indices(&self.free[o.photo]);
            let k = 6 + cols.len();
            let mut jc = DMatrix::zeros(2, k);
            jc.view_mut((0, 0), (2, 6)).copy_from(&(pj.d_pose * w));
            for (c, &col) in cols.iter().enumerate() {
                jc[(0, 6 + c)] = pj.d_intrinsics[(0, col)] * w;
                jc[(1, 6 + c)] = pj.d_intrinsics[(1, col)] * w;
            }
            let oc = self.offsets[o.photo];
            let jct = jc.transpose();
            let mut ncc = n.view_mut((oc, oc), (k, k));
            ncc += &jct * &jc;
            let mut gc = g.rows_mut(oc, k);
            gc += &jct * DVector::from_column_slice(r.as_slice());
            if let PointRef::Unknown(q) = o.point {
                let op = self.camera_columns + 3 * q;
                let jp = pj.d_point * w;
                let jpt = jp.transpose();
                let npp = jpt * jp;
                let mut block = n.fixed_view_mut::<3, 3>(op, op);
                block += npp;
                let ncp = &jct * DMatrix::from_column_slice(2, 3, jp.as_slice());
                let mut upper = n.view_mut((oc, op), (k, 3));
                upper += &ncp;
                let mut lower = n.view_mut((op, oc), (3, k));
                lower += ncp.transpose();
                let mut gp = g.fixed_rows_mut::<3>(op);
                gp += jpt * r;
            }
        }
        for (q, dropped) in self.dropped.iter().enumerate() {
            if *dropped {
                let op = self.camera_columns + 3 * q;
                for i in 0..3 {
                    n[(op + i, op + i)] += 1.0;
                }
            }
        }
        for (q, prior) in self.priors.iter().enumerate() {
            if let Some((x0, sigma)) = prior {
                let op = self.camera_columns + 3 * q;
                let d = s.points[q] - x0;
                for i in 0..3 {
                    let w2 = 1.0 / (sigma[i] * sigma[i]);
                    n[(op + i, op + i)] += w2;
                    g[op + i] += d[i] * w2;
                    cost += d[i] * d[i] * w2;
                }
            }
        }
        Some((n, g, cost))
    }
    fn update(&self, s: &State, delta: &DVector<f64>) -> State {
        let d = delta.as_slice();
        let cameras = s
            .cameras
            .iter()
            .enumerate()
            .map(|(p, c)| {
                let o = self.offsets[p];
                let k = self.camera_block(p);
                Camera {
                    pose: apply_pose_increment(&c.pose, &d[o..o + 6]),
                    intrinsics: apply_intrinsics_increment(
                        &c.intrinsics,
                        &self.free[p],
                        &d[o + 6..o + k],
                    ),
                }
            })
            .collect();
        let points = s
            .points
            .iter()
            .enumerate()
            .map(|(q, x)| {
                let o = self.camera_columns + 3 * q;
                x + Vector3::new(d[o], d[o + 1], d[o + 2])
            })
            .collect();
        State { cameras, points }
    }
    fn solve(&self, damped: &DMatrix<f64>, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        schur_solve(damped, rhs, self.camera_columns, self.priors.len())
    }
}

/// Solves N x = b by eliminating the 3×3 point blocks.
fn schur_solve(
    n: &DMatrix<f64>,
    b: &DVector<f64>,
    nc: usize,
    points: usize,
) -> Option<DVector<f64>> {
    let (s, rs, cinv) = reduce(n, b, nc, points)?;
    let chol = s.cholesky()?;
    let xc = chol.solve(&rs);
    let mut x = DVector::zeros(nc + 3 * points);
    x.rows_mut(0, nc).copy_from(&xc);
    for (q, ci) in cinv.iter().enumerate() {
        let o = nc + 3 * q;
        let bq = n.view((0, o), (nc, 3));
        let rhs = b.fixed_rows::<3>(o) - bq.transpose() * &xc;
        x.fixed_rows_mut::<3>(o).copy_from(&(ci * rhs));
    }
    Some(x)
}

type Reduced = (DMatrix<f64>, DVector<f64>, Vec<Matrix3<f64>>);

/// Reduced camera system S = A − B C⁻¹ Bᵀ, its right-hand side and the C_q⁻¹.
fn reduce(n: &DMatrix<f64>, b: &DVector<f64>, nc: usize, points: usize) -> Option<Reduced> {
    let mut s = n.view((0, 0), (nc, nc)).clone_owned();
    let mut rs = b.rows(0, nc).clone_owned();
    let mut cinv = Vec::with_capacity(points);
    for q in 0..points {
        let o = nc + 3 * q;
        let ci = n.fixed_view::<3, 3>(o, o).into_owned().try_inverse()?;
        let bq = n.view((0, o), (nc, 3));
        // Only cameras observing q have non-zero rows in B_q.
        let rows: Vec<usize> = (0..nc)
            .filter(|&i| bq.row(i).iter().any(|v| *v != 0.0))
            .collect();
        let bci: Vec<nalgebra::RowVector3<f64>> = rows
            .iter()
            .map(|&i| bq.fixed_view::<1, 3>(i, 0) * ci)
            .collect();
        let bq_rhs = b.fixed_rows::<3>(o);
        for (a, &i) in rows.iter().enumerate() {
            for &j in &rows {
                s[(i, j)] -= (bci[a] * bq.fixed_view::<1, 3>(j, 0).transpose())[0];
            }
            rs[i] -= (bci[a] * bq_rhs)[0];
        }
        cinv.push(ci);
    }
    Some((s, rs, cinv))
}

/// Camera block of N⁻¹ and the 3×3 point blocks of N⁻¹.
fn reduced_inverse(
    n: &DMatrix<f64>,
    nc: usize,
    points: usize,
) -> Option<(DMatrix<f64>, Vec<Matrix3<f64>>)> {
    let zero = DVector::zeros(nc + 3 * points);
    let (s, _, cinv) = reduce(n, &zero, nc, points)?;
    let s_inv = super::least_squares::spd_inverse(&s)?;
    let mut point_cov = Vec::with_capacity(points);
    for (q, ci) in cinv.iter().enumerate() {
        let o = nc + 3 * q;
        let bq = n.view((0, o), (nc, 3));
        let t = ci * bq.transpose(); // 3 × nc
        point_cov.push(ci + &t * &s_inv * t.transpose());
    }
    Some((s_inv, point_cov))
}

/// Adjusts all photos, points and requested intrinsics together.
///
/// # Errors
/// Invalid input (non-finite values, duplicate ids, σ ≤ 0), `NotEnoughPoints` when fewer than
/// two photos or no usable observations, `Degenerate` when the control does not fix the datum,
/// `PointBehindCamera` when a tie point cannot be initialised in front of its cameras.
pub fn bundle_adjust(
    photos: &[BundlePhoto],
    control: &[ControlPoint],
    options: &BundleOptions,
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
        let mut offsets = Vec::with_capacity(free.len());
        let mut col = 0;
        for f in free {
            offsets.push(col);
            col += 6 + intrinsic_indices(f).len();
        }
        Problem {
            dropped: vec![false; priors.len()],
            observations,
            priors: priors.clone(),
            free: free.to_vec(),
            offsets,
            camera_columns: col,
        }
    };
    let mut problem = build(&free, observations);
    let unsolvable = || {
        PhotogrammetryError::Degenerate {
        reason: "the adjustment is singular: control does not fix every photo and point (datum, or too few rays)".to_owned(),
    }
    };

    // Solve; drop unsupported intrinsics; then outlier rounds.
    let mut solution =
        levenberg_marquardt(&problem, state.clone()).ok_or(PhotogrammetryError::NoConvergence)?;
    if free.iter().any(SelfCalibration::any) {
        let (s_inv, _) = reduced_inverse(
            &solution.normal,
            problem.camera_columns,
            problem.priors.len(),
        )
        .ok_or_else(unsolvable)?;
        let mut changed = false;
        for (p, f) in free.iter_mut().enumerate() {
            let cols = intrinsic_indices(f);
            let o = problem.offsets[p];
            for (name, index) in [("focal", 0), ("principal_point", 1), ("k1", 3), ("k2", 4)] {
                let Some(pos) = cols.iter().position(|c| *c == index) else {
                    continue;
                };
                let rho = multiple_correlation(&solution.normal, &s_inv, o + 6 + pos);
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

    // Statistics.
    let nc = problem.camera_columns;
    let (s_inv, point_cov) =
        reduced_inverse(&solution.normal, nc, problem.priors.len()).ok_or_else(unsolvable)?;
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
        let cov = point_cov[q] * variance;
        let sigma_m = if problem.dropped[q] {
            [f64::NAN; 3]
        } else {
            [0, 1, 2].map(|i| cov[(i, i)].max(0.0).sqrt())
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
