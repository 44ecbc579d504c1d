//! The view geometry of re-projected views: a planar view at a standard focal length
//! ([`super::planar_view`]) and a cylindrical panorama ([`super::cylindrical_view`]), so that
//! their sheets, reports and image metadata state the view's own lens, fields of view and
//! viewing distance (Landscape Institute TGN 06/19 §3 and Appendix 1; NatureScot, *Visual
//! Representation of Wind Farms*, 2017, §2 on cylindrical panoramas and their viewing distance).
//!
//! **Planar.** The photo's report with the virtual camera's lens: focal length, 35 mm
//! equivalent, fields of view, principal point and (no) distortion of the view; bearing, pitch
//! and roll from the virtual camera (the photo's rotation); viewing distance
//! `w / (2·tan(HFoV/2))` as for a photo.
//!
//! **Cylindrical.** The camera position is the cylinder's centre (the photos' mean centre);
//! `bearing` is the azimuth of the image's centre column, `pitch` the elevation of its centre row
//! (`atan(h_top − H/(2f))`), `roll` 0 (the cylinder is level); `focal_px` is the radius `f`,
//! `HFoV = W/f` (radians), `VFoV = atan(h_top) − atan(h_top − H/f)`; the principal point is the
//! centre column on the horizon row (`y = f·h_top − 0.5`). A cylinder printed `w` wide and viewed
//! curved about the eye shows the correct perspective at the radius **`d = w / HFoV`** (HFoV in
//! radians): the printed image is the cylinder unrolled at that radius.
//!
//! # Known limitations
//! For a cylinder, the capture time, sun, ground, and distance to the proposal are those of the
//! first photo (the photos' centres agree within the panorama's spread tolerance); the residual
//! table lists every photo's observations (`photo:point`), `rms_px` is the root mean square of
//! the photos' RMS and `sigma_center_m` the largest σ per axis. Residuals of a planar view are
//! those of the photo's solve, in photo pixels.

use nalgebra::Point3;

use super::cylindrical_view::Cylinder;
use super::geometry::{
    ViewGeometry, ViewGeometryError, ViewGeometryOptions, ViewProjection, camera_angles,
    fields_of_view_deg, focal_35mm_equiv_mm, normalise_deg, view_geometry,
};
use super::paper::viewing_distance_mm;
use crate::camera::Camera;
use crate::geo::ProjectedCrs;
use crate::site::SiteDocument;

/// The report of a planar view of photo `photo_id` seen through the virtual `camera` (the
/// photo's centre and rotation, see [`super::planar_view::planar_camera`]).
///
/// # Errors
/// As [`view_geometry`]; [`ViewGeometryError::FocalNotConvertible`] for the view's lens.
pub fn planar_view_geometry(
    doc: &SiteDocument,
    photo_id: &str,
    camera: &Camera,
    options: &ViewGeometryOptions,
) -> Result<ViewGeometry, ViewGeometryError> {
    let mut r = view_geometry(doc, photo_id, options)?;
    let intr = camera.intrinsics;
    r.focal_35mm_equiv_mm =
        focal_35mm_equiv_mm(intr.focal_px, intr.image_size_px).ok_or_else(|| {
            ViewGeometryError::FocalNotConvertible {
                photo: photo_id.to_owned(),
                focal_px: intr.focal_px,
                image_size_px: intr.image_size_px,
            }
        })?;
    let angles = camera_angles(camera).ok_or_else(|| ViewGeometryError::VerticalAxis {
        photo: photo_id.to_owned(),
    })?;
    let [hfov_deg, vfov_deg] = fields_of_view_deg(&intr);
    r.projection = ViewProjection::Planar;
    r.bearing_grid_deg = angles.bearing_grid_deg;
    r.bearing_true_deg = normalise_deg(angles.bearing_grid_deg - r.grid_convergence_deg);
    r.pitch_deg = angles.pitch_deg;
    r.roll_deg = angles.roll_deg;
    r.focal_px = intr.focal_px;
    r.hfov_deg = hfov_deg;
    r.vfov_deg = vfov_deg;
    r.image_size_px = intr.image_size_px;
    r.principal_point_px = intr.principal_point_px;
    r.distortion = intr.distortion;
    r.printed_image_width_mm = options
        .paper
        .layout()
        .printed_image_size_mm(intr.image_size_px)[0];
    r.viewing_distance_mm = viewing_distance_mm(r.printed_image_width_mm, hfov_deg);
    r.notes.push(format!(
        "planar view re-projected from photo {photo_id} at {:.2} mm equivalent; the residuals \
         and RMS are those of the photo's solve, in photo pixels",
        r.focal_35mm_equiv_mm
    ));
    Ok(r)
}

/// Viewing distance of a cylindrical view printed `printed_width_mm` wide: the radius at which
/// the print, curved about the eye, subtends the panorama's `hfov_deg` (`w / HFoV`, radians).
#[must_use]
pub fn cylinder_viewing_distance_mm(printed_width_mm: f64, hfov_deg: f64) -> f64 {
    printed_width_mm / hfov_deg.to_radians()
}

/// `r` for a sheet on `paper`: the printed width and the viewing distance (flat for a photo or
/// planar view, the cylinder's radius for a cylindrical one) recomputed.
#[must_use]
pub fn with_paper(r: &ViewGeometry, paper: super::paper::PaperSize) -> ViewGeometry {
    let mut r = r.clone();
    r.paper = paper;
    r.printed_image_width_mm = paper.layout().printed_image_size_mm(r.image_size_px)[0];
    r.viewing_distance_mm = match r.projection {
        ViewProjection::Cylindrical => {
            cylinder_viewing_distance_mm(r.printed_image_width_mm, r.hfov_deg)
        }
        ViewProjection::Photo | ViewProjection::Planar => {
            viewing_distance_mm(r.printed_image_width_mm, r.hfov_deg)
        }
    };
    r
}

/// The report of the cylindrical view `cylinder` composed from `photo_ids`.
///
/// # Errors
/// As [`view_geometry`] for any of the photos (naming it).
pub fn cylindrical_view_geometry(
    doc: &SiteDocument,
    photo_ids: &[&str],
    cylinder: &Cylinder,
    options: &ViewGeometryOptions,
) -> Result<ViewGeometry, ViewGeometryError> {
    let reports = photo_ids
        .iter()
        .map(|id| view_geometry(doc, id, options))
        .collect::<Result<Vec<_>, _>>()?;
    let Some(first) = reports.first() else {
        return Err(ViewGeometryError::NoPhotos);
    };
    let mut r = first.clone();
    let f = cylinder.focal_px;
    let [w, h] = cylinder.size_px.map(f64::from);
    let centre = Point3::from(cylinder.centre_in_world_m);
    r.photo_id = photo_ids.join("+");
    r.projection = ViewProjection::Cylindrical;
    r.source_photos = photo_ids.iter().map(|s| (*s).to_owned()).collect();
    r.camera_position_m = cylinder.centre_in_world_m;
    r.height_above_datum_m = centre.z;
    r.height_above_ground_m = r.ground_level_m.map(|g| centre.z - g);
    if let Some(crs) = r
        .crs
        .as_deref()
        .and_then(|n| ProjectedCrs::from_name(n).ok())
        && let Ok((lat, lon)) = crs.to_lat_lon_deg(centre.x, centre.y)
    {
        r.latitude_deg = Some(lat);
        r.longitude_deg = Some(lon);
    }
    r.bearing_grid_deg = normalise_deg((cylinder.azimuth_left + w / (2.0 * f)).to_degrees());
    r.bearing_true_deg = normalise_deg(r.bearing_grid_deg - r.grid_convergence_deg);
    r.pitch_deg = (cylinder.height_top - h / (2.0 * f)).atan().to_degrees();
    r.roll_deg = 0.0;
    r.focal_px = f;
    r.focal_35mm_equiv_mm = focal_35mm_equiv_mm(f, first.image_size_px).ok_or_else(|| {
        ViewGeometryError::FocalNotConvertible {
            photo: first.photo_id.clone(),
            focal_px: f,
            image_size_px: first.image_size_px,
        }
    })?;
    r.hfov_deg = (w / f).to_degrees();
    r.vfov_deg = (cylinder.height_top.atan() - (cylinder.height_top - h / f).atan()).to_degrees();
    r.image_size_px = cylinder.size_px;
    r.principal_point_px = [w / 2.0 - 0.5, f * cylinder.height_top - 0.5];
    r.distortion = crate::camera::BrownConrady::default();
    #[allow(clippy::cast_precision_loss)]
    let n = reports.len() as f64;
    r.rms_px = (reports.iter().map(|p| p.rms_px * p.rms_px).sum::<f64>() / n).sqrt();
    r.sigma_center_m = [0, 1, 2].map(|k| {
        reports
            .iter()
            .map(|p| p.sigma_center_m[k])
            .fold(0.0, f64::max)
    });
    r.residuals = reports
        .iter()
        .flat_map(|p| {
            p.residuals.iter().map(|row| {
                let mut row = row.clone();
                row.point_id = format!("{}:{}", p.photo_id, row.point_id);
                row
            })
        })
        .collect();
    r.printed_image_width_mm = options
        .paper
        .layout()
        .printed_image_size_mm(cylinder.size_px)[0];
    r.viewing_distance_mm = cylinder_viewing_distance_mm(r.printed_image_width_mm, r.hfov_deg);
    r.notes.push(format!(
        "cylindrical view of photos {}: viewing distance = printed width / HFoV (radians), the \
         radius at which the print is viewed curved about the eye; capture time, sun, ground and \
         distances to the proposal are those of photo {}",
        photo_ids.join(", "),
        first.photo_id
    ));
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cylinder_printed_as_wide_as_its_circumference_is_viewed_from_its_radius() {
        // 360° printed 2π·100 mm wide: the eye sits at the centre of a 100 mm radius cylinder.
        let d = cylinder_viewing_distance_mm(std::f64::consts::TAU * 100.0, 360.0);
        assert!((d - 100.0).abs() < 1e-12, "{d}");
    }
}
