//! One-bounce interreflection of the differential tracer (see the module doc of [`super`]):
//! gathers over the facets of [`super::Lighting::photo_bounce_dome`] that bring the photographed
//! surroundings' radiance onto artificial points (Durisch 1992 §6.2, the secondary ray of case D,
//! the photo standing for the true colour), the light artificial objects reflect onto natural
//! points, and the natural interreflection before and after the artificial objects arrive;
//! inside a render each gather goes through the tile's irradiance cache
//! ([`crate::render::irradiance_cache`], Ward 1988).
//!
//! # Known limitations
//! One bounce on a fixed facet set (quantisation error rather than noise); see [`super`].

use nalgebra::{Point3, Vector3};

use super::{DifferentialTracer, SURFACE_OFFSET_M, bilinear};
use crate::render::illumination::{
    Rgb, add, diffuse_radiance_rgb, diffuse_reflectance_from_true_colour, mul,
    natural_irradiance_rgb, natural_irradiance_weighted_rgb, scale,
};
use crate::render::irradiance_cache::{GatherKind, MeanDistance, cached_gather};
use crate::scene::{ObjectKind, SceneHit, SceneTracer};

impl DifferentialTracer<'_> {
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
    pub(super) fn cached_photo_bounce(
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
    pub(super) fn natural_point_gathers(
        &self,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> [Rgb; 3] {
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
    pub(super) fn photo_colour_of(&self, point: &Point3<f64>) -> Option<(Rgb, f64)> {
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
