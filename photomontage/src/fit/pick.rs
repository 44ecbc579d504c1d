//! Which scene polygon a pixel of a photo shows: the ray through the pixel of the photo's solved
//! camera, cast into the site's natural scene (its polygons, as [`super::natural_scene::natural_scene`]
//! builds it for every caller), gives the polygon, its material and the world point hit. This is
//! how a colour sample picked on the photo gets its material (Durisch 1992 §4.2–4.3: a sample is
//! a point on a scene polygon whose material attribute names its reflectance), and it is the
//! same ray the fit casts for a pixel sample, so a sample picked here is located on the same
//! polygon by [`super::site::fit_site`].
//!
//! # Known limitations
//! The natural polygons only (the planned CAD models are not in the photos); polygons whose
//! vertices have no coordinates yet are skipped. The picker is rebuilt when the site changes
//! (the caller decides when); no subpixel snapping to polygon edges.

use nalgebra::{Point2, Point3};

use super::natural_scene::natural_scene;
use crate::bvh::BuildQuality;
use crate::scene::{MaterialLibrary, SceneHit, SceneTracer};
use crate::site::{Site, stored_camera};

/// What can go wrong picking a polygon on a photo.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PickError {
    /// The photo has no solved camera.
    #[error("photo `{photo}` is not solved: solve it before picking samples on it")]
    NotSolved {
        /// The photo.
        photo: String,
    },
    /// The ray through the pixel meets no polygon.
    #[error(
        "no scene polygon at ({x_px:.1}, {y_px:.1}) px of photo `{photo}`: the ray through it hits nothing"
    )]
    NoPolygon {
        /// The photo.
        photo: String,
        /// Pixel x.
        x_px: f64,
        /// Pixel y.
        y_px: f64,
    },
    /// The natural scene could not be built.
    #[error("scene: {0}")]
    Scene(String),
}

/// The polygon a pixel shows.
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonHit {
    /// Id of the site polygon.
    pub polygon: String,
    /// Its material attribute (the name a sample on it must carry).
    pub material: String,
    /// The point hit, world frame, metres.
    pub point_in_world_m: [f64; 3],
    /// Distance from the camera centre, metres.
    pub distance_m: f64,
}

/// The natural scene of a site ready for picking.
#[derive(Debug)]
pub struct PolygonPicker {
    tracer: SceneTracer,
    polygon_of_triangle: Vec<usize>,
    polygons: Vec<(String, String)>,
    /// Polygons skipped (a vertex without coordinates).
    pub warnings: Vec<String>,
}

impl PolygonPicker {
    /// Builds the natural scene of `site` (materials from `library` where it has them).
    ///
    /// # Errors
    /// [`PickError::Scene`] when a polygon is degenerate or the scene is empty.
    pub fn new(site: &Site, library: Option<&MaterialLibrary>) -> Result<Self, PickError> {
        let natural = natural_scene(site, library).map_err(|e| PickError::Scene(e.to_string()))?;
        let warnings = natural.skipped_warnings();
        let polygon_of_triangle = natural.polygon_of_triangle;
        let tracer = SceneTracer::new(&natural.scene, BuildQuality::default())
            .map_err(|e| PickError::Scene(e.to_string()))?;
        Ok(Self {
            tracer,
            polygon_of_triangle,
            polygons: site
                .polygons
                .iter()
                .map(|p| (p.id.clone(), p.material.clone()))
                .collect(),
            warnings,
        })
    }

    /// For every triangle of the picker's scene, the index of its polygon in `site.polygons`
    /// (the natural scene of [`natural_scene`], the same for every caller).
    #[must_use]
    pub fn polygon_of_triangle(&self) -> &[usize] {
        &self.polygon_of_triangle
    }

    /// The polygon shown at `pixel_px` of photo `photo` of `site` (the site the picker was
    /// built from), nearest along the ray.
    ///
    /// # Errors
    /// [`PickError::NotSolved`] or [`PickError::NoPolygon`].
    pub fn pick(
        &self,
        site: &Site,
        photo: &str,
        pixel_px: [f64; 2],
    ) -> Result<PolygonHit, PickError> {
        let no_polygon = || PickError::NoPolygon {
            photo: photo.to_owned(),
            x_px: pixel_px[0],
            y_px: pixel_px[1],
        };
        let hit = cast_pixel(&self.tracer, site, photo, pixel_px)
            .ok_or_else(|| PickError::NotSolved {
                photo: photo.to_owned(),
            })?
            .ok_or_else(no_polygon)?;
        let (polygon, material) = self
            .polygon_of_triangle
            .get(hit.hit.hit.triangle_id as usize)
            .and_then(|i| self.polygons.get(*i))
            .ok_or_else(no_polygon)?;
        Ok(PolygonHit {
            polygon: polygon.clone(),
            material: material.clone(),
            point_in_world_m: hit.point_in_world_m.into(),
            distance_m: hit.distance_m,
        })
    }
}

/// What the ray through a pixel of a solved photo meets first.
#[derive(Debug, Clone, Copy)]
pub struct PixelHit {
    /// The tracer's hit (triangle, material, object, distance along the ray).
    pub hit: SceneHit,
    /// The point hit, world frame, metres.
    pub point_in_world_m: Point3<f64>,
    /// Distance from the camera centre, metres.
    pub distance_m: f64,
}

/// Casts the ray of `pixel_px` of photo `photo` of `site` into `tracer`'s scene: `None` when
/// the photo has no solved camera, `Some(None)` when the ray meets nothing (sky). One cast for
/// every picker (polygons here, materials in `site::material_pick`).
#[must_use]
pub fn cast_pixel(
    tracer: &SceneTracer,
    site: &Site,
    photo: &str,
    pixel_px: [f64; 2],
) -> Option<Option<PixelHit>> {
    let camera = stored_camera(site, photo)?;
    let centre = camera.pose.camera_center_in_world;
    let dir = camera.ray_dir_in_world(Point2::new(pixel_px[0], pixel_px[1]));
    let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
    Some(tracer.closest_hit(&ray).map(|hit| {
        let point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
        PixelHit {
            hit,
            point_in_world_m: point,
            distance_m: (point - centre).norm(),
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::site::tests::base_site;
    use nalgebra::Point3;

    /// The hit point is computed in f32 relative to a local origin (metres from it ≲ 100 here,
    /// f32 steps ≈ 1e-5 m) along a ray of ≈ 30 m: 1 mm is far above that and far below any
    /// polygon size.
    const HIT_TOL_M: f64 = 1e-3;

    #[test]
    fn pixel_of_a_known_point_gives_its_polygon_and_the_sky_gives_none() {
        let mut site = base_site();
        // Give the wall its own material to see it come back.
        if let Some(p) = site.polygons.iter_mut().find(|p| p.id == "wall") {
            p.material = "brick".into();
        }
        let picker = PolygonPicker::new(&site, None).expect("scene");
        assert!(picker.warnings.is_empty());
        let camera = stored_camera(&site, "P1").expect("solved");
        // A point near the east end of the south-facing wall (y = 20, x −30…−12, z 0…8), inside
        // the 53° field of view, ≈ 33 m from the camera at (0, −10, 1.6).
        let on_wall = Point3::new(-13.0, 20.0, 4.0);
        let p = camera.project(&on_wall).expect("in front");
        let hit = picker.pick(&site, "P1", [p.x, p.y]).expect("hit");
        assert_eq!(hit.polygon, "wall");
        assert_eq!(hit.material, "brick");
        for k in 0..3 {
            assert!(
                (hit.point_in_world_m[k] - on_wall[k]).abs() < HIT_TOL_M,
                "{:?} vs {on_wall:?}",
                hit.point_in_world_m
            );
        }
        let expected_distance = (on_wall - Point3::new(0.0, -10.0, 1.6)).norm();
        assert!((hit.distance_m - expected_distance).abs() < HIT_TOL_M);
        // The ground in front of the camera.
        let on_ground = Point3::new(1.0, 0.0, 0.0);
        let g = camera.project(&on_ground).expect("in front");
        let hit = picker.pick(&site, "P1", [g.x, g.y]).expect("hit");
        assert_eq!(hit.polygon, "ground");
        assert_eq!(hit.material, "stone");
        // The top row looks above the horizon (camera level, ground ends 4 km away): sky.
        assert!(matches!(
            picker.pick(&site, "P1", [200.0, 0.0]),
            Err(PickError::NoPolygon { .. })
        ));
        // An unsolved photo.
        site.photos[0].exterior = None;
        assert_eq!(
            picker.pick(&site, "P1", [p.x, p.y]),
            Err(PickError::NotSolved { photo: "P1".into() })
        );
    }

    #[test]
    fn polygons_without_coordinates_are_skipped_with_a_warning() {
        let mut site = base_site();
        site.polygons[0].vertices[0] = "nowhere".into();
        let natural = natural_scene(&site, None).expect("scene");
        let warnings = natural.skipped_warnings();
        let index = natural.polygon_of_triangle;
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains(&site.polygons[0].id));
        assert!(index.iter().all(|i| *i != 0), "polygon 0 has no triangles");
        assert!(!index.is_empty());
    }
}
