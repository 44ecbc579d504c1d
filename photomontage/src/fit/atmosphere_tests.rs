//! Tests of the eq. 7 haze fit (Durisch's first inversion) on seeded synthetic ground truth.

use super::*;
use crate::atmosphere::schachter::apparent_radiance;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::sync::Mutex;

/// Exact synthetic samples: the fit must reach the truth to round-off amplified by the
/// conditioning of the exponential fit (≲ 1e-9 here); 1e-7 leaves margin.
const EXACT_TOL: f64 = 1e-7;

struct Recorder(Mutex<Vec<FitIteration>>);
use super::super::FitIteration;
impl FitObserver for Recorder {
    fn on_iteration(&self, event: &FitIteration) {
        self.0.lock().unwrap().push(*event);
    }
}

#[test]
fn recovers_exact_haze_and_reports_iterations() {
    let (tau, l0, linf) = (0.62, 0.12, 0.85);
    let samples: Vec<(f64, f64)> = [120.0, 480.0, 900.0, 1700.0, 2600.0]
        .iter()
        .map(|&d| (d, apparent_radiance(l0, linf, tau, d, 1000.0)))
        .collect();
    let rec = Arc::new(Recorder(Mutex::new(Vec::new())));
    let s = solve_eq7(linf, &samples, 1000.0, Some((rec.clone(), 2))).unwrap();
    assert!((s.transmittance - tau).abs() < EXACT_TOL, "{s:?}");
    assert!((s.true_radiance - l0).abs() < EXACT_TOL, "{s:?}");
    assert!(!s.clamped);
    let events = rec.0.lock().unwrap();
    assert!(
        events.len() >= 2,
        "observer saw {} iterations",
        events.len()
    );
    assert!(
        events
            .iter()
            .all(|e| e.channel == 2 && e.stage == FitStage::Atmosphere)
    );
    // The cost falls from the start (τ = 1) to the solution.
    assert!(events.last().unwrap().cost < events[0].cost * 1e-6);
}

#[test]
fn sigma_matches_the_scatter_of_repeated_noisy_fits() {
    // Monte-Carlo check of σ(τ) = sqrt((JᵀJ)⁻¹₂₂ s²)·dτ/du: over 400 seeded noisy sample
    // sets the spread of the fitted τ must match the mean predicted σ.
    let (tau, l0, linf, noise) = (0.7, 0.1, 0.8, 0.004);
    let distances = [100.0, 300.0, 600.0, 1000.0, 1500.0, 2200.0, 3000.0];
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let normal = Normal::new(0.0, noise).unwrap();
    let (mut taus, mut sigmas) = (Vec::new(), Vec::new());
    for _ in 0..400 {
        let samples: Vec<(f64, f64)> = distances
            .iter()
            .map(|&d| {
                (
                    d,
                    apparent_radiance(l0, linf, tau, d, 1000.0) + normal.sample(&mut rng),
                )
            })
            .collect();
        let s = solve_eq7(linf, &samples, 1000.0, None).unwrap();
        taus.push(s.transmittance);
        sigmas.push(s.transmittance_sigma.unwrap());
    }
    let mean = taus.iter().sum::<f64>() / taus.len() as f64;
    let spread =
        (taus.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / (taus.len() - 1) as f64).sqrt();
    let predicted = sigmas.iter().sum::<f64>() / sigmas.len() as f64;
    // 400 draws estimate a standard deviation to ≈ 1/sqrt(2·400) = 3.5 %; the linearised σ
    // is itself approximate for this curvature: 20 % agreement is the test.
    assert!(
        (spread / predicted - 1.0).abs() < 0.2,
        "spread {spread} vs predicted {predicted}"
    );
    assert!(
        (mean - tau).abs() < 3.0 * spread / 20.0,
        "bias {}",
        mean - tau
    );
}

#[test]
fn random_truths_from_the_paper_start() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..50 {
        let tau: f64 = rng.random_range(0.2..0.995);
        let l0: f64 = rng.random_range(0.0..2.0);
        let linf: f64 = rng.random_range(0.2..1.5);
        if (l0 - linf).abs() < 0.05 {
            continue;
        }
        let samples: Vec<(f64, [f64; 3])> = (0..5)
            .map(|_| {
                let d = rng.random_range(50.0..3000.0);
                (d, [apparent_radiance(l0, linf, tau, d, 1000.0); 3])
            })
            .collect();
        let fit = fit_atmosphere_rgb([linf; 3], &samples, 1000.0, None).unwrap();
        for k in 0..3 {
            assert!(
                (fit.transmittance[k] - tau).abs() < EXACT_TOL,
                "{fit:?} τ {tau}"
            );
            assert!((fit.true_colour[k] - l0).abs() < 1e-6, "{fit:?} L0 {l0}");
        }
    }
}

#[test]
fn a_corrupted_sample_is_flagged_and_does_not_bias() {
    // Ten samples, one (10 %) mis-clicked on a darker object: flagged, τ exact again.
    let (tau, l0, linf) = ([0.7, 0.65, 0.55], [0.2, 0.22, 0.25], [0.7, 0.75, 0.9]);
    let samples: Vec<(f64, [f64; 3])> = (0..10)
        .map(|i| {
            let d = 100.0 + 300.0 * f64::from(i);
            let mut c = [0, 1, 2].map(|k| apparent_radiance(l0[k], linf[k], tau[k], d, 1000.0));
            if i == 6 {
                c = c.map(|v| v * 0.7);
            }
            (d, c)
        })
        .collect();
    let plain = fit_atmosphere_rgb(linf, &samples, 1000.0, None).unwrap();
    assert!(
        (plain.transmittance[0] - tau[0]).abs() > 0.01,
        "the outlier biases a plain fit"
    );
    let fit = fit_atmosphere_robust(linf, &samples, 1000.0, 3.5, None).unwrap();
    assert_eq!(fit.flagged.iter().filter(|f| **f).count(), 1);
    assert!(fit.flagged[6]);
    for k in 0..3 {
        assert!((fit.transmittance[k] - tau[k]).abs() < EXACT_TOL, "{fit:?}");
    }
}

#[test]
fn inconsistent_samples_are_clamped_to_clear_air() {
    // Contrast growing with distance: τ > 1 would fit; clamped to 1.
    let samples = [(100.0, 0.5), (500.0, 0.4), (1000.0, 0.3)];
    let s = solve_eq7(0.6, &samples, 1000.0, None).unwrap();
    assert!(s.clamped);
    assert!((s.transmittance - 1.0).abs() < 1e-15);
    assert!(s.transmittance_sigma.is_none());
}

/// Eq. 7 fit from samples stored as f32 colours: their 7-digit rounding (≈6e-8 relative) is
/// amplified by the fit's conditioning (distances 0.15–4 dₐ) to ≲1e-6; 1e-5 leaves margin.
const COLOUR_FIT_TOL: f32 = 1e-5;
/// Noise-free synthetic data: Gauss–Newton converges quadratically to round-off.
const FIT_TOL: f64 = 1e-9;

#[test]
fn eq7_fit_recovers_seeded_ground_truth() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..20 {
        let tau: f64 = rng.random_range(0.3..0.99);
        let l0: f64 = rng.random_range(0.0..2.0);
        let linf: f64 = rng.random_range(0.2..1.5);
        if (l0 - linf).abs() < 0.05 {
            continue; // an object of the horizon's colour shows no haze
        }
        let samples: Vec<(f64, f64)> = (0..6)
            .map(|_| {
                let d = rng.random_range(100.0..4000.0);
                (d, apparent_radiance(l0, linf, tau, d, 1000.0))
            })
            .collect();
        let fit = solve_eq7(linf, &samples, 1000.0, None).unwrap();
        assert!(
            (fit.transmittance - tau).abs() < FIT_TOL,
            "{fit:?} vs τ {tau}"
        );
        assert!(
            (fit.true_radiance - l0).abs() < FIT_TOL,
            "{fit:?} vs L0 {l0}"
        );
        assert!(fit.rms_residual < FIT_TOL);
    }
}

#[test]
fn colour_fit_recovers_per_channel_haze() {
    // Bluish haze: short wavelengths are scattered more, so τ is lowest in blue.
    let tau = Colour::from_slice(&[0.85, 0.80, 0.70]);
    let horizon = Colour::from_slice(&[0.70, 0.75, 0.90]);
    let truth = SchachterAtmosphere::new(tau, horizon, 1000.0, 3).unwrap();
    let wall = Colour::from_slice(&[0.35, 0.30, 0.20]);
    let samples: Vec<(f64, Colour)> = [150.0, 600.0, 1400.0, 2500.0, 4000.0]
        .iter()
        .map(|&d| (d, truth.apparent(&wall, d)))
        .collect();
    let (fitted, l0) = fit_schachter_atmosphere(horizon, &samples, 1000.0, 3).unwrap();
    for k in 0..3 {
        assert!((fitted.transmittance().channels[k] - tau.channels[k]).abs() < COLOUR_FIT_TOL);
        assert!((l0.channels[k] - wall.channels[k]).abs() < COLOUR_FIT_TOL);
    }
}

#[test]
fn eq7_fit_rejects_undetermined_input() {
    assert!(matches!(
        solve_eq7(0.5, &[(100.0, 0.3)], 1000.0, None),
        Err(AtmosphereError::NotEnoughSamples { .. })
    ));
    assert!(matches!(
        solve_eq7(0.5, &[(100.0, 0.3), (100.0, 0.31)], 1000.0, None),
        Err(AtmosphereError::NotEnoughSamples { .. })
    ));
    assert!(matches!(
        solve_eq7(0.5, &[(100.0, 0.5), (300.0, 0.5)], 1000.0, None),
        Err(AtmosphereError::Undetermined { .. })
    ));
    assert!(matches!(
        solve_eq7(0.5, &[(100.0, f64::NAN), (300.0, 0.5)], 1000.0, None),
        Err(AtmosphereError::InvalidSample { index: 0 })
    ));
}
