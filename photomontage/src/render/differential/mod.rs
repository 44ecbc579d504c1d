//! The per-ray logic of the differential ray tracer, each case named as in Durisch 1992 §6.2:
//!
//! - **Case A** ([`DifferentialTracer::case_a_primary_miss`]): a primary ray hits nothing → the
//!   photo's pixel.
//! - **Case B** ([`DifferentialTracer::case_b_secondary_miss`]): a secondary ray hits nothing →
//!   the horizon colour L∞ if it points above the horizon.
//! - **Case C** ([`DifferentialTracer::case_c_artificial_hit`]): an artificial object → eq. 6 with
//!   the natural lights (sun, ambient, sky facets, visibility by any-hit against the whole scene)
//!   and the artificial lights (points or luminaires), the GGX lobe ([`specular`]), mirror
//!   and thin-glass reflection and transmission recursively ([`glass`]), water-wave
//!   shading normals ([`super::water`]), then the atmosphere (eq. 2).
//! - **Case D** ([`DifferentialTracer::case_d_natural_hit`]): a natural object → its apparent
//!   colour from the photo, its true colour L₀ by the atmosphere's second inversion (eq. 8), its
//!   albedo ρ_d by the illumination model's second inversion (eq. 10), then
//!   **D1** artificial lights add `ρ_d/π·E`, **D2** natural lights are already in the photo, and
//!   **D3** natural lights blocked *only* by artificial objects add `ρ_d/π·(−E)`; the change is
//!   carried to the camera through eq. 2.
//!
//! A natural light counts as blocked by artificial objects when an any-hit against the artificial
//! geometry succeeds and one against the natural geometry fails (separate BVHs); glass panes take
//! only the fraction they do not transmit ([`glass`]). Shadow rays to
//! the artificial BVH are first culled by its bounding box, so the cost of proving that a pixel is
//! unchanged is one closest hit plus a slab test per light.
//!
//! **Interreflection** (one bounce, when [`Lighting::photo_bounce_dome`] is set): an artificial
//! point gathers the radiance of the natural surfaces around it from the photo (Durisch's
//! secondary ray in case D, the photo standing for their true colour), and a changed natural
//! point gathers the light the artificial objects reflect onto it (added like D1), those objects
//! lit in turn by the photo over [`Lighting::photo_bounce_nested_dome`]. A changed natural point
//! also gathers the light its photographed surroundings reflect onto it, once against the natural
//! geometry (part of the natural irradiance that the eq. 10 inversion divides by: without it a
//! point in a street lit by sunny façades gets too high an albedo and its new shadow comes out
//! too dark) and once against all geometry with the sun removed where only artificial objects
//! block it; the difference is added like D1/D3. Inside a render these gathers go through the
//! tile's irradiance cache ([`super::irradiance_cache`], Ward 1988): a gather runs once per small
//! surface region and nearby ray samples interpolate its records
//! ([`DifferentialTracer::set_irradiance_cache`] turns it off).
//!
//! Because eq. 2 is affine in L₀, the apparent colour of a changed natural point is computed as
//! `L_photo + τ(d)·ΔL₀`: an unchanged point returns the photo value unaltered, bit for bit.
//!
//! # Known limitations
//! Secondary rays that hit natural objects take their apparent colour from the current photo only
//! (not from the polygon's image attribute photo), when the point is visible in it; otherwise the
//! library material is shaded by eq. 6. Glass is a thin pane (no refraction through solids;
//! shadow rays pass it attenuated but straight); the glossy lobe is sampled with few rays (see [`specular`]).
//! The gather is one bounce on a fixed facet set (deterministic, so it has
//! quantisation error rather than noise); the artificial radiance a natural point gathers takes sky
//! facets as visible and gets its own photo bounce only from the coarser nested dome; natural surfaces blocked from the photo's view
//! fall back to their library material; the light a natural surface no longer receives from
//! other natural surfaces hidden by the building is not removed, and the bounce onto natural
//! points is only added where a natural light is already changed (D1/D3). Below-horizon
//! secondary misses return black.

use std::sync::atomic::{AtomicU64, Ordering};

use image::Rgb32FImage;
use nalgebra::{Point2, Point3};

mod cases;
pub mod glass;
mod interreflection;
pub mod radiosity_light;
pub mod replay;
mod shading;
pub use shading::{Shade, true_colour_rgb};
pub mod specular;
mod visibility;

use super::illumination::{Daylight, Rgb};
use super::irradiance_cache::IrradianceCacheSettings;
use super::luminaire_light::ArtificialLight;
use crate::atmosphere::schachter::SchachterAtmosphere;
use crate::bvh::BuildQuality;
use crate::camera::Camera;
use crate::scene::material::GradientNoise;
use crate::scene::{ImportedModel, Material, ObjectKind, Scene, SceneError, SceneHit, SceneTracer};

/// Shadow and reflection rays start this far off the surface, along its normal, so they do not
/// re-hit it: 1 mm, far above the `f32` spacing (≤ 0.5 mm) of the local tracing frame within
/// kilometres, far below any architectural detail that casts a visible shadow.
pub const SURFACE_OFFSET_M: f64 = 1e-3;

/// Errors preparing the differential tracer.
#[derive(Debug, thiserror::Error)]
pub enum DifferentialError {
    /// Building a BVH failed.
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
    /// The scene has no artificial object: there is nothing to render into the photo.
    #[error("the scene has no artificial object")]
    NoArtificialObject,
}

/// Lights and atmosphere of a render.
#[derive(Debug, Clone, Default)]
pub struct Lighting {
    /// Natural daylight (from the first inversion, §4.3).
    pub daylight: Daylight,
    /// Artificial lights of the project: isotropic points or luminaires with a photometric web
    /// ([`super::luminaire_light`]).
    pub artificial_lights: Vec<ArtificialLight>,
    /// Schachter atmosphere (eq. 2); `None` for a clear atmosphere.
    pub atmosphere: Option<SchachterAtmosphere>,
    /// Light reflected by the photographed surroundings onto artificial objects (one diffuse
    /// bounce gathered over these facets and their mirror images below the horizon): a gather
    /// ray that hits a natural object brings the photo's radiance of that point (its true colour,
    /// darkened where the sun is blocked by an artificial object only). `None` disables it.
    pub photo_bounce_dome: Option<crate::sky_dome::SkyDome>,
    /// Facets of the second, coarser gather that gives the artificial surfaces seen by a natural
    /// point's gather their own light from the photographed surroundings (a second bounce,
    /// artificial → natural). `None` skips it.
    pub photo_bounce_nested_dome: Option<crate::sky_dome::SkyDome>,
    /// Horizon colour L∞ returned by case B (when there is no atmosphere, the sky colour seen in
    /// mirrors).
    pub horizon_rgb: Rgb,
    /// The radiosity lighting mode ([`radiosity_light`]): sky and interreflected light from
    /// solutions with and without the artificial objects instead of the sky facets and the
    /// photo bounce. `None`: the facet mode.
    pub radiosity: Option<std::sync::Arc<radiosity_light::RadiosityLight>>,
    /// The radiosity lighting mode of a spectral render: the solutions of each pass
    /// ([`crate::render::spectral`]); `radiosity` stays `None` then. `None`: the facet mode, or an
    /// RGB render.
    pub radiosity_spectral: Option<std::sync::Arc<radiosity_light::SpectralRadiosity>>,
}

/// What one ray returned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaySample {
    /// Apparent radiance towards the ray origin, linear RGB.
    pub radiance_rgb: Rgb,
    /// Whether the result differs from what the photo shows (some artificial object or light is
    /// involved); `false` means the photo value is returned unaltered.
    pub changed: bool,
    /// Whether the ray's first hit is an artificial object (coverage).
    pub hit_artificial: bool,
    /// The first hit (distance along the ray, object), for the depth and object-id layers.
    pub first_hit: Option<PrimaryHit>,
    /// For a changed natural point on the photo's line of sight (case D by eq. 10), the parts
    /// of its radiance `L_photo + τ·L₀·ΔE/E`; the pixel combines such samples as a ratio of
    /// means ([`NaturalRatio`]).
    pub natural_ratio: Option<NaturalRatio>,
}

/// The parts of a natural sample's change on the photo's line of sight: radiance
/// `L_photo + τ·L₀·ΔE/E` per channel, with E the natural irradiance eq. 10 divides by and ΔE
/// the irradiance the artificial objects and lights add or take away.
///
/// A pixel's photo value is the mean over its footprint, so where the footprint straddles an
/// existing shadow edge, L₀ is a mix of lit and shadowed ground. Dividing that mix by each
/// sample's own E (a mean of ratios) over-brightens the shadowed samples and darkens the lit
/// ones, leaving a bright seam along the old edge inside a new shadow. The renderer instead
/// takes the pixel's samples together: `L_photo + mean(τ·L₀)·ΣΔE/ΣE` (a ratio of means), which
/// is exact for a footprint of one reflectance whatever its mix of light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NaturalRatio {
    /// τ(d)·L₀: the photo's true colour carried back to the camera.
    pub tau_l0_rgb: Rgb,
    /// E: the natural irradiance at the point (sun, sky, interreflection), positive.
    pub e_natural_rgb: Rgb,
    /// ΔE: the change of irradiance (zero for an unchanged point).
    pub e_change_rgb: Rgb,
}

/// Where a primary ray first hit the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimaryHit {
    /// Distance from the camera centre along the (unit) ray, metres.
    pub distance_m: f64,
    /// The object hit.
    pub object: crate::scene::ObjectId,
}

/// The scene split for differential tracing: all geometry, natural only and artificial only.
#[derive(Debug, Clone)]
pub struct DifferentialTracer<'a> {
    scene: &'a Scene,
    all: SceneTracer,
    natural: Option<SceneTracer>,
    artificial: SceneTracer,
    /// The glass panes among the artificial triangles and the rest, when there are panes:
    /// shadow rays pass panes attenuated ([`glass`]) and stop at the rest.
    pub(super) artificial_split: Option<GlassSplit>,
    artificial_bounds_in_world_m: [Point3<f64>; 2],
    lighting: &'a Lighting,
    camera: &'a Camera,
    photo_linear: &'a Rgb32FImage,
    max_depth: u32,
    /// The materials shaded (the scene's, or per-band ones in spectral mode).
    pub(super) materials: &'a [Material],
    /// Noise of each material's water waves (index = material id).
    pub(super) water_noise: Vec<Option<GradientNoise>>,
    /// Irradiance caching of the gathers inside a tile ([`super::irradiance_cache`]); `None`
    /// gathers every time.
    irradiance_cache: Option<IrradianceCacheSettings>,
    /// Identifies this tracer's records in a tile cache (unique per set of inputs).
    cache_id: u64,
}

/// Source of [`DifferentialTracer::cache_id`].
static NEXT_CACHE_ID: AtomicU64 = AtomicU64::new(0);

fn next_cache_id() -> u64 {
    NEXT_CACHE_ID.fetch_add(1, Ordering::Relaxed)
}

fn water_noise_of(materials: &[Material]) -> Vec<Option<GradientNoise>> {
    materials
        .iter()
        .map(|m| m.water.map(|w| GradientNoise::new(w.seed)))
        .collect()
}

/// The artificial triangles split into glass panes and opaque ones (BVHs over each; `opaque`
/// is `None` when every artificial triangle is glass).
#[derive(Debug, Clone)]
pub(super) struct GlassSplit {
    pub(super) glass: SceneTracer,
    pub(super) opaque: Option<SceneTracer>,
}

/// The triangles of `scene` whose object is of `kind` (and, with `glass`, whose material is or
/// is not glass), as one object; material ids are kept (the materials are copied in order, so
/// a hit's material id means the same in both scenes).
fn sub_scene(scene: &Scene, kind: ObjectKind, glass: Option<bool>) -> Scene {
    let is_glass = |material: u32| {
        scene
            .materials()
            .get(material as usize)
            .is_some_and(|m| m.glass.is_some())
    };
    let (triangles, triangle_materials): (Vec<[Point3<f64>; 3]>, Vec<u32>) = scene
        .triangles()
        .iter()
        .filter(|t| {
            scene
                .objects()
                .get(t.object.0 as usize)
                .is_some_and(|o| o.kind == kind)
                && glass.is_none_or(|g| is_glass(t.material.0) == g)
        })
        .map(|t| (t.vertices_in_world_m, t.material.0))
        .unzip();
    let model = ImportedModel {
        triangle_materials,
        triangles_in_world_m: triangles,
        materials: scene.materials().to_vec(),
        warnings: vec![],
    };
    let mut out = Scene::new();
    // A fresh scene cannot overflow its ids with the triangles of an existing one.
    let _ = out.add_model(&model, "part", kind);
    out
}

impl<'a> DifferentialTracer<'a> {
    /// Builds the three BVHs. `photo_linear` is the current photo as linear RGB, the size of the
    /// camera's image.
    ///
    /// # Errors
    /// [`DifferentialError::NoArtificialObject`] or a BVH build error.
    pub fn new(
        scene: &'a Scene,
        lighting: &'a Lighting,
        camera: &'a Camera,
        photo_linear: &'a Rgb32FImage,
        max_depth: u32,
    ) -> Result<Self, DifferentialError> {
        let artificial_scene = sub_scene(scene, ObjectKind::Artificial, None);
        let Some(artificial_bounds_in_world_m) = artificial_scene.bounding_box_in_world_m() else {
            return Err(DifferentialError::NoArtificialObject);
        };
        let glass_scene = sub_scene(scene, ObjectKind::Artificial, Some(true));
        let artificial_split = if glass_scene.triangles().is_empty() {
            None
        } else {
            let opaque_scene = sub_scene(scene, ObjectKind::Artificial, Some(false));
            Some(GlassSplit {
                glass: SceneTracer::new(&glass_scene, BuildQuality::Medium)?,
                opaque: if opaque_scene.triangles().is_empty() {
                    None
                } else {
                    Some(SceneTracer::new(&opaque_scene, BuildQuality::Medium)?)
                },
            })
        };
        let natural_scene = sub_scene(scene, ObjectKind::Natural, None);
        let natural = if natural_scene.triangles().is_empty() {
            None
        } else {
            Some(SceneTracer::new(&natural_scene, BuildQuality::Medium)?)
        };
        Ok(Self {
            scene,
            all: SceneTracer::new(scene, BuildQuality::Medium)?,
            natural,
            artificial: SceneTracer::new(&artificial_scene, BuildQuality::Medium)?,
            artificial_split,
            artificial_bounds_in_world_m,
            lighting,
            camera,
            photo_linear,
            max_depth,
            materials: scene.materials(),
            water_noise: water_noise_of(scene.materials()),
            irradiance_cache: Some(IrradianceCacheSettings::default()),
            cache_id: next_cache_id(),
        })
    }

    /// The same geometry (BVHs cloned, not rebuilt) with other lights, photo and materials
    /// (`materials` indexed like the scene's): the spectral mode's per-band passes.
    #[must_use]
    pub fn with_inputs<'b>(
        &self,
        lighting: &'b Lighting,
        photo_linear: &'b Rgb32FImage,
        materials: &'b [Material],
    ) -> DifferentialTracer<'b>
    where
        'a: 'b,
    {
        DifferentialTracer {
            scene: self.scene,
            all: self.all.clone(),
            natural: self.natural.clone(),
            artificial: self.artificial.clone(),
            artificial_split: self.artificial_split.clone(),
            artificial_bounds_in_world_m: self.artificial_bounds_in_world_m,
            lighting,
            camera: self.camera,
            photo_linear,
            max_depth: self.max_depth,
            materials,
            water_noise: water_noise_of(materials),
            irradiance_cache: self.irradiance_cache,
            cache_id: next_cache_id(),
        }
    }

    /// Sets the irradiance caching of the gathers (`None`: every gather traced; default: on
    /// with [`IrradianceCacheSettings::default`]). It only acts inside a render's tiles.
    pub fn set_irradiance_cache(&mut self, settings: Option<IrradianceCacheSettings>) {
        self.irradiance_cache = settings;
    }

    /// The irradiance cache settings (`None` when off).
    #[must_use]
    pub fn irradiance_cache(&self) -> Option<IrradianceCacheSettings> {
        self.irradiance_cache
    }

    /// The material of a hit (`None` for an unknown id).
    pub(super) fn material_of(&self, hit: &SceneHit) -> Option<&'a Material> {
        self.materials.get(hit.material.0 as usize)
    }

    /// The scene this tracer traces.
    #[must_use]
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// The lighting of this tracer.
    #[must_use]
    pub fn lighting(&self) -> &'a Lighting {
        self.lighting
    }

    /// The mirror / glass / glossy recursion depth limit.
    #[must_use]
    pub fn max_depth(&self) -> u32 {
        self.max_depth
    }

    /// The current photo, linear RGB.
    #[must_use]
    pub fn photo(&self) -> &'a Rgb32FImage {
        self.photo_linear
    }

    /// The current camera.
    #[must_use]
    pub fn camera(&self) -> &'a Camera {
        self.camera
    }

    /// The artificial objects' bounding box, world frame.
    #[must_use]
    pub fn artificial_bounds_in_world_m(&self) -> [Point3<f64>; 2] {
        self.artificial_bounds_in_world_m
    }
}

/// Bilinear lookup in pixel-centre coordinates, clamped at the borders.
#[must_use]
pub fn bilinear(image: &Rgb32FImage, pixel: Point2<f64>) -> Rgb {
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 {
        return [0.0; 3];
    }
    let max_x = f64::from(w - 1);
    let max_y = f64::from(h - 1);
    let x = pixel.x.clamp(0.0, max_x);
    let y = pixel.y.clamp(0.0, max_y);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (x0, y0) = (x.floor() as u32, y.floor() as u32);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - f64::from(x0), y - f64::from(y0));
    let p = |x: u32, y: u32| image.get_pixel(x, y).0.map(f64::from);
    let (a, b, c, d) = (p(x0, y0), p(x1, y0), p(x0, y1), p(x1, y1));
    [0, 1, 2].map(|k| {
        (a[k] * (1.0 - fx) + b[k] * fx) * (1.0 - fy) + (c[k] * (1.0 - fx) + d[k] * fx) * fy
    })
}
