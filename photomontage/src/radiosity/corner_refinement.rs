//! Where to refine the mesh at corners (issue 13 item 2, "refined where radiosity changes fast
//! (shadow boundaries, corners)"; Tonn & Donath, seed 000, "Generation of patches": finer
//! patches "in areas of high … gradients"; Cohen & Wallace, seed 002, §8.3: elements next to a
//! surface in front of them see it under a solid angle that changes across the element).
//!
//! Where two surfaces meet in a concave corner (a wall standing on the ground, two walls of a
//! courtyard) or one faces another close by (the ground under an overhang), the light each gets
//! from the other, and the sky the other hides, fall off over a distance of the order of the gap
//! between them. An element a few times larger than that gap averages the fall-off away: at the
//! feet of the courtyard's sunlit walls the 0.25 m element means were 5.3–5.6 % below Radiance's
//! point values (`peer_tests`). A convex edge (a roof's rim) sees nothing in front of it and is
//! left alone.
//!
//! A node is split when a surface faces it from closer than its own longest edge: rays
//! from its centroid and its corners (taken [`CORNER_INSET`] of the way toward the centroid,
//! [`SURFACE_OFFSET_M`] off the surface) along the normal and along [`PROBE_AZIMUTHS`] directions
//! [`PROBE_ELEVATION_DEG`] above the surface hit the front of a surface within that distance
//! (the back of a wall, seen from the ground inside a building's footprint, does not count). The
//! split is
//! geometric only (made before the solve, the same for every lighting), so the studio's relights
//! keep the mesh.
//!
//! # Known limitations
//! A surface in front that all probe rays pass by (a thin post between two rays) does not count;
//! a corner whose other surface leans in steeper than the probe elevation toward the node (an
//! acute wedge) is found only along the normal.

use nalgebra::{Point3, Vector3};

use super::shadow_refinement::{CORNER_INSET, SURFACE_OFFSET_M};
use crate::scene::SceneTracer;

/// Probe directions around the normal.
pub const PROBE_AZIMUTHS: usize = 8;
/// Elevation of the probe directions above the node's plane, degrees: low enough that a wall
/// standing on the ground is hit from ground a little more than a wall height away, high enough
/// that the ray leaves the node's own plane cleanly in `f32`.
pub const PROBE_ELEVATION_DEG: f64 = 20.0;

/// Whether a surface of `tracer` lies in front of the node `v` (unit normal `normal`) closer than
/// `reach_m`, the node's longest edge (module doc; the mesher passes the edge it has measured, so
/// this module needs nothing of the mesh).
#[must_use]
pub fn faces_a_surface_nearby(
    tracer: &SceneTracer,
    v: &[Point3<f64>; 3],
    normal: &Vector3<f64>,
    reach_m: f64,
) -> bool {
    let centroid = Point3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
    let points = [
        centroid,
        v[0] + (centroid - v[0]) * CORNER_INSET,
        v[1] + (centroid - v[1]) * CORNER_INSET,
        v[2] + (centroid - v[2]) * CORNER_INSET,
    ]
    .map(|p| p + normal * SURFACE_OFFSET_M);
    let directions = probe_directions(normal, &(v[1] - v[0]));
    #[allow(clippy::cast_possible_truncation)]
    let (t_min, t_max) = (SURFACE_OFFSET_M as f32, reach_m as f32);
    points.iter().any(|p| {
        directions.iter().any(|d| {
            let ray = tracer.ray_from_world(p, d, t_min, t_max);
            // Only a surface that faces the node: the back of a wall (the ground inside a
            // building's footprint) neither lights the node nor hides sky it could see.
            tracer.closest_hit(&ray).is_some_and(|h| {
                let [x, y, z] = h.hit.normal_geometric.map(f64::from);
                x * d.x + y * d.y + z * d.z < 0.0
            })
        })
    })
}

/// The normal and [`PROBE_AZIMUTHS`] unit directions [`PROBE_ELEVATION_DEG`] above the plane of
/// `normal`, the first along the plane's direction of `along` (an edge of the node).
fn probe_directions(normal: &Vector3<f64>, along: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let n = normal.normalize();
    let t = (along - n * n.dot(along)).normalize();
    let b = n.cross(&t);
    let (sin_e, cos_e) = PROBE_ELEVATION_DEG.to_radians().sin_cos();
    let mut out = vec![n];
    #[allow(clippy::cast_precision_loss)]
    for k in 0..PROBE_AZIMUTHS {
        let a = std::f64::consts::TAU * k as f64 / PROBE_AZIMUTHS as f64;
        out.push((t * a.cos() + b * a.sin()) * cos_e + n * sin_e);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_are_unit_and_above_the_plane() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let d = probe_directions(&n, &Vector3::new(1.0, 1.0, 0.3));
        assert_eq!(d.len(), PROBE_AZIMUTHS + 1);
        let sin_e = PROBE_ELEVATION_DEG.to_radians().sin();
        for v in &d[1..] {
            assert!((v.norm() - 1.0).abs() < 1e-12);
            assert!((v.dot(&n) - sin_e).abs() < 1e-12);
        }
        // Opposite azimuths are mirror images in the plane.
        let half = PROBE_AZIMUTHS / 2;
        let s = d[1] + d[1 + half];
        assert!((s - n * 2.0 * sin_e).norm() < 1e-12);
    }
}
