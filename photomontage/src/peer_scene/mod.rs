//! Scenes of the peer benchmarks, assembled for the differential renderer: the Mitsuba 3
//! ground-plus-box pair described by the shared bench's `data/mitsuba/scene.json` (written by
//! `peers/mitsuba/render_pair.py`). The accuracy test (`tests/tests/render_mitsuba.rs`) and the
//! render-speed bench (`render_bench`) both build their scene, camera and lights here, so they
//! measure the same thing; [`radiosity`] adds the pair's radiosity lighting mode.
//!
//! Conventions of the JSON (its `units_and_axes` and `camera.pixel_convention` fields): metres,
//! right-handed, Z up; a look-at pinhole camera with a vertical field of view, forward =
//! target − position, right = forward × up, image down = forward × right. Mitsuba's pixel (i, j)
//! covers [i, i+1) × [j, j+1), so its image centre (W/2, H/2) is our (W−1)/2, (H−1)/2
//! ([`Intrinsics::centred`]). The sun is a directional light of normal irradiance
//! `irradiance_rgb`; the sky a constant radiance over the sphere, which on the upper hemisphere is
//! Durisch's uniform sky (1992 §3.4, k_h = π·L) sampled on a Durisch facet dome.
//!
//! # Known limitations
//! Only the ground-plus-box pair is understood (other peer scenes have no JSON description). The
//! constant sky's lower hemisphere is hidden by the ground in this scene and is not modelled.

pub mod radiosity;

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use serde_json::Value;

use crate::camera::{Camera, Intrinsics, Pose};
use crate::render::{Daylight, DistantLight, Lighting};
use crate::scene::{Material, ObjectKind, Scene, SceneError, SceneObject};
use crate::sky_dome::DomeError;
use crate::sky_dome::durisch_facets::durisch_dome;

/// Durisch dome resolution m_h of the sky facets (8 → 256 facets).
pub const SKY_DOME_M_H: u32 = 8;
/// Dome resolution of the gathered bounce from the photographed surroundings.
pub const PHOTO_BOUNCE_M_H: u32 = 6;
/// Dome resolution of the nested bounce (the building's light reaching the shadow).
pub const PHOTO_BOUNCE_NESTED_M_H: u32 = 2;

/// Mirror recursion depth for [`crate::render::DifferentialTracer::new`]: every surface of the
/// scene is Lambertian, so no mirror bounce is ever taken.
pub const MAX_DEPTH: u32 = 1;

/// Errors of [`mitsuba_pair_scene`].
#[derive(Debug, thiserror::Error)]
pub enum PeerSceneError {
    /// A field is missing or has the wrong type.
    #[error("scene.json: field `{field}` is missing or not {expected}")]
    Field {
        /// JSON path of the field.
        field: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The geometry is degenerate (camera looking along `up`, zero-size image).
    #[error("scene.json: degenerate {what}")]
    Degenerate {
        /// What is degenerate.
        what: &'static str,
    },
    /// Building the scene failed.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Building the sky dome failed.
    #[error(transparent)]
    Dome(#[from] DomeError),
    /// A radiosity solve of the pair failed ([`radiosity::mitsuba_pair_radiosity`]).
    #[error(transparent)]
    Radiosity(#[from] crate::radiosity::RadiosityError),
}

/// The Mitsuba pair as the differential renderer sees it.
#[derive(Debug, Clone)]
pub struct PeerScene {
    /// The natural ground and the artificial box.
    pub scene: Scene,
    /// The camera, scaled to the requested image size.
    pub camera: Camera,
    /// Sun, sky facets and the gathered photo bounce.
    pub lighting: Lighting,
}

fn field<'a>(v: &'a Value, path: &[&str]) -> Result<&'a Value, PeerSceneError> {
    let mut cur = v;
    for key in path {
        cur = cur.get(key).ok_or_else(|| PeerSceneError::Field {
            field: path.join("."),
            expected: "present",
        })?;
    }
    Ok(cur)
}

fn num(v: &Value, path: &[&str]) -> Result<f64, PeerSceneError> {
    field(v, path)?
        .as_f64()
        .filter(|x| x.is_finite())
        .ok_or_else(|| PeerSceneError::Field {
            field: path.join("."),
            expected: "a finite number",
        })
}

fn vec3_of(v: &Value, name: &str) -> Result<[f64; 3], PeerSceneError> {
    let err = || PeerSceneError::Field {
        field: name.to_owned(),
        expected: "an array of 3 finite numbers",
    };
    let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(err)?;
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64().filter(|x| x.is_finite()).ok_or_else(err)?;
    }
    Ok(out)
}

fn vec3(v: &Value, path: &[&str]) -> Result<[f64; 3], PeerSceneError> {
    vec3_of(field(v, path)?, &path.join("."))
}

fn points(v: &Value, path: &[&str], count: usize) -> Result<Vec<[f64; 3]>, PeerSceneError> {
    let name = path.join(".");
    let a = field(v, path)?
        .as_array()
        .filter(|a| a.len() == count)
        .ok_or_else(|| PeerSceneError::Field {
            field: name.clone(),
            expected: "an array of the expected number of points",
        })?;
    a.iter().map(|p| vec3_of(p, &name)).collect()
}

/// The camera of `scene.json` for an image of `size_px` (the JSON's own size or a box-filtered
/// downscale of it: the vertical field of view is kept).
///
/// # Errors
/// [`PeerSceneError::Field`] for missing fields, [`PeerSceneError::Degenerate`] when the view
/// direction is parallel to `up` or the size is zero.
pub fn mitsuba_camera(spec: &Value, size_px: [u32; 2]) -> Result<Camera, PeerSceneError> {
    let eye = Point3::from(vec3(spec, &["camera", "position"])?);
    let target = Point3::from(vec3(spec, &["camera", "target"])?);
    let up = Vector3::from(vec3(spec, &["camera", "up"])?);
    let vfov = num(spec, &["camera", "vfov_deg"])?.to_radians();
    let forward = (target - eye)
        .try_normalize(1e-12)
        .ok_or(PeerSceneError::Degenerate { what: "camera" })?;
    let right = forward
        .cross(&up)
        .try_normalize(1e-12)
        .ok_or(PeerSceneError::Degenerate { what: "camera" })?;
    let down = forward.cross(&right);
    if size_px[0] == 0 || size_px[1] == 0 || !(vfov > 0.0 && vfov < std::f64::consts::PI) {
        return Err(PeerSceneError::Degenerate {
            what: "image size or field of view",
        });
    }
    let focal_px = f64::from(size_px[1]) / 2.0 / (vfov / 2.0).tan();
    Ok(Camera {
        intrinsics: Intrinsics::centred(focal_px, size_px),
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                right, down, forward,
            ])),
            camera_center_in_world: eye,
        },
    })
}

/// The box's six faces from its 8 corners in `render_pair.py`'s order (x fastest, then y, z).
const BOX_FACES: [[usize; 4]; 6] = [
    [0, 1, 3, 2],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [1, 3, 7, 5],
    [3, 2, 6, 7],
    [2, 0, 4, 6],
];

fn add_object(
    scene: &mut Scene,
    name: &str,
    kind: ObjectKind,
    albedo_rgb: [f64; 3],
    faces: &[Vec<[f64; 3]>],
) -> Result<(), PeerSceneError> {
    let material = scene.add_material(Material::diffuse(name, albedo_rgb))?;
    let object = scene.add_object(SceneObject {
        name: name.into(),
        kind,
        image_attribute: None,
    })?;
    for face in faces {
        let poly: Vec<Point3<f64>> = face.iter().copied().map(Point3::from).collect();
        scene.add_polygon(&poly, material, object)?;
    }
    Ok(())
}

/// The Mitsuba ground-plus-box pair of `scene.json` (parsed) for an image of `size_px`: the
/// ground as a natural polygon, the box as an artificial object, the sun, the uniform sky on a
/// Durisch dome of [`SKY_DOME_M_H`], and the gathered photo bounce ([`PHOTO_BOUNCE_M_H`],
/// nested [`PHOTO_BOUNCE_NESTED_M_H`]); the horizon colour is the sky radiance.
///
/// # Errors
/// [`PeerSceneError`] for missing or malformed fields and degenerate geometry.
pub fn mitsuba_pair_scene(spec: &Value, size_px: [u32; 2]) -> Result<PeerScene, PeerSceneError> {
    let camera = mitsuba_camera(spec, size_px)?;
    let mut scene = Scene::new();
    let ground = points(spec, &["ground", "corners"], 4)?;
    add_object(
        &mut scene,
        "ground",
        ObjectKind::Natural,
        vec3(spec, &["ground", "albedo_rgb"])?,
        &[ground],
    )?;
    let corners = points(spec, &["building", "corners"], 8)?;
    let faces: Vec<Vec<[f64; 3]>> = BOX_FACES
        .iter()
        .map(|f| f.iter().map(|&i| corners[i]).collect())
        .collect();
    add_object(
        &mut scene,
        "box",
        ObjectKind::Artificial,
        vec3(spec, &["building", "albedo_rgb"])?,
        &faces,
    )?;

    let sky_radiance_rgb = vec3(spec, &["sky", "radiance_rgb"])?;
    let sun_dir = Vector3::from(vec3(spec, &["sun", "direction_to_sun"])?)
        .try_normalize(1e-12)
        .ok_or(PeerSceneError::Degenerate {
            what: "sun direction",
        })?;
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: sun_dir,
                normal_irradiance_rgb: vec3(spec, &["sun", "irradiance_rgb"])?,
            }),
            ambient_radiance_rgb: [0.0; 3],
            sky: Daylight::uniform_sky_lights(&durisch_dome(SKY_DOME_M_H)?, sky_radiance_rgb),
        },
        photo_bounce_dome: Some(durisch_dome(PHOTO_BOUNCE_M_H)?),
        photo_bounce_nested_dome: Some(durisch_dome(PHOTO_BOUNCE_NESTED_M_H)?),
        horizon_rgb: sky_radiance_rgb,
        ..Lighting::default()
    };
    Ok(PeerScene {
        scene,
        camera,
        lighting,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn spec() -> Value {
        serde_json::json!({
            "camera": {"position": [0.0, -10.0, 2.0], "target": [0.0, 0.0, 2.0], "up": [0.0, 0.0, 1.0],
                       "vfov_deg": 90.0},
            "sun": {"direction_to_sun": [0.0, 0.0, 2.0], "irradiance_rgb": [3.0, 2.0, 1.0]},
            "sky": {"radiance_rgb": [0.25, 0.3, 0.4]},
            "ground": {"corners": [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], "albedo_rgb": [0.3, 0.3, 0.3]},
            "building": {"corners": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
                         "albedo_rgb": [0.7, 0.6, 0.5]}
        })
    }

    /// A 90° vertical field of view over 100 rows is a focal length of exactly 50 px; the camera
    /// looks along +Y with image down = −Z.
    #[test]
    fn camera_focal_and_axes_follow_the_look_at() {
        let cam = mitsuba_camera(&spec(), [200, 100]).unwrap();
        assert!((cam.intrinsics.focal_px - 50.0).abs() < 1e-9);
        let r = cam.pose.rotation_world_from_camera;
        assert!((r * Vector3::z() - Vector3::y()).norm() < 1e-12);
        assert!((r * Vector3::y() + Vector3::z()).norm() < 1e-12);
        assert!((r * Vector3::x() - Vector3::x()).norm() < 1e-12);
    }

    /// The ground square (2 triangles) and the box (12), the sun normalised, 256 sky facets whose
    /// normal irradiances sum to the sky radiance times the hemisphere's 2π sr.
    #[test]
    fn scene_and_lights_match_the_description() {
        let peer = mitsuba_pair_scene(&spec(), [64, 32]).unwrap();
        assert_eq!(peer.scene.triangles().len(), 14);
        let sun = peer.lighting.daylight.sun.unwrap();
        assert!((sun.dir_in_world - Vector3::z()).norm() < 1e-12);
        let sky = &peer.lighting.daylight.sky;
        assert_eq!(sky.len(), 256);
        let total: f64 = sky.iter().map(|l| l.normal_irradiance_rgb[0]).sum();
        assert!((total - 0.25 * 2.0 * std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn missing_and_degenerate_fields_are_named() {
        let mut s = spec();
        s["building"]["corners"] = serde_json::json!([[0, 0, 0]]);
        let e = mitsuba_pair_scene(&s, [8, 8]).unwrap_err();
        assert!(e.to_string().contains("building.corners"), "{e}");
        let mut s = spec();
        s["camera"]["target"] = serde_json::json!([0.0, -10.0, 5.0]);
        assert!(matches!(
            mitsuba_camera(&s, [8, 8]),
            Err(PeerSceneError::Degenerate { .. })
        ));
        assert!(matches!(
            mitsuba_camera(&spec(), [0, 8]),
            Err(PeerSceneError::Field { .. } | PeerSceneError::Degenerate { .. })
        ));
    }
}
