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

/// Barycentric weights of the projection of `p` on triangle `a b c` with normal `n`.
pub(super) fn barycentric(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
    n: &Vector3<f64>,
) -> [f64; 3] {
    let area2 = (b - a).cross(&(c - a)).dot(n);
    let wa = (b - p).cross(&(c - p)).dot(n) / area2;
    let wb = (c - p).cross(&(a - p)).dot(n) / area2;
    [wa, wb, 1.0 - wa - wb]
}

/// Cosine-distributed direction about `n` from two uniform numbers (Malley's method).
pub(super) fn cosine_direction(n: &Vector3<f64>, u1: f64, u2: f64) -> Vector3<f64> {
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    let t = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let a = n.cross(&t).normalize();
    let b = n.cross(&a);
    a * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()
}

/// A random seed from a surface point and its normal (their bits, mixed with `salt`), so that
/// the rays a point gathers with depend on the point alone.
pub(super) fn point_seed(salt: u64, p: &Point3<f64>, n: &Vector3<f64>) -> u64 {
    p.coords.iter().chain(n.iter()).fold(salt, |h, x| {
        (h ^ x.to_bits()).wrapping_mul(0x9E37_79B9_7F4A_7C15)
    })
}
