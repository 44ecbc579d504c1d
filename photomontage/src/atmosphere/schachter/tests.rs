//! Tests of Schachter's model: closed-form round trips, limits, Koschmieder's law, (the eq. 7 fit is tested in
//! `fit/atmosphere_tests.rs`).

use super::*;
use proptest::prelude::*;

/// Forward then inverse in f64 loses only round-off, amplified by 1/τ^(d/dₐ) ≤ 1e3 here.
const ROUND_TRIP_TOL: f64 = 1e-10;
/// The `Colour` path stores f32 (7 digits), amplified by 1/τ^(d/dₐ) ≤ ~20 in these cases.
const COLOUR_ROUND_TRIP_TOL: f32 = 1e-5;

#[test]
fn distance_zero_is_identity_and_infinity_is_horizon() {
    for tau in [0.2, 0.7, 0.999] {
        assert!((apparent_radiance(0.3, 0.9, tau, 0.0, 1000.0) - 0.3).abs() < 1e-15);
        assert!((apparent_radiance(0.3, 0.9, tau, f64::INFINITY, 1000.0) - 0.9).abs() < 1e-15);
        assert!((apparent_radiance(0.3, 0.9, tau, 1e9, 1.0) - 0.9).abs() < 1e-15);
    }
    // Clear air: unchanged at any distance.
    assert!((apparent_radiance(0.3, 0.9, 1.0, 5e4, 1000.0) - 0.3).abs() < 1e-15);
    // At the reference distance the transmission is τ itself: L = 0.5·0.3 + 0.5·0.9 = 0.6.
    assert!((apparent_radiance(0.3, 0.9, 0.5, 1000.0, 1000.0) - 0.6).abs() < 1e-15);
    // Two reference distances: τ² = 0.25 → 0.25·0.3 + 0.75·0.9 = 0.75.
    assert!((apparent_radiance(0.3, 0.9, 0.5, 2000.0, 1000.0) - 0.75).abs() < 1e-15);
}

#[test]
fn second_inversion_undoes_forward() {
    for &(l0, linf, tau, d) in &[
        (0.0, 1.0, 0.5, 3000.0),
        (2.5, 0.4, 0.9, 12_000.0),
        (0.1, 0.1, 0.3, 500.0),
        (7.0, 0.0, 0.95, 40_000.0),
    ] {
        let l = apparent_radiance(l0, linf, tau, d, 1000.0);
        let back = true_radiance(l, linf, tau, d, 1000.0);
        assert!(
            (back - l0).abs() < ROUND_TRIP_TOL * (1.0 + l0),
            "{l0} → {l} → {back}"
        );
    }
}

#[test]
fn koschmieder_black_object_at_visibility_has_threshold_contrast() {
    // V = 10 km: σ = ln(50)/V, so τ over 1 km is e^(−0.391202) = 0.676243.
    let tau = transmittance_from_visibility(10_000.0, 1000.0, KOSCHMIEDER_CONTRAST);
    assert!((tau - (-(50.0_f64).ln() / 10.0).exp()).abs() < 1e-15);
    assert!((tau - 0.676_243).abs() < 1e-6, "{tau}");
    let linf = 0.8;
    let l = apparent_radiance(0.0, linf, tau, 10_000.0, 1000.0);
    assert!(((linf - l) / linf - 0.02).abs() < 1e-12);
    // WMO's 5 % threshold: MOR = ln(20)/σ = 2.996/σ.
    let tau_mor = transmittance_from_visibility(2996.0, 1.0, WMO_MOR_CONTRAST);
    assert!((-tau_mor.ln() - 1.0 / 1000.0).abs() < 1e-6);
}

#[test]
fn colour_atmosphere_round_trip_and_limits() {
    let tau = Colour::from_slice(&[0.80, 0.85, 0.90]);
    let horizon = Colour::from_slice(&[0.6, 0.7, 0.9]);
    let atm = SchachterAtmosphere::new(tau, horizon, 1000.0, 3).unwrap();
    let object = Colour::from_slice(&[0.2, 0.3, 0.1]);
    for d in [0.0, 250.0, 2000.0, 10_000.0] {
        let seen = atm.apparent(&object, d);
        let back = atm.true_colour(&seen, d).unwrap();
        for k in 0..3 {
            assert!(
                (back.channels[k] - object.channels[k]).abs() < COLOUR_ROUND_TRIP_TOL,
                "d = {d}"
            );
        }
    }
    assert_eq!(atm.apparent(&object, 0.0), object);
    let far = atm.apparent(&object, f64::INFINITY);
    assert_eq!(far.channels[..3], horizon.channels[..3]);
    assert!(matches!(
        atm.true_colour(&far, 1e6),
        Err(AtmosphereError::TooHazyToInvert { channel: 0, .. })
    ));
    assert_eq!(SchachterAtmosphere::clear(3).apparent(&object, 1e5), object);
}

#[test]
fn invalid_atmospheres_are_errors() {
    let h = Colour::BLACK;
    let bad = Colour::from_slice(&[0.5, 1.5, 0.5]);
    assert!(matches!(
        SchachterAtmosphere::new(bad, h, 1000.0, 3),
        Err(AtmosphereError::InvalidTransmittance { channel: 1, .. })
    ));
    let zero = Colour::from_slice(&[0.5, 0.0, 0.5]);
    assert!(SchachterAtmosphere::new(zero, h, 1000.0, 3).is_err());
    let ok = Colour::from_slice(&[0.5, 0.5, 0.5]);
    assert!(SchachterAtmosphere::new(ok, h, 0.0, 3).is_err());
    assert!(SchachterAtmosphere::new(ok, h, f64::NAN, 3).is_err());
    let atm = SchachterAtmosphere::new(ok, h, 1000.0, 3).unwrap();
    assert!(atm.true_colour(&ok, -1.0).is_err());
}

proptest! {
    #[test]
    fn forward_and_inverse_stay_finite_and_non_negative(
        l0 in 0.0_f64..100.0,
        linf in 0.0_f64..100.0,
        tau in 0.05_f64..=1.0,
        d in 0.0_f64..5000.0,
    ) {
        let l = apparent_radiance(l0, linf, tau, d, 1000.0);
        prop_assert!(l.is_finite() && l >= 0.0);
        // Between the object and the horizon colour.
        prop_assert!(l >= l0.min(linf) - 1e-12 && l <= l0.max(linf) + 1e-12);
        let t = transmission(tau, d, 1000.0);
        prop_assume!(t >= MIN_INVERTIBLE_TRANSMISSION);
        let back = true_radiance(l, linf, tau, d, 1000.0);
        prop_assert!(back.is_finite());
        prop_assert!((back - l0).abs() <= 1e-12 * (l0 + linf + 1.0) / t);
        prop_assert!(back >= -1e-12 * (l0 + linf + 1.0) / t);
    }
}
