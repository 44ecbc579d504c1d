//! The per-ray cases of Durisch 1992 §6.2 (see the module doc of [`super`]): primary and
//! secondary rays ([`DifferentialTracer::trace_primary`], [`DifferentialTracer::trace_secondary`])
//! and the four cases they dispatch to: A (primary miss), B (secondary miss), C (artificial hit,
//! eq. 6 with mirror, glossy and glass recursion) and D (natural hit: second inversions by eq. 8
//! and eq. 10, then D1/D2/D3).
//!
//! # Known limitations
//! See [`super`]: secondary rays take a natural point's colour from the current photo only.

use nalgebra::{Point3, Vector3};

use super::glass::PhotoBehind;
use super::replay::{ArtificialParts, NaturalParts, SampleReplay};
use super::specular::{SurfaceFrame, reflect_above};
use super::{DifferentialTracer, NaturalRatio, PrimaryHit, RaySample, SURFACE_OFFSET_M};
use crate::render::illumination::{
    DistantLight, Rgb, add, diffuse_radiance_rgb, diffuse_reflectance_from_true_colour, mul,
    natural_irradiance_rgb, natural_irradiance_weighted_rgb, scale,
};
use crate::render::irradiance_cache::GatherKind;
use crate::render::water::shading_normal;
use crate::scene::{ObjectKind, SceneHit};

/// A natural point's photographed apparent colour and the distance it was photographed from.
#[derive(Debug, Clone, Copy)]
struct PhotoSeen {
    rgb: Rgb,
    distance_m: f64,
}

impl DifferentialTracer<'_> {
    /// Traces a primary ray through a sample of the pixel whose photo value is `photo_pixel_rgb`
    /// (the reconstructed image function at the sample, box reconstruction).
    #[must_use]
    pub fn trace_primary(&self, dir_in_world: &Vector3<f64>, photo_pixel_rgb: Rgb) -> RaySample {
        self.trace_primary_with(dir_in_world, photo_pixel_rgb, None)
    }

    /// [`Self::trace_primary`], filling `record` with what a replay needs in the radiosity mode
    /// ([`super::replay`]; left as it is elsewhere).
    pub(super) fn trace_primary_with(
        &self,
        dir_in_world: &Vector3<f64>,
        photo_pixel_rgb: Rgb,
        record: Option<&mut SampleReplay>,
    ) -> RaySample {
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
                            record,
                        ),
                        changed: true,
                        hit_artificial: true,
                        first_hit,
                        natural_ratio: None,
                    },
                    ObjectKind::Natural => {
                        let photo = PhotoSeen {
                            rgb: photo_pixel_rgb,
                            distance_m: d,
                        };
                        let (radiance_rgb, changed, natural_ratio) =
                            self.case_d_parts(&hit, &point, dir_in_world, photo, d, record);
                        RaySample {
                            radiance_rgb,
                            changed,
                            hit_artificial: false,
                            first_hit,
                            natural_ratio,
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
            natural_ratio: None,
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
        self.case_c_shade(hit, point, dir_in_world, distance_m, depth, None, None)
    }

    /// Case C with, for a ray still on the camera's line of sight (`behind` given), the photo's
    /// value at that pixel as what a glass pane lets through from behind; `record` (a primary
    /// ray's) receives the parts a replay evaluates again ([`super::replay`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn case_c_shade(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        distance_m: f64,
        depth: u32,
        behind: Option<PhotoBehind>,
        record: Option<&mut SampleReplay>,
    ) -> Rgb {
        let normal = self.normal_facing(hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let material = self.material_of(hit);
        let noise = self
            .water_noise
            .get(hit.material.0 as usize)
            .and_then(Option::as_ref);
        let shading_normal = shading_normal(material, noise, point, &normal, dir_in_world);
        let daylight = &self.lighting.daylight;
        let sun_passed = self.sun_transmittance(&origin, &normal);
        // Radiosity mode: sky and every bounce from the solution with the artificial objects.
        let radiosity = self.lighting.radiosity.as_deref();
        let at = radiosity.and_then(|r| r.with_artificial.locate_point(point, &normal));
        let e_radiosity = radiosity.zip(at.as_ref()).and_then(|(r, at)| r.with_on(at));
        let lights = self.visible_artificial_lights(point, &origin, &normal);
        let e_lights_rgb = Self::artificial_light_irradiance(&lights, &shading_normal).0;
        // The facet path where the point has no radiosity value.
        let e_traced_rgb = e_radiosity.is_none().then(|| {
            let e_natural =
                natural_irradiance_weighted_rgb(daylight, &shading_normal, sun_passed, |i| {
                    self.light_transmittance(&origin, &daylight.sky[i].dir_in_world, f64::INFINITY)
                });
            let mut e = add(e_natural, e_lights_rgb);
            if depth < self.max_depth {
                e = add(
                    e,
                    self.cached_photo_bounce(GatherKind::ArtificialPoint, &origin, &shading_normal),
                );
            }
            e
        });
        let mut parts = ArtificialParts {
            material: hit.material.0,
            distance_m,
            shading_normal,
            sun_passed,
            e_lights_rgb,
            e_traced_rgb,
            mirror_incoming_rgb: None,
            specular_rgb: None,
            glass_rgb: None,
        };
        if let Some(m) = material {
            if let (Some(_), true) = (m.mirror_rgb, depth < self.max_depth) {
                let reflected = reflect_above(dir_in_world, &shading_normal, &normal);
                parts.mirror_incoming_rgb =
                    Some(self.trace_secondary(&origin, &reflected, depth + 1));
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
                parts.specular_rgb = Some(self.specular_radiance(
                    spec,
                    &frame,
                    dir_in_world,
                    sun.as_ref(),
                    &lights,
                    depth,
                ));
            }
            if let (Some(glass), true) = (&m.glass, depth < self.max_depth) {
                let behind = behind.map(|b| PhotoBehind {
                    camera_distance_m: b.camera_distance_m + distance_m,
                    ..b
                });
                parts.glass_rgb = Some(self.glass_radiance(
                    glass,
                    point,
                    &normal,
                    &shading_normal,
                    dir_in_world,
                    depth,
                    behind,
                ));
            }
        }
        let radiance = self.shade().artificial_radiance(&parts, e_radiosity);
        if let Some(record) = record {
            *record = SampleReplay::Artificial {
                parts: Box::new(parts),
                at: at.filter(|_| e_radiosity.is_some()),
            };
        }
        radiance
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
        let photo = PhotoSeen {
            rgb: photo_rgb,
            distance_m: photo_distance_m,
        };
        let (rgb, changed, _) =
            self.case_d_parts(hit, point, dir_in_world, photo, distance_m, None);
        (rgb, changed)
    }

    /// [`Self::case_d_natural_hit`] with the parts of a changed point's radiance on the photo's
    /// line of sight ([`NaturalRatio`]; `None` elsewhere and in the radiosity mode); `record` (a
    /// primary ray's) receives the parts a replay evaluates again in the radiosity mode
    /// ([`super::replay`]).
    fn case_d_parts(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        dir_in_world: &Vector3<f64>,
        photo: PhotoSeen,
        distance_m: f64,
        record: Option<&mut SampleReplay>,
    ) -> (Rgb, bool, Option<NaturalRatio>) {
        let normal = self.normal_facing(hit, dir_in_world);
        if let Some(radiosity) = self.lighting.radiosity.as_deref()
            && let [Some(at_with), Some(at_without)] = radiosity.locate(point, &normal)
            && let (Some(e_with), Some(e_without)) = (
                radiosity.with_on(&at_with),
                radiosity.without_on(&at_without),
            )
        {
            let parts = self.natural_parts(hit, point, &normal, photo, distance_m);
            let (rgb, changed) =
                self.shade()
                    .natural_radiance(&parts, [e_with, e_without], radiosity);
            if let Some(record) = record {
                *record = SampleReplay::Natural {
                    parts: Box::new(parts),
                    at: [at_with, at_without],
                };
            }
            return (rgb, changed, None);
        }
        let PhotoSeen {
            rgb: photo_rgb,
            distance_m: photo_distance_m,
        } = photo;
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
                return (photo_rgb, false, None);
            }
            let l0 = self.true_colour(photo_rgb, photo_distance_m);
            return (self.apparent(l0, distance_m), false, None);
        }
        // Second inversions: atmosphere (eq. 8), then illumination (eq. 10) with the natural
        // irradiance as if there were no artificial objects.
        let l0 = self.true_colour(photo_rgb, photo_distance_m);
        let e_natural = self.natural_daylight_irradiance(&origin, &normal);
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
            let (rgb, changed) =
                self.changed_apparent(photo_rgb, l0, delta, photo_distance_m, distance_m);
            return (rgb, changed, None);
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
        let e_change = add(
            add(add(e_d1, e_reflected), scale(e_d3, -1.0)),
            e_inter_change,
        );
        let delta = diffuse_radiance_rgb(rho, e_change);
        let ratio = (photo_distance_m.to_bits() == distance_m.to_bits()).then(|| NaturalRatio {
            tau_l0_rgb: mul(self.transmission(distance_m), l0),
            e_natural_rgb: e_natural,
            e_change_rgb: e_change,
        });
        let (rgb, changed) =
            self.changed_apparent(photo_rgb, l0, delta, photo_distance_m, distance_m);
        (rgb, changed, ratio)
    }

    /// The daylight at a natural point as photographed (eq. 10's E without the interreflection):
    /// the sun and the sky facets where the natural geometry lets them through, plus the ambient.
    fn natural_daylight_irradiance(&self, origin: &Point3<f64>, normal: &Vector3<f64>) -> Rgb {
        let daylight = &self.lighting.daylight;
        let inf = f64::INFINITY;
        let sun_natural = daylight.sun.as_ref().is_some_and(|s| {
            s.dir_in_world.dot(normal) > 0.0 && !self.natural_blocks(origin, &s.dir_in_world, inf)
        });
        natural_irradiance_rgb(daylight, normal, sun_natural, |i| {
            !self.natural_blocks(origin, &daylight.sky[i].dir_in_world, inf)
        })
    }

    /// The [`NaturalRatio`] of an unchanged natural sample (ΔE = 0) of a primary ray, for a
    /// pixel whose other samples changed: `None` when the ray's first hit is not natural, in
    /// the radiosity mode, or where no natural light reaches the point.
    #[must_use]
    pub fn unchanged_natural_ratio(
        &self,
        dir_in_world: &Vector3<f64>,
        photo_pixel_rgb: Rgb,
    ) -> Option<NaturalRatio> {
        if self.lighting.radiosity.is_some() {
            return None;
        }
        let origin = self.camera.pose.camera_center_in_world;
        let ray = self
            .all
            .ray_from_world(&origin, dir_in_world, 0.0, f32::INFINITY);
        let hit = self.all.closest_hit(&ray)?;
        if hit.kind != ObjectKind::Natural {
            return None;
        }
        let point = self.all.hit_point_in_world_m(&ray, hit.hit.t);
        let d = f64::from(hit.hit.t);
        let normal = self.normal_facing(&hit, dir_in_world);
        let origin = point + normal * SURFACE_OFFSET_M;
        let e_natural = self.natural_daylight_irradiance(&origin, &normal);
        // Gathered exactly, not through the tile's cache: these few samples at shadow edges do
        // not add records, so the cache serves every other pixel as before.
        let e_natural = add(
            e_natural,
            self.natural_interreflection_irradiance(&point, &normal),
        );
        if e_natural.iter().any(|&e| !(e > 0.0 && e.is_finite())) {
            return None;
        }
        let l0 = self.true_colour(photo_pixel_rgb, d);
        Some(NaturalRatio {
            tau_l0_rgb: mul(self.transmission(d), l0),
            e_natural_rgb: e_natural,
            e_change_rgb: [0.0; 3],
        })
    }

    /// Case D in the radiosity mode ([`super::radiosity_light`]): what the shadow and light rays
    /// at a natural point find, for [`Self::natural_radiance`].
    fn natural_parts(
        &self,
        hit: &SceneHit,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
        photo: PhotoSeen,
        distance_m: f64,
    ) -> NaturalParts {
        let origin = point + normal * SURFACE_OFFSET_M;
        let daylight = &self.lighting.daylight;
        let inf = f64::INFINITY;
        // D3 for the sun, exact: blocked by an artificial object and by no natural one.
        let sun_d3 = daylight.sun.as_ref().and_then(|s| {
            if s.dir_in_world.dot(normal) <= 0.0 {
                return None;
            }
            let passed = self.artificial_transmittance(&origin, &s.dir_in_world, inf);
            (passed.iter().any(|&x| x < 1.0) && !self.natural_blocks(&origin, &s.dir_in_world, inf))
                .then(|| passed.map(|x| 1.0 - x))
        });
        let (e_d1_rgb, lit_d1) = Self::artificial_light_irradiance(
            &self.visible_artificial_lights(point, &origin, normal),
            normal,
        );
        let sun_natural = daylight.sun.as_ref().is_some_and(|s| {
            s.dir_in_world.dot(normal) > 0.0 && !self.natural_blocks(&origin, &s.dir_in_world, inf)
        });
        NaturalParts {
            material: hit.material.0,
            photo_rgb: photo.rgb,
            photo_distance_m: photo.distance_m,
            distance_m,
            normal: *normal,
            sun_natural,
            sun_d3,
            e_d1_rgb,
            lit_d1,
        }
    }

    /// [`super::Shade::changed_apparent`] with this tracer's atmosphere.
    fn changed_apparent(
        &self,
        photo_rgb: Rgb,
        l0: Rgb,
        delta: Rgb,
        photo_distance_m: f64,
        distance_m: f64,
    ) -> (Rgb, bool) {
        self.shade()
            .changed_apparent(photo_rgb, l0, delta, photo_distance_m, distance_m)
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
}
