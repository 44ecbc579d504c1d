//! Form factors against the closed forms of `../shared/reference/lighting.md` §5.1 (Howell's
//! catalogue, cases C-11, C-14, C-41), reciprocity, enclosure closure and an exactly half-blocked
//! pair.
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;

use super::direct::element_matrix;
use super::form_factor::{FormFactorEngine, FormFactorParams, point_to_triangle};
use super::mesh::{Mesh, MeshParams};
use super::test_scenes;
use crate::bvh::BuildQuality;
use crate::scene::{Scene, SceneTracer};

/// The acceptance tolerance of issue 13 for the closed forms.
const CLOSED_FORM_REL_TOL: f64 = 0.005;
/// The closed forms are quoted to 7 digits in lighting.md.
const QUOTED_DIGITS_TOL: f64 = 5e-7;
/// Unoccluded closure of a cube: exact point-to-polygon factors sum to 1 up to f64 rounding of
/// a few dozen terms.
const CLOSURE_TOL: f64 = 1e-9;
/// With shadow rays, a few `f32` rays grazing the cube's edges are stopped by the adjacent
/// face (observed: 4.7e-6 of one row of 192).
const CLOSURE_WITH_RAYS_TOL: f64 = 1e-4;
/// Half-blocked pair: binary visibility over 32×32 strata per triangle pair (4096 samples for
/// the two squares); the per-sample Bernoulli noise, reduced by stratification, is about 0.5 % of
/// F, and 2 % is four of those.
const HALF_BLOCKED_REL_TOL: f64 = 0.02;
/// Reciprocity of individual element pairs is broken only by the outer quadrature (16 strata on
/// the sender versus on the receiver), worst for small perpendicular elements meeting at the
/// cube's edges, where the integrand's derivative is singular; observed 3.0 % in the
/// area-weighted L1 sense over all pairs of the 192-element cube, bounded at 4 %.
const RECIPROCITY_REL_TOL: f64 = 0.04;

/// Howell C-11: directly opposed equal rectangles a × b at separation c.
fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * ((((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Howell C-14: perpendicular rectangles l × w (sender) and l × h with a common edge l.
fn perpendicular_rectangles(l: f64, w: f64, h: f64) -> f64 {
    let (hh, ww) = (h / l, w / l);
    let (h2, w2) = (hh * hh, ww * ww);
    let s = (h2 + w2).sqrt();
    let log = ((1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2)).ln()
        + w2 * (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).ln()
        + h2 * (h2 * (1.0 + w2 + h2) / ((1.0 + h2) * (w2 + h2))).ln();
    1.0 / (PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan() + 0.25 * log)
}

/// Howell C-41: coaxial discs r1 (sender), r2 at separation h.
fn coaxial_discs(r1: f64, r2: f64, h: f64) -> f64 {
    let (a, b) = (r1 / h, r2 / h);
    let x = 1.0 + (1.0 + b * b) / (a * a);
    0.5 * (x - (x * x - 4.0 * (b / a).powi(2)).sqrt())
}

#[test]
fn closed_forms_reproduce_the_quoted_values() {
    for (got, want) in [
        (parallel_rectangles(1.0, 1.0, 1.0), 0.199_824_9),
        (parallel_rectangles(2.0, 1.0, 1.0), 0.285_875_4),
        (perpendicular_rectangles(1.0, 1.0, 1.0), 0.200_043_8),
        (perpendicular_rectangles(1.0, 2.0, 1.0), 0.116_426_3),
        (perpendicular_rectangles(2.0, 1.0, 3.0), 0.308_140_3),
        (coaxial_discs(1.0, 1.0, 1.0), 0.381_966_0),
        (coaxial_discs(0.1, 0.2, 0.5), 0.133_931_3),
    ] {
        assert!((got - want).abs() < QUOTED_DIGITS_TOL, "{got} vs {want}");
    }
}

struct Setup {
    mesh: Mesh,
    tracer: SceneTracer,
}

fn setup(scene: &Scene, element_edge_m: f64) -> Setup {
    let mesh = Mesh::build(
        scene,
        &MeshParams {
            max_patch_edge_m: element_edge_m,
            max_element_edge_m: element_edge_m,
            ..MeshParams::default()
        },
    )
    .unwrap();
    let tracer = SceneTracer::new(scene, BuildQuality::Medium).unwrap();
    Setup { mesh, tracer }
}

/// F from every element of object `from` to every element of object `to`, area-weighted.
fn object_factor(s: &Setup, params: FormFactorParams, from: &str, to: &str) -> f64 {
    let engine = FormFactorEngine::new(&s.mesh, &s.tracer, params).unwrap();
    let of = |name: &str| -> Vec<u32> {
        s.mesh
            .elements
            .iter()
            .copied()
            .filter(|&n| s.mesh.object_name(n as usize) == name)
            .collect()
    };
    let (senders, receivers) = (of(from), of(to));
    let mut area = 0.0;
    let mut sum = 0.0;
    for &p in &senders {
        let a = s.mesh.nodes[p as usize].area_m2;
        area += a;
        sum += a * engine.row(p, &receivers).iter().sum::<f64>();
    }
    sum / area
}

fn check(label: &str, got: f64, want: f64, tol: f64) {
    let rel = (got - want).abs() / want;
    assert!(rel < tol, "{label}: {got} vs {want} ({:.3} %)", 100.0 * rel);
}

const FINE: FormFactorParams = FormFactorParams {
    samples_per_axis: 16,
    seed: 7,
    visibility: true,
};

#[test]
fn unit_squares_parallel() {
    let s = setup(&test_scenes::squares_parallel(1.0, 1.0), 10.0);
    let f = object_factor(&s, FINE, "emitter", "receiver");
    check("parallel", f, 0.199_824_9, CLOSED_FORM_REL_TOL);
    // 2 × 1 at distance 1, meshed into elements (16 per triangle).
    let mut scene = Scene::new();
    let p = nalgebra::Point3::new;
    test_scenes::add(
        &mut scene,
        "emitter",
        test_scenes::quad(p(0., 0., 0.), p(2., 0., 0.), p(2., 1., 0.), p(0., 1., 0.)),
        test_scenes::grey("w", 0.5),
    );
    test_scenes::add(
        &mut scene,
        "receiver",
        test_scenes::quad(p(0., 0., 1.), p(0., 1., 1.), p(2., 1., 1.), p(2., 0., 1.)),
        test_scenes::grey("w", 0.5),
    );
    let s = setup(&scene, 0.6);
    let coarse = FormFactorParams {
        samples_per_axis: 4,
        ..FINE
    };
    let f = object_factor(&s, coarse, "emitter", "receiver");
    check("parallel 2×1", f, 0.285_875_4, CLOSED_FORM_REL_TOL);
}

#[test]
fn unit_squares_perpendicular() {
    let s = setup(&test_scenes::squares_perpendicular(), 10.0);
    let f = object_factor(&s, FINE, "emitter", "receiver");
    check("perpendicular", f, 0.200_043_8, CLOSED_FORM_REL_TOL);
    let f = object_factor(&s, FINE, "receiver", "emitter");
    check(
        "perpendicular, reversed",
        f,
        0.200_043_8,
        CLOSED_FORM_REL_TOL,
    );
}

#[test]
fn coaxial_unit_discs() {
    let s = setup(&test_scenes::discs(1.0, 1.0, 128), 10.0);
    let params = FormFactorParams {
        samples_per_axis: 4,
        ..FINE
    };
    let f = object_factor(&s, params, "emitter", "receiver");
    check("discs", f, 0.381_966_0, CLOSED_FORM_REL_TOL);
}

#[test]
fn half_blocking_plate_halves_the_factor() {
    let s = setup(&test_scenes::squares_half_blocked(), 10.0);
    let params = FormFactorParams {
        samples_per_axis: 32,
        ..FINE
    };
    let f = object_factor(&s, params, "emitter", "receiver");
    check("half blocked", f, 0.5 * 0.199_824_9, HALF_BLOCKED_REL_TOL);
    // Without shadow rays the plate is ignored.
    let open = FormFactorParams {
        visibility: false,
        ..params
    };
    let f = object_factor(&s, open, "emitter", "receiver");
    check("visibility off", f, 0.199_824_9, CLOSED_FORM_REL_TOL);
}

#[test]
fn reciprocity_and_closure_in_a_cube() {
    let scene = test_scenes::closed_box(1.0, &test_scenes::grey("w", 0.5));
    let s = setup(&scene, 0.5);
    let never = AtomicBool::new(false);
    let with_rays = FormFactorEngine::new(&s.mesh, &s.tracer, FormFactorParams::default()).unwrap();
    let f = element_matrix(&with_rays, &never).unwrap();
    let n = s.mesh.elements.len();
    for i in 0..n {
        let row_sum: f64 = f[i * n..(i + 1) * n].iter().sum();
        assert!(
            (row_sum - 1.0).abs() < CLOSURE_WITH_RAYS_TOL,
            "row {i}: Σ F = {row_sum}"
        );
    }
    let open = FormFactorParams {
        visibility: false,
        ..FormFactorParams::default()
    };
    let engine = FormFactorEngine::new(&s.mesh, &s.tracer, open).unwrap();
    let f = element_matrix(&engine, &never).unwrap();
    assert_eq!(n, 6 * 2 * 16);
    let area = |i: usize| s.mesh.element_node(i).area_m2;
    let mut asymmetry = 0.0;
    let mut total = 0.0;
    for i in 0..n {
        let row_sum: f64 = f[i * n..(i + 1) * n].iter().sum();
        assert!(
            (row_sum - 1.0).abs() < CLOSURE_TOL,
            "row {i}: Σ F = {row_sum}"
        );
        for j in 0..n {
            asymmetry += (area(i) * f[i * n + j] - area(j) * f[j * n + i]).abs();
            total += area(i) * f[i * n + j];
        }
    }
    assert!(
        asymmetry / total < RECIPROCITY_REL_TOL,
        "{}",
        asymmetry / total
    );
}

#[test]
fn point_to_triangle_known_values() {
    // Under the centre of a 1 × 1 square at height 1 (lighting.md §5.1: 0.2394565), the square
    // as two triangles facing down.
    let p = nalgebra::Point3::new;
    let down = nalgebra::Vector3::new(0.0, 0.0, -1.0);
    let up = nalgebra::Vector3::z();
    let x = p(0.0, 0.0, 0.0);
    let a = [p(-0.5, -0.5, 1.0), p(-0.5, 0.5, 1.0), p(0.5, 0.5, 1.0)];
    let b = [p(-0.5, -0.5, 1.0), p(0.5, 0.5, 1.0), p(0.5, -0.5, 1.0)];
    let f = point_to_triangle(&x, &up, &a, &down) + point_to_triangle(&x, &up, &b, &down);
    assert!((f - 0.239_456_5).abs() < QUOTED_DIGITS_TOL, "{f}");
    // Seen from behind (one-sided) or from below its own plane: nothing.
    assert!(point_to_triangle(&x, &up, &a, &up).abs() < f64::EPSILON);
    assert!(point_to_triangle(&x, &-up, &a, &down).abs() < f64::EPSILON);
}

#[test]
fn factors_are_thread_count_independent() {
    let scene = test_scenes::small_room();
    let s = setup(&scene, 0.25);
    let engine = FormFactorEngine::new(&s.mesh, &s.tracer, FormFactorParams::default()).unwrap();
    let never = AtomicBool::new(false);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| element_matrix(&engine, &never).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert!(
        one.iter()
            .zip(&two)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
    assert!(one.iter().any(|&f| f > 0.0));
}
