//! The studio's one worker type: a job on a named thread with progress, cancellation, panic
//! capture and a repaint of the UI whenever it has something to show (the pattern of rerun,
//! which bans raw `std::thread::spawn` for the same reason). Solve, fit, render, the file
//! dialogs and photo decoding all run through [`Worker`].
//!
//! A job is a closure receiving a [`Progress`] handle: it reports a fraction and a message
//! ([`Progress::set`]), streams intermediate values to the UI ([`Progress::send`], e.g. the
//! render's finished tiles) and checks [`Progress::is_cancelled`] at its own safe points. The
//! UI calls [`Worker::poll`] every frame and gets [`Poll::Running`] with the latest progress,
//! then exactly once [`Poll::Done`], [`Poll::Failed`] or [`Poll::Cancelled`]. A panic inside the
//! job is caught (`catch_unwind`) and becomes `Failed("<name> panicked: <payload>")`; a job
//! thread that ends without an answer any other way (its channel disconnects) becomes
//! `Failed("<name> stopped without an answer")`, so a panel is never left busy forever.
//!
//! # Known limitations
//! Cancellation is cooperative: a job that never checks [`Progress::is_cancelled`] runs to its
//! end, and its result is then dropped and reported as [`Poll::Cancelled`]. One job per
//! `Worker` at a time (callers refuse a second request with a message). A panicking job still
//! prints the panic to stderr through the default panic hook.

use eframe::egui;
use std::any::Any;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The latest progress a job reported.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ProgressReport {
    /// Fraction done in 0…1, when the job knows it.
    pub fraction: Option<f32>,
    /// What the job is doing now (empty until it says).
    pub message: String,
    /// Whether a cancel was requested.
    pub cancelling: bool,
    /// Seconds since the job started.
    pub elapsed_s: f64,
}

/// The state of a worker, as seen from the UI thread.
#[derive(Debug, PartialEq)]
pub enum Poll<T> {
    /// No job was started (or its outcome was already returned).
    Idle,
    /// The job runs.
    Running(ProgressReport),
    /// The job returned this value.
    Done(T),
    /// The job panicked or its thread ended without an answer: a readable message.
    Failed(String),
    /// A cancel was requested and the job has ended.
    Cancelled,
}

struct Shared {
    fraction: Mutex<Option<f32>>,
    message: Mutex<String>,
    cancel: AtomicBool,
    ctx: egui::Context,
}

/// The job's handle: report progress, stream values to the UI, check for cancellation. Cloned
/// into library observers that want an owned handle (the fit's `FitObserver`).
pub struct Progress<U = ()> {
    shared: Arc<Shared>,
    tx: Sender<U>,
}

impl<U> Clone for Progress<U> {
    fn clone(&self) -> Self {
        Self {
            shared: Arc::clone(&self.shared),
            tx: self.tx.clone(),
        }
    }
}

impl<U> Progress<U> {
    /// Sets the fraction done (clamped to 0…1) and what the job is doing.
    pub fn set(&self, fraction: Option<f32>, message: impl Into<String>) {
        if let Ok(mut f) = self.shared.fraction.lock() {
            *f = fraction.map(|x| x.clamp(0.0, 1.0));
        }
        if let Ok(mut m) = self.shared.message.lock() {
            *m = message.into();
        }
        self.shared.ctx.request_repaint();
    }

    /// Sends an intermediate value to the UI thread (delivered in order by
    /// [`Worker::poll_with`] before the outcome).
    pub fn send(&self, update: U) {
        // A closed channel means the worker was dropped (the studio is gone or the job was
        // abandoned); nothing to report to.
        let _ = self.tx.send(update);
        self.shared.ctx.request_repaint();
    }

    /// Whether the UI asked the job to stop.
    #[must_use]
    pub fn is_cancelled(&self) -> bool {
        self.shared.cancel.load(Ordering::Relaxed)
    }

    /// The cancel flag itself, for library calls that take an `&AtomicBool`.
    #[must_use]
    pub fn cancel_flag(&self) -> &AtomicBool {
        &self.shared.cancel
    }
}

struct Running<T, U> {
    shared: Arc<Shared>,
    updates: Receiver<U>,
    outcome: Receiver<Result<T, String>>,
    started: Instant,
}

/// A job on a named worker thread (at most one at a time), with its progress, cancel flag and
/// outcome. `T`: the job's result; `U`: intermediate values it streams ([`Progress::send`]).
pub struct Worker<T, U = ()> {
    name: String,
    running: Option<Running<T, U>>,
    /// Test hook: the next job panics instead of running ([`Worker::inject_panic_for_tests`]).
    panic_next: bool,
}

/// The panic message of the test hook ([`Worker::inject_panic_for_tests`]).
pub const INJECTED_PANIC: &str = "injected fault (test hook)";

impl<T, U> Worker<T, U> {
    /// An idle worker whose thread and messages are called `name` ("render", "solve", …).
    #[must_use]
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            running: None,
            panic_next: false,
        }
    }
}

impl<T, U> Default for Worker<T, U> {
    fn default() -> Self {
        Self::new("worker")
    }
}

/// The text of a panic payload (`&str` and `String` payloads; others are named as such).
#[must_use]
pub fn panic_text(payload: &(dyn Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a non-text panic payload".to_owned())
}

impl<T: Send + 'static, U: Send + 'static> Worker<T, U> {
    /// Starts `job` on a thread named after the worker; `ctx` is repainted whenever the job
    /// reports and when it ends. Returns false (and starts nothing) when a job is running or
    /// the thread cannot be created.
    pub fn spawn(
        &mut self,
        ctx: &egui::Context,
        job: impl FnOnce(&Progress<U>) -> T + Send + 'static,
    ) -> bool {
        if self.running.is_some() {
            return false;
        }
        let shared = Arc::new(Shared {
            fraction: Mutex::new(None),
            message: Mutex::new(String::new()),
            cancel: AtomicBool::new(false),
            ctx: ctx.clone(),
        });
        let (update_tx, updates) = mpsc::channel();
        let (outcome_tx, outcome) = mpsc::channel();
        let progress = Progress {
            shared: Arc::clone(&shared),
            tx: update_tx,
        };
        let name = self.name.clone();
        let panic = self.panic_next;
        let spawned = std::thread::Builder::new()
            .name(self.name.clone())
            .spawn(move || {
                // The job owns everything it touches; a panic leaves nothing shared with the UI
                // half-updated except the progress fields, which are plain values.
                let result = std::panic::catch_unwind(AssertUnwindSafe(|| {
                    assert!(!panic, "{INJECTED_PANIC}");
                    job(&progress)
                }))
                .map_err(|payload| format!("{name} panicked: {}", panic_text(&*payload)));
                let ctx = progress.shared.ctx.clone();
                drop(progress);
                // A closed channel means the worker was dropped; nothing to report to.
                let _ = outcome_tx.send(result);
                ctx.request_repaint();
            });
        if spawned.is_err() {
            return false;
        }
        self.panic_next = false;
        self.running = Some(Running {
            shared,
            updates,
            outcome,
            started: Instant::now(),
        });
        true
    }

    /// Test hook: the next job started on this worker panics on its thread with
    /// [`INJECTED_PANIC`] instead of running (the kittests that check a crashed job leaves a
    /// usable studio use it, through `Studio::inject_panic_for_tests`). Nothing in the studio's
    /// UI, command line, settings or files calls it, so it cannot be triggered by accident.
    #[doc(hidden)]
    pub fn inject_panic_for_tests(&mut self) {
        self.panic_next = true;
    }

    /// Whether a job is running (its outcome not yet returned by [`Worker::poll`]).
    #[must_use]
    pub fn busy(&self) -> bool {
        self.running.is_some()
    }

    /// Asks the running job to stop at its next check of [`Progress::is_cancelled`].
    pub fn cancel(&self) {
        if let Some(r) = &self.running {
            r.shared.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Whether a cancel was requested for the running job.
    #[must_use]
    pub fn cancelling(&self) -> bool {
        self.running
            .as_ref()
            .is_some_and(|r| r.shared.cancel.load(Ordering::Relaxed))
    }

    /// The running job's latest progress.
    #[must_use]
    pub fn progress(&self) -> Option<ProgressReport> {
        let r = self.running.as_ref()?;
        Some(ProgressReport {
            fraction: r.shared.fraction.lock().ok().and_then(|f| *f),
            message: r
                .shared
                .message
                .lock()
                .map(|m| m.clone())
                .unwrap_or_default(),
            cancelling: r.shared.cancel.load(Ordering::Relaxed),
            elapsed_s: r.started.elapsed().as_secs_f64(),
        })
    }

    /// Hands the values the job sent since the last call to `on_update` (in order), then
    /// returns the job's state; the outcome (`Done`, `Failed`, `Cancelled`) is returned once,
    /// after which the worker is idle.
    pub fn poll_with(&mut self, mut on_update: impl FnMut(U)) -> Poll<T> {
        let Some(r) = self.running.as_ref() else {
            return Poll::Idle;
        };
        // Look at the outcome first: every update was sent before it, so draining afterwards
        // delivers all of them.
        let outcome = match r.outcome.try_recv() {
            Ok(o) => Some(o),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                Some(Err(format!("{} stopped without an answer", self.name)))
            }
        };
        while let Ok(u) = r.updates.try_recv() {
            on_update(u);
        }
        let Some(outcome) = outcome else {
            return self.progress().map_or(Poll::Idle, Poll::Running);
        };
        let cancelled = r.shared.cancel.load(Ordering::Relaxed);
        self.running = None;
        match outcome {
            Err(message) => Poll::Failed(message),
            Ok(_) if cancelled => Poll::Cancelled,
            Ok(value) => Poll::Done(value),
        }
    }

    /// [`Worker::poll_with`], dropping intermediate values.
    pub fn poll(&mut self) -> Poll<T> {
        self.poll_with(drop)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use std::sync::mpsc::channel;
    use std::time::Duration;

    /// Longest wait for a worker thread in these tests (they finish in milliseconds; the bound
    /// only turns a hang into a failure on a loaded machine).
    const WAIT: Duration = Duration::from_secs(30);

    fn wait<T: Send + 'static, U: Send + 'static>(
        w: &mut Worker<T, U>,
        mut on_update: impl FnMut(U),
    ) -> Poll<T> {
        let start = Instant::now();
        loop {
            match w.poll_with(&mut on_update) {
                Poll::Running(_) => {}
                other => return other,
            }
            assert!(start.elapsed() < WAIT, "the job did not end");
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    #[test]
    fn a_job_returns_its_value_once_then_the_worker_is_idle() {
        let mut w: Worker<u64> = Worker::new("sum");
        assert_eq!(w.poll(), Poll::Idle);
        assert!(w.spawn(&egui::Context::default(), |_| (1..=100).sum()));
        assert!(w.busy());
        assert_eq!(wait(&mut w, drop), Poll::Done(5050));
        assert!(!w.busy());
        assert_eq!(w.poll(), Poll::Idle);
    }

    #[test]
    fn progress_and_updates_reach_the_ui_in_order_before_the_outcome() {
        let mut w: Worker<&str, usize> = Worker::new("steps");
        let (go_tx, go_rx) = channel::<()>();
        let (at_tx, at_rx) = channel::<()>();
        w.spawn(&egui::Context::default(), move |p| {
            for i in 0..10 {
                p.send(i);
            }
            p.set(Some(0.5), "half way");
            at_tx.send(()).unwrap();
            go_rx.recv().unwrap();
            p.set(Some(2.0), "clamped");
            "end"
        });
        at_rx.recv_timeout(WAIT).unwrap();
        let mut seen = Vec::new();
        match w.poll_with(|u| seen.push(u)) {
            Poll::Running(r) => {
                assert_eq!(r.fraction, Some(0.5));
                assert_eq!(r.message, "half way");
                assert!(!r.cancelling);
            }
            other => panic!("expected Running, got {other:?}"),
        }
        assert_eq!(seen, (0..10).collect::<Vec<_>>());
        // A second job is refused while this one runs.
        assert!(!w.spawn(&egui::Context::default(), |_| "second"));
        go_tx.send(()).unwrap();
        assert_eq!(wait(&mut w, |u| seen.push(u)), Poll::Done("end"));
        assert_eq!(seen.len(), 10, "no update after the outcome");
    }

    #[test]
    fn cancel_is_seen_by_the_job_and_reported_as_cancelled() {
        let mut w: Worker<u32> = Worker::new("loop");
        let (started_tx, started_rx) = channel::<()>();
        w.spawn(&egui::Context::default(), move |p| {
            started_tx.send(()).unwrap();
            let mut n = 0;
            while !p.is_cancelled() {
                n += 1;
                std::thread::sleep(Duration::from_millis(1));
            }
            n
        });
        started_rx.recv_timeout(WAIT).unwrap();
        assert!(!w.cancelling());
        w.cancel();
        assert!(w.cancelling());
        assert_eq!(wait(&mut w, drop), Poll::Cancelled);
        assert!(!w.busy());
    }

    #[test]
    fn a_panic_becomes_a_failure_message_with_its_payload() {
        let mut w: Worker<()> = Worker::new("render");
        w.spawn(&egui::Context::default(), |_| panic!("tile 3 exploded"));
        assert_eq!(
            wait(&mut w, drop),
            Poll::Failed("render panicked: tile 3 exploded".into())
        );
        assert!(!w.busy());
        // The worker is usable again.
        w.spawn(&egui::Context::default(), |_| ());
        assert_eq!(wait(&mut w, drop), Poll::Done(()));
        // The test hook: the next job panics instead of running, the one after runs.
        w.inject_panic_for_tests();
        w.spawn(&egui::Context::default(), |_| {
            unreachable!("the hook panics first")
        });
        assert_eq!(
            wait(&mut w, drop),
            Poll::Failed(format!("render panicked: {INJECTED_PANIC}"))
        );
        w.spawn(&egui::Context::default(), |_| ());
        assert_eq!(wait(&mut w, drop), Poll::Done(()));
        // A formatted (String) payload too.
        let mut w: Worker<()> = Worker::new("solve");
        w.spawn(&egui::Context::default(), |_| panic!("{} of {}", 2, 5));
        assert_eq!(
            wait(&mut w, drop),
            Poll::Failed("solve panicked: 2 of 5".into())
        );
    }
}
