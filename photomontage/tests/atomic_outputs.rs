//! Atomic outputs (issue 16 item 4): a render killed with SIGKILL at any moment leaves the old
//! output file or the complete new one, never a torn or empty one. 20 kills at seeded moments
//! spread over a render's whole run time (loading, tracing, encoding, writing), into EXR and PNG.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TRIES: u32 = 20;
const SIZE_PX: [u32; 2] = [256, 192];

fn render(site: &Path, out: &Path, seed: u32) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_photomontage"));
    c.arg("render")
        .arg(site)
        .args(["--view", "p1", "--seed", &seed.to_string(), "--out"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

#[test]
fn a_killed_render_leaves_the_old_file_or_the_complete_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site_sized(dir.path(), SIZE_PX);
    for ext in ["exr", "png"] {
        // The two possible contents: the old file (seed 1) and the complete new one (seed 2).
        let old = dir.path().join(format!("old.{ext}"));
        let new = dir.path().join(format!("new.{ext}"));
        assert!(render(&site, &old, 1).status().unwrap().success());
        let start = Instant::now();
        assert!(render(&site, &new, 2).status().unwrap().success());
        let run_time = start.elapsed();
        let (old_bytes, new_bytes) = (std::fs::read(&old).unwrap(), std::fs::read(&new).unwrap());
        assert_ne!(old_bytes, new_bytes, "the seeds must give different files");
        let out = dir.path().join(format!("out.{ext}"));
        let mut state = 0x2545_f491_u32;
        let (mut saw_old, mut saw_new) = (0, 0);
        for _ in 0..TRIES {
            std::fs::write(&out, &old_bytes).unwrap();
            // A seeded moment between 0 and 120 % of a full run.
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let fraction = f64::from(state >> 8) / f64::from(1_u32 << 24) * 1.2;
            let mut child = render(&site, &out, 2).spawn().unwrap();
            std::thread::sleep(run_time.mul_f64(fraction));
            let _ = child.kill(); // SIGKILL on Unix
            let _ = child.wait();
            let now = std::fs::read(&out).unwrap();
            if now == old_bytes {
                saw_old += 1;
            } else if now == new_bytes {
                saw_new += 1;
            } else {
                panic!(
                    "{ext}: killed at {fraction:.2} of a run, the output is neither file ({} bytes)",
                    now.len()
                );
            }
        }
        eprintln!("{ext}: {saw_old} kills left the old file, {saw_new} the new one");
        assert!(saw_old > 0, "{ext}: no kill landed before the rename");
        std::thread::sleep(Duration::from_millis(10));
    }
}
