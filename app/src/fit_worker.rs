//! The lighting fit on the studio's [`Worker`]: `photomontage::fit::site::fit_site` (the CLI's
//! call, default options; Durisch 1992 §4.2–4.3) on a snapshot of the site. The solver's
//! iterations come back through a `FitObserver` that writes them into the worker's progress
//! message, and the same observer carries the worker's cancel flag into the fit.
//!
//! # Known limitations
//! The fit polls the cancel flag between its steps (before each sample is read, before each
//! daylight pass), not inside one (a pass of the interreflection gather may take seconds).

use eframe::egui;
use photomontage::fit::site::{SiteFitOptions, SiteFitReport, fit_site};
use photomontage::fit::{FitIteration, FitObserver, FitStage};
use photomontage::site::SiteDocument;
use std::sync::Arc;

use crate::worker::{Poll, Progress, Worker};

/// The observer handed to the fit: iterations → progress message, cancel flag ← worker.
struct FitProgress(Progress);

impl FitObserver for FitProgress {
    fn on_iteration(&self, event: &FitIteration) {
        self.0.set(None, iteration_text(event));
    }

    fn cancelled(&self) -> bool {
        self.0.is_cancelled()
    }
}

/// One solver iteration as the Fit tab shows it.
#[must_use]
pub fn iteration_text(e: &FitIteration) -> String {
    let stage = match e.stage {
        FitStage::Atmosphere => "atmosphere (eq. 7)",
        FitStage::Daylight => "daylight (eq. 9)",
    };
    let channel = ["red", "green", "blue"].get(e.channel).unwrap_or(&"?");
    format!(
        "{stage} {channel} iteration {} |r| = {:.3e}",
        e.iteration, e.cost
    )
}

/// A fit running on the worker: its outcome is the report or the fit's error message.
pub struct FitWorker {
    worker: Worker<Result<SiteFitReport, String>>,
}

impl Default for FitWorker {
    fn default() -> Self {
        Self {
            worker: Worker::new("lighting fit"),
        }
    }
}

impl FitWorker {
    /// Starts `fit_site` on a snapshot of the site. False when a fit is already running.
    pub fn start(&mut self, doc: SiteDocument, ctx: &egui::Context) -> bool {
        self.worker.spawn(ctx, move |progress| {
            let observer: Arc<dyn FitObserver> = Arc::new(FitProgress(progress.clone()));
            fit_site(&doc, &SiteFitOptions::default(), Some(observer)).map_err(|e| e.to_string())
        })
    }

    /// Test hook: the next fit panics ([`Worker::inject_panic_for_tests`]).
    #[doc(hidden)]
    pub fn inject_panic_for_tests(&mut self) {
        self.worker.inject_panic_for_tests();
    }

    /// Whether a fit is running.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Asks the running fit to stop at its next step; it then polls as [`Poll::Cancelled`].
    pub fn cancel(&self) {
        self.worker.cancel();
    }

    /// Whether a cancel was requested for the running fit.
    #[must_use]
    pub fn cancelling(&self) -> bool {
        self.worker.cancelling()
    }

    /// The worker's state; the outcome is returned once.
    pub fn poll(&mut self) -> Poll<Result<SiteFitReport, String>> {
        self.worker.poll()
    }

    /// A line describing the progress: elapsed time and the latest solver iteration.
    #[must_use]
    pub fn progress_text(&self) -> Option<String> {
        let p = self.worker.progress()?;
        let secs = p.elapsed_s;
        Some(if p.cancelling {
            format!("cancelling… {secs:.1} s (stops at the fit's next step)")
        } else if p.message.is_empty() {
            format!("fitting… {secs:.1} s (locating and reading samples)")
        } else {
            format!("fitting… {secs:.1} s: {}", p.message)
        })
    }
}
