//! Crash safety: the real studio binary applies scripted edits (the same command path as
//! clicks) to a temp copy of the sample site, autosaves, is killed with SIGKILL, and the site
//! opened again the way the studio opens it has every edit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use photomontage_studio::{Studio, StudioOptions, autosave};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The debounce is 0.5 s; the binary starts in well under a second even in debug builds. 60 s
/// only guards against a hung CI machine.
const AUTOSAVE_WAIT: Duration = Duration::from_secs(60);

#[test]
// Exact comparisons on purpose: the site file writes floats with round-trip precision.
#[allow(clippy::float_cmp)]
fn sigkill_after_autosave_loses_nothing() {
    let (dir, site_path) = common::copy_sample();
    let before = photomontage::site::SiteDocument::load(&site_path).expect("loads");
    let moved = before
        .site
        .observations
        .iter()
        .find(|o| o.photo == "P3")
        .expect("P3 has observations")
        .clone();
    let removed = before
        .site
        .observations
        .iter()
        .find(|o| o.photo == "P1")
        .expect("P1 has observations")
        .clone();
    let script = dir.path().join("edits.txt");
    let (x, y) = (moved.x_px + 1.25, moved.y_px - 2.5);
    std::fs::write(
        &script,
        format!(
            "# edits a user would make by clicking\nplace P3 {} {x} {y}\nremove P1 {}\ncontrol NEW1 1.0 2.0 3.0\n",
            moved.point, removed.point
        ),
    )
    .expect("script");

    let mut child = Command::new(env!("CARGO_BIN_EXE_photomontage-studio"))
        .arg(&site_path)
        .arg("--script")
        .arg(&script)
        .arg("--headless")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("studio starts");
    let sidecar = autosave::sidecar_path(&site_path);
    let start = Instant::now();
    loop {
        let text = std::fs::read_to_string(&sidecar).unwrap_or_default();
        if text.contains("NEW1") {
            break;
        }
        if let Ok(Some(status)) = child.try_wait() {
            panic!("studio exited early with {status}");
        }
        assert!(start.elapsed() < AUTOSAVE_WAIT, "no autosave appeared");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().expect("SIGKILL"); // Child::kill sends SIGKILL on Unix.
    let status = child.wait().expect("reaped");
    assert!(!status.success(), "killed, not exited");

    // The site file itself was never saved; the edits live in the sidecar.
    let on_disk = photomontage::site::SiteDocument::load(&site_path).expect("loads");
    assert_eq!(
        on_disk.site, before.site,
        "the kill did not touch the site file"
    );

    // Open it again the way the studio does.
    let studio = Studio::new(StudioOptions {
        site_path: site_path.clone(),
        state_path: None,
    });
    assert!(
        studio
            .messages()
            .iter()
            .any(|m| m.text.contains("restored")),
        "the user is told: {:?}",
        studio.messages()
    );
    let site = &studio.document().expect("open").site;
    let o = site
        .observations
        .iter()
        .find(|o| o.photo == "P3" && o.point == moved.point)
        .expect("moved observation");
    assert_eq!(
        (o.x_px, o.y_px),
        (x, y),
        "moved exactly (TOML floats round-trip)"
    );
    assert!(
        !site
            .observations
            .iter()
            .any(|o| o.photo == "P1" && o.point == removed.point),
        "removal kept"
    );
    let new = site
        .control_points
        .iter()
        .find(|c| c.id == "NEW1")
        .expect("new control point");
    assert_eq!(new.xyz, [1.0, 2.0, 3.0]);
    assert_eq!(studio.document().expect("open").path, site_path);
}
