//! The interreflection term E_r of the daylight fit ([`super::daylight`]): the irradiance the
//! photographed natural surfaces reflect onto a sample, gathered exactly as the renderer gathers
//! it for a natural point (Durisch 1992 §6.2 case D, the photo standing for the true colour of
//! the surfaces a gather ray meets; [`crate::render::DifferentialTracer::natural_interreflection_irradiance`]),
//! with the sample's own photo and solved camera, so that the weights fitted with it mean what
//! the renderer's eq. 10 inversion divides by.
//!
//! The renderer's tracer needs an artificial object; the photos show the site without the planned
//! building, so a 1 cm probe triangle is placed [`PROBE_DEPTH_M`] below the natural scene, where
//! no gather ray can reach it (the gather for E_r traces against the natural geometry only).
//!
//! # Known limitations
//! One diffuse bounce over a fixed facet set (the renderer's photo-bounce dome): surfaces the
//! photo does not show are shaded by their library material with the lighting passed in (the
//! caller iterates with the fitted weights); specular surroundings are treated as diffuse.

use std::collections::BTreeMap;

use image::Rgb32FImage;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::daylight::DaylightFit;
use crate::render::DifferentialTracer;
use crate::scene::{Material, ObjectKind, Scene, SceneObject};
use crate::site::SiteDocument;
use crate::site::render::{SiteLightingOptions, site_lighting};
use crate::site::stored_camera;

/// Depth of the probe triangle below the lowest point of the natural scene, metres: far enough
/// that no surface offset or f32 rounding reaches it, near enough not to widen the tracing frame.
pub const PROBE_DEPTH_M: f64 = 100.0;

/// Most fits of the interreflection iteration (E_r gathered with the previous pass's weights).
/// Each pass shrinks the weights' error by the share of E_r that comes from surfaces the photo
/// does not show (typically ≪ 1/2); a pass costs one gather per sample.
pub const INTERREFLECTION_MAX_PASSES: usize = 12;

/// The iteration stops when no weight moves by more than this fraction of the largest weight of
/// its kind: 0.01 %, far below the colour noise of a photo sample.
pub const INTERREFLECTION_SETTLED_REL: f64 = 1e-4;

/// Errors of the interreflection gather.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InterreflectionError {
    /// The natural scene is empty or the probe could not be added.
    #[error("scene: {0}")]
    Scene(String),
    /// A photo has no solved camera.
    #[error("photo `{photo}` has no solved camera")]
    NoCamera {
        /// Photo id.
        photo: String,
    },
    /// A photo could not be read or does not match its camera.
    #[error("photo `{photo}`: {message}")]
    Photo {
        /// Photo id.
        photo: String,
        /// Why.
        message: String,
    },
    /// The lighting of a photo could not be built (sun, sky model, atmosphere).
    #[error("lighting of photo `{photo}`: {message}")]
    Lighting {
        /// Photo id.
        photo: String,
        /// Why.
        message: String,
    },
}

/// A point at which E_r is gathered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GatherPoint<'a> {
    /// The photo the sample was read from.
    pub photo: &'a str,
    /// The point, world frame.
    pub point_in_world_m: Point3<f64>,
    /// Unit surface normal on the side the photo sees, world frame.
    pub normal_in_world: Vector3<f64>,
}

/// `natural` plus the probe triangle (an artificial object, see the module doc).
///
/// # Errors
/// [`InterreflectionError::Scene`] for an empty scene or an id overflow.
pub fn scene_with_probe(natural: &Scene) -> Result<Scene, InterreflectionError> {
    let scene_err = |e: crate::scene::SceneError| InterreflectionError::Scene(e.to_string());
    let [lo, hi] = natural
        .bounding_box_in_world_m()
        .ok_or_else(|| InterreflectionError::Scene("the natural scene is empty".into()))?;
    let mut scene = natural.clone();
    let object = scene
        .add_object(SceneObject {
            name: "interreflection probe".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .map_err(scene_err)?;
    let material = scene
        .add_material(Material::diffuse("probe", [0.0; 3]))
        .map_err(scene_err)?;
    let c = Point3::new(
        0.5 * (lo.x + hi.x),
        0.5 * (lo.y + hi.y),
        lo.z - PROBE_DEPTH_M,
    );
    let tri = [
        c,
        c + Vector3::new(0.01, 0.0, 0.0),
        c + Vector3::new(0.0, 0.01, 0.0),
    ];
    scene
        .add_polygon(&tri, material, object)
        .map_err(scene_err)?;
    Ok(scene)
}

/// E_r (linear RGB, photo units) at each point, gathered with its photo's camera and the
/// lighting `doc` gives that photo (`[lighting]` weights and atmosphere: they shade the surfaces
/// the photo does not show, the sky over a dome of `sky_m_h`) over a photo-bounce dome of
/// `bounce_m_h` (4·m_h² facets and their mirror images). `scene` is [`scene_with_probe`]'s; `photo_linear` returns a photo as linear
/// RGB by id.
///
/// # Errors
/// A photo without a solved camera, unreadable or of another size than its camera, or a
/// lighting error.
pub fn gather_interreflection(
    doc: &SiteDocument,
    scene: &Scene,
    points: &[GatherPoint<'_>],
    sky_m_h: u32,
    bounce_m_h: u32,
    mut photo_linear: impl FnMut(&str) -> Result<Rgb32FImage, String>,
) -> Result<Vec<[f64; 3]>, InterreflectionError> {
    // Luminaires do not light the photographed scene: leave them out (and their files unread).
    let mut doc = doc.clone();
    doc.site.luminaires.clear();
    let options = SiteLightingOptions {
        sky_dome_m_h: sky_m_h,
        photo_bounce_m_h: Some(bounce_m_h),
        photo_bounce_nested_m_h: None,
    };
    let mut by_photo: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, p) in points.iter().enumerate() {
        by_photo.entry(p.photo).or_default().push(i);
    }
    let mut out = vec![[0.0; 3]; points.len()];
    for (photo, indices) in by_photo {
        let camera =
            stored_camera(&doc.site, photo).ok_or_else(|| InterreflectionError::NoCamera {
                photo: photo.to_owned(),
            })?;
        let image = photo_linear(photo).map_err(|message| InterreflectionError::Photo {
            photo: photo.to_owned(),
            message,
        })?;
        let size = [image.width(), image.height()];
        if size != camera.intrinsics.image_size_px {
            return Err(InterreflectionError::Photo {
                photo: photo.to_owned(),
                message: format!(
                    "{}×{} px, its camera {}×{} px",
                    size[0],
                    size[1],
                    camera.intrinsics.image_size_px[0],
                    camera.intrinsics.image_size_px[1]
                ),
            });
        }
        let (lighting, _) =
            site_lighting(&doc, photo, &options).map_err(|e| InterreflectionError::Lighting {
                photo: photo.to_owned(),
                message: e.to_string(),
            })?;
        let tracer = DifferentialTracer::new(scene, &lighting, &camera, &image, 1)
            .map_err(|e| InterreflectionError::Scene(e.to_string()))?;
        let gathered: Vec<(usize, [f64; 3])> = indices
            .par_iter()
            .map(|&i| {
                let p = &points[i];
                (
                    i,
                    tracer.natural_interreflection_irradiance(
                        &p.point_in_world_m,
                        &p.normal_in_world,
                    ),
                )
            })
            .collect();
        for (i, e) in gathered {
            out[i] = e;
        }
    }
    Ok(out)
}

/// Whether every weight of `b` is within [`INTERREFLECTION_SETTLED_REL`] of `a`'s, relative to
/// the largest weight of its kind.
#[must_use]
pub fn weights_settled(a: &DaylightFit, b: &DaylightFit) -> bool {
    [
        (a.sun_weight, b.sun_weight),
        (a.ambient_weight, b.ambient_weight),
        (a.sky_weight, b.sky_weight),
    ]
    .iter()
    .all(|(x, y)| {
        let scale = x.iter().chain(y).fold(0.0_f64, |m, v| m.max(v.abs()));
        (0..3).all(|k| (x[k] - y[k]).abs() <= INTERREFLECTION_SETTLED_REL * scale)
    })
}

#[cfg(test)]
mod tests;
