//! The photogrammetry core: inversions of the camera model (Durisch 1992 §4.1, "inversion of the
//! camera model") — single-photo resection, multi-photo intersection, bundle adjustment — and
//! the illumination geometry measured in the photos (zenith and sun directions, Durisch §3.3 and
//! §4.1).
//!
//! # Method, and why
//! - **Start with no user guess.** [`resect`] runs RANSAC over minimal three-point samples
//!   solved in closed form (Grunert's P3P as reviewed by Haralick et al. 1994, module [`p3p`]).
//!   P3P needs the focal length (known, or the EXIF value when it is to be refined) but works
//!   unchanged for planar and non-planar control, for wide and tele lenses, and needs no
//!   separate homography/DLT branch; each sample yields at most four poses that are scored on all
//!   points (MSAC). Small point sets are enumerated exhaustively, so results are deterministic.
//! - **Refine** with Levenberg–Marquardt on whitened reprojection residuals with analytic
//!   Jacobians (module [`least_squares`]; rotation updated by a local rotation-vector increment).
//!   We use our own LM on the normal equations rather than the `levenberg-marquardt` crate
//!   because the normal matrix N = JᵀWJ is needed anyway for the covariance, the redundancy
//!   numbers of the outlier test and the support check of self-calibration, and the bundle
//!   adjustment must store N sparsely (camera, point and camera–point blocks) and solve it
//!   through the reduced camera system without ever storing J or a dense N.
//! - **Weights.** Each observation has σ_px; a control point's per-axis σ is propagated into the
//!   image (2×2 covariance J_X Σ_X J_Xᵀ added to σ_px² I), so the pose is not forced through
//!   loosely surveyed points. In the bundle adjustment control σ enters instead as weighted
//!   observations of the coordinates (σ = 0: fixed).
//! - **Outliers.** RANSAC consensus, then iterative data snooping (Baarda 1968): the
//!   observation with the largest normalised residual w = v / (σ √r), r its redundancy number,
//!   is removed if w exceeds the threshold, and the adjustment is repeated.
//! - **Self-calibration** of focal length, principal point, k1 and k2 is attempted only for the
//!   parameters requested, and each is freed only if the geometry supports it: its multiple
//!   correlation with all other unknowns (from N⁻¹) must stay below a bound and the redundancy
//!   must be sufficient. Otherwise it stays fixed and a warning names the parameter and why.
//! - **Precision.** Covariance = σ₀² N⁻¹ with σ₀ = max(1, σ̂₀): the a-posteriori variance
//!   factor inflates the reported σ when the residuals are worse than the stated σ_px, but never
//!   shrinks it (σ̂₀ from small redundancy is itself uncertain).
//! - **Cheirality.** A photo cannot see a point behind it: only points at positive depth count
//!   as inliers of a pose, and input whose points lie behind the camera is refused with
//!   [`PhotogrammetryError::PointsBehindCamera`] naming them (and the photo, in the bundle
//!   adjustment), never answered with a camera.
//!
//! # Known limitations
//! Resection needs at least four control points for a unique pose (three give up to four P3P
//! solutions) and a usable initial focal length. Lens distortion beyond k1 and k2 (k3, p1, p2) is
//! used when given but never estimated. The bundle adjustment's reduced camera system is dense
//! (fine for hundreds of photos; 10⁵ observations of 20 photos take well under a minute) and it
//! detects outliers by normalised residuals without redundancy numbers. With planar control,
//! points behind the camera are explained exactly by the camera mirrored across their plane,
//! which is returned (see [`resection`]).

pub mod absolute;
pub mod block_start;
pub mod bundle;
pub mod control_crs;
pub mod control_io;
pub mod illumination;
pub mod intersection;
pub(crate) mod least_squares;
pub mod p3p;
pub(crate) mod projection;
pub mod radial_pattern;
pub mod resection;
pub mod synthetic;

pub use bundle::{
    BundleOptions, BundlePhoto, BundlePhotoReport, BundlePointReport, BundleReport, bundle_adjust,
};
pub use illumination::{IlluminationError, sun_dir_from_shadow, zenith_dir_from_vertical_edge};
pub use intersection::{Intersection, intersect};
pub use resection::{ObservationResidual, Resection, ResectionOptions, resect};

use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// A surveyed control point in world coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControlPoint {
    /// Point identifier, unique within a site.
    pub id: String,
    /// Surveyed position (metres).
    pub point_in_world: Point3<f64>,
    /// Standard deviation per world axis (metres); 0 = error-free (fixed).
    pub sigma_m: [f64; 3],
}

/// A measured image position of a point in one photo.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageObservation {
    /// Identifier of the observed point (control or tie point).
    pub point_id: String,
    /// Pixel position (pixel-centre convention of [`crate::camera`]).
    pub pixel: Point2<f64>,
    /// Standard deviation of each pixel coordinate.
    pub sigma_px: f64,
}

/// Which interior-orientation parameters to estimate. `Default` = none.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct SelfCalibration {
    pub focal: bool,
    pub principal_point: bool,
    pub k1: bool,
    pub k2: bool,
}

impl SelfCalibration {
    /// Whether any parameter is requested.
    #[must_use]
    pub fn any(&self) -> bool {
        self.focal || self.principal_point || self.k1 || self.k2
    }
}

/// Everything that can go wrong in the photogrammetric solvers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PhotogrammetryError {
    #[error("not enough points: {required} required, {found} found")]
    NotEnoughPoints { required: usize, found: usize },
    #[error(
        "the control points are collinear; the camera rotation about their line is undetermined"
    )]
    Collinear,
    #[error("point {point_id} lies behind the camera")]
    PointBehindCamera { point_id: String },
    /// Cheirality: points observed in a photo lie at depth ≤ 0 in its camera frame. No camera
    /// is returned: a photo cannot show what lies behind it.
    #[error(
        "{} behind the camera{}: a photo cannot show a point behind it (check these points' coordinates and pixels)",
        behind_points(.point_ids),
        .photo.as_ref().map(|p| format!(" of photo {p}")).unwrap_or_default()
    )]
    PointsBehindCamera {
        /// The photo, where the solver knows it (the bundle adjustment; a single resection
        /// does not).
        photo: Option<String>,
        point_ids: Vec<String>,
    },
    #[error(
        "intrinsics: {field} = {value:e} px is outside {min:e}–{max:e} px, the sane range for a {width}×{height} px image"
    )]
    IntrinsicOutOfRange {
        field: &'static str,
        value: f64,
        min: f64,
        max: f64,
        width: u32,
        height: u32,
    },
    #[error("non-finite value in {what}")]
    NonFinite { what: String },
    #[error("duplicate id {id}")]
    DuplicateId { id: String },
    #[error("observation of unknown point {id}")]
    UnknownPoint { id: String },
    #[error(
        "observations of {first} and {second} are {pixel_distance_px:.2} px apart but the points are {world_distance_m:.2} m apart on a plane: one label is wrong"
    )]
    CoincidentObservations {
        first: String,
        second: String,
        pixel_distance_px: f64,
        world_distance_m: f64,
    },
    #[error("invalid σ {value} for {what}")]
    InvalidSigma { what: String, value: f64 },
    #[error("the adjustment did not converge")]
    NoConvergence,
    #[error("degenerate geometry: {reason}")]
    Degenerate { reason: String },
}

/// "point a lies" / "points a, b lie" for [`PhotogrammetryError::PointsBehindCamera`].
fn behind_points(point_ids: &[String]) -> String {
    match point_ids {
        [one] => format!("point {one} lies"),
        many => format!("points {} lie", many.join(", ")),
    }
}

/// Rejects non-finite coordinates and invalid σ in control points, and duplicate ids.
pub(crate) fn validate_control(control: &[ControlPoint]) -> Result<(), PhotogrammetryError> {
    let mut seen = std::collections::HashSet::new();
    for c in control {
        if !c.point_in_world.coords.iter().all(|v| v.is_finite()) {
            return Err(PhotogrammetryError::NonFinite {
                what: format!("control point {}", c.id),
            });
        }
        for &s in &c.sigma_m {
            if !(s.is_finite() && s >= 0.0) {
                return Err(PhotogrammetryError::InvalidSigma {
                    what: format!("control point {}", c.id),
                    value: s,
                });
            }
        }
        if !seen.insert(c.id.as_str()) {
            return Err(PhotogrammetryError::DuplicateId { id: c.id.clone() });
        }
    }
    Ok(())
}

/// Rejects non-finite pixels, σ ≤ 0 and a point observed twice in the same photo.
pub(crate) fn validate_observations(
    observations: &[ImageObservation],
) -> Result<(), PhotogrammetryError> {
    let mut seen = std::collections::HashSet::new();
    for o in observations {
        if !(o.pixel.x.is_finite() && o.pixel.y.is_finite()) {
            return Err(PhotogrammetryError::NonFinite {
                what: format!("observation of {}", o.point_id),
            });
        }
        if !(o.sigma_px.is_finite() && o.sigma_px > 0.0) {
            return Err(PhotogrammetryError::InvalidSigma {
                what: format!("observation of {}", o.point_id),
                value: o.sigma_px,
            });
        }
        if !seen.insert(o.point_id.as_str()) {
            return Err(PhotogrammetryError::DuplicateId {
                id: o.point_id.clone(),
            });
        }
    }
    Ok(())
}

/// The focal length may be at least this fraction of the larger image side: a rectilinear lens
/// with f = 0.01·w would see 176° across, beyond any real lens, and smaller values only feed
/// NaN into P3P.
pub const MIN_FOCAL_FRACTION_OF_IMAGE: f64 = 0.01;
/// The focal length may be at most this multiple of the larger image side. A 2000 mm lens on a
/// full-frame sensor is ≈ 56 × the width, but small crops of telephoto images and synthetic
/// near-orthographic test cameras (f = 1e5 px on a 15-px image, `tests/cli_lights.rs`) go far
/// beyond; the bound only keeps the arithmetic finite.
pub const MAX_FOCAL_MULTIPLE_OF_IMAGE: f64 = 1e5;
/// The principal point may lie at most this many image sides outside the image (shifted-lens
/// crops put it outside, but never by more than an image or two).
pub const PRINCIPAL_POINT_MARGIN_IMAGES: f64 = 10.0;

/// Rejects non-finite intrinsics, an empty image, and a focal length or principal point
/// outside the sane range for the image size (checked before any work: values far outside send
/// NaN into the solvers).
pub(crate) fn validate_intrinsics(
    intrinsics: &crate::camera::Intrinsics,
) -> Result<(), PhotogrammetryError> {
    let d = &intrinsics.distortion;
    let named = [
        ("focal_px", intrinsics.focal_px),
        ("principal_point_px[0]", intrinsics.principal_point_px[0]),
        ("principal_point_px[1]", intrinsics.principal_point_px[1]),
        ("distortion.k1", d.k1),
        ("distortion.k2", d.k2),
        ("distortion.k3", d.k3),
        ("distortion.p1", d.p1),
        ("distortion.p2", d.p2),
    ];
    if let Some((field, _)) = named.iter().find(|(_, v)| !v.is_finite()) {
        return Err(PhotogrammetryError::NonFinite {
            what: format!("intrinsics {field}"),
        });
    }
    if intrinsics.focal_px <= 0.0 {
        return Err(PhotogrammetryError::Degenerate {
            reason: format!("focal length {} px is not positive", intrinsics.focal_px),
        });
    }
    let [width, height] = intrinsics.image_size_px;
    if width == 0 || height == 0 {
        return Err(PhotogrammetryError::Degenerate {
            reason: format!("image size {width}×{height} px is empty"),
        });
    }
    let out_of_range = |field: &'static str, value: f64, min: f64, max: f64| {
        (!(min..=max).contains(&value)).then_some(PhotogrammetryError::IntrinsicOutOfRange {
            field,
            value,
            min,
            max,
            width,
            height,
        })
    };
    let side = f64::from(width.max(height));
    let focal = out_of_range(
        "focal_px",
        intrinsics.focal_px,
        MIN_FOCAL_FRACTION_OF_IMAGE * side,
        MAX_FOCAL_MULTIPLE_OF_IMAGE * side,
    );
    let pp = |field, value: f64, size: u32| {
        let size = f64::from(size);
        out_of_range(
            field,
            value,
            -PRINCIPAL_POINT_MARGIN_IMAGES * size,
            (1.0 + PRINCIPAL_POINT_MARGIN_IMAGES) * size,
        )
    };
    let pp_x = pp(
        "principal_point_px[0]",
        intrinsics.principal_point_px[0],
        width,
    );
    let pp_y = pp(
        "principal_point_px[1]",
        intrinsics.principal_point_px[1],
        height,
    );
    match focal.or(pp_x).or(pp_y) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
