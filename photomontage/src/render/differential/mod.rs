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
use nalgebra::{Point2, Point3, Vector3};

pub mod glass;
pub mod specular;

use super::illumination::{
    Daylight, DistantLight, Rgb, add, diffuse_radiance_rgb, diffuse_reflectance_from_true_colour,
    mul, natural_irradiance_rgb, natural_irradiance_weighted_rgb, scale,
};
use super::irradiance_cache::{GatherKind, IrradianceCacheSettings, MeanDistance, cached_gather};
use super::luminaire_light::ArtificialLight;
use super::water::shading_normal;
use crate::atmosphere::schachter::SchachterAtmosphere;
use crate::bvh::BuildQuality;
use crate::camera::Camera;
use crate::colour::Colour;
use crate::scene::material::GradientNoise;
use crate::scene::{ImportedModel, Material, ObjectKind, Scene, SceneError, SceneHit, SceneTracer};
use glass::PhotoBehind;
use specular::{SurfaceFrame, reflect_above};

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

    /// Traces a primary ray through a sample of the pixel whose photo value is `photo_pixel_rgb`
    /// (the reconstructed image function at the sample, box reconstruction).
    #[must_use]
    pub fn trace_primary(&self, dir_in_world: &Vector3<f64>, photo_pixel_rgb: Rgb) -> RaySample {
        let origin = self.camera.pose.camera_center_in_world;
        let ray = self
            .all
            .ray_from_world(&origin, dir_in_world, 0.0, f32::INFINITY);
        match self.all.closest_hit(&ray) {
            None => self.case_a_primary_miss(photo_pixel_rgb),
            Some(hit) => {
                let point = self.all.hit_point_in_world_m(&ray, hit.hit.t);
                let d = f64::from(hit.hit.t);
                let first_hit = Some(PrimaryHit {
                    distance_m: d,
                    object: hit.object,
                });
                match hit.kind {
                    ObjectKind::Artificial => RaySample {
                        radiance_rgb: self.case_c_shade(
                            &hit,
                            &point,
                            dir_in_world,
                            d,
                            0,
                            Some(PhotoBehind::at_camera(photo_pixel_rgb)),
                        ),
                        changed: true,
                        hit_artificial: true,
                        first_hit,
                    },
                    ObjectKind::Natural => {
                        let (radiance_rgb, changed) = self.case_d_natural_hit(
                            &hit,
                            &point,
                            dir_in_world,
                            photo_pixel_rgb,
                            d,
                            d,
                        );
                        RaySample {
                            radiance_rgb,
                            changed,
                            hit_artificial: false,
                            first_hit,
                        }
                    }
                }
            }
        }
    }

    /// Case A: a primary ray hits nothing; the photo is returned.
    #[must_use]
    pub fn case_a_primary_miss(&self, photo_pixel_rgb: Rgb) -> RaySample {
        RaySample {
            radiance_rgb: photo_pixel_rgb,
            changed: false,
            hit_artificial: false,
            first_hit: None,
        }
    }

    /// Case B: a secondary ray hits nothing; the horizon colour above the horizon, black below.
    #[must_use]
    pub fn case_b_secondary_miss(&self, dir_in_world: &Vector3<f64>) -> Rgb {
        if dir_in_world.z > 0.0 {
            self.lighting.horizon_rgb
        } else {
            [0.0; 3]
        }
    }

    pub(super) fn normal_facing(
        &self,
        hit: &SceneHit,
        dir_in_world: &Vector3<f64>,
    ) -> Vector3<f64> {
        let n = self
            .scene
            .triangles()
            .get(hit.hit.triangle_id as usize)
            .map_or_else(Vector3::z, |t| {
                let [a, b, c] = t.vertices_in_world_m;
                (b - a).cross(&(c - a)).normalize()
            });
        if n.dot(dir_in_world) > 0.0 { -n } else { n }
    }

    pub(super) fn blocked_by(
        tracer: &SceneTracer,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        t_max: f64,
    ) -> bool {
        #[allow(clippy::cast_possible_truncation)]
        let t_max = t_max as f32;
        tracer.any_hit(&tracer.ray_from_world(origin, dir, 0.0, t_max))
    }

    /// Whether the ray `origin + t·dir` can meet the artificial bounding box for t in [0, t_max].
    pub(super) fn may_hit_artificial(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        t_max: f64,
    ) -> bool {
        let [lo, hi] = self.artificial_bounds_in_world_m;
        let (mut t0, mut t1) = (0.0_f64, t_max);
        for k in 0..3 {
            let inv = 1.0 / dir[k];
            let (mut a, mut b) = ((lo[k] - origin[k]) * inv, (hi[k] - origin[k]) * inv);
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            // NaN (0·∞ for a ray in the slab's plane) compares false and keeps the interval.
            if a > t0 {
                t0 = a;
            }
            if b < t1 {
                t1 = b;
            }
            if t0 > t1 {
                return false;
            }
        }
        true
    }

    /// The BVH over all geometry.
    pub(super) fn all_tracer(&self) -> &SceneTracer {
        &self.all
    }

    /// The BVH over the artificial geometry (panes included).
    pub(super) fn artificial_tracer(&self) -> &SceneTracer {
        &self.artificial
    }

    pub(super) fn natural_blocks(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        t_max: f64,
    ) -> bool {
        self.natural
            .as_ref()
            .is_some_and(|n| Self::blocked_by(n, origin, dir, t_max))
    }

    /// Fraction of the sun reaching the offset point `origin` of a surface with geometric
    /// `normal` (zero from behind or without a sun); see [`Self::light_transmittance`].
    fn sun_transmittance(&self, origin: &Point3<f64>, normal: &Vector3<f64>) -> Rgb {
        self.lighting
            .daylight
            .sun
            .as_ref()
            .filter(|s| s.dir_in_world.dot(normal) > 0.0)
            .map_or([0.0; 3], |s| {
                self.light_transmittance(origin, &s.dir_in_world, f64::INFINITY)
            })
    }

    /// The artificial lights that reach the surface point `point` (in front of the geometric
    /// `normal`; shadow ray from the offset point `origin` by any-hit against everything): unit
    /// direction towards each and its irradiance at `point` on a surface facing it, `I(−dir)/d²`
    /// (inverse-square law).
    pub(super) fn visible_artificial_lights(
        &self,
        point: &Point3<f64>,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> Vec<(Vector3<f64>, Rgb)> {
        let mut out = Vec::new();
        for light in &self.lighting.artificial_lights {
            let to_light = light.position_in_world_m() - origin;
            let dist = to_light.norm();
            if dist <= SURFACE_OFFSET_M || to_light.dot(normal) <= 0.0 {
                continue;
            }
            let dir = to_light / dist;
            let passed = self.light_transmittance(origin, &dir, dist - SURFACE_OFFSET_M);
            if passed.iter().any(|&x| x > 0.0) {
                let to_light_from_point = light.position_in_world_m() - point;
                let dir_from_point = to_light_from_point.try_normalize(0.0).unwrap_or(dir);
                out.push((
                    dir_from_point,
                    mul(light.normal_irradiance_rgb(point), passed),
                ));
            }
        }
        out
    }

    /// Irradiance from the artificial lights `visible` on a surface of unit (shading) normal
    /// `normal` (cosine law); also says whether any light reaches the point.
    fn artificial_light_irradiance(
        visible: &[(Vector3<f64>, Rgb)],
        normal: &Vector3<f64>,
    ) -> (Rgb, bool) {
        let mut e = [0.0; 3];
        for (dir, e_normal) in visible {
            e = add(e, scale(*e_normal, dir.dot(normal).max(0.0)));
        }
        (e, !visible.is_empty())
    }

    fn transmission(&self, distance_m: f64) -> Rgb {
        self.lighting.atmosphere.as_ref().map_or([1.0; 3], |a| {
            let t = a.transmission(distance_m);
            [0, 1, 2].map(|k| f64::from(t.channels[k]))
        })
    }

    /// Eq. 2 forward: apparent colour of a true colour seen over `distance_m`.
    fn apparent(&self, true_rgb: Rgb, distance_m: f64) -> Rgb {
        let t = self.transmission(distance_m);
        let horizon = self.lighting.atmosphere.as_ref().map_or([0.0; 3], |a| {
            [0, 1, 2].map(|k| f64::from(a.horizon().channels[k]))
        });
        [0, 1, 2].map(|k| true_rgb[k] * t[k] + horizon[k] * (1.0 - t[k]))
    }

    /// Eq. 8: true colour from an apparent colour seen over `distance_m` (unchanged when there
    /// is no atmosphere or the inversion is refused).
    fn true_colour(&self, apparent_rgb: Rgb, distance_m: f64) -> Rgb {
        let Some(a) = &self.lighting.atmosphere else {
            return apparent_rgb;
        };
        #[allow(clippy::cast_possible_truncation)]
        let c = Colour::from_slice(&apparent_rgb.map(|x| x as f32));
        a.true_colour(&c, distance_m).map_or(apparent_rgb, |t| {
            [0, 1, 2].map(|k| f64::from(t.channels[k]))
        })
    }

    /// Case C: an artificial object at `point` (hit at distance `distance_m` along a ray of
    /// direction `dir_in_world`, recursion depth `depth`). Returns the apparent radiance.
    #[must_use]
    pub fn case_c_artificial_hit(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
        depth: u32,
    ) -> Rgb {
        self.case_c_shade(hit, point, dir_in_world, distance_m, depth, None)
    }

    /// Case C with, for a ray still on the camera's line of sight (`behind` given), the photo's
    /// value at that pixel as what a glass pane lets through from behind.
    pub(super) fn case_c_shade(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
        depth: u32,
        behind: Option<PhotoBehind>,
    ) -> Rgb {
        let normal = self.normal_facing(hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let material = self.material_of(hit);
        let noise = self
            .water_noise
            .get(hit.material.0 as usize)
            .and_then(Option::as_ref);
        let shading_normal = shading_normal(material, noise, point, &normal, dir_in_world);
        let rho = material.map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb);
        let daylight = &self.lighting.daylight;
        let sun_passed = self.sun_transmittance(&origin, &normal);
        let e_natural =
            natural_irradiance_weighted_rgb(daylight, &shading_normal, sun_passed, |i| {
                self.light_transmittance(&origin, &daylight.sky[i].dir_in_world, f64::INFINITY)
            });
        let lights = self.visible_artificial_lights(point, &origin, &normal);
        let mut e = add(
            e_natural,
            Self::artificial_light_irradiance(&lights, &shading_normal).0,
        );
        if depth < self.max_depth {
            e = add(
                e,
                self.cached_photo_bounce(GatherKind::ArtificialPoint, &origin, &shading_normal),
            );
        }
        let mut l0 = diffuse_radiance_rgb(rho, e);
        if let Some(m) = material {
            if let Some(emission) = m.emission_rgb_w_m2_sr {
                l0 = add(l0, emission);
            }
            if let (Some(mirror), true) = (m.mirror_rgb, depth < self.max_depth) {
                let reflected = reflect_above(dir_in_world, &shading_normal, &normal);
                let incoming = self.trace_secondary(&origin, &reflected, depth + 1);
                l0 = add(l0, mul(mirror, incoming));
            }
            if let Some(spec) = &m.specular {
                let frame = SurfaceFrame {
                    origin: &origin,
                    normal: &normal,
                    shading_normal: &shading_normal,
                };
                // The sun as it reaches the point (through panes: attenuated).
                let sun = daylight
                    .sun
                    .filter(|_| sun_passed.iter().any(|&x| x > 0.0))
                    .map(|s| DistantLight {
                        normal_irradiance_rgb: mul(s.normal_irradiance_rgb, sun_passed),
                        ..s
                    });
                l0 = add(
                    l0,
                    self.specular_radiance(
                        spec,
                        &frame,
                        dir_in_world,
                        sun.as_ref(),
                        &lights,
                        depth,
                    ),
                );
            }
            if let (Some(glass), true) = (&m.glass, depth < self.max_depth) {
                let behind = behind.map(|b| PhotoBehind {
                    camera_distance_m: b.camera_distance_m + distance_m,
                    ..b
                });
                l0 = add(
                    l0,
                    self.glass_radiance(
                        glass,
                        point,
                        &normal,
                        &shading_normal,
                        dir_in_world,
                        depth,
                        behind,
                    ),
                );
            }
        }
        self.apparent(l0, distance_m)
    }

    /// Case D: a natural object at `point`, hit along `dir_in_world` at `distance_m` from the ray
    /// origin, whose apparent colour `photo_rgb` was photographed from `photo_distance_m`.
    /// Returns the apparent radiance along the ray and whether it differs from the photo.
    #[must_use]
    pub fn case_d_natural_hit(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        photo_rgb: Rgb,
        photo_distance_m: f64,
        distance_m: f64,
    ) -> (Rgb, bool) {
        let normal = self.normal_facing(hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let daylight = &self.lighting.daylight;
        let inf = f64::INFINITY;

        // D3 candidates: natural lights that an artificial object blocks (and no natural one),
        // with the fraction per channel it takes (1 when opaque, 1 − Π T_pane through panes).
        let blocked_fraction = |d: &Vector3<f64>| -> Option<Rgb> {
            if d.dot(&normal) <= 0.0 {
                return None;
            }
            let passed = self.artificial_transmittance(&origin, d, inf);
            (passed.iter().any(|&x| x < 1.0) && !self.natural_blocks(&origin, d, inf))
                .then(|| passed.map(|x| 1.0 - x))
        };
        let sun_d3 = daylight
            .sun
            .as_ref()
            .and_then(|s| blocked_fraction(&s.dir_in_world));
        let sky_d3: Vec<(usize, Rgb)> = (0..daylight.sky.len())
            .filter_map(|i| blocked_fraction(&daylight.sky[i].dir_in_world).map(|b| (i, b)))
            .collect();
        // D1: artificial lights add.
        let (e_d1, lit_d1) = Self::artificial_light_irradiance(
            &self.visible_artificial_lights(point, &origin, &normal),
            &normal,
        );
        let unchanged = sun_d3.is_none() && sky_d3.is_empty() && !lit_d1;
        if unchanged {
            // D2 only: the natural light is already in the photo.
            if photo_distance_m.to_bits() == distance_m.to_bits() {
                return (photo_rgb, false);
            }
            let l0 = self.true_colour(photo_rgb, photo_distance_m);
            return (self.apparent(l0, distance_m), false);
        }
        // Second inversions: atmosphere (eq. 8), then illumination (eq. 10) with the natural
        // irradiance as if there were no artificial objects.
        let l0 = self.true_colour(photo_rgb, photo_distance_m);
        let sun_natural = daylight.sun.as_ref().is_some_and(|s| {
            s.dir_in_world.dot(&normal) > 0.0 && !self.natural_blocks(&origin, &s.dir_in_world, inf)
        });
        let e_natural = natural_irradiance_rgb(daylight, &normal, sun_natural, |i| {
            !self.natural_blocks(&origin, &daylight.sky[i].dir_in_world, inf)
        });
        // Light the photographed surroundings reflect onto the point, before and after the
        // artificial objects arrive (they block some of it and shade the surfaces it comes from).
        let [e_inter_before, e_inter_after, e_reflected] =
            self.natural_point_gathers(&origin, &normal);
        let e_natural = add(e_natural, e_inter_before);
        let Some(rho) = diffuse_reflectance_from_true_colour(l0, e_natural) else {
            // No natural light reaches the point: nothing to remove; D1 needs ρ_d from the
            // material library.
            let rho = self
                .material_of(hit)
                .map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb);
            let delta = diffuse_radiance_rgb(rho, e_d1);
            return self.changed_apparent(photo_rgb, l0, delta, photo_distance_m, distance_m);
        };
        // D3: the blocked natural irradiance, negated.
        let mut e_d3 = [0.0; 3];
        if let (Some(blocked), Some(s)) = (sun_d3, &daylight.sun) {
            e_d3 = add(e_d3, mul(s.irradiance_rgb(&normal), blocked));
        }
        for &(i, blocked) in &sky_d3 {
            e_d3 = add(e_d3, mul(daylight.sky[i].irradiance_rgb(&normal), blocked));
        }
        // D1 for the light the artificial objects reflect onto the point: `e_reflected`.
        let e_inter_change = add(e_inter_after, scale(e_inter_before, -1.0));
        let delta = diffuse_radiance_rgb(
            rho,
            add(
                add(add(e_d1, e_reflected), scale(e_d3, -1.0)),
                e_inter_change,
            ),
        );
        self.changed_apparent(photo_rgb, l0, delta, photo_distance_m, distance_m)
    }

    /// The apparent colour after adding `delta` to the true colour `l0`: along the photo's own
    /// line of sight `L_photo + τ(d)·ΔL₀` (eq. 2 is affine), otherwise eq. 2 at `distance_m`.
    fn changed_apparent(
        &self,
        photo_rgb: Rgb,
        l0: Rgb,
        delta: Rgb,
        photo_distance_m: f64,
        distance_m: f64,
    ) -> (Rgb, bool) {
        if photo_distance_m.to_bits() == distance_m.to_bits() {
            let t = self.transmission(distance_m);
            (add(photo_rgb, mul(t, delta)), true)
        } else {
            (self.apparent(add(l0, delta), distance_m), true)
        }
    }

    /// The closest hit of the ray `origin + t·dir` (`dir` unit), its point and distance.
    pub(super) fn closest_hit_from(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
    ) -> Option<(SceneHit, Point3<f64>, f64)> {
        let ray = self.all.ray_from_world(origin, dir, 0.0, f32::INFINITY);
        let hit = self.all.closest_hit(&ray)?;
        let point = self.all.hit_point_in_world_m(&ray, hit.hit.t);
        let t = f64::from(hit.hit.t);
        Some((hit, point, t))
    }

    /// A secondary ray (reflection) from `origin` along `dir`, at recursion depth `depth`.
    #[must_use]
    pub fn trace_secondary(&self, origin: &Point3<f64>, dir: &Vector3<f64>, depth: u32) -> Rgb {
        let dir = dir.normalize();
        let ray = self.all.ray_from_world(origin, &dir, 0.0, f32::INFINITY);
        let Some(hit) = self.all.closest_hit(&ray) else {
            return self.case_b_secondary_miss(&dir);
        };
        let point = self.all.hit_point_in_world_m(&ray, hit.hit.t);
        let d = f64::from(hit.hit.t);
        match hit.kind {
            ObjectKind::Artificial => self.case_c_artificial_hit(&hit, &point, &dir, d, depth),
            ObjectKind::Natural => match self.photo_colour_of(&point) {
                Some((photo_rgb, photo_distance_m)) => {
                    self.case_d_natural_hit(&hit, &point, &dir, photo_rgb, photo_distance_m, d)
                        .0
                }
                None => {
                    // Not visible in the photo: shade its library material by eq. 6.
                    self.case_c_artificial_hit(&hit, &point, &dir, d, self.max_depth)
                }
            },
        }
    }

    /// Irradiance at an artificial point from natural surfaces, their radiance taken from the
    /// photo (see [`Lighting::photo_bounce_dome`]).
    fn photo_bounce_irradiance(
        &self,
        dome: Option<&crate::sky_dome::SkyDome>,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
        distances: &mut MeanDistance,
    ) -> Rgb {
        let Some(dome) = dome else {
            return [0.0; 3];
        };
        self.gather_over_dome(
            &self.all,
            dome,
            origin,
            normal,
            ObjectKind::Natural,
            |_| true,
            |hit, point, dir, t| self.natural_radiance_for_bounce(hit, point, dir, t),
            distances,
        )
    }

    /// [`Self::photo_bounce_irradiance`] over the main (`ArtificialPoint`) or nested
    /// (`ArtificialNested`) dome, through the tile's irradiance cache.
    fn cached_photo_bounce(
        &self,
        kind: GatherKind,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> Rgb {
        let dome = match kind {
            GatherKind::ArtificialNested => self.lighting.photo_bounce_nested_dome.as_ref(),
            _ => self.lighting.photo_bounce_dome.as_ref(),
        };
        if dome.is_none() {
            return [0.0; 3];
        }
        let compute = || {
            let mut distances = MeanDistance::default();
            let e = self.photo_bounce_irradiance(dome, origin, normal, &mut distances);
            ([e, [0.0; 3], [0.0; 3]], distances)
        };
        self.cached(kind, origin, normal, compute)[0]
    }

    /// The gathers at a changed natural point (`origin`, unit `normal`), through the tile's
    /// irradiance cache: interreflection before and after the artificial objects arrive
    /// ([`Self::natural_interreflection`]) and the light the artificial objects reflect onto it
    /// ([`Self::artificial_bounce_irradiance`]).
    fn natural_point_gathers(&self, origin: &Point3<f64>, normal: &Vector3<f64>) -> [Rgb; 3] {
        if self.lighting.photo_bounce_dome.is_none() {
            return [[0.0; 3]; 3];
        }
        let compute = || {
            let mut distances = MeanDistance::default();
            let (before, after) = self.natural_interreflection(origin, normal, &mut distances);
            let reflected = self.artificial_bounce_irradiance(origin, normal, &mut distances);
            ([before, after, reflected], distances)
        };
        self.cached(GatherKind::NaturalPoint, origin, normal, compute)
    }

    /// `compute` through the tile cache when caching is on.
    fn cached(
        &self,
        kind: GatherKind,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
        compute: impl FnOnce() -> ([Rgb; 3], MeanDistance),
    ) -> [Rgb; 3] {
        let Some(settings) = &self.irradiance_cache else {
            return compute().0;
        };
        let footprint_m = (origin - self.camera.pose.camera_center_in_world).norm()
            / self.camera.intrinsics.focal_px;
        cached_gather(
            settings,
            self.cache_id,
            kind,
            origin,
            normal,
            footprint_m,
            compute,
        )
    }

    /// Irradiance at `origin` gathered over the facets of `dome` and their mirror images below
    /// the horizon: each direction with a positive cosine that `worth_tracing` admits is traced,
    /// and the first hit, if it is of `kind`, contributes `radiance · cos · solid angle`. Each
    /// traced ray's hit distance goes into `distances` (the irradiance cache's record radius).
    #[allow(clippy::too_many_arguments)]
    fn gather_over_dome(
        &self,
        tracer: &SceneTracer,
        dome: &crate::sky_dome::SkyDome,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
        kind: ObjectKind,
        worth_tracing: impl Fn(&Vector3<f64>) -> bool,
        radiance: impl Fn(&SceneHit, &Point3<f64>, &Vector3<f64>, f64) -> Rgb,
        distances: &mut MeanDistance,
    ) -> Rgb {
        let mut e = [0.0; 3];
        for facet in &dome.facets {
            let up = facet.centre_dir_in_world;
            let down = Vector3::new(up.x, up.y, -up.z);
            for dir in [up, down] {
                let cos = dir.dot(normal);
                if cos <= 0.0 || !worth_tracing(&dir) {
                    continue;
                }
                let ray = tracer.ray_from_world(origin, &dir, 0.0, f32::INFINITY);
                let Some(hit) = tracer.closest_hit(&ray) else {
                    distances.add(f64::INFINITY);
                    continue;
                };
                distances.add(f64::from(hit.hit.t));
                if hit.kind != kind {
                    continue;
                }
                let point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
                let l = radiance(&hit, &point, &dir, f64::from(hit.hit.t));
                e = add(e, scale(l, cos * facet.solid_angle_sr));
            }
        }
        e
    }

    /// Irradiance at a natural point from light reflected by artificial objects, gathered over
    /// the facets of [`Lighting::photo_bounce_dome`] (upper and mirrored lower hemisphere).
    fn artificial_bounce_irradiance(
        &self,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
        distances: &mut MeanDistance,
    ) -> Rgb {
        let Some(dome) = &self.lighting.photo_bounce_dome else {
            return [0.0; 3];
        };
        self.gather_over_dome(
            &self.all,
            dome,
            origin,
            normal,
            ObjectKind::Artificial,
            |dir| self.may_hit_artificial(origin, dir, f64::INFINITY),
            |hit, point, dir, t| self.artificial_radiance_for_bounce(hit, point, dir, t),
            distances,
        )
    }

    /// Radiance leaving an artificial point towards a gather ray: eq. 6 with the sun's
    /// visibility traced and the sky facets facing the surface taken as visible (one bounce
    /// only: no further gather), then eq. 2 over `distance_m`.
    fn artificial_radiance_for_bounce(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
    ) -> Rgb {
        let normal = self.normal_facing(hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let daylight = &self.lighting.daylight;
        let rho = self
            .material_of(hit)
            .map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb);
        let sun_passed = self.sun_transmittance(&origin, &normal);
        let e = add(
            natural_irradiance_weighted_rgb(daylight, &normal, sun_passed, |_| [1.0; 3]),
            self.cached_photo_bounce(GatherKind::ArtificialNested, &origin, &normal),
        );
        self.apparent(diffuse_radiance_rgb(rho, e), distance_m)
    }

    /// Radiance leaving a natural point towards a gather ray: the photo's true colour, with the
    /// sun removed where only an artificial object blocks it (case D3 for the sun; sky
    /// visibility at the point is taken as unobstructed for the inversion), then eq. 2 over
    /// `distance_m`. Points not seen in the photo are shaded by their library material.
    fn natural_radiance_for_bounce(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
    ) -> Rgb {
        self.natural_radiance_towards(hit, point, dir_in_world, distance_m, true)
    }

    /// Irradiance at a natural point (`origin` offset along its unit `normal`) from the natural
    /// surfaces around it, their radiance taken from the photo, over
    /// [`Lighting::photo_bounce_dome`]: `(before, after)` the artificial objects arrive. Before:
    /// traced against the natural geometry, the photo's radiance as is (it is in the photo, so
    /// it belongs in the denominator of the eq. 10 inversion). After: traced against all
    /// geometry (artificial objects block some directions) with the surfaces' radiance less the
    /// sun the artificial objects take from them. Both zero without a dome.
    fn natural_interreflection(
        &self,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
        distances: &mut MeanDistance,
    ) -> (Rgb, Rgb) {
        let (Some(dome), Some(natural)) = (&self.lighting.photo_bounce_dome, &self.natural) else {
            return ([0.0; 3], [0.0; 3]);
        };
        let before = self.gather_over_dome(
            natural,
            dome,
            origin,
            normal,
            ObjectKind::Natural,
            |_| true,
            |hit, point, dir, t| self.natural_radiance_towards(hit, point, dir, t, false),
            distances,
        );
        let after = self.photo_bounce_irradiance(Some(dome), origin, normal, distances);
        (before, after)
    }

    /// Radiance leaving a natural point towards a gather ray; with `with_artificial` the sun
    /// blocked only by artificial objects is removed (case D3 at the bounce), without it the
    /// radiance is the photo's (the scene before the artificial objects).
    fn natural_radiance_towards(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
        with_artificial: bool,
    ) -> Rgb {
        let normal = self.normal_facing(hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let daylight = &self.lighting.daylight;
        let sun_natural = daylight.sun.as_ref().is_some_and(|s| {
            s.dir_in_world.dot(&normal) > 0.0
                && !self.natural_blocks(&origin, &s.dir_in_world, f64::INFINITY)
        });
        let e_natural = natural_irradiance_rgb(daylight, &normal, sun_natural, |_| true);
        let l0 = match self.photo_colour_of(point) {
            Some((photo_rgb, photo_distance_m)) => {
                let l0 = self.true_colour(photo_rgb, photo_distance_m);
                // The fraction of the sun the artificial objects take (D3 at the bounce).
                let sun_d3 = daylight
                    .sun
                    .as_ref()
                    .filter(|_| with_artificial && sun_natural)
                    .map(|s| {
                        let passed =
                            self.artificial_transmittance(&origin, &s.dir_in_world, f64::INFINITY);
                        (s, passed.map(|x| 1.0 - x))
                    })
                    .filter(|(_, blocked)| blocked.iter().any(|&x| x > 0.0));
                match sun_d3 {
                    Some((s, blocked)) => diffuse_reflectance_from_true_colour(l0, e_natural)
                        .map_or(l0, |rho| {
                            let e_blocked = mul(s.irradiance_rgb(&normal), blocked);
                            add(l0, scale(diffuse_radiance_rgb(rho, e_blocked), -1.0))
                        }),
                    None => l0,
                }
            }
            None => {
                let rho = self
                    .material_of(hit)
                    .map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb);
                let sun_passed = match (&daylight.sun, sun_natural, with_artificial) {
                    (Some(s), true, true) => {
                        self.artificial_transmittance(&origin, &s.dir_in_world, f64::INFINITY)
                    }
                    (Some(_), true, false) => [1.0; 3],
                    _ => [0.0; 3],
                };
                diffuse_radiance_rgb(
                    rho,
                    natural_irradiance_weighted_rgb(daylight, &normal, sun_passed, |_| [1.0; 3]),
                )
            }
        };
        self.apparent(l0, distance_m)
    }

    /// The photo's colour (bilinear) at a world point and its distance from the camera, when the
    /// point is seen in the photo (projects inside and is not hidden by other geometry).
    fn photo_colour_of(&self, point: &Point3<f64>) -> Option<(Rgb, f64)> {
        let pixel = self.camera.project(point)?;
        if !self.camera.intrinsics.contains(pixel) {
            return None;
        }
        let centre = self.camera.pose.camera_center_in_world;
        let to_point = point - centre;
        let dist = to_point.norm();
        // The photo shows no artificial object: visibility against the natural geometry only.
        let natural = self.natural.as_ref()?;
        let ray = natural.ray_from_world(&centre, &to_point, 0.0, f32::INFINITY);
        let hit = natural.closest_hit(&ray)?;
        if (f64::from(hit.hit.t) - dist).abs() > 1e-3 * dist.max(1.0) {
            return None;
        }
        Some((bilinear(self.photo_linear, pixel), dist))
    }

    /// Irradiance at a natural point (`point_in_world_m`, unit `normal_in_world` on the side
    /// looked at) from the natural surfaces around it, their radiance taken from the photo (the
    /// library material shaded by eq. 6 where the photo does not show them), gathered over
    /// [`Lighting::photo_bounce_dome`] against the natural geometry only: the scene as
    /// photographed, the term E_r of the daylight fit ([`crate::fit::daylight`]). Zero without a
    /// dome.
    #[must_use]
    pub fn natural_interreflection_irradiance(
        &self,
        point_in_world_m: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
    ) -> Rgb {
        let origin = point_in_world_m + normal_in_world * SURFACE_OFFSET_M;
        // Exact gather (no cache): the daylight fit calls this outside any render tile.
        let mut distances = MeanDistance::default();
        self.natural_interreflection(&origin, normal_in_world, &mut distances)
            .0
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
