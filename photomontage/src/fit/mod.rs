//! Lighting fitted to the photos: the first inversions of Durisch 1992 §4.2 (atmosphere, eq. 7)
//! and §4.3 (daylight, eq. 9), by least squares with uncertainties, residuals and warnings, so the
//! lighting of a verified view is as auditable as its geometry.
//!
//! - [`atmosphere`]: τₐ and L₀ per channel from samples of one material at different distances
//!   (eq. 7), argmin's Gauss–Newton with a line search on a supplied Jacobian, σ(τₐ) from
//!   (JᵀJ)⁻¹·s². [`crate::fit::atmosphere::fit_schachter_atmosphere`] applies it per channel.
//! - [`daylight`]: k_s, k_u, k_h per channel from samples of diffuse materials under different
//!   illumination (eq. 9, with interreflection; several materials share absolute weights): the irradiance components E_s, E_u, E_h per sample with the scene's
//!   visibility, non-negative least squares, robust flagging of outlying samples.
//! - [`interreflection`]: the light the photographed surroundings reflect onto a daylight
//!   sample (E_r), gathered from its photo as the renderer does, subtracted in eq. 9.
//! - [`colour`]: a sample's colour read robustly from the photo (median over a window, saturated
//!   and underexposed pixels rejected), linearised.
//! - [`pick`]: the scene polygon (and its material) a pixel of a photo shows, for picking
//!   samples on the photo.
//! - [`sun_check`]: the sun direction measured from an object/shadow pair against the SPA sun for
//!   the photo's time, with the camera-clock offset that would explain a disagreement.
//! - [`site`]: the glue that runs all of it on a site file; [`report`] its report and the
//!   write-back into the site.
//!
//! Progress of the iterative solvers is reported through [`FitObserver`] (an adapter turns it
//! into an argmin observer).
//!
//! # Known limitations
//! RGB only (the spectral mode of Durisch's Appendix A is not used here); the atmosphere is fitted
//! with the horizon colour L∞ given (picked in the photo), as in the paper; the daylight weights
//! are relative unless the material's diffuse reflectance is given in the material library.

pub mod atmosphere;
pub mod colour;
pub mod daylight;
pub mod interreflection;
pub mod natural_scene;
pub mod pick;
pub mod radiosity_interreflection;
pub mod report;
pub mod site;
pub mod sun_check;

use std::sync::Arc;

use argmin::core::{Error as ArgminError, KV, State, observers::Observe};

/// Which fit an iteration belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FitStage {
    /// The atmosphere's first inversion (eq. 7).
    Atmosphere,
    /// The daylight first inversion (eq. 9), one round of the robust refit.
    Daylight,
}

/// One iteration of a fit, as reported to a [`FitObserver`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FitIteration {
    /// Which fit.
    pub stage: FitStage,
    /// Colour channel (0 = red, 1 = green, 2 = blue).
    pub channel: usize,
    /// Iteration number (0 = the start).
    pub iteration: u64,
    /// Cost at this iteration (the solver's, here ‖r‖).
    pub cost: f64,
}

/// Receives the progress of the fits (the CLI prints it as a progress line, the studio shows it).
pub trait FitObserver: Send + Sync {
    /// Called once per solver iteration.
    fn on_iteration(&self, event: &FitIteration);

    /// Polled by [`site::fit_site`] between its steps (before each sample is located and read,
    /// before each daylight fit pass): `true` stops the fit with
    /// [`site::SiteFitError::Cancelled`]. The default never cancels.
    fn cancelled(&self) -> bool {
        false
    }
}

/// An observer that ignores everything.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl FitObserver for NoProgress {
    fn on_iteration(&self, _event: &FitIteration) {}
}

/// Adapter from argmin's observer interface to a [`FitObserver`].
pub(crate) struct ArgminProgress {
    pub(crate) inner: Arc<dyn FitObserver>,
    pub(crate) stage: FitStage,
    pub(crate) channel: usize,
}

impl<I: State<Float = f64>> Observe<I> for ArgminProgress {
    fn observe_init(&mut self, _name: &str, state: &I, _kv: &KV) -> Result<(), ArgminError> {
        self.report(state);
        Ok(())
    }

    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), ArgminError> {
        self.report(state);
        Ok(())
    }
}

impl ArgminProgress {
    fn report<I: State<Float = f64>>(&self, state: &I) {
        self.inner.on_iteration(&FitIteration {
            stage: self.stage,
            channel: self.channel,
            iteration: state.get_iter(),
            cost: state.get_cost(),
        });
    }
}
