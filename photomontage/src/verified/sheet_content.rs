//! What the verified-view sheet says, as text and plan geometry (TGN 06/19 Appendix 1:
//! photograph/photomontage information template and technical methodology template): the view
//! geometry table, the methodology lines (survey, camera, software, models, lighting, render
//! settings), the residual table and the location map's plan data. Drawn by [`super::sheet`].
//!
//! Every number of the view geometry report ([`super::geometry::ViewGeometry`]) appears in the
//! table with a stated precision: metres and degrees to 3 decimals (latitude and longitude to 7),
//! pixels to 2, distortion coefficients to 6, millimetres to 1 (the 35 mm equivalent to 2); in
//! the residual table pixel positions to 2, residuals and σ to 3, normalised residuals to 2.
//!
//! # Known limitations
//! Text is limited to the WinAnsi (Latin-1) characters of the sheet's font encoding; other
//! characters print as `?`.

use nalgebra::Point3;

use super::avr::AvrLevel;
use super::geometry::{GroundSource, ViewGeometry, ViewProjection};
use crate::scene::ObjectKind;
use crate::site::SiteDocument;
use crate::site::render::SiteRenderError;

fn opt(v: Option<f64>, digits: usize, unit: &str) -> String {
    v.map_or_else(|| "unknown".to_owned(), |v| format!("{v:.digits$}{unit}"))
}

/// The sheet's viewing-distance sentence: for a photo or planar view the flat print seen from
/// the viewing distance; for a cylinder the print curved about the eye at that radius.
#[must_use]
pub fn viewing_sentence(r: &ViewGeometry) -> String {
    match r.projection {
        ViewProjection::Photo | ViewProjection::Planar => format!(
            "Viewing distance {:.1} mm: the image is printed {:.1} mm wide on {} landscape; view \
             it from {:.1} mm for the correct perspective (HFoV {:.3} deg).",
            r.viewing_distance_mm,
            r.printed_image_width_mm,
            r.paper.name(),
            r.viewing_distance_mm,
            r.hfov_deg
        ),
        ViewProjection::Cylindrical => format!(
            "Viewing distance {:.1} mm: the panorama is printed {:.1} mm wide on {} landscape; \
             curve it about the eye at a radius of {:.1} mm (width / HFoV {:.3} deg in radians).",
            r.viewing_distance_mm,
            r.printed_image_width_mm,
            r.paper.name(),
            r.viewing_distance_mm,
            r.hfov_deg
        ),
    }
}

/// The view geometry table: (label, value) rows, every number of the report.
#[must_use]
pub fn geometry_rows(r: &ViewGeometry) -> Vec<(String, String)> {
    let [e, n, h] = r.camera_position_m;
    let [se, sn, sh] = r.sigma_center_m;
    let d = &r.distortion;
    let ground_source = match &r.ground_level_source {
        Some(GroundSource::ScenePolygon(id)) => format!("polygon {id}"),
        Some(GroundSource::Given) => "given".to_owned(),
        None => "unknown".to_owned(),
    };
    let rows: Vec<(&str, String)> = vec![
        ("Photo", r.photo_id.clone()),
        (
            "Projection",
            match r.projection {
                ViewProjection::Photo => "photo (as taken)".to_owned(),
                ViewProjection::Planar => format!("planar, from {}", r.source_photos.join(" ")),
                ViewProjection::Cylindrical => {
                    format!("cylindrical, from {}", r.source_photos.join(" "))
                }
            },
        ),
        ("Camera E", format!("{e:.3} m")),
        ("Camera N", format!("{n:.3} m")),
        ("Camera H (datum)", format!("{h:.3} m")),
        ("CRS", r.crs.clone().unwrap_or_else(|| "unnamed".into())),
        ("Latitude", opt(r.latitude_deg, 7, " deg")),
        ("Longitude", opt(r.longitude_deg, 7, " deg")),
        ("Ground level", opt(r.ground_level_m, 3, " m")),
        ("Ground from", ground_source),
        ("Height above ground", opt(r.height_above_ground_m, 3, " m")),
        ("Bearing (true N)", format!("{:.3} deg", r.bearing_true_deg)),
        ("Bearing (grid N)", format!("{:.3} deg", r.bearing_grid_deg)),
        (
            "Grid convergence",
            format!("{:.3} deg", r.grid_convergence_deg),
        ),
        (
            "CRS convergence",
            opt(r.crs_grid_convergence_deg, 3, " deg"),
        ),
        ("Pitch", format!("{:.3} deg", r.pitch_deg)),
        ("Roll", format!("{:.3} deg", r.roll_deg)),
        ("Focal length", format!("{:.2} px", r.focal_px)),
        (
            "35 mm equivalent",
            format!("{:.2} mm", r.focal_35mm_equiv_mm),
        ),
        ("EXIF focal length", opt(r.exif_focal_length_mm, 2, " mm")),
        ("EXIF 35 mm equiv.", opt(r.exif_focal_35mm_mm, 2, " mm")),
        (
            "HFoV x VFoV",
            format!("{:.3} x {:.3} deg", r.hfov_deg, r.vfov_deg),
        ),
        (
            "Image size",
            format!("{} x {} px", r.image_size_px[0], r.image_size_px[1]),
        ),
        (
            "Principal point",
            format!(
                "{:.2}, {:.2} px",
                r.principal_point_px[0], r.principal_point_px[1]
            ),
        ),
        ("Distortion k1 k2", format!("{:.6} {:.6}", d.k1, d.k2)),
        ("Distortion k3", format!("{:.6}", d.k3)),
        ("Distortion p1 p2", format!("{:.6} {:.6}", d.p1, d.p2)),
        (
            "Captured",
            r.capture_time.clone().unwrap_or_else(|| "unknown".into()),
        ),
        ("Sun azimuth", opt(r.sun_azimuth_deg, 3, " deg")),
        ("Sun elevation", opt(r.sun_elevation_deg, 3, " deg")),
        ("RMS residual", format!("{:.3} px", r.rms_px)),
        ("Sigma centre E N H", format!("{se:.3} {sn:.3} {sh:.3} m")),
        (
            "Proposal nearest",
            opt(r.distance_to_proposal_nearest_m, 3, " m"),
        ),
        (
            "Proposal centroid",
            opt(r.distance_to_proposal_centroid_m, 3, " m"),
        ),
        (
            "Centroid E",
            opt(r.proposal_centroid_m.map(|c| c[0]), 3, " m"),
        ),
        (
            "Centroid N",
            opt(r.proposal_centroid_m.map(|c| c[1]), 3, " m"),
        ),
        (
            "Centroid H",
            opt(r.proposal_centroid_m.map(|c| c[2]), 3, " m"),
        ),
        (
            "Printed image width",
            format!("{:.1} mm", r.printed_image_width_mm),
        ),
        (
            "Viewing distance",
            format!("{:.1} mm", r.viewing_distance_mm),
        ),
    ];
    rows.into_iter().map(|(l, v)| (l.to_owned(), v)).collect()
}

/// The residual table: a header and one line per observation.
#[must_use]
pub fn residual_lines(r: &ViewGeometry) -> Vec<String> {
    let mut lines = vec![format!(
        "{:<12} {:>7} {:>9} {:>9} {:>8} {:>8} {:>7} {:>7} {:>6}",
        "point", "kind", "x px", "y px", "vx px", "vy px", "|v| px", "s px", "|v|/s"
    )];
    for row in &r.residuals {
        lines.push(format!(
            "{:<12} {:>7} {:>9.2} {:>9.2} {:>8.3} {:>8.3} {:>7.3} {:>7.3} {:>6.2}{}",
            row.point_id,
            row.point_kind,
            row.observed_px[0],
            row.observed_px[1],
            row.residual_px[0],
            row.residual_px[1],
            row.residual_norm_px,
            row.sigma_px,
            row.normalised,
            if row.flagged { " !" } else { "" }
        ));
    }
    lines
}

/// The methodology page's text: (heading, lines).
#[must_use]
pub fn methodology(
    doc: &SiteDocument,
    r: &ViewGeometry,
    avr: AvrLevel,
) -> Vec<(String, Vec<String>)> {
    let site = &doc.site;
    let photo_id = r.source_photos.first().unwrap_or(&r.photo_id);
    let photo = site.photos.iter().find(|p| &p.id == photo_id);
    let enabled = site.control_points.iter().filter(|c| c.enabled).count();
    let camera_name = photo
        .and_then(|p| crate::photo::read_exif(&doc.resolve(&p.file)).ok())
        .and_then(|e| e.camera_name())
        .unwrap_or_else(|| "not stated in EXIF".into());
    let l = &site.lighting;
    let rs = &site.render;
    let mut sections = vec![
        (
            "Survey".to_owned(),
            vec![
                format!(
                    "{} control points ({} enabled) in {}; {} tie points; {} observations in this photo.",
                    site.control_points.len(),
                    enabled,
                    r.crs.as_deref().unwrap_or("an unnamed survey CRS"),
                    site.tie_points.len(),
                    r.residuals.len()
                ),
                format!(
                    "Grid convergence {:.3} deg (site); bearings from true north use it.",
                    r.grid_convergence_deg
                ),
            ],
        ),
        (
            "Camera".to_owned(),
            vec![
                format!(
                    "Photo {} ({}), camera {camera_name}, {} x {} px.",
                    r.photo_id,
                    photo.map_or("?", |p| p.file.as_str()),
                    r.image_size_px[0],
                    r.image_size_px[1]
                ),
                format!(
                    "Solved by {} (resection with RANSAC/P3P start, Levenberg-Marquardt, data snooping; \
                     bundle adjustment); RMS {:.3} px.",
                    r.solved_by, r.rms_px
                ),
                "Pinhole with Brown-Conrady distortion (Durisch 1992 s3.5; OpenCV convention)."
                    .into(),
                match r.projection {
                    ViewProjection::Photo => "The view is the photo as taken.".to_owned(),
                    ViewProjection::Planar => format!(
                        "Planar view re-projected from photo {} to a {:.2} mm equivalent \
                         (distortion-free pinhole, same centre and rotation).",
                        photo_id, r.focal_35mm_equiv_mm
                    ),
                    ViewProjection::Cylindrical => format!(
                        "Cylindrical view composed from photos {} (level cylinder, radius {:.2} px, \
                         seams feathered); viewing distance = printed width / HFoV in radians.",
                        r.source_photos.join(", "),
                        r.focal_px
                    ),
                },
            ],
        ),
        (
            "Software".to_owned(),
            vec![format!(
                "photomontage {} (Rust); view geometry, AVR modes and this sheet from \
                 photomontage::verified.",
                env!("CARGO_PKG_VERSION")
            )],
        ),
    ];
    let models: Vec<String> = site
        .models
        .iter()
        .filter(|m| m.visible)
        .map(|m| {
            format!(
                "{}: {} ({}, up {}, placed at {:.3} {:.3} {:.3}, rotated {:.3} deg, scale {})",
                m.id,
                m.file,
                m.units,
                m.up_axis,
                m.placement.translation[0],
                m.placement.translation[1],
                m.placement.translation[2],
                m.placement.rotation_z_deg,
                m.placement.scale
            )
        })
        .collect();
    sections.push((
        "Models".to_owned(),
        if models.is_empty() {
            vec!["No visible model.".into()]
        } else {
            models
        },
    ));
    sections.push((
        "Lighting".to_owned(),
        vec![
            format!(
                "Sky {}, sun weight {:?}, sky weight {:?}, ambient {:?}.",
                l.sky_model, l.sun_weight, l.sky_weight, l.ambient_weight
            ),
            match &l.sun_manual {
                Some(m) => format!(
                    "Sun set by hand: azimuth {:.3} deg, elevation {:.3} deg.",
                    m.azimuth_deg, m.elevation_deg
                ),
                None => format!(
                    "Sun from NREL SPA at {}.",
                    l.time.as_deref().unwrap_or("the capture time")
                ),
            },
        ],
    ));
    sections.push((
        "Rendering".to_owned(),
        vec![
            format!("{}: {}.", avr.name(), avr.description()),
            format!(
                "Differential ray tracing (Durisch 1992 s6): {}-{} rays per pixel, seed {}, depth {}, \
                 exposure {}.",
                rs.spp_min, rs.spp_max, rs.seed, rs.max_depth, rs.exposure
            ),
        ],
    ));
    sections.push(("Notes".to_owned(), r.notes.clone()));
    sections
}

/// Plan data of the location map inset (survey E, N).
#[derive(Debug, Clone, PartialEq)]
pub struct MapInset {
    pub control_points_en: Vec<[f64; 2]>,
    pub camera_en: [f64; 2],
    /// Optical axis, clockwise from grid north.
    pub bearing_grid_deg: f64,
    pub hfov_deg: f64,
    /// Convex hull of the proposal in plan (may be empty).
    pub proposal_hull_en: Vec<[f64; 2]>,
}

/// Convex hull (Andrew's monotone chain), counter-clockwise.
#[must_use]
pub fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// The map inset of a report: the enabled control points, the camera and its view, the proposal.
///
/// # Errors
/// [`SiteRenderError`] when the scene cannot be built.
pub fn map_inset(doc: &SiteDocument, r: &ViewGeometry) -> Result<MapInset, SiteRenderError> {
    let scene = crate::site::render::site_scene(doc)?.scene;
    let objects = scene.objects();
    let proposal: Vec<[f64; 2]> = scene
        .triangles()
        .iter()
        .filter(|t| {
            usize::try_from(t.object.0)
                .ok()
                .and_then(|i| objects.get(i))
                .is_some_and(|o| o.kind == ObjectKind::Artificial)
        })
        .flat_map(|t| {
            t.vertices_in_world_m
                .iter()
                .map(|p: &Point3<f64>| [p.x, p.y])
        })
        .collect();
    Ok(MapInset {
        control_points_en: doc
            .site
            .control_points
            .iter()
            .filter(|c| c.enabled)
            .map(|c| [c.xyz[0], c.xyz[1]])
            .collect(),
        camera_en: [r.camera_position_m[0], r.camera_position_m[1]],
        bearing_grid_deg: r.bearing_grid_deg,
        hfov_deg: r.hfov_deg,
        proposal_hull_en: convex_hull(&proposal),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 1.0],
            [1.0, 0.0],
            [0.5, 1.5],
        ];
        let hull = convex_hull(&pts);
        assert_eq!(hull.len(), 4, "{hull:?}");
        for corner in [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]] {
            assert!(hull.contains(&corner));
        }
    }
}
