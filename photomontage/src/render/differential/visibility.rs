//! Ray queries of the differential tracer against its split BVHs (Durisch 1992 §6.2): the
//! closest hit over all geometry, any-hit shadow tests against the natural or artificial
//! geometry alone, the slab test that culls shadow rays by the artificial bounding box, and the
//! geometric normal facing a ray.
//!
//! # Known limitations
//! The normal is the flat triangle normal (no interpolated vertex normals).

use nalgebra::{Point3, Vector3};

use super::DifferentialTracer;
use crate::scene::{SceneHit, SceneTracer};

impl DifferentialTracer<'_> {
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
}
