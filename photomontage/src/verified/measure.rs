//! Distances the view geometry report measures in the scene, in `f64` world metres: the ground
//! below the camera (a vertical ray against the natural polygons), the nearest point of the
//! proposal (closest point on a triangle, Ericson, *Real-Time Collision Detection*, 2005, §5.1.5)
//! and the proposal's centroid: the volume centroid of the solid its triangles bound, closed by
//! its base plane (CAD buildings usually have no bottom face), from signed tetrahedra to a point
//! on that plane (divergence theorem; Zhang & Chen 2001, "Efficient feature extraction for 2D/3D
//! objects in mesh representation"); a missing face lying in the base plane adds nothing there.
//!
//! # Known limitations
//! The volume centroid needs a consistently oriented mesh that is closed apart from faces in its
//! base plane; when the bounded volume vanishes (a flat or inconsistent mesh) the area-weighted
//! surface centroid is used instead and said so. The ground is the first natural surface
//! straight below the camera; a camera on a balcony gets the balcony.

use nalgebra::{Point3, Vector3};

/// The ground straight below `point`: the highest natural triangle below it along the vertical,
/// as (ground height Z, index of the triangle in `triangles`), or `None` when no triangle is
/// below.
#[must_use]
pub fn ground_below(
    point_in_world: &Point3<f64>,
    triangles: &[[Point3<f64>; 3]],
) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for (i, [a, b, c]) in triangles.iter().enumerate() {
        // Barycentric coordinates of the point's plan position in the triangle's plan.
        let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if det.abs() < f64::EPSILON * (1.0 + (b - a).norm_squared() + (c - a).norm_squared()) {
            continue; // vertical (or degenerate) in plan: no unique height
        }
        let (px, py) = (point_in_world.x - a.x, point_in_world.y - a.y);
        let u = (px * (c.y - a.y) - (c.x - a.x) * py) / det;
        let v = ((b.x - a.x) * py - px * (b.y - a.y)) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        let z = a.z + u * (b.z - a.z) + v * (c.z - a.z);
        if z <= point_in_world.z && best.is_none_or(|(zb, _)| z > zb) {
            best = Some((z, i));
        }
    }
    best
}

/// The point of triangle `abc` nearest to `p` (Ericson 2005, §5.1.5, Voronoi regions).
#[must_use]
pub fn closest_point_on_triangle(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> Point3<f64> {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The smallest distance from `p` to any of `triangles`, `None` when there are none.
#[must_use]
pub fn nearest_distance_m(p: &Point3<f64>, triangles: &[[Point3<f64>; 3]]) -> Option<f64> {
    triangles
        .iter()
        .map(|[a, b, c]| (closest_point_on_triangle(p, a, b, c) - p).norm())
        .reduce(f64::min)
}

/// How a centroid was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CentroidKind {
    /// Volume centroid of the solid closed by its base plane.
    Volume,
    /// Area-weighted centroid of the surface (the volume vanished).
    Surface,
}

/// The bounded volume counts as vanishing below this fraction of the bounding box's volume.
const MIN_VOLUME_FRACTION: f64 = 1e-9;

/// The centroid of the solid the triangles bound, closed by its base plane (lowest Z), or the
/// surface centroid when that volume vanishes; `None` when the triangles have no area.
#[must_use]
pub fn centroid(triangles: &[[Point3<f64>; 3]]) -> Option<(Point3<f64>, CentroidKind)> {
    let first = triangles.first()?[0];
    let (mut lo, mut hi) = (first, first);
    for p in triangles.iter().flatten() {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    // A reference point on the base plane, near the mesh (keeps the sums well conditioned).
    let origin = Point3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, lo.z);
    let mut volume = 0.0;
    let mut moment = Vector3::zeros();
    for [a, b, c] in triangles {
        let (a, b, c) = (a - origin, b - origin, c - origin);
        let v = a.dot(&b.cross(&c)) / 6.0;
        volume += v;
        moment += (a + b + c) / 4.0 * v;
    }
    let box_volume = (hi - lo)
        .iter()
        .map(|e| e.max(f64::EPSILON))
        .product::<f64>();
    if volume.abs() > MIN_VOLUME_FRACTION * box_volume {
        return Some((origin + moment / volume, CentroidKind::Volume));
    }
    surface_centroid(triangles).map(|c| (c, CentroidKind::Surface))
}

/// The area-weighted centroid of the triangles' surface, `None` when their total area is zero.
#[must_use]
pub fn surface_centroid(triangles: &[[Point3<f64>; 3]]) -> Option<Point3<f64>> {
    let mut sum = Vector3::zeros();
    let mut area_sum = 0.0;
    for [a, b, c] in triangles {
        let area = (b - a).cross(&(c - a)).norm() / 2.0;
        sum += (a.coords + b.coords + c.coords) / 3.0 * area;
        area_sum += area;
    }
    (area_sum > 0.0).then(|| Point3::from(sum / area_sum))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed forms below are exact up to round-off on coordinates of order 10.
    const TOL_M: f64 = 1e-12;

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    #[test]
    fn ground_is_the_highest_surface_below() {
        let ground = [p(0.0, 0.0, 1.0), p(10.0, 0.0, 2.0), p(0.0, 10.0, 3.0)];
        let roof = [p(0.0, 0.0, 8.0), p(10.0, 0.0, 8.0), p(0.0, 10.0, 8.0)];
        let tris = [ground, roof];
        // Below the roof: the roof; on top of it the ground is still the roof; outside: none.
        let (z, i) = ground_below(&p(2.0, 3.0, 9.0), &tris).expect("hit");
        assert!((z - 8.0).abs() < TOL_M && i == 1);
        let (z, i) = ground_below(&p(2.0, 3.0, 5.0), &tris).expect("hit");
        // Plane z = 1 + 0.1 x + 0.2 y.
        assert!((z - (1.0 + 0.2 + 0.6)).abs() < TOL_M && i == 0, "{z}");
        assert!(ground_below(&p(8.0, 8.0, 5.0), &tris).is_none());
    }

    #[test]
    fn closest_points_in_every_region() {
        let (a, b, c) = (p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(0.0, 4.0, 0.0));
        let cases = [
            (p(1.0, 1.0, 3.0), p(1.0, 1.0, 0.0)),  // face
            (p(-1.0, -2.0, 1.0), a),               // vertex a
            (p(6.0, -1.0, 0.0), b),                // vertex b
            (p(-1.0, 6.0, 0.0), c),                // vertex c
            (p(2.0, -3.0, 0.0), p(2.0, 0.0, 0.0)), // edge ab
            (p(-3.0, 2.0, 0.0), p(0.0, 2.0, 0.0)), // edge ac
            (p(3.0, 3.0, 1.0), p(2.0, 2.0, 0.0)),  // edge bc
        ];
        for (q, want) in cases {
            let got = closest_point_on_triangle(&q, &a, &b, &c);
            assert!((got - want).norm() < TOL_M, "{q} -> {got}, want {want}");
        }
        let d = nearest_distance_m(&p(1.0, 1.0, 3.0), &[[a, b, c]]).expect("one");
        assert!((d - 3.0).abs() < TOL_M);
    }

    #[test]
    fn centroid_of_a_box_open_or_closed_at_the_bottom() {
        // Unit cube as 12 triangles.
        let v = |i: usize| p((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let quads = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        let tris: Vec<_> = quads
            .iter()
            .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
            .collect();
        let (c, kind) = centroid(&tris).expect("area");
        assert!(
            (c - p(0.5, 0.5, 0.5)).norm() < TOL_M && kind == CentroidKind::Volume,
            "{c}"
        );
        let c = surface_centroid(&tris).expect("area");
        assert!((c - p(0.5, 0.5, 0.5)).norm() < TOL_M, "{c}");
        // Without its bottom face (as CAD buildings come) the volume centroid is unchanged,
        // while the surface centroid rises: walls at z = 1/2 (area 4), roof at 1 (area 1).
        let open = &tris[2..];
        let (c, kind) = centroid(open).expect("area");
        assert!(
            (c - p(0.5, 0.5, 0.5)).norm() < TOL_M && kind == CentroidKind::Volume,
            "{c}"
        );
        let s = surface_centroid(open).expect("area");
        assert!((s.z - 0.6).abs() < TOL_M, "{s}");
        // A single flat square bounds nothing: the surface centroid, said so.
        let (c, kind) = centroid(&tris[..2]).expect("area");
        assert!((c - p(0.5, 0.5, 0.0)).norm() < TOL_M && kind == CentroidKind::Surface);
        assert!(centroid(&[]).is_none());
    }
}
