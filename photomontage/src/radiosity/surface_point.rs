//! Points on the mesh's surfaces: barycentric weights, the key that identifies an element
//! vertex across the elements of one plane (nodal averaging, [`super::query`]; vertex gathers,
//! [`super::vertex_gather`]) and cosine-distributed directions (Malley's method, Cohen & Wallace
//! §9.3.2 final gathers).

use nalgebra::{Point3, Vector3};

/// The key of vertex `p` on a surface of unit normal `n`: position to 10 µm, normal to 1e-3.
#[allow(clippy::cast_possible_truncation)]
pub(super) fn vertex_key(p: &Point3<f64>, n: &Vector3<f64>) -> [i64; 6] {
    let q = |v: f64, s: f64| (v * s).round() as i64;
    [
        q(p.x, 1e5),
        q(p.y, 1e5),
        q(p.z, 1e5),
        q(n.x, 1e3),
        q(n.y, 1e3),
        q(n.z, 1e3),
    ]
}

/// A triangle made ready for many point tests: a vertex, the unit normal, the dual vectors that
/// give the barycentric weights of the other two vertices by dot products (w_b = (p − a)·(e_c ×
/// n)/A, w_c = (p − a)·(n × e_b)/A with e_b = b − a, e_c = c − a and A = (e_b × e_c)·n: the
/// weights of the point's projection on the plane), and the longest edge.
#[derive(Debug, Clone)]
pub(super) struct TriangleShape {
    a: Point3<f64>,
    pub(super) normal: Vector3<f64>,
    dual_b: Vector3<f64>,
    dual_c: Vector3<f64>,
    pub(super) longest_edge_m: f64,
}

impl TriangleShape {
    pub(super) fn new(vertices: &[Point3<f64>; 3], normal: &Vector3<f64>) -> Self {
        let [a, b, c] = vertices;
        let (eb, ec) = (b - a, c - a);
        let area2 = eb.cross(&ec).dot(normal);
        let longest_edge_m = eb.norm().max((c - b).norm()).max(ec.norm());
        Self {
            a: *a,
            normal: *normal,
            dual_b: ec.cross(normal) / area2,
            dual_c: normal.cross(&eb) / area2,
            longest_edge_m,
        }
    }

    /// Barycentric weights (of a, b, c) of the projection of `p` on the triangle's plane.
    pub(super) fn weights(&self, p: &Point3<f64>) -> [f64; 3] {
        let pa = p - self.a;
        let wb = pa.dot(&self.dual_b);
        let wc = pa.dot(&self.dual_c);
        [1.0 - wb - wc, wb, wc]
    }

    /// Distance of `p` from the triangle's plane, metres.
    pub(super) fn distance_m(&self, p: &Point3<f64>) -> f64 {
        (p - self.a).dot(&self.normal).abs()
    }
}

/// Cosine-distributed direction about `n` from two uniform numbers (Malley's method).
pub(super) fn cosine_direction(n: &Vector3<f64>, u1: f64, u2: f64) -> Vector3<f64> {
    CosineFrame::new(n).direction(u1, u2)
}

/// The tangent frame of [`cosine_direction`] about one normal, made once for many rays.
#[derive(Debug, Clone, Copy)]
pub(super) struct CosineFrame {
    n: Vector3<f64>,
    a: Vector3<f64>,
    b: Vector3<f64>,
}

impl CosineFrame {
    pub(super) fn new(n: &Vector3<f64>) -> Self {
        let t = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let a = n.cross(&t).normalize();
        let b = n.cross(&a);
        Self { n: *n, a, b }
    }

    /// Malley's method: a uniform point of the unit disc lifted to the hemisphere.
    pub(super) fn direction(&self, u1: f64, u2: f64) -> Vector3<f64> {
        let r = u1.sqrt();
        let phi = std::f64::consts::TAU * u2;
        let (sin, cos) = phi.sin_cos();
        self.a * (r * cos) + self.b * (r * sin) + self.n * (1.0 - u1).max(0.0).sqrt()
    }
}

/// A random seed from a surface point and its normal (their bits, mixed with `salt`), so that
/// the rays a point gathers with depend on the point alone.
pub(super) fn point_seed(salt: u64, p: &Point3<f64>, n: &Vector3<f64>) -> u64 {
    p.coords.iter().chain(n.iter()).fold(salt, |h, x| {
        (h ^ x.to_bits()).wrapping_mul(0x9E37_79B9_7F4A_7C15)
    })
}
