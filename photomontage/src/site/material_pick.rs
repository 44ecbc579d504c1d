//! Which material a pixel of a photo shows, in the one scene every renderer uses
//! ([`super::site_scene::site_scene`]: the natural polygons, the visible CAD models and the
//! site's `[[materials]]`): the ray through the pixel of the photo's solved camera (lens
//! distortion included, `Camera::ray_dir_in_world`) is cast into that scene and the nearest
//! triangle's material is the answer. This is how the studio's Materials tab picks a material
//! by a click on the photo (the colour design workflow of Tonn & Donath: choose a surface,
//! then its colour). It is the same ray and scene as [`crate::fit::pick`]'s, with the planned
//! models included.
//!
//! # Known limitations
//! The picker is built from the scene at one moment; the caller rebuilds it when the site's
//! models, polygons or materials change. Glass and mirrors are hit like any surface (the
//! material shown through them is not followed).

use super::Site;
use super::site_scene::{ObjectSource, SiteScene};
use crate::bvh::BuildQuality;
use crate::fit::pick::cast_pixel;
use crate::scene::{SceneError, SceneTracer};

/// What can go wrong picking a material on a photo.
#[derive(Debug, thiserror::Error)]
pub enum MaterialPickError {
    /// The photo has no solved camera.
    #[error("photo `{photo}` is not solved: solve it before picking on it")]
    NotSolved {
        /// The photo.
        photo: String,
    },
    /// The scene could not be prepared for ray queries (e.g. it is empty).
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
}

/// The surface a pixel shows.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialHit {
    /// The material's name (as the Materials tab lists it).
    pub material: String,
    /// Where the triangle came from (`polygon:ID` or `model:ID`).
    pub object: String,
    /// The point hit, world frame, metres.
    pub point_in_world_m: [f64; 3],
    /// Distance from the camera centre, metres.
    pub distance_m: f64,
}

/// A site scene ready for material picks.
#[derive(Debug, Clone)]
pub struct MaterialPicker {
    tracer: SceneTracer,
    materials: Vec<String>,
    objects: Vec<String>,
}

impl MaterialPicker {
    /// Prepares `scene` (from [`super::site_scene::site_scene`]) for picks.
    ///
    /// # Errors
    /// [`MaterialPickError::Scene`] when the tracer cannot be built (an empty scene).
    pub fn new(scene: &SiteScene) -> Result<Self, MaterialPickError> {
        Ok(Self {
            tracer: SceneTracer::new(&scene.scene, BuildQuality::default())?,
            materials: scene
                .scene
                .materials()
                .iter()
                .map(|m| m.name.clone())
                .collect(),
            objects: scene
                .object_sources
                .iter()
                .map(ObjectSource::label)
                .collect(),
        })
    }

    /// The surface shown at `pixel_px` of photo `photo` of `site`, nearest along the ray;
    /// `None` when the ray meets nothing (sky).
    ///
    /// # Errors
    /// [`MaterialPickError::NotSolved`] for a photo without a solved camera.
    pub fn pick(
        &self,
        site: &Site,
        photo: &str,
        pixel_px: [f64; 2],
    ) -> Result<Option<MaterialHit>, MaterialPickError> {
        let Some(hit) = cast_pixel(&self.tracer, site, photo, pixel_px).ok_or_else(|| {
            MaterialPickError::NotSolved {
                photo: photo.to_owned(),
            }
        })?
        else {
            return Ok(None);
        };
        let name = |names: &[String], i: u32| {
            names
                .get(i as usize)
                .cloned()
                .unwrap_or_else(|| format!("#{i}"))
        };
        Ok(Some(MaterialHit {
            material: name(&self.materials, hit.hit.material.0),
            object: name(&self.objects, hit.hit.object.0),
            point_in_world_m: hit.point_in_world_m.into(),
            distance_m: hit.distance_m,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::site::render::site_scene;
    use crate::site::stored_camera;
    use nalgebra::Point3;

    /// The hit point is computed in f32 relative to a local origin (coordinates ≲ 20 m here,
    /// f32 steps ≈ 2e-6 m) along a ray of ≈ 10 m: 1 mm is far above that and far below the
    /// box's size.
    const HIT_TOL_M: f64 = 1e-3;

    #[test]
    fn a_pixel_of_the_planned_box_gives_its_material_and_the_sky_gives_none() {
        let dir = tempfile::tempdir().unwrap();
        let doc = crate::site::render::tests::fixture(dir.path());
        let scene = site_scene(&doc).unwrap();
        let picker = MaterialPicker::new(&scene).unwrap();
        let camera = stored_camera(&doc.site, "p1").unwrap();
        // The middle of the unit box's south face (y = 0, x 0…1, z 0…1), facing the camera.
        let on_box = Point3::new(0.5, 0.0, 0.5);
        let p = camera.project(&on_box).unwrap();
        let hit = picker.pick(&doc.site, "p1", [p.x, p.y]).unwrap().unwrap();
        assert_eq!(hit.object, "model:box");
        let box_material = scene
            .scene
            .triangles()
            .iter()
            .find(|t| scene.object_sources[t.object.0 as usize].label() == "model:box")
            .map(|t| scene.scene.materials()[t.material.0 as usize].name.clone())
            .unwrap();
        assert_eq!(hit.material, box_material);
        for k in 0..3 {
            assert!(
                (hit.point_in_world_m[k] - on_box[k]).abs() < HIT_TOL_M,
                "{hit:?}"
            );
        }
        // The top row of the photo looks above the ground's far edge: sky.
        assert_eq!(picker.pick(&doc.site, "p1", [32.0, 0.0]).unwrap(), None);
        // An unsolved photo.
        assert!(matches!(
            picker.pick(&doc.site, "p2", [1.0, 1.0]),
            Err(MaterialPickError::NotSolved { .. })
        ));
    }
}
