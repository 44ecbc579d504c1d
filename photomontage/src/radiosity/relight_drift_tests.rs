//! A long series of relights (a sun drag) against a cold shooting of the last one: each ΔB
//! shooting stops with a remainder under the stop rule's residual, and the transfer keeps that
//! remainder and shoots it once it carries more than the residual (`Transfer::unshot`), so the
//! series does not drift.
#![allow(clippy::unwrap_used)]

use super::transfer::{LightingChange, RelightStrategy, Sweep};
use super::transfer_tests::{STOP, build, lighting, params, sun_at, yard};
use super::{Solution, luminance};

/// Steps of 1° in the drag.
const STEPS: u32 = 120;

/// The drag's end is within its kept remainder (at most the residual) and its last one (at most
/// 0.9 × the residual) of the fixed point, the cold shooting within 0.9 × the residual, each
/// amplified by 1/(1 − ρF) < 2 (as `SAME_LINKS_L1_REL_TOL` argues): 2 × 2.8 < 6 residuals bound
/// their difference. A drag that dropped each remainder adds up to one residual per step
/// (1.3e-3 after these 120, 13 residuals; the kept ones end 2.7e-5 away).
const DRAG_L1_REL_TOL: f64 = 6.0 * STOP.residual;

/// The sun group's area-weighted L1 difference over `reference`'s.
pub(super) fn sun_l1_rel(a: &Solution, reference: &Solution) -> f64 {
    let (x, y) = (
        &a.groups[0].radiosity_rgb,
        &reference.groups[0].radiosity_rgb,
    );
    assert_eq!(reference.groups[0].name, "sun");
    let (mut diff, mut norm) = (0.0, 0.0);
    for (e, (p, q)) in x.iter().zip(y.iter()).enumerate() {
        let w = reference.mesh.element_node(e).area_m2;
        diff += luminance(&std::array::from_fn(|c| (p[c] - q[c]).abs())) * w;
        norm += luminance(&q.map(f64::abs)) * w;
    }
    diff / norm
}

#[test]
fn a_long_sun_drag_does_not_drift_from_a_cold_shooting() {
    let scene = yard([0.6, 0.5, 0.4]);
    let p = params(RelightStrategy::LinearResponses, Sweep::Shooting);
    let mut t = build(&scene, &lighting(), &p);
    let sun = |k: u32| sun_at(0.6, 2.3 + f64::from(k) * 1f64.to_radians());
    for k in 1..=STEPS {
        t.relight_in_place(&LightingChange {
            sun: Some(Some(sun(k))),
            ..LightingChange::default()
        })
        .unwrap();
    }
    let dragged = t.solution().clone();
    // The same sun shot cold: from a dark sun (nothing old, nothing carried).
    let mut cold = build(&scene, &lighting(), &p);
    for s in [None, Some(sun(STEPS))] {
        cold.relight_in_place(&LightingChange {
            sun: Some(s),
            ..LightingChange::default()
        })
        .unwrap();
    }
    let d = sun_l1_rel(&dragged, cold.solution());
    assert!(d < DRAG_L1_REL_TOL, "after {STEPS} steps: L1 {d:.2e}");
}
