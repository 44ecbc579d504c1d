//! Accurate Visual Representation levels as render modes (Greater London Authority, *London View
//! Management Framework SPG*, 2012, Appendix C; TGN 06/19 Types 3–4):
//!
//! - **AVR0** location and extent: the proposal's silhouette as it would be seen, i.e. the pixels
//!   whose first surface is the proposal (hidden by the existing scene where the scene polygons
//!   say so), outlined and lightly tinted over the photo;
//! - **AVR1** location, size and degree of visibility: the wireline of [`super::wireline`],
//!   visible edges solid, edges hidden by the scene or the proposal itself dashed;
//! - **AVR2** plus architectural form: the montage with every planned surface given one neutral
//!   diffuse material ([`MASSING_ALBEDO`]) under the site's light;
//! - **AVR3** plus materials: the full montage (the differential renderer as it is).
//!
//! AVR0 and AVR1 are drawn here ([`avr_overlay`]); AVR2 is the ordinary render of a scene
//! changed by [`apply_massing`]; AVR3 is the ordinary render.
//!
//! # Known limitations
//! The silhouette is sampled at pixel centres (no antialiasing); lines are one pixel wide in one
//! colour ([`LINE_RGB`]); the existing scene hides the proposal only where the scene polygons
//! model it, exactly as in the montage.

use nalgebra::Point2;

use super::wireline::{LinePixel, rasterise, wireline_runs};
use crate::bvh::BuildQuality;
use crate::camera::Camera;
use crate::render::RenderedImage;
use crate::scene::{Material, ObjectKind, Scene, SceneError, SceneTracer};
use crate::site::SiteDocument;
use crate::site::render::{SiteRenderError, site_camera, site_scene};

/// Linear RGB of the drawn lines and outline: a saturated red that no façade is (planning
/// practice draws wirelines in red).
pub const LINE_RGB: [f32; 3] = [1.0, 0.05, 0.02];
/// AVR0: inside the silhouette the photo is mixed with [`LINE_RGB`] by this much.
pub const SILHOUETTE_TINT: f32 = 0.3;
/// AVR2: diffuse reflectance of the neutral massing material (a light grey, as massing models
/// are usually presented).
pub const MASSING_ALBEDO: [f64; 3] = [0.6; 3];

/// The four levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum AvrLevel {
    Avr0,
    Avr1,
    Avr2,
    Avr3,
}

impl AvrLevel {
    /// The level of a number 0–3.
    ///
    /// # Errors
    /// [`AvrError::UnknownLevel`] for any other number.
    pub fn from_number(level: u8) -> Result<Self, AvrError> {
        match level {
            0 => Ok(Self::Avr0),
            1 => Ok(Self::Avr1),
            2 => Ok(Self::Avr2),
            3 => Ok(Self::Avr3),
            _ => Err(AvrError::UnknownLevel { level }),
        }
    }

    /// `AVR0` … `AVR3`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Avr0 => "AVR0",
            Self::Avr1 => "AVR1",
            Self::Avr2 => "AVR2",
            Self::Avr3 => "AVR3",
        }
    }

    /// What the level shows (LVMF Appendix C).
    #[must_use]
    pub fn description(self) -> &'static str {
        match self {
            Self::Avr0 => "location and extent (silhouette)",
            Self::Avr1 => "location, size and degree of visibility (wireline)",
            Self::Avr2 => "as AVR1 plus architectural form (massing in a neutral material)",
            Self::Avr3 => "as AVR2 plus materials (full photomontage)",
        }
    }
}

/// What can go wrong drawing an AVR0/AVR1 view.
#[derive(Debug, thiserror::Error)]
pub enum AvrError {
    #[error("AVR level {level} does not exist (0, 1, 2 or 3)")]
    UnknownLevel { level: u8 },
    #[error("{level:?} is rendered by the montage renderer, not drawn as an overlay")]
    NotAnOverlay { level: AvrLevel },
    #[error("photo {photo}: the site has no visible model, so there is no proposal to show")]
    NoProposal { photo: String },
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
}

/// AVR2: gives every planned (artificial) triangle the neutral [`MASSING_ALBEDO`] material.
///
/// # Errors
/// [`SceneError`] when the material cannot be added.
pub fn apply_massing(scene: &mut Scene) -> Result<usize, SceneError> {
    let neutral = scene.add_material(Material::diffuse("avr2_massing", MASSING_ALBEDO))?;
    scene.set_material_of_kind(ObjectKind::Artificial, neutral)
}

/// Pixels (row-major) whose first surface along the camera ray through the pixel centre is a
/// planned (artificial) one.
#[must_use]
pub fn silhouette_mask(tracer: &SceneTracer, camera: &Camera) -> Vec<bool> {
    let [w, h] = camera.intrinsics.image_size_px;
    let centre = camera.pose.camera_center_in_world;
    let rays: Vec<_> = (0..h)
        .flat_map(|y| (0..w).map(move |x| Point2::new(f64::from(x), f64::from(y))))
        .map(|px| tracer.ray_from_world(&centre, &camera.ray_dir_in_world(px), 0.0, f32::INFINITY))
        .collect();
    tracer
        .closest_hits(&rays)
        .iter()
        .map(|hit| hit.is_some_and(|h| h.kind == ObjectKind::Artificial))
        .collect()
}

/// Pixels of `mask` with a 4-neighbour outside it (or on the image border).
#[must_use]
pub fn outline(mask: &[bool], size_px: [u32; 2]) -> Vec<bool> {
    let [w, h] = size_px.map(|v| v as usize);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            mask[i]
                && (x == 0
                    || y == 0
                    || x + 1 == w
                    || y + 1 == h
                    || !mask[i - 1]
                    || !mask[i + 1]
                    || !mask[i - w]
                    || !mask[i + w])
        })
        .collect()
}

/// An AVR0 or AVR1 image drawn over the photo, with the raster it was drawn from.
#[derive(Debug, Clone)]
pub struct AvrOverlay {
    /// The photo with the drawing; alpha 1 where something was drawn (or, for AVR0, inside the
    /// silhouette), 0 elsewhere.
    pub image: RenderedImage,
    /// AVR1: the wireline raster; AVR0: empty.
    pub lines: Vec<LinePixel>,
    /// AVR0: the silhouette mask; AVR1: empty.
    pub silhouette: Vec<bool>,
}

/// Draws AVR0 (silhouette) or AVR1 (wireline) of photo `photo_id` over the photo.
///
/// # Errors
/// [`AvrError::NotAnOverlay`] for AVR2/AVR3, [`AvrError::NoProposal`] without a visible model,
/// the site errors of an unknown or unsolved view, an unreadable scene or photo, or a photo whose
/// size is not the camera's.
pub fn avr_overlay(
    doc: &SiteDocument,
    photo_id: &str,
    level: AvrLevel,
) -> Result<AvrOverlay, AvrError> {
    if matches!(level, AvrLevel::Avr2 | AvrLevel::Avr3) {
        return Err(AvrError::NotAnOverlay { level });
    }
    if !doc.site.models.iter().any(|m| m.visible) {
        // Name an unknown or unsolved view first, then the missing proposal.
        site_camera(doc, photo_id)?;
        return Err(AvrError::NoProposal {
            photo: photo_id.to_owned(),
        });
    }
    let (camera, photo_linear) = super::planar_view::solved_photo(doc, photo_id)?;
    let size_px = camera.intrinsics.image_size_px;
    let scene = site_scene(doc)?.scene;
    let tracer = SceneTracer::new(&scene, BuildQuality::default())?;
    let mut rgba: Vec<[f32; 4]> = photo_linear
        .pixels()
        .map(|p| [p.0[0], p.0[1], p.0[2], 0.0])
        .collect();
    let line = [LINE_RGB[0], LINE_RGB[1], LINE_RGB[2], 1.0];
    let (lines, silhouette, primary_rays) = if level == AvrLevel::Avr1 {
        let runs = wireline_runs(&scene, &tracer, &camera);
        let rays = runs.iter().map(|r| r.points_px.len() as u64).sum();
        let lines = rasterise(&runs, size_px);
        for (px, l) in rgba.iter_mut().zip(&lines) {
            if *l != LinePixel::None {
                *px = line;
            }
        }
        (lines, Vec::new(), rays)
    } else {
        let mask = silhouette_mask(&tracer, &camera);
        let edge = outline(&mask, size_px);
        for ((px, inside), on_edge) in rgba.iter_mut().zip(&mask).zip(&edge) {
            if *on_edge {
                *px = line;
            } else if *inside {
                for k in 0..3 {
                    px[k] += SILHOUETTE_TINT * (LINE_RGB[k] - px[k]);
                }
                px[3] = 1.0;
            }
        }
        (Vec::new(), mask, rgba.len() as u64)
    };
    let changed_pixels = rgba.iter().filter(|p| p[3] > 0.0).count();
    Ok(AvrOverlay {
        image: RenderedImage {
            size_px,
            rgba,
            changed_pixels,
            primary_rays,
        },
        lines,
        silhouette,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_by_number() {
        assert_eq!(AvrLevel::from_number(1).expect("valid"), AvrLevel::Avr1);
        assert_eq!(AvrLevel::from_number(3).expect("valid").name(), "AVR3");
        assert!(matches!(
            AvrLevel::from_number(4),
            Err(AvrError::UnknownLevel { level: 4 })
        ));
    }

    #[test]
    fn outline_of_a_square() {
        // A 3 × 3 square in a 5 × 5 image: its 8 border pixels, not its centre.
        let mask: Vec<bool> = (0..25)
            .map(|i| (1..=3).contains(&(i % 5)) && (1..=3).contains(&(i / 5)))
            .collect();
        let edge = outline(&mask, [5, 5]);
        assert_eq!(edge.iter().filter(|e| **e).count(), 8);
        assert!(!edge[12] && edge[6]);
    }

    #[test]
    fn massing_replaces_only_planned_materials() {
        use crate::scene::SceneObject;
        use nalgebra::Point3;
        let mut scene = Scene::new();
        let brick = scene
            .add_material(Material::diffuse("brick", [0.4, 0.2, 0.1]))
            .expect("material");
        for (name, kind) in [
            ("old", ObjectKind::Natural),
            ("new", ObjectKind::Artificial),
        ] {
            let o = scene
                .add_object(SceneObject {
                    name: name.into(),
                    kind,
                    image_attribute: None,
                })
                .expect("object");
            let tri = [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ];
            scene.add_polygon(&tri, brick, o).expect("polygon");
        }
        assert_eq!(apply_massing(&mut scene).expect("massing"), 1);
        let albedo = |i: usize| {
            scene.materials()[scene.triangles()[i].material.0 as usize].diffuse_reflectance_rgb()
        };
        // The same numbers copied through, so compared exactly (bit for bit).
        assert_eq!(
            albedo(0).map(f64::to_bits),
            [0.4, 0.2, 0.1].map(f64::to_bits)
        );
        assert_eq!(
            albedo(1).map(f64::to_bits),
            MASSING_ALBEDO.map(f64::to_bits)
        );
    }
}
