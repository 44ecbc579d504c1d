//! The view geometry report of one solved photo: everything a verified view states about the
//! camera (Landscape Institute TGN 06/19 Appendix 1 "Technical methodology" and its
//! photograph/photomontage information template; London View Management Framework SPG 2012,
//! Appendix C "Accurate Visual Representations"): where the camera stood (survey CRS, latitude and
//! longitude, height above datum and above ground), where it looked (bearing from true and grid
//! north, pitch, roll), its lens (focal length in pixels and as a 35 mm equivalent, fields of view,
//! principal point, distortion), when the photo was taken and where the sun stood then, how well
//! the camera is determined (residual table, RMS, σ of the centre), how far the proposal is, and
//! the viewing distance of the printed sheet.
//!
//! # Definitions
//! With `d = rotation_world_from_camera · (0, 0, 1)` the optical axis in the world (X east = grid
//! east, Y grid north, Z up):
//! - `bearing_grid_deg = atan2(d_x, d_y)` in [0°, 360°), clockwise from grid north;
//!   `bearing_true_deg = bearing_grid_deg − grid_convergence_deg` (the site's convergence is the
//!   angle from grid north to true north, clockwise);
//! - `pitch_deg = atan2(d_z, √(d_x² + d_y²))`, the optical axis above the horizontal;
//! - `roll_deg`: the angle, in the image plane, from the level direction `h = d × Z / |d × Z|` (the
//!   horizon's direction in the photo) to the image x axis `x = R·(1, 0, 0)`, positive when x
//!   points below the horizontal on the right (clockwise as the photographer sees it):
//!   `atan2(x · (d × h), x · h)`. This is the third angle of the heading–pitch–roll
//!   decomposition `R = R_heading · R_pitch · R_roll(about the optical axis)`;
//! - fields of view: the angle between the rays through the two edges of the image (pixel −0.5 and
//!   W − 0.5) on the row of the principal point (HFoV), and through the top and bottom edges on
//!   its column (VFoV), distortion removed; for a distortion-free camera with a central principal
//!   point `HFoV = 2·atan(W / 2f)`;
//! - `focal_35mm_equiv_mm = f_px · 43.27 mm / √(W² + H²)`: the lens that gives the image's
//!   diagonal angle of view on the 36 × 24 mm frame (the convention of EXIF
//!   `FocalLengthIn35mmFilm`); it needs no sensor data, only the solved focal length and the image
//!   size as displayed;
//! - `viewing_distance_mm = w / (2·tan(HFoV/2))` with `w` the printed image width of the sheet
//!   ([`super::paper`]).
//!
//! # Known limitations
//! Heights are the survey's heights (no geoid model). The ground is the first scene polygon
//! straight below the camera; without one (or with `ground_level_m`) the height above ground is
//! unknown or given. The sun is computed at the camera's latitude and longitude when the CRS is
//! known, else at the site's `[location]`. The residual table is recomputed from the stored
//! camera and the enabled observations; the solve's outlier decisions are not stored, so
//! observations beyond the site's `outlier_threshold_sigma` are flagged here again.

use chrono::DateTime;
use nalgebra::{Point2, Point3, Vector3};
use serde::Serialize;

use super::measure;
use super::paper::{PaperSize, viewing_distance_mm};
use crate::camera::{BrownConrady, Camera, Intrinsics};
use crate::geo::ProjectedCrs;
use crate::photo::exif::FULL_FRAME_DIAGONAL_MM;
use crate::scene::ObjectKind;
use crate::site::SiteDocument;
use crate::site::render::{SiteRenderError, site_camera, site_scene};
use crate::sun::{SpaParams, solar_position};

/// The optical axis counts as vertical (bearing and roll undefined) when its horizontal part is
/// below this (1e-9 of a unit vector: 2e-7° from the vertical).
const VERTICAL_AXIS_TOL: f64 = 1e-9;
/// A grid convergence computed from the CRS that differs from the site's by more than this gets a
/// note (0.01°: the precision the bearings are given to).
const CONVERGENCE_NOTE_DEG: f64 = 0.01;

/// What can go wrong building the report.
#[derive(Debug, thiserror::Error)]
pub enum ViewGeometryError {
    /// The view is unknown or not solved, or the scene cannot be built.
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    /// A view made from several photos was given none.
    #[error("a view needs at least one solved photo; none was given")]
    NoPhotos,
    /// The optical axis is vertical: no bearing and no roll.
    #[error("photo {photo}: the optical axis is vertical, so bearing and roll are undefined")]
    VerticalAxis { photo: String },
    /// The focal length or image size cannot give a 35 mm equivalent.
    #[error(
        "photo {photo}: focal length {focal_px} px with image size {image_size_px:?} px cannot be \
         converted to a 35 mm equivalent (both must be positive and finite)"
    )]
    FocalNotConvertible {
        photo: String,
        focal_px: f64,
        image_size_px: [u32; 2],
    },
}

/// What image the geometry describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViewProjection {
    /// The photo itself (its solved camera).
    #[default]
    Photo,
    /// A pinhole view re-projected from a photo to a standard focal length
    /// ([`super::planar_view`]).
    Planar,
    /// A level cylinder composed from several photos taken from one point
    /// ([`super::cylindrical_view`]): `focal_px` is the cylinder radius, the fields of view are
    /// the cylinder's.
    Cylindrical,
}

/// Where the ground level below the camera came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", content = "polygon", rename_all = "snake_case")]
pub enum GroundSource {
    /// The scene polygon straight below the camera (its id).
    ScenePolygon(String),
    /// Given by the user (`--ground-level-m`).
    Given,
}

/// One row of the control-point residual table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualRow {
    /// The point observed.
    pub point_id: String,
    /// `control` or `tie`.
    pub point_kind: &'static str,
    /// Where it was clicked.
    pub observed_px: [f64; 2],
    /// Projected minus observed.
    pub residual_px: [f64; 2],
    /// |residual|.
    pub residual_norm_px: f64,
    /// σ of the residual: the click's σ and the point's survey σ (RMS over the axes) projected
    /// at its depth, `√(σ_px² + (f·σ_m/depth)²)`.
    pub sigma_px: f64,
    /// |residual| / `sigma_px`.
    pub normalised: f64,
    /// Above the site's `solve.outlier_threshold_sigma`.
    pub flagged: bool,
}

/// The view geometry of one solved photo. Angles in degrees, lengths in metres unless the name
/// says otherwise; `None` (JSON `null`) where the site does not give what is needed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewGeometry {
    /// The view's name: the photo's id, or the photos' ids joined by `+` for a cylinder.
    pub photo_id: String,
    /// The image described: the photo, or a view re-projected from it.
    pub projection: ViewProjection,
    /// The solved photos the view is made from.
    pub source_photos: Vec<String>,
    /// Projection centre [E, N, H] in the survey CRS.
    pub camera_position_m: [f64; 3],
    /// The survey CRS named by the site (`location.crs`).
    pub crs: Option<String>,
    /// WGS84 latitude of the camera (from the CRS).
    pub latitude_deg: Option<f64>,
    /// WGS84 longitude of the camera (from the CRS).
    pub longitude_deg: Option<f64>,
    /// The camera's height in the survey's vertical datum (its Z).
    pub height_above_datum_m: f64,
    /// Ground level straight below the camera.
    pub ground_level_m: Option<f64>,
    pub ground_level_source: Option<GroundSource>,
    pub height_above_ground_m: Option<f64>,
    /// Optical axis, clockwise from true north.
    pub bearing_true_deg: f64,
    /// Optical axis, clockwise from grid north (survey +Y).
    pub bearing_grid_deg: f64,
    /// The site's `location.grid_convergence_deg` (grid north to true north, clockwise), used
    /// for `bearing_true_deg`.
    pub grid_convergence_deg: f64,
    /// The convergence the CRS gives at the camera (same convention), when the CRS is known.
    pub crs_grid_convergence_deg: Option<f64>,
    /// Optical axis above the horizontal.
    pub pitch_deg: f64,
    /// Image x axis below the horizontal on the right (clockwise as the photographer sees it).
    pub roll_deg: f64,
    pub focal_px: f64,
    /// 35 mm-equivalent focal length (diagonal angle of view on a 36 × 24 mm frame).
    pub focal_35mm_equiv_mm: f64,
    /// Focal length stated by the photo's EXIF, when readable.
    pub exif_focal_length_mm: Option<f64>,
    /// 35 mm equivalent stated by the photo's EXIF, when present.
    pub exif_focal_35mm_mm: Option<f64>,
    pub hfov_deg: f64,
    pub vfov_deg: f64,
    pub image_size_px: [u32; 2],
    pub principal_point_px: [f64; 2],
    pub distortion: BrownConrady,
    /// Capture time, RFC 3339 with its offset.
    pub capture_time: Option<String>,
    /// `photos.taken_at` or `exif`.
    pub capture_time_source: Option<&'static str>,
    /// Sun azimuth at capture, clockwise from true north (NREL SPA).
    pub sun_azimuth_deg: Option<f64>,
    /// Sun elevation at capture, refraction included.
    pub sun_elevation_deg: Option<f64>,
    /// RMS reprojection residual of the solve.
    pub rms_px: f64,
    /// σ of the camera centre per axis [σE, σN, σH].
    pub sigma_center_m: [f64; 3],
    /// `resection` or `bundle`.
    pub solved_by: String,
    pub residuals: Vec<ResidualRow>,
    /// Visible models making up the proposal.
    pub proposal_models: Vec<String>,
    /// Distance from the camera to the nearest point of the proposal.
    pub distance_to_proposal_nearest_m: Option<f64>,
    /// Distance from the camera to the proposal's centroid.
    pub distance_to_proposal_centroid_m: Option<f64>,
    /// The proposal's centroid [E, N, H].
    pub proposal_centroid_m: Option<[f64; 3]>,
    /// `volume` (closed by its base plane) or `surface` ([`measure::centroid`]).
    pub proposal_centroid_kind: Option<measure::CentroidKind>,
    /// Paper of the sheet the viewing distance is for.
    pub paper: PaperSize,
    /// Printed width of the image on that sheet.
    pub printed_image_width_mm: f64,
    /// Distance at which the printed image shows the correct perspective.
    pub viewing_distance_mm: f64,
    /// What could not be determined and why, and other remarks.
    pub notes: Vec<String>,
}

/// Choices of the report.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewGeometryOptions {
    /// Paper of the sheet the viewing distance is computed for.
    pub paper: PaperSize,
    /// Ground level below the camera given by the user (overrides the scene polygons).
    pub ground_level_m: Option<f64>,
}

/// Bearing (grid), pitch and roll of a camera, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraAngles {
    pub bearing_grid_deg: f64,
    pub pitch_deg: f64,
    pub roll_deg: f64,
}

/// Bearing from grid north, pitch and roll of `camera` (definitions in the module doc), or `None`
/// when the optical axis is vertical.
#[must_use]
pub fn camera_angles(camera: &Camera) -> Option<CameraAngles> {
    let r = camera.pose.rotation_world_from_camera;
    let d = r * Vector3::z();
    let horizontal = d.x.hypot(d.y);
    if horizontal < VERTICAL_AXIS_TOL {
        return None;
    }
    let level_right = Vector3::new(d.y, -d.x, 0.0) / horizontal; // d × Z, normalised
    let level_down = d.cross(&level_right);
    let x_axis = r * Vector3::x();
    Some(CameraAngles {
        bearing_grid_deg: normalise_deg(d.x.atan2(d.y).to_degrees()),
        pitch_deg: d.z.atan2(horizontal).to_degrees(),
        roll_deg: x_axis
            .dot(&level_down)
            .atan2(x_axis.dot(&level_right))
            .to_degrees(),
    })
}

/// An angle in degrees brought into [0, 360).
#[must_use]
pub fn normalise_deg(angle_deg: f64) -> f64 {
    let a = angle_deg.rem_euclid(360.0);
    if a >= 360.0 { 0.0 } else { a }
}

fn angle_between_pixels(intrinsics: &Intrinsics, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ray = |p| {
        let n = intrinsics.normalised_from_pixel(p);
        Vector3::new(n.x, n.y, 1.0)
    };
    let (ra, rb) = (ray(a), ray(b));
    ra.cross(&rb).norm().atan2(ra.dot(&rb)).to_degrees()
}

/// Horizontal and vertical field of view in degrees (definitions in the module doc).
#[must_use]
pub fn fields_of_view_deg(intrinsics: &Intrinsics) -> [f64; 2] {
    let [w, h] = intrinsics.image_size_px.map(f64::from);
    let [cx, cy] = intrinsics.principal_point_px;
    [
        angle_between_pixels(intrinsics, Point2::new(-0.5, cy), Point2::new(w - 0.5, cy)),
        angle_between_pixels(intrinsics, Point2::new(cx, -0.5), Point2::new(cx, h - 0.5)),
    ]
}

/// 35 mm-equivalent focal length (diagonal convention), `None` when the focal length or the image
/// size is not positive and finite.
#[must_use]
pub fn focal_35mm_equiv_mm(focal_px: f64, image_size_px: [u32; 2]) -> Option<f64> {
    let diagonal_px = f64::from(image_size_px[0]).hypot(f64::from(image_size_px[1]));
    (focal_px.is_finite() && focal_px > 0.0 && diagonal_px > 0.0)
        .then(|| focal_px * FULL_FRAME_DIAGONAL_MM / diagonal_px)
}

fn residual_table(doc: &SiteDocument, camera: &Camera, photo_id: &str) -> Vec<ResidualRow> {
    let site = &doc.site;
    let threshold = site.solve.outlier_threshold_sigma;
    site.observations
        .iter()
        .filter(|o| o.photo == photo_id && o.enabled)
        .filter_map(|o| {
            let (xyz, sigma_m, kind) = site
                .control_points
                .iter()
                .find(|c| c.id == o.point && c.enabled)
                .map(|c| (c.xyz, c.sigma_m, "control"))
                .or_else(|| {
                    site.tie_points
                        .iter()
                        .find(|t| t.id == o.point)
                        .map(|t| (t.xyz, t.sigma_m, "tie"))
                })?;
            let point = Point3::from(xyz);
            let projected = camera.project(&point)?;
            let depth_m = camera.pose.camera_from_world(&point).z;
            let point_sigma_m = (sigma_m.iter().map(|s| s * s).sum::<f64>() / 3.0).sqrt();
            let sigma_px = o
                .sigma_px
                .hypot(camera.intrinsics.focal_px * point_sigma_m / depth_m);
            let residual_px = [projected.x - o.x_px, projected.y - o.y_px];
            let norm = residual_px[0].hypot(residual_px[1]);
            let normalised = norm / sigma_px;
            Some(ResidualRow {
                point_id: o.point.clone(),
                point_kind: kind,
                observed_px: [o.x_px, o.y_px],
                residual_px,
                residual_norm_px: norm,
                sigma_px,
                normalised,
                flagged: normalised > threshold,
            })
        })
        .collect()
}

/// The capture time of a photo: `taken_at`, else its EXIF time with offset.
fn capture_time(doc: &SiteDocument, photo_id: &str) -> Option<(String, &'static str)> {
    let photo = doc.site.photos.iter().find(|p| p.id == photo_id)?;
    if let Some(t) = &photo.taken_at {
        return Some((t.clone(), "photos.taken_at"));
    }
    crate::photo::read_exif(&doc.resolve(&photo.file))
        .ok()?
        .taken_at_rfc3339()
        .map(|t| (t, "exif"))
}

/// The view geometry report of photo `photo_id` of a solved site.
///
/// # Errors
/// [`ViewGeometryError::Site`] for an unknown or unsolved view or a scene that cannot be built,
/// [`ViewGeometryError::VerticalAxis`], [`ViewGeometryError::FocalNotConvertible`].
pub fn view_geometry(
    doc: &SiteDocument,
    photo_id: &str,
    options: &ViewGeometryOptions,
) -> Result<ViewGeometry, ViewGeometryError> {
    let camera = site_camera(doc, photo_id)?;
    let site = &doc.site;
    let photo = site.photos.iter().find(|p| p.id == photo_id);
    let exterior =
        photo
            .and_then(|p| p.exterior.clone())
            .ok_or_else(|| SiteRenderError::NotSolved {
                photo: photo_id.to_owned(),
            })?;
    let mut notes = Vec::new();
    let photo_err = || photo_id.to_owned();
    let intr = camera.intrinsics;
    let focal_35 = focal_35mm_equiv_mm(intr.focal_px, intr.image_size_px).ok_or_else(|| {
        ViewGeometryError::FocalNotConvertible {
            photo: photo_err(),
            focal_px: intr.focal_px,
            image_size_px: intr.image_size_px,
        }
    })?;
    let angles = camera_angles(&camera)
        .ok_or_else(|| ViewGeometryError::VerticalAxis { photo: photo_err() })?;
    let centre = camera.pose.camera_center_in_world;

    // Where on Earth.
    let crs_name = site.location.as_ref().and_then(|l| l.crs.clone());
    let crs = crs_name
        .as_deref()
        .and_then(|name| match ProjectedCrs::from_name(name) {
            Ok(crs) => Some(crs),
            Err(e) => {
                notes.push(format!("latitude/longitude not given: {e}"));
                None
            }
        });
    if crs_name.is_none() {
        notes.push("latitude/longitude not given: the site names no location.crs".to_owned());
    }
    let lat_lon = crs
        .as_ref()
        .and_then(|c| match c.to_lat_lon_deg(centre.x, centre.y) {
            Ok(ll) => Some(ll),
            Err(e) => {
                notes.push(format!("latitude/longitude not given: {e}"));
                None
            }
        });
    let grid_convergence_deg = site
        .location
        .as_ref()
        .map_or(0.0, |l| l.grid_convergence_deg);
    let crs_convergence = crs
        .as_ref()
        .and_then(|c| c.grid_convergence_deg(centre.x, centre.y).ok());
    if let Some(c) = crs_convergence
        && (c - grid_convergence_deg).abs() > CONVERGENCE_NOTE_DEG
    {
        notes.push(format!(
            "location.grid_convergence_deg is {grid_convergence_deg:.3}° but {} gives {c:.3}° at \
             the camera; bearing_true_deg uses the site's value",
            crs_name.as_deref().unwrap_or("the CRS")
        ));
    }

    // The scene: ground below and the proposal.
    let scene = site_scene(doc)?;
    let objects = scene.scene.objects();
    let mut natural = Vec::new();
    let mut natural_ids = Vec::new();
    let mut artificial = Vec::new();
    for t in scene.scene.triangles() {
        let Ok(index) = usize::try_from(t.object.0) else {
            continue;
        };
        match objects.get(index).map(|o| o.kind) {
            Some(ObjectKind::Natural) => {
                natural.push(t.vertices_in_world_m);
                natural_ids.push(index);
            }
            Some(ObjectKind::Artificial) => artificial.push(t.vertices_in_world_m),
            None => {}
        }
    }
    let (ground_level_m, ground_level_source) = if let Some(z) = options.ground_level_m {
        (Some(z), Some(GroundSource::Given))
    } else if let Some((z, i)) = measure::ground_below(&centre, &natural) {
        let name = natural_ids
            .get(i)
            .and_then(|&o| objects.get(o))
            .map_or_else(String::new, |o| o.name.clone());
        (Some(z), Some(GroundSource::ScenePolygon(name)))
    } else {
        notes.push(
            "height above ground not given: no scene polygon lies below the camera (give the \
             ground level)"
                .to_owned(),
        );
        (None, None)
    };
    let proposal_models: Vec<String> = site
        .models
        .iter()
        .filter(|m| m.visible)
        .map(|m| m.id.clone())
        .collect();
    if artificial.is_empty() {
        notes.push("distance to the proposal not given: the site has no visible model".to_owned());
    }

    // When, and the sun then.
    let capture = capture_time(doc, photo_id);
    let sun = capture.as_ref().and_then(|(time, _)| {
        let parsed = match DateTime::parse_from_rfc3339(time) {
            Ok(t) => t,
            Err(e) => {
                notes.push(format!("sun not given: capture time `{time}`: {e}"));
                return None;
            }
        };
        let (lat, lon, elevation_m) = match (lat_lon, &site.location) {
            (Some((lat, lon)), loc) => (lat, lon, loc.as_ref().map_or(0.0, |l| l.elevation_m)),
            (None, Some(l)) => (l.latitude_deg, l.longitude_deg, l.elevation_m),
            (None, None) => {
                notes.push("sun not given: the site has no [location]".to_owned());
                return None;
            }
        };
        let params = SpaParams {
            elevation_m,
            ..SpaParams::at(lat, lon)
        };
        match solar_position(&parsed, &params) {
            Ok(p) => Some(p),
            Err(e) => {
                notes.push(format!("sun not given: {e}"));
                None
            }
        }
    });
    if capture.is_none() {
        notes.push(
            "capture time and sun not given: no photos.taken_at and no EXIF time with offset"
                .to_owned(),
        );
    }
    let exif = photo.and_then(|p| crate::photo::read_exif(&doc.resolve(&p.file)).ok());
    let [hfov_deg, vfov_deg] = fields_of_view_deg(&intr);
    let proposal_centroid = measure::centroid(&artificial);
    let layout = options.paper.layout();
    let printed_image_width_mm = layout.printed_image_size_mm(intr.image_size_px)[0];
    Ok(ViewGeometry {
        photo_id: photo_id.to_owned(),
        projection: ViewProjection::Photo,
        source_photos: vec![photo_id.to_owned()],
        camera_position_m: centre.coords.into(),
        crs: crs_name,
        latitude_deg: lat_lon.map(|(lat, _)| lat),
        longitude_deg: lat_lon.map(|(_, lon)| lon),
        height_above_datum_m: centre.z,
        ground_level_m,
        ground_level_source,
        height_above_ground_m: ground_level_m.map(|g| centre.z - g),
        bearing_true_deg: normalise_deg(angles.bearing_grid_deg - grid_convergence_deg),
        bearing_grid_deg: angles.bearing_grid_deg,
        grid_convergence_deg,
        crs_grid_convergence_deg: crs_convergence,
        pitch_deg: angles.pitch_deg,
        roll_deg: angles.roll_deg,
        focal_px: intr.focal_px,
        focal_35mm_equiv_mm: focal_35,
        exif_focal_length_mm: exif.as_ref().and_then(|e| e.focal_length_mm),
        exif_focal_35mm_mm: exif.as_ref().and_then(|e| e.focal_length_35mm),
        hfov_deg,
        vfov_deg,
        image_size_px: intr.image_size_px,
        principal_point_px: intr.principal_point_px,
        distortion: intr.distortion,
        capture_time: capture.as_ref().map(|(t, _)| t.clone()),
        capture_time_source: capture.as_ref().map(|(_, s)| *s),
        sun_azimuth_deg: sun.map(|p| p.azimuth_deg),
        sun_elevation_deg: sun.map(|p| p.elevation_deg),
        rms_px: exterior.rms_px,
        sigma_center_m: exterior.sigma_center_m,
        solved_by: exterior.solved_by,
        residuals: residual_table(doc, &camera, photo_id),
        proposal_models,
        distance_to_proposal_nearest_m: measure::nearest_distance_m(&centre, &artificial),
        distance_to_proposal_centroid_m: proposal_centroid.map(|(c, _)| (c - centre).norm()),
        proposal_centroid_m: proposal_centroid.map(|(c, _)| c.coords.into()),
        proposal_centroid_kind: proposal_centroid.map(|(_, k)| k),
        paper: options.paper,
        printed_image_width_mm,
        viewing_distance_mm: viewing_distance_mm(printed_image_width_mm, hfov_deg),
        notes,
    })
}

#[cfg(test)]
#[path = "geometry_tests.rs"]
mod tests;
