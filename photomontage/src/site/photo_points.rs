//! The site's points as seen in a solved photo: control points and intersected tie points
//! projected with the photo's stored camera (`site::stored_camera`, lens distortion included),
//! the candidates the studio's Scene tab offers for picking polygon vertices (Durisch 1992
//! §4.1: scene geometry built from surveyed and intersected points).
//!
//! # Known limitations
//! Only points with world coordinates are projected (a tie point observed but not yet
//! intersected has none); points behind the camera or outside the image are left out.

use super::{Site, stored_camera};

/// A scene point projected into a photo.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectedPoint {
    /// Control-point or tie-point id.
    pub id: String,
    /// Pixel position in the photo (pixel-centre convention).
    pub pixel_px: [f64; 2],
}

/// The site's control points, then its tie points that are not also control points, projected
/// into the solved photo `photo_id`, keeping those in front of the camera and inside the image
/// (−½ … size − ½). Empty when the photo is unknown or not solved.
#[must_use]
pub fn projected_points(site: &Site, photo_id: &str) -> Vec<ProjectedPoint> {
    let Some(camera) = stored_camera(site, photo_id) else {
        return Vec::new();
    };
    let [w, h] = camera.intrinsics.image_size_px.map(f64::from);
    let controls = site.control_points.iter().map(|c| (&c.id, c.xyz));
    let ties = site
        .tie_points
        .iter()
        .filter(|t| !site.control_points.iter().any(|c| c.id == t.id))
        .map(|t| (&t.id, t.xyz));
    controls
        .chain(ties)
        .filter_map(|(id, xyz)| {
            let p = camera.project(&xyz.into())?;
            let inside = (-0.5..w - 0.5).contains(&p.x) && (-0.5..h - 0.5).contains(&p.y);
            inside.then(|| ProjectedPoint {
                id: id.clone(),
                pixel_px: [p.x, p.y],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;

    /// Pinhole projection of points 10 m ahead with f = 100 px: a few f64 operations, exact up
    /// to rounding.
    const EXACT_PX: f64 = 1e-9;

    /// A photo at the origin looking north (+Y; image x east, y down), f = 100 px, 200 × 100,
    /// with control points ahead, behind, outside the image, and tie points.
    const SITE: &str = r#"
name = "t"
[[photos]]
id = "P1"
file = "p1.jpg"
[photos.interior]
focal_px = 100.0
image_size_px = [200, 100]
[photos.exterior]
camera_center = [0.0, 0.0, 0.0]
rotation_world_from_camera = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]
[[photos]]
id = "P2"
file = "p2.jpg"
[[control_points]]
id = "ahead"
xyz = [0.0, 10.0, 0.0]
[[control_points]]
id = "east"
xyz = [1.0, 10.0, 0.0]
[[control_points]]
id = "behind"
xyz = [0.0, -10.0, 0.0]
[[control_points]]
id = "outside"
xyz = [20.0, 10.0, 0.0]
[[tie_points]]
id = "below"
xyz = [0.0, 10.0, -1.0]
[[tie_points]]
id = "ahead"
xyz = [5.0, 10.0, 0.0]
"#;

    #[test]
    fn points_project_with_the_stored_camera_and_leave_out_the_unseen() {
        let text = format!("schema_version = {}\n{SITE}", crate::site::SCHEMA_VERSION);
        let site: Site = toml::from_str(&text).unwrap();
        let points = projected_points(&site, "P1");
        let ids: Vec<&str> = points.iter().map(|p| p.id.as_str()).collect();
        // Behind the camera and outside the image are left out; a tie point sharing a control
        // point's id is the control point.
        assert_eq!(ids, ["ahead", "east", "below"]);
        // Principal point ((w − 1)/2, (h − 1)/2); 1 m at 10 m is f/10 = 10 px (x east, y down).
        for (p, want) in points
            .iter()
            .zip([[99.5, 49.5], [109.5, 49.5], [99.5, 59.5]])
        {
            let err = (p.pixel_px[0] - want[0]).hypot(p.pixel_px[1] - want[1]);
            assert!(
                err <= EXACT_PX,
                "{} at {:?}, expected {want:?}",
                p.id,
                p.pixel_px
            );
        }
        // Unsolved and unknown photos have nothing to show.
        assert!(projected_points(&site, "P2").is_empty());
        assert!(projected_points(&site, "P9").is_empty());
    }
}
