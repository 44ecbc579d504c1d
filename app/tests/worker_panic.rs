//! A crashed job never leaves the studio stuck: the Solve, Run fit and Render Start buttons
//! start their jobs on the one worker type (`photomontage_studio::worker::Worker`), whose test
//! hook (`Studio::inject_panic_for_tests`) makes the next job panic on its thread. Each panic
//! must end as an error message naming the job and the panic's payload, free the panel (not
//! busy), and the same button must then run the job normally.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::kittest::Queryable;
use photomontage::verified::AvrLevel;
use photomontage_studio::render_panel::Quality;
use photomontage_studio::worker::INJECTED_PANIC;
use photomontage_studio::{Studio, WorkerJob};

/// The last message, which must be an error containing `expected`.
fn assert_last_error(s: &Studio, expected: &str) {
    let last = s.messages().last().expect("a message");
    assert!(
        last.is_error && last.text.contains(expected),
        "expected an error containing {expected:?}, got {:?}",
        s.messages()
    );
}

#[test]
fn a_panicking_solve_fit_or_render_is_a_message_and_the_studio_stays_usable() {
    let (_dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);

    // Solve: the panic is a message, nothing solved, then Solve works.
    h.state_mut().inject_panic_for_tests(WorkerJob::Solve);
    h.get_by_label("Solve").click();
    step_until(&mut h, "panicking solve", Studio::is_idle);
    assert_last_error(h.state(), &format!("solve panicked: {INJECTED_PANIC}"));
    assert!(h.state().solution().is_none());
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());

    // Render: the panic frees the panel; the next render (AVR1 wireline: no tracing, so the
    // test stays short) finishes with a montage.
    h.get_by_label("Render").click();
    h.run();
    h.state_mut().inject_panic_for_tests(WorkerJob::Render);
    h.get_by_label("Start").click();
    step_until(&mut h, "panicking render", |s| !s.render_panel().busy());
    assert_last_error(
        h.state(),
        &format!("render of P1 failed: render panicked: {INJECTED_PANIC}"),
    );
    assert!(h.state().render_panel().montage().is_none());
    h.state_mut().render_panel_mut().quality = Quality {
        avr: AvrLevel::Avr1,
        ..Quality::default()
    };
    h.get_by_label("Start").click();
    h.step();
    step_until(&mut h, "render after the panic", |s| {
        !s.render_panel().busy() && s.render_panel().montage().is_some()
    });
    let last = h.state().messages().last().unwrap().clone();
    assert!(
        !last.is_error && last.text.starts_with("rendered P1 (AVR1)"),
        "{last:?}"
    );

    // Fit: the panic is the fit's error, and Run fit is enabled again.
    h.get_by_label("Fit tab").click();
    h.run();
    h.state_mut().inject_panic_for_tests(WorkerJob::Fit);
    h.get_by_label("Run fit").click();
    step_until(&mut h, "panicking fit", Studio::is_idle);
    assert_last_error(
        h.state(),
        &format!("fit failed: lighting fit panicked: {INJECTED_PANIC}"),
    );
    assert!(h.state().fit_report().is_none());
    // Run fit again: the fit itself runs now and answers (the courtyard has no fit samples,
    // so with the library's own message, not a panic).
    let before = h.state().messages().len();
    h.get_by_label("Run fit").click();
    h.step();
    step_until(&mut h, "fit after the panic", Studio::is_idle);
    let last = h.state().messages().last().unwrap().clone();
    assert!(
        h.state().messages().len() > before
            && last.text.starts_with("fit ")
            && !last.text.contains("panicked"),
        "{:?}",
        h.state().messages()
    );
}
