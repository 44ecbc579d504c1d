//! The sun through its axis responses against the sun group shot whole: the same fixed point
//! within the stop rule, the same bits on 1 and 2 threads, dropped by a reflectance change.
#![allow(clippy::unwrap_used)]

use crate::radiosity::TransferParams;
use crate::radiosity::relight_drift_tests::sun_l1_rel;
use crate::radiosity::sources::GroundBelowHorizon;
use crate::radiosity::transfer::{LightingChange, RelightStrategy, Sweep, Transfer};
use crate::radiosity::transfer_tests::{STOP, build, lighting, params, sun_at, yard};

/// Both relights stop within the residual of the same fixed point and keep a remainder under
/// it, each amplified by 1/(1 − ρF) < 2 (`relight_drift_tests`): 6 residuals bound their
/// difference.
const AXES_L1_REL_TOL: f64 = 6.0 * STOP.residual;

/// The yard with the unmodelled ground below the horizon (its sun-lit part is on the z axis).
fn params_with_ground(strategy: RelightStrategy) -> TransferParams {
    let mut p = params(strategy, Sweep::Shooting);
    p.solve.ground = Some(GroundBelowHorizon {
        albedo_rgb: [0.3, 0.2, 0.1],
        cluster_tolerance: 0.05,
    });
    p
}

/// A sun drag's step (a quarter degree of azimuth).
const STEP_RAD: f64 = 0.25 * std::f64::consts::PI / 180.0;

fn step(t: &mut Transfer, k: u32) {
    t.relight_in_place(&LightingChange {
        sun: Some(Some(sun_at(0.6, 2.3 + STEP_RAD * f64::from(k)))),
        ..LightingChange::default()
    })
    .unwrap();
}

#[test]
fn sun_steps_through_the_axes_match_the_sun_group_shot_whole() {
    let scene = yard([0.6, 0.5, 0.4]);
    let mut axes = build(
        &scene,
        &lighting(),
        &params_with_ground(RelightStrategy::LinearResponses),
    );
    // Warm Gauss–Seidel relights shoot the sun group as one (no axes).
    let mut whole = build(
        &scene,
        &lighting(),
        &params_with_ground(RelightStrategy::WarmGaussSeidel),
    );
    let mut kept_steps = 0;
    for k in 1..=12 {
        step(&mut axes, k);
        step(&mut whole, k);
        assert!(axes.sun_basis.is_some(), "step {k} goes through the axes");
        assert!(whole.sun_basis.is_none());
        // The direct light is exact at every step, shot or kept.
        assert_eq!(
            axes.solution().groups[0].direct_irradiance_rgb,
            whole.solution().groups[0].direct_irradiance_rgb
        );
        // The axes a step shot, by their convergence rows.
        let rows = &axes.solution().groups[0].convergence;
        let shot = ["x", "y", "z"]
            .iter()
            .filter(|a| rows.iter().any(|r| r.group == format!("sun ({a} axis)")))
            .count();
        kept_steps += 3 - shot;
        let d = sun_l1_rel(axes.solution(), whole.solution());
        assert!(d < AXES_L1_REL_TOL, "step {k}: L1 {d:.2e}");
    }
    // Some axes kept their remainder (read no link), some shot it.
    assert!(
        kept_steps > 0 && kept_steps < 36,
        "{kept_steps} of 36 axis steps kept"
    );
}

#[test]
fn a_reflectance_change_drops_the_axes_and_the_next_sun_step_builds_them_again() {
    let scene = yard([0.6, 0.5, 0.4]);
    let p = params_with_ground(RelightStrategy::LinearResponses);
    let mut t = build(&scene, &lighting(), &p);
    step(&mut t, 1);
    assert!(t.sun_basis.is_some());
    t.relight_in_place(&LightingChange {
        material_reflectance: vec![("render".into(), [0.3, 0.6, 0.2])],
        ..LightingChange::default()
    })
    .unwrap();
    assert!(
        t.sun_basis.is_none(),
        "the axes hold for the old reflectances"
    );
    step(&mut t, 2);
    assert!(t.sun_basis.is_some());
    // Against the same lighting and material shot whole.
    let mut whole = build(
        &scene,
        &lighting(),
        &params_with_ground(RelightStrategy::WarmGaussSeidel),
    );
    for k in [1, 2] {
        if k == 2 {
            whole
                .relight_in_place(&LightingChange {
                    material_reflectance: vec![("render".into(), [0.3, 0.6, 0.2])],
                    ..LightingChange::default()
                })
                .unwrap();
        }
        step(&mut whole, k);
    }
    let d = sun_l1_rel(t.solution(), whole.solution());
    assert!(d < AXES_L1_REL_TOL, "L1 {d:.2e}");
}

#[test]
fn sun_steps_through_the_axes_are_the_same_on_one_and_two_threads() {
    let scene = yard([0.6, 0.5, 0.4]);
    let p = params_with_ground(RelightStrategy::LinearResponses);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut t = build(&scene, &lighting(), &p);
            for k in 1..=6 {
                step(&mut t, k);
            }
            t.solution().groups[0].radiosity_rgb.clone()
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(
        one.iter()
            .zip(two.iter())
            .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits))
    );
}
