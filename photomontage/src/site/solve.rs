//! Solving a site: the resection of every photo from its control observations, then a bundle
//! adjustment of all solved photos with control and tie points (Durisch 1992 §4.1, "first and
//! second inversion of the camera model"), and writing the results back into the site.
//!
//! Photos are solved independently first, each with no user guess; a photo that cannot be solved
//! (too few control points, missing file, an observation outside the image) is reported with its
//! error and the others go on. The bundle adjustment then refines every solved photo together
//! with the tie points seen in two or more of them.
//!
//! # Known limitations
//! A photo needs at least four control points of its own for its first resection; photos tied to
//! the others only through tie points are not yet solved by relative orientation.

use std::collections::{HashMap, HashSet};

use nalgebra::{Point2, Point3, Rotation3};
use serde::Serialize;

use super::{Exterior, Interior, Site, SiteDocument, TiePoint};
#[path = "solve_ties.rs"]
mod tie_start;
use crate::camera::{Camera, Intrinsics};
use crate::photo::{self, FocalSource};
use crate::photogrammetry::{
    self as pg, BundleOptions, BundlePhoto, BundlePointReport, ControlPoint, ImageObservation,
    ObservationResidual, PhotogrammetryError, ResectionOptions, SelfCalibration,
};

/// Why a photo could not be solved.
#[derive(Debug, thiserror::Error)]
pub enum PhotoSolveError {
    #[error(transparent)]
    Photo(#[from] photo::PhotoError),
    #[error(
        "no focal length: EXIF gives none ({reason}); set photos.interior.focal_px for photo `{photo}`"
    )]
    NoFocalLength { photo: String, reason: String },
    #[error(
        "observation of `{point}` at ({x_px:.1}, {y_px:.1}) lies outside photo `{photo}` ({width}×{height} px)"
    )]
    ObservationOutsideImage {
        photo: String,
        point: String,
        x_px: f64,
        y_px: f64,
        width: u32,
        height: u32,
    },
    #[error(
        "photos.interior.image_size_px of `{photo}` is {stated:?} but the file is {actual:?} px"
    )]
    SizeMismatch {
        photo: String,
        stated: [u32; 2],
        actual: [u32; 2],
    },
    #[error(transparent)]
    Solver(#[from] PhotogrammetryError),
    #[error("photo `{photo}`: {source}")]
    Profile {
        photo: String,
        source: crate::calibration::profile::ProfileError,
    },
}

/// The solution of one photo.
#[derive(Debug, Clone, Serialize)]
pub struct PhotoSolution {
    pub id: String,
    pub camera: Camera,
    pub rms_px: f64,
    pub redundancy: i64,
    pub sigma_center_m: [f64; 3],
    pub sigma_angles_deg: [f64; 3],
    pub sigma_focal_px: Option<f64>,
    pub residuals: Vec<ObservationResidual>,
    pub outliers: Vec<String>,
    pub warnings: Vec<String>,
    pub estimated: SelfCalibration,
    /// `resection` or `bundle`.
    pub solved_by: &'static str,
    /// Where the starting focal length came from.
    pub focal_source: &'static str,
    /// Radial residual pattern of the resection (k1 warning; see
    /// [`crate::photogrammetry::radial_pattern`]).
    pub radial_pattern: Option<crate::photogrammetry::radial_pattern::RadialPattern>,
    /// OpenCV's `solvePnP` started from this camera on the same points (only with the
    /// `opencv` feature).
    pub opencv_check: Option<PoseCheck>,
}

/// An independent solution of a photo's pose compared with ours.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PoseCheck {
    /// Points used (control, and tie points with adjusted coordinates).
    pub points: usize,
    /// Distance between the two camera centres (metres).
    pub center_difference_m: f64,
    /// Angle between the two rotations (degrees).
    pub rotation_difference_deg: f64,
}

/// A photo that could not be solved.
#[derive(Debug, Clone, Serialize)]
pub struct PhotoFailure {
    pub id: String,
    pub error: String,
}

/// Everything a solve found.
#[derive(Debug, Clone, Serialize)]
pub struct SiteSolution {
    pub photos: Vec<PhotoSolution>,
    pub failures: Vec<PhotoFailure>,
    /// Control and tie points as the bundle adjustment estimated them.
    pub points: Vec<BundlePointReport>,
    /// RMS of the bundle adjustment over all observations, when it ran.
    pub bundle_rms_px: Option<f64>,
    pub warnings: Vec<String>,
}

pub(crate) struct Prepared {
    pub(crate) id: String,
    pub(crate) intrinsics: Intrinsics,
    pub(crate) focal_source: &'static str,
    pub(crate) observations: Vec<ImageObservation>,
    pub(crate) self_calibration: SelfCalibration,
}

fn prepare(
    doc: &SiteDocument,
    photo_index: usize,
    warnings: &mut Vec<String>,
) -> Result<Prepared, PhotoSolveError> {
    let p = &doc.site.photos[photo_index];
    let path = doc.resolve(&p.file);
    let actual = photo::size_px(&path)?;
    if let Some(stated) = p.interior.as_ref().and_then(|i| i.image_size_px)
        && stated != actual
    {
        return Err(PhotoSolveError::SizeMismatch {
            photo: p.id.clone(),
            stated,
            actual,
        });
    }
    let (intrinsics, focal_source) = match (&p.interior, &p.profile) {
        (Some(interior), _) => (interior_to_intrinsics(interior, actual), "site"),
        (None, Some(profile)) => {
            let profile_path = doc.resolve(profile);
            let loaded = crate::calibration::profile::CameraProfile::load(&profile_path)
                .and_then(|c| c.intrinsics_for(&profile_path, &p.id, actual))
                .map_err(|source| PhotoSolveError::Profile {
                    photo: p.id.clone(),
                    source,
                })?;
            (loaded, "camera_profile")
        }
        (None, None) => {
            let exif = photo::read_exif(&path);
            let estimate = exif
                .as_ref()
                .ok()
                .and_then(|e| photo::initial_focal_px(e, actual));
            match estimate {
                Some(est) => (
                    Intrinsics::centred(est.focal_px, actual),
                    match est.source {
                        FocalSource::FocalPlaneResolution => "exif_focal_plane_resolution",
                        FocalSource::SensorTable => "exif_sensor_table",
                        FocalSource::Equivalent35mm => "exif_35mm_equivalent",
                    },
                ),
                None => {
                    let reason = match exif {
                        Err(e) => {
                            warnings.push(format!("photo `{}`: {e}", p.id));
                            e.to_string()
                        }
                        Ok(_) => "no focal length tags".into(),
                    };
                    return Err(PhotoSolveError::NoFocalLength {
                        photo: p.id.clone(),
                        reason,
                    });
                }
            }
        }
    };
    let mut observations = Vec::new();
    for o in doc
        .site
        .observations
        .iter()
        .filter(|o| o.photo == p.id && o.enabled)
    {
        let pixel = Point2::new(o.x_px, o.y_px);
        if !intrinsics.contains(pixel) {
            return Err(PhotoSolveError::ObservationOutsideImage {
                photo: p.id.clone(),
                point: o.point.clone(),
                x_px: o.x_px,
                y_px: o.y_px,
                width: actual[0],
                height: actual[1],
            });
        }
        observations.push(ImageObservation {
            point_id: o.point.clone(),
            pixel,
            sigma_px: o.sigma_px,
        });
    }
    let f = p.self_calibration;
    Ok(Prepared {
        id: p.id.clone(),
        intrinsics,
        focal_source,
        observations,
        self_calibration: SelfCalibration {
            focal: f.focal,
            principal_point: f.principal_point,
            k1: f.k1,
            k2: f.k2,
        },
    })
}

fn interior_to_intrinsics(interior: &Interior, image_size_px: [u32; 2]) -> Intrinsics {
    let mut i = Intrinsics::centred(interior.focal_px, image_size_px);
    if let Some(pp) = interior.principal_point_px {
        i.principal_point_px = pp;
    }
    i.distortion = interior.distortion;
    i
}

/// The enabled control points of a site in the solver's form.
#[must_use]
pub fn control_points(site: &Site) -> Vec<ControlPoint> {
    site.control_points
        .iter()
        .filter(|c| c.enabled)
        .map(|c| ControlPoint {
            id: c.id.clone(),
            point_in_world: Point3::from(c.xyz),
            sigma_m: c.sigma_m,
        })
        .collect()
}

/// Solves every photo of a site (and the bundle adjustment when the site asks for it).
#[must_use]
pub fn solve_site(doc: &SiteDocument) -> SiteSolution {
    solve_site_with(doc, pg::bundle_adjust)
}

/// The bundle adjustment [`solve_site_with`] runs (the tests swap in the dense reference).
pub(crate) type BundleAdjust = fn(
    &[BundlePhoto],
    &[ControlPoint],
    &BundleOptions,
) -> Result<pg::BundleReport, PhotogrammetryError>;

/// [`solve_site`] with the bundle adjustment `adjust`.
pub(crate) fn solve_site_with(doc: &SiteDocument, adjust: BundleAdjust) -> SiteSolution {
    let site = &doc.site;
    let control = control_points(site);
    let control_ids: HashSet<&str> = control.iter().map(|c| c.id.as_str()).collect();
    let mut warnings = Vec::new();
    let mut photos = Vec::new();
    let mut failures = Vec::new();
    let mut prepared_by_id: HashMap<String, Prepared> = HashMap::new();

    // Photos whose resection from control failed although they were prepared: the tie points
    // may still place them (`place_by_tie_points`).
    let mut unresected: Vec<(Prepared, PhotoSolveError)> = Vec::new();
    for (index, p) in site.photos.iter().enumerate() {
        let prep = match prepare(doc, index, &mut warnings) {
            Ok(prep) => prep,
            Err(e) => {
                failures.push(PhotoFailure {
                    id: p.id.clone(),
                    error: e.to_string(),
                });
                continue;
            }
        };
        let control_obs: Vec<ImageObservation> = prep
            .observations
            .iter()
            .filter(|o| control_ids.contains(o.point_id.as_str()))
            .cloned()
            .collect();
        let mut options = ResectionOptions::new(prep.intrinsics);
        options.self_calibration = prep.self_calibration;
        options.outlier_threshold_sigma = site.solve.outlier_threshold_sigma;
        options.seed = site.solve.seed;
        match pg::resect(&control, &control_obs, &options) {
            Ok(r) => {
                photos.push(PhotoSolution {
                    id: p.id.clone(),
                    camera: r.camera,
                    rms_px: r.rms_px,
                    redundancy: r.redundancy,
                    sigma_center_m: r.sigma_center_m,
                    sigma_angles_deg: r.sigma_angles_deg,
                    sigma_focal_px: r.sigma_focal_px,
                    residuals: r.residuals,
                    outliers: r.outliers,
                    warnings: r.warnings,
                    estimated: r.estimated,
                    solved_by: "resection",
                    focal_source: prep.focal_source,
                    radial_pattern: r.radial_pattern,
                    opencv_check: None,
                });
                prepared_by_id.insert(p.id.clone(), prep);
            }
            Err(e) => {
                failures.push(PhotoFailure {
                    id: p.id.clone(),
                    error: e.to_string(),
                });
                unresected.push((
                    Prepared {
                        id: p.id.clone(),
                        ..prep
                    },
                    e.into(),
                ));
            }
        }
    }
    let mut rejected_ties = HashSet::new();
    let mut mislabelled: Vec<(String, String, String)> = Vec::new();
    if !unresected.is_empty() {
        let placed = tie_start::place_by_tie_points(
            site,
            &control,
            &mut photos,
            &prepared_by_id,
            unresected,
            &mut warnings,
        );
        for f in &mut failures {
            if let Some(reason) = placed.unplaced.get(&f.id) {
                f.error = format!("{}; {reason}", f.error);
            }
        }
        failures.retain(|f| !placed.prepared.contains_key(&f.id));
        prepared_by_id.extend(placed.prepared);
        rejected_ties = placed.rejected_ties;
        mislabelled = placed.mislabelled;
    }

    let mut points = Vec::new();
    let mut bundle_rms_px = None;
    if site.solve.bundle_adjustment && photos.len() >= 2 {
        // Observations the resection flagged as outliers stay out of the adjustment.
        let bundle_photos: Vec<BundlePhoto> = photos
            .iter()
            .filter_map(|s| {
                let prep = prepared_by_id.get(&s.id)?;
                let outliers: HashSet<&str> = s.outliers.iter().map(String::as_str).collect();
                Some(BundlePhoto {
                    id: s.id.clone(),
                    camera: s.camera,
                    observations: prep
                        .observations
                        .iter()
                        .filter(|o| {
                            !outliers.contains(o.point_id.as_str())
                                && !rejected_ties.contains(&o.point_id)
                        })
                        .cloned()
                        .collect(),
                    self_calibration: s.estimated,
                })
            })
            .collect();
        let options = BundleOptions {
            outlier_threshold_sigma: site.solve.outlier_threshold_sigma,
            // The tie points' σ are written back into the site.
            point_covariance: true,
            ..BundleOptions::default()
        };
        match adjust(&bundle_photos, &control, &options) {
            Ok(report) => {
                bundle_rms_px = Some(report.rms_px);
                warnings.extend(report.warnings.iter().cloned());
                for pr in report.photos {
                    if let Some(s) = photos.iter_mut().find(|s| s.id == pr.id) {
                        let mut outliers = s.outliers.clone();
                        for o in &pr.outliers {
                            if !outliers.contains(o) {
                                outliers.push(o.clone());
                            }
                        }
                        // Observations left out as outliers keep a row in the residual
                        // table, measured against the adjusted camera.
                        let mut residuals = pr.residuals;
                        if let Some(prep) = prepared_by_id.get(&s.id) {
                            for o in &prep.observations {
                                let listed = residuals.iter().any(|r| r.point_id == o.point_id);
                                let known = control.iter().find(|c| c.id == o.point_id);
                                if let (false, Some(c)) = (listed, known)
                                    && let Some(px) = pr.camera.project(&c.point_in_world)
                                {
                                    let v = [px.x - o.pixel.x, px.y - o.pixel.y]; // projected − observed, as everywhere
                                    residuals.push(ObservationResidual {
                                        point_id: o.point_id.clone(),
                                        residual_px: v,
                                        normalised: [v[0] / o.sigma_px, v[1] / o.sigma_px],
                                        outlier: true,
                                    });
                                }
                            }
                        }
                        *s = PhotoSolution {
                            camera: pr.camera,
                            rms_px: pr.rms_px,
                            sigma_center_m: pr.sigma_center_m,
                            sigma_angles_deg: pr.sigma_angles_deg,
                            sigma_focal_px: pr.sigma_focal_px,
                            residuals,
                            outliers,
                            warnings: s.warnings.iter().chain(&pr.warnings).cloned().collect(),
                            estimated: pr.estimated,
                            solved_by: "bundle",
                            ..s.clone()
                        };
                    }
                }
                points = report.points;
            }
            Err(e) => warnings.push(format!(
                "bundle adjustment failed, keeping the single-photo resections: {e}"
            )),
        }
    }
    // A photo placed by tie points has only its start camera unless the bundle adjusted it.
    if bundle_rms_px.is_none() {
        let reason = if site.solve.bundle_adjustment {
            "placed by tie points, but the bundle adjustment that must refine it did not run or failed"
        } else {
            "placed by tie points, but solve.bundle_adjustment is off and only the bundle adjustment can refine it"
        };
        for s in photos
            .iter()
            .filter(|s| s.solved_by == tie_start::SOLVED_BY_TIES)
        {
            failures.push(PhotoFailure {
                id: s.id.clone(),
                error: reason.to_owned(),
            });
        }
        photos.retain(|s| s.solved_by != tie_start::SOLVED_BY_TIES);
    }
    for (photo, a, b) in &mislabelled {
        if let Some(s) = photos.iter().find(|s| &s.id == photo) {
            warnings.push(tie_start::which_label_fits(s, a, b));
        }
    }
    #[cfg(feature = "opencv")]
    for s in &mut photos {
        s.opencv_check = opencv_pose_check(s, &control, &points);
    }
    SiteSolution {
        photos,
        failures,
        points,
        bundle_rms_px,
        warnings,
    }
}

/// OpenCV's `solvePnP` from the adjusted camera on its enabled control and tie observations.
#[cfg(feature = "opencv")]
fn opencv_pose_check(
    s: &PhotoSolution,
    control: &[ControlPoint],
    points: &[BundlePointReport],
) -> Option<PoseCheck> {
    let pairs: Vec<(Point3<f64>, Point2<f64>)> = s
        .residuals
        .iter()
        .filter(|r| !r.outlier)
        .filter_map(|r| {
            let x = control
                .iter()
                .find(|c| c.id == r.point_id)
                .map(|c| c.point_in_world)
                .or_else(|| {
                    points
                        .iter()
                        .find(|p| p.id == r.point_id)
                        .map(|p| p.point_in_world)
                })?;
            let projected = s.camera.project(&x)?;
            // The residual is projected − observed.
            Some((
                x,
                Point2::new(
                    projected.x - r.residual_px[0],
                    projected.y - r.residual_px[1],
                ),
            ))
        })
        .collect();
    crate::features::pnp::pnp_check(&s.camera, &pairs)
        .ok()
        .map(|c| PoseCheck {
            points: c.points,
            center_difference_m: c.center_difference_m,
            rotation_difference_deg: c.rotation_difference_deg,
        })
}

/// Writes a solution into the site: exterior orientations, refined interiors and tie points.
pub fn apply_solution(site: &mut Site, solution: &SiteSolution) {
    for s in &solution.photos {
        let Some(p) = site.photos.iter_mut().find(|p| p.id == s.id) else {
            continue;
        };
        let intr = s.camera.intrinsics;
        let refined = Interior {
            focal_px: intr.focal_px,
            principal_point_px: Some(intr.principal_point_px),
            distortion: intr.distortion,
            image_size_px: Some(intr.image_size_px),
        };
        p.interior = Some(refined);
        let r: Rotation3<f64> = s.camera.pose.rotation_world_from_camera;
        let m = r.matrix();
        p.exterior = Some(Exterior {
            camera_center: s.camera.pose.camera_center_in_world.coords.into(),
            rotation_world_from_camera: [
                [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
                [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
                [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
            ],
            rms_px: s.rms_px,
            sigma_center_m: s.sigma_center_m,
            solved_by: s.solved_by.into(),
        });
    }
    let control: HashSet<&str> = site.control_points.iter().map(|c| c.id.as_str()).collect();
    let ties: Vec<TiePoint> = solution
        .points
        .iter()
        .filter(|p| !p.is_control && !control.contains(p.id.as_str()))
        .map(|p| TiePoint {
            id: p.id.clone(),
            xyz: p.point_in_world.coords.into(),
            sigma_m: p.sigma_m,
        })
        .collect();
    if !ties.is_empty() || !solution.points.is_empty() {
        site.tie_points = ties;
    }
}

/// The camera of a solved photo of a site, as stored in the file.
#[must_use]
pub fn stored_camera(site: &Site, photo_id: &str) -> Option<Camera> {
    let p = site.photos.iter().find(|p| p.id == photo_id)?;
    let interior = p.interior.as_ref()?;
    let ext = p.exterior.as_ref()?;
    let size = interior.image_size_px?;
    let m = nalgebra::Matrix3::from_row_slice(&ext.rotation_world_from_camera.concat());
    Some(Camera {
        intrinsics: interior_to_intrinsics(interior, size),
        pose: crate::camera::Pose {
            rotation_world_from_camera: Rotation3::from_matrix(&m),
            camera_center_in_world: Point3::from(ext.camera_center),
        },
    })
}

#[cfg(test)]
#[path = "solve_tests.rs"]
mod tests;
