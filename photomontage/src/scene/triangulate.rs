//! Triangulation of planar polygons, convex or concave, by ear clipping in the polygon's plane
//! (Meisters 1975, "Polygons have ears"; the O(n²)–O(n³) variant of Eberly, *Triangulation by
//! Ear Clipping*, 2002). Durisch 1992 §4.1 approximates the photographed scene by planar polygons;
//! these become triangles for the BVH.
//!
//! The plane normal is Newell's (robust for slightly non-planar, measured polygons); vertices are
//! projected onto the two axes orthogonal to it, and the output triangles keep the polygon's
//! winding, so a counter-clockwise polygon gives counter-clockwise triangles.
//!
//! # Known limitations
//! Simple polygons only: no holes, no self-intersections (a self-intersecting polygon may give
//! [`TriangulateError::NoEar`]). Non-planar polygons are triangulated in their best-fit plane
//! without a warning. Collinear vertices are clipped as zero-area ears and dropped.

use nalgebra::{Point3, Vector2, Vector3};

/// Upper bound on polygon size (the algorithm is quadratic or worse in the vertex count).
pub const MAX_POLYGON_VERTICES: usize = 100_000;

/// Why a polygon could not be triangulated.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TriangulateError {
    /// Fewer than three vertices.
    #[error("a polygon needs at least 3 vertices, got {count}")]
    TooFewVertices {
        /// Vertices given.
        count: usize,
    },
    /// More vertices than [`MAX_POLYGON_VERTICES`].
    #[error("a polygon may have at most {max} vertices, got {count}")]
    TooManyVertices {
        /// Vertices given.
        count: usize,
        /// The limit.
        max: usize,
    },
    /// The polygon has no area (all vertices collinear or coincident) or non-finite coordinates.
    #[error("the polygon is degenerate (zero area or non-finite coordinates)")]
    Degenerate,
    /// No ear was found: the polygon intersects itself.
    #[error("no ear found with {remaining} vertices left: the polygon intersects itself")]
    NoEar {
        /// Vertices still unclipped.
        remaining: usize,
    },
}

/// Newell's normal of a polygon (length = twice the area of its projection), not normalised.
#[must_use]
pub fn newell_normal(polygon: &[Point3<f64>]) -> Vector3<f64> {
    // Relative to the first vertex, so large survey coordinates do not cancel catastrophically.
    let Some(&o) = polygon.first() else {
        return Vector3::zeros();
    };
    let mut n = Vector3::zeros();
    for (i, p) in polygon.iter().enumerate() {
        let a = p - o;
        let b = polygon[(i + 1) % polygon.len()] - o;
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    n
}

fn cross2(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Triangulates a simple planar polygon; returns index triples into `polygon` with the same
/// winding as the polygon.
///
/// # Errors
/// See [`TriangulateError`].
pub fn triangulate_polygon(polygon: &[Point3<f64>]) -> Result<Vec<[usize; 3]>, TriangulateError> {
    let n = polygon.len();
    if n < 3 {
        return Err(TriangulateError::TooFewVertices { count: n });
    }
    if n > MAX_POLYGON_VERTICES {
        return Err(TriangulateError::TooManyVertices {
            count: n,
            max: MAX_POLYGON_VERTICES,
        });
    }
    let normal = newell_normal(polygon);
    let scale = polygon
        .iter()
        .map(|p| (p - polygon[0]).norm_squared())
        .fold(0.0, f64::max);
    if !normal.iter().all(|c| c.is_finite()) || normal.norm_squared() <= 1e-24 * scale * scale {
        return Err(TriangulateError::Degenerate);
    }
    // An orthonormal basis (u, v) of the plane with u × v = n̂: projected coordinates then wind
    // counter-clockwise exactly when the polygon does about its own Newell normal.
    let n_hat = normal.normalize();
    let helper = if n_hat.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = helper.cross(&n_hat).normalize();
    let v = n_hat.cross(&u);
    let origin = polygon[0];
    let p2: Vec<Vector2<f64>> = polygon
        .iter()
        .map(|p| {
            let d = p - origin;
            Vector2::new(d.dot(&u), d.dot(&v))
        })
        .collect();

    let mut remaining: Vec<usize> = (0..n).collect();
    let mut triangles = Vec::with_capacity(n - 2);
    // Tolerance on the signed doubled area: relative to the squared polygon size.
    let area_eps = 1e-14 * scale;
    while remaining.len() > 3 {
        let m = remaining.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (
                remaining[(k + m - 1) % m],
                remaining[k],
                remaining[(k + 1) % m],
            );
            let (a, b, c) = (p2[ia], p2[ib], p2[ic]);
            let turn = cross2(b - a, c - b);
            if turn.abs() <= area_eps {
                // Collinear (or coincident): drop the middle vertex, no triangle.
                remaining.remove(k);
                clipped = true;
                break;
            }
            if turn < 0.0 {
                continue; // reflex vertex
            }
            let contains_other = remaining.iter().any(|&j| {
                if j == ia || j == ib || j == ic {
                    return false;
                }
                let p = p2[j];
                cross2(b - a, p - a) >= -area_eps
                    && cross2(c - b, p - b) >= -area_eps
                    && cross2(a - c, p - c) >= -area_eps
            });
            if contains_other {
                continue;
            }
            triangles.push([ia, ib, ic]);
            remaining.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            return Err(TriangulateError::NoEar {
                remaining: remaining.len(),
            });
        }
    }
    let (a, b, c) = (p2[remaining[0]], p2[remaining[1]], p2[remaining[2]]);
    if cross2(b - a, c - b).abs() > area_eps {
        triangles.push([remaining[0], remaining[1], remaining[2]]);
    }
    if triangles.is_empty() {
        return Err(TriangulateError::Degenerate);
    }
    Ok(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Areas are sums of products of coordinates of order 1–10: 1e-9 relative is far above the
    /// rounding of a few dozen such products and far below any real triangulation error.
    const AREA_REL_TOL: f64 = 1e-9;

    fn area(poly: &[Point3<f64>]) -> f64 {
        newell_normal(poly).norm() / 2.0
    }

    fn check(poly: &[Point3<f64>]) -> Vec<[usize; 3]> {
        let tris = triangulate_polygon(poly).unwrap();
        let n_poly = newell_normal(poly).normalize();
        let mut sum = 0.0;
        for t in &tris {
            let [a, b, c] = t.map(|i| poly[i]);
            let n = (b - a).cross(&(c - a));
            assert!(n.dot(&n_poly) > 0.0, "triangle {t:?} flipped");
            sum += n.norm() / 2.0;
        }
        let expected = area(poly);
        assert!(
            ((sum - expected) / expected).abs() < AREA_REL_TOL,
            "{sum} vs {expected}"
        );
        tris
    }

    fn xy(points: &[(f64, f64)]) -> Vec<Point3<f64>> {
        points
            .iter()
            .map(|&(x, y)| Point3::new(x, y, 0.0))
            .collect()
    }

    #[test]
    fn square_gives_two_triangles() {
        let tris = check(&xy(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]));
        assert_eq!(tris.len(), 2);
    }

    #[test]
    fn concave_shapes_keep_area_and_orientation() {
        // L shape, area 3.
        let l = xy(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]);
        assert!((area(&l) - 3.0).abs() < 1e-12);
        assert_eq!(check(&l).len(), 4);
        // Comb with three teeth (a fan from any vertex would leave the polygon).
        let comb = xy(&[
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 3.0),
            (4.0, 3.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ]);
        assert_eq!(check(&comb).len(), 10);
        // Clockwise star, tilted into a vertical plane at survey coordinates.
        let star: Vec<Point3<f64>> = (0..10)
            .rev()
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::PI / 5.0;
                let r = if k % 2 == 0 { 3.0 } else { 1.2 };
                Point3::new(600_000.0 + r * a.cos(), 200_000.0, 450.0 + r * a.sin())
            })
            .collect();
        assert_eq!(check(&star).len(), 8);
    }

    #[test]
    fn collinear_vertices_are_dropped() {
        let poly = xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]);
        // Five vertices, one collinear: at most three triangles, none degenerate (`check` asserts
        // every triangle has a strictly positive area along the polygon normal).
        assert!(check(&poly).len() <= 3);
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        assert_eq!(
            triangulate_polygon(&xy(&[(0.0, 0.0), (1.0, 0.0)])),
            Err(TriangulateError::TooFewVertices { count: 2 })
        );
        assert_eq!(
            triangulate_polygon(&xy(&[(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)])),
            Err(TriangulateError::Degenerate)
        );
        let mut nan = xy(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]);
        nan[1].x = f64::NAN;
        assert_eq!(triangulate_polygon(&nan), Err(TriangulateError::Degenerate));
    }
}
