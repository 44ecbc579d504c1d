//! The material table (`material_table.rs`): the Chebyshev interpolant against closed forms, and
//! the table's relights against exact relights of the same change, between the nodes.
#![allow(clippy::unwrap_used)]
#![allow(clippy::float_cmp)] // bit-identity across thread counts is compared on purpose

use super::transfer::{
    LightingChange, MaterialTableReport, RelightStrategy, Sweep, TABLE_NODES, Transfer,
    chebyshev_coefficients, chebyshev_value, table_nodes,
};
use super::transfer_tests::{STOP, build, lighting, params, sun_at, yard};
use super::{Rgb, Solution, StopRule};

/// 1/(2 − s) has its pole at x = 3 on the interpolation interval's [−1, 1] scale: Bernstein
/// ellipse parameter r = 3 + √8 ≈ 5.83, so the 8-point interpolant errs by ≈ 2·r⁻⁸/(r − 1)
/// ≈ 6e-7 (Trefethen 2013, thm 8.2); 2e-6 bounds it.
const RATIONAL_ABS_TOL: f64 = 2e-6;
/// A polynomial of degree < 8 is reproduced to rounding.
const POLYNOMIAL_ABS_TOL: f64 = 1e-12;
/// The table against an exact relight of the same change: the node solves stop at a tenth of the
/// test's residual 1e-4, amplified by the interpolant's Lebesgue constant (≈ 2.2) and by
/// 1/(1 − ρF) < 2; the exact relight stops within 1e-4 of the fixed point, amplified alike;
/// f32 coefficients add 1e-7. 1e-3 bounds the area-weighted L1 difference.
const TABLE_L1_REL_TOL: f64 = 1e-3;

#[test]
fn chebyshev_interpolant_meets_closed_forms() {
    let nodes = table_nodes();
    assert!(nodes.iter().all(|s| (0.0..=1.0).contains(s)));
    let f = nodes.map(|s| 1.0 / (2.0 - s));
    let c = chebyshev_coefficients(&f);
    let worst = (0..=100)
        .map(|i| {
            let s = f64::from(i) / 100.0;
            (chebyshev_value(&c, s) - 1.0 / (2.0 - s)).abs()
        })
        .fold(0.0, f64::max);
    assert!(worst < RATIONAL_ABS_TOL, "rational: {worst}");
    assert!(worst > 0.0, "a rational function is not a polynomial");
    let cubic = |s: f64| 0.3 - 1.2 * s + 0.7 * s * s * s;
    let c = chebyshev_coefficients(&nodes.map(cubic));
    for i in 0..=20 {
        let s = f64::from(i) / 20.0;
        assert!((chebyshev_value(&c, s) - cubic(s)).abs() < POLYNOMIAL_ABS_TOL);
    }
    // The nodes' own values come back.
    for (s, v) in nodes.iter().zip(nodes.map(cubic)) {
        assert!((chebyshev_value(&c, *s) - v).abs() < POLYNOMIAL_ABS_TOL);
    }
    assert_eq!(TABLE_NODES, c.len());
}

fn exact(t: &Transfer, material: &str, value: Rgb) -> Solution {
    let mut copy = t.clone();
    copy.relight(&LightingChange {
        material_reflectance: vec![(material.into(), value)],
        ..LightingChange::default()
    })
    .unwrap()
}

fn assert_close(label: &str, table: &Solution, exact: &Solution) {
    let d = table.relative_difference(exact).unwrap();
    assert!(d.l1_rel < TABLE_L1_REL_TOL, "{label}: L1 {}", d.l1_rel);
    for (g, (x, y)) in table.groups.iter().zip(&exact.groups).enumerate() {
        assert_eq!(
            x.direct_irradiance_rgb, y.direct_irradiance_rgb,
            "{label}: group {g} direct term"
        );
    }
    assert_eq!(
        table.mesh.surfaces, exact.mesh.surfaces,
        "{label}: the material's reflectance is set"
    );
}

#[test]
fn a_material_table_gives_the_exact_relight_between_its_nodes() {
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::Shooting),
    );
    // First change of `render`: the table is built and read.
    let first: Rgb = [0.8, 0.3, 0.2];
    let before = t.clone();
    let report = t.relight_material("render", first).unwrap();
    assert!(report.built && report.from_table, "{report:?}");
    let tail = report.tail.unwrap();
    assert!(tail > 0.0 && tail <= STOP.residual, "tail {tail}");
    assert_close("first", t.solution(), &exact(&before, "render", first));
    // Further changes read the table, anywhere in [0, 1]³.
    for value in [[0.15, 0.9, 0.45], [0.0, 1.0, 0.55], [0.6, 0.6, 0.6]] {
        let before = t.clone();
        let report = t.relight_material("render", value).unwrap();
        assert_eq!(
            report,
            MaterialTableReport {
                built: false,
                from_table: true,
                tail: None
            }
        );
        assert_close(
            &format!("{value:?}"),
            t.solution(),
            &exact(&before, "render", value),
        );
    }
    // Another material's change, or a sun move, drops the table: the next change builds again.
    t.relight(&LightingChange {
        sun: Some(Some(sun_at(0.9, 3.4))),
        ..LightingChange::default()
    })
    .unwrap();
    let before = t.clone();
    let report = t.relight_material("render", first).unwrap();
    assert!(report.built && report.from_table, "{report:?}");
    assert_close(
        "after the sun",
        t.solution(),
        &exact(&before, "render", first),
    );
    let report = t.relight_material("brick", [0.2, 0.3, 0.4]).unwrap();
    assert!(report.built, "another material: {report:?}");
    // Bad input changes nothing.
    let kept = t.solution().clone();
    assert!(t.relight_material("marble", [0.5; 3]).is_err());
    assert!(t.relight_material("render", [1.5, 0.2, 0.2]).is_err());
    assert_eq!(t.solution().groups, kept.groups);
}

#[test]
fn a_table_whose_tail_is_over_the_residual_is_refused() {
    // A residual far below what 8 nodes resolve: the table is refused, the change relit exactly.
    let scene = yard([0.6; 3]);
    let mut p = params(RelightStrategy::LinearResponses, Sweep::Shooting);
    p.solve.stop = StopRule {
        residual: 1e-12,
        ..STOP
    };
    let mut t = build(&scene, &lighting(), &p);
    let value = [0.8, 0.3, 0.2];
    let report = t.relight_material("render", value).unwrap();
    assert!(report.built && !report.from_table, "{report:?}");
    assert!(report.tail.unwrap() > 1e-12);
    let exact_t = {
        let mut e = build(&scene, &lighting(), &p);
        e.relight(&LightingChange {
            material_reflectance: vec![("render".into(), value)],
            ..LightingChange::default()
        })
        .unwrap()
    };
    assert_close("refused", t.solution(), &exact_t);
    // The refusal is kept: the next change of the material relights exactly without a build.
    let report = t.relight_material("render", [0.5; 3]).unwrap();
    assert!(!report.built && !report.from_table, "{report:?}");
}

#[test]
fn table_relights_are_bit_identical_on_one_and_two_threads() {
    let scene = yard([0.6; 3]);
    let p = params(RelightStrategy::LinearResponses, Sweep::Shooting);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut t = build(&scene, &lighting(), &p);
                t.relight_material("render", [0.7, 0.4, 0.1]).unwrap();
                t.relight_material("render", [0.2, 0.5, 0.9]).unwrap();
                t.solution().clone()
            })
    };
    let (one, two) = (on(1), on(2));
    let bits = |s: &Solution| -> Vec<u64> {
        s.groups
            .iter()
            .flat_map(|g| g.radiosity_rgb.iter())
            .flat_map(|v| v.map(f64::to_bits))
            .collect()
    };
    assert_eq!(bits(&one), bits(&two));
}

/// A relight back from a channel at ρ = 0 against the solution it started from (the same links):
/// a ρ of 0 keeps nothing of the light the element gathers, so that relight is shot cold
/// (transfer.rs); within the same-links tolerance of `transfer_tests`.
#[test]
fn a_material_lit_again_from_zero_returns_to_its_solution() {
    let scene = yard([0.6; 3]);
    let mut t = build(
        &scene,
        &lighting(),
        &params(RelightStrategy::LinearResponses, Sweep::Shooting),
    );
    let start = t.solution().clone();
    for value in [[0.0, 0.5, 0.5], [0.6; 3]] {
        t.relight(&LightingChange {
            material_reflectance: vec![("render".into(), value)],
            ..LightingChange::default()
        })
        .unwrap();
    }
    let d = t.solution().relative_difference(&start).unwrap();
    assert!(
        d.l1_rel < super::transfer_tests::SAME_LINKS_L1_REL_TOL,
        "L1 {}",
        d.l1_rel
    );
}
