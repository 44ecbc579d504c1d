//! The studio's jobs on its workers ([`crate::worker::Worker`]): starting a solve, polling every
//! worker once per frame (photo decoding, solve, render, file dialogs, fit) and acting on the
//! outcomes, the idle test the headless tests and the screenshot mode wait on, and the test hook
//! that makes a job panic.
//!
//! # Known limitations
//! A solve cannot be cancelled (the library solver has no cancellation hook).

use eframe::egui;

use crate::commands::Command;
use crate::{PhotoView, SideTab, Studio, WorkerJob, solve, worker};

impl Studio {
    /// Whether no worker is running and the current photo is fully decoded and uploaded.
    #[must_use]
    pub fn is_idle(&self) -> bool {
        let photo_ready = match self.current_photo.as_ref().and_then(|p| self.photos.get(p)) {
            Some(PhotoView::Ready(_) | PhotoView::Failed(_)) => true,
            Some(PhotoView::Loading) => false,
            None => self.current_photo.is_none(),
        };
        photo_ready
            && !self.solver.busy()
            && !self.loader.busy()
            && !self.render.busy()
            && !self.dialogs.busy()
            && !self.fit.worker.busy()
            && !self.study.busy()
            && !self.variants.busy()
            && !self.materials.elevation_busy()
    }

    /// Opens the Materials tab's unfolded elevation and draws it (the `--elevation` start
    /// option; the tab must be shown for the drawing to start).
    pub fn start_elevation(&mut self, irradiance: bool) {
        self.materials.request_elevation(irradiance);
    }

    /// Scrolls the Site & light tab to its render settings (the exposure and the radiosity
    /// switches) and keeps them in view (the `--light-render-settings` start option).
    pub fn scroll_light_to_render_settings(&mut self) {
        self.light.scroll_to_render = true;
    }

    /// Starts a solve of the site as it is now on the worker thread.
    pub fn start_solve(&mut self, ctx: &egui::Context) {
        let Some(doc) = self.doc.clone() else {
            return;
        };
        if solve::start_solve(&mut self.solver, doc, ctx) {
            self.say("solving…", false);
        } else {
            self.say("a solve is already running", true);
        }
    }

    pub(crate) fn poll_solve(&mut self) {
        match self.solver.poll() {
            worker::Poll::Done(solution) => {
                for f in &solution.failures {
                    self.say(format!("photo {} not solved: {}", f.id, f.error), true);
                }
                for w in &solution.warnings {
                    self.say(format!("warning: {w}"), false);
                }
                if let Some(doc) = self.doc.as_ref() {
                    let mut solved = doc.site.clone();
                    photomontage::site::apply_solution(&mut solved, &solution);
                    let mut batch: Vec<Command> = solved
                        .photos
                        .iter()
                        .map(|p| Command::SetOrientation {
                            photo: p.id.clone(),
                            interior: p.interior.clone(),
                            exterior: p.exterior.clone(),
                        })
                        .collect();
                    batch.push(Command::SetTiePoints(solved.tie_points.clone()));
                    self.apply(Command::Batch(batch), None);
                }
                let summary = solution.bundle_rms_px.map_or_else(
                    || format!("solved {} photo(s)", solution.photos.len()),
                    |r| {
                        format!(
                            "solved {} photo(s), bundle RMS {r:.3} px",
                            solution.photos.len()
                        )
                    },
                );
                self.say(summary, false);
                self.solution = Some(solution);
                self.tab = SideTab::Solve;
            }
            worker::Poll::Failed(e) => self.say(format!("{e}; the site is unchanged"), true),
            worker::Poll::Cancelled => self.say("solve cancelled; the site is unchanged", true),
            worker::Poll::Idle | worker::Poll::Running(_) => {}
        }
    }

    pub(crate) fn poll_workers(&mut self, ctx: &egui::Context) {
        for d in self.loader.poll() {
            let view = match d.result {
                Ok(p) => PhotoView::Ready(Box::new(p)),
                Err(e) => {
                    self.say(e.clone(), true);
                    PhotoView::Failed(e)
                }
            };
            self.photos.insert(d.photo_id, view);
        }
        self.poll_solve();
        self.poll_render(ctx);
        self.poll_dialogs(ctx);
        self.poll_fit(ctx);
        self.poll_study(ctx);
        self.poll_variants(ctx);
        // Start decoding the current photo.
        if let (Some(id), Some(doc)) = (self.current_photo.clone(), self.doc.as_ref())
            && !self.photos.contains_key(&id)
            && let Some(p) = doc.site.photos.iter().find(|p| p.id == id)
        {
            let path = doc.resolve(&p.file);
            self.photos.insert(id.clone(), PhotoView::Loading);
            self.loader.request(id, path, ctx);
        }
        if self.loader.busy() || self.solver.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// Test hook: the next job of `job` panics on its worker thread
    /// ([`worker::Worker::inject_panic_for_tests`]); the kittests use it to check that a crashed
    /// solve, fit or render ends as a message and leaves the studio usable. Not reachable from
    /// the UI, the command line or any file.
    #[doc(hidden)]
    pub fn inject_panic_for_tests(&mut self, job: WorkerJob) {
        match job {
            WorkerJob::Solve => self.solver.inject_panic_for_tests(),
            WorkerJob::Fit => self.fit.worker.inject_panic_for_tests(),
            WorkerJob::Render => self.render.inject_panic_for_tests(),
        }
    }
}
