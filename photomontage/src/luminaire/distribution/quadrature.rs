//! Quadrature weights for [`super::PhotometricWeb::total_flux_lm`]: the exact integral of the
//! linearly interpolated web (see "Flux quadrature" in the module doc of [`super`]), trapezoid
//! weights across planes (cyclic over C) and closed-form sin/cos-weighted weights along the polar
//! angle.

use std::f64::consts::TAU;

#[derive(Clone, Copy)]
pub(super) enum Kernel {
    Sin,
    Cos,
}

/// Trapezoid weights (radians) on a non-cyclic axis; a single angle gets weight 0.
pub(super) fn trapezoid_weights(angles: &[f64]) -> Vec<f64> {
    let n = angles.len();
    (0..n)
        .map(|i| {
            if n < 2 {
                return 0.0;
            }
            let left = if i == 0 {
                0.0
            } else {
                angles[i] - angles[i - 1]
            };
            let right = if i + 1 == n {
                0.0
            } else {
                angles[i + 1] - angles[i]
            };
            0.5 * (left + right)
        })
        .collect()
}

/// Trapezoid weights over a cyclic axis of period 2π; a single angle gets the full 2π.
pub(super) fn cyclic_trapezoid_weights(angles: &[f64]) -> Vec<f64> {
    let n = angles.len();
    if n == 1 {
        return vec![TAU];
    }
    (0..n)
        .map(|i| {
            let prev = if i == 0 {
                angles[0] - (angles[n - 1] - TAU)
            } else {
                angles[i] - angles[i - 1]
            };
            let next = if i + 1 == n {
                angles[0] + TAU - angles[i]
            } else {
                angles[i + 1] - angles[i]
            };
            0.5 * (prev + next)
        })
        .collect()
}

/// Weights w such that Σ w_i f_i = ∫ f(x)·k(x) dx exactly for f linear between the samples,
/// k = sin or cos. Per segment [a, b] of width h:
/// sin: ∫ sin = cos a − cos b and ∫ (x−a) sin x = −h cos b + sin b − sin a;
/// cos: ∫ cos = sin b − sin a and ∫ (x−a) cos x = h sin b + cos b − cos a.
pub(super) fn linear_quadrature_weights(x: &[f64], kernel: Kernel) -> Vec<f64> {
    let mut w = vec![0.0; x.len()];
    for i in 1..x.len() {
        let (a, b) = (x[i - 1], x[i]);
        let h = b - a;
        if h <= 0.0 {
            continue;
        }
        let (whole, first_moment) = match kernel {
            Kernel::Sin => (a.cos() - b.cos(), -h * b.cos() + b.sin() - a.sin()),
            Kernel::Cos => (b.sin() - a.sin(), h * b.sin() + b.cos() - a.cos()),
        };
        // f = f_a + (f_b − f_a)(x − a)/h.
        w[i - 1] += whole - first_moment / h;
        w[i] += first_moment / h;
    }
    w
}
