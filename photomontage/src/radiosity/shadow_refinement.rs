//! Where to refine the mesh: nodes that a sun shadow edge crosses (issue 13 item 2, "refined
//! where radiosity changes fast (shadow boundaries …)"; Cohen & Wallace, seed 002, §8.4:
//! a posteriori refinement where the direct light changes across an element, here judged before
//! the solve from the sun's visibility, the sharpest change a site has).
//!
//! A node is split when the sun, seen from its corners and its centroid, is visible from some of
//! them and hidden from others. Corners are taken [`CORNER_INSET`] of the way toward the
//! centroid and every point [`SURFACE_OFFSET_M`] off the surface, so that the surfaces a corner
//! touches (a wall standing on the ground) do not count as its shadow. Nodes facing away from a
//! direction are not split for it (no sun reaches either side of an edge there).
//!
//! # Known limitations
//! A shadow that falls between the five points (narrower than the node and not crossing a
//! corner or the centre) is missed at that node and may be found at none; the mesh follows the
//! sun it was built for, not a sun moved afterwards (the studio's relights keep the mesh).

use nalgebra::{Point3, Vector3};

use crate::scene::SceneTracer;

/// Corner points lie this fraction of the way from a corner toward the centroid.
pub const CORNER_INSET: f64 = 0.02;

/// Points lie this far off the surface, metres (above the `f32` rounding of a BVH a few hundred
/// metres across).
pub const SURFACE_OFFSET_M: f64 = 1e-3;

/// Shadow rays stop here, metres (beyond any site).
const RAY_LENGTH_M: f32 = 1e7;

/// Whether a sun shadow edge crosses the node `v` with unit normal `normal` (module doc):
/// for some direction of `dirs_to_sun` (unit vectors toward distant sources), the five points
/// disagree about its visibility in `occluders`.
#[must_use]
pub fn crosses_shadow_edge(
    occluders: &SceneTracer,
    dirs_to_sun: &[Vector3<f64>],
    v: &[Point3<f64>; 3],
    normal: &Vector3<f64>,
) -> bool {
    let centroid = Point3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
    let points = [
        v[0] + (centroid - v[0]) * CORNER_INSET,
        v[1] + (centroid - v[1]) * CORNER_INSET,
        v[2] + (centroid - v[2]) * CORNER_INSET,
        centroid,
    ]
    .map(|p| p + normal * SURFACE_OFFSET_M);
    dirs_to_sun.iter().any(|d| {
        if normal.dot(d) <= 0.0 {
            return false;
        }
        let lit = |p: &Point3<f64>| {
            #[allow(clippy::cast_possible_truncation)]
            let ray = occluders.ray_from_world(p, d, SURFACE_OFFSET_M as f32, RAY_LENGTH_M);
            !occluders.any_hit(&ray)
        };
        let first = lit(&points[0]);
        points[1..].iter().any(|p| lit(p) != first)
    })
}
