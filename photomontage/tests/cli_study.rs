//! `photomontage study` on the small hand-made site of `common` (a black box on a ground plane,
//! 96 × 64 px), placed in Zurich with `time_zone = "Europe/Zurich"`: every frame is byte for byte
//! the `photomontage render` of the site at that time, the JSON lists the frames with the sun
//! `photomontage sun` gives, and bad input (no daylight, unknown zone, bad time text, no zone)
//! is refused with nothing written. Ctrl-C leaves the output folder absent.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;

const LATITUDE_DEG: f64 = 47.3769;
const LONGITUDE_DEG: f64 = 8.5417;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The common test site with a `[location]` in Zurich (`zone` as its time zone line, if any).
fn zurich_site(dir: &Path, zone: Option<&str>, size_px: [u32; 2]) -> PathBuf {
    let site = common::make_site_sized(dir, size_px);
    let text = std::fs::read_to_string(&site).unwrap();
    let zone_line = zone.map_or(String::new(), |z| format!("time_zone = \"{z}\"\n"));
    let location = format!(
        "[location]\nlatitude_deg = {LATITUDE_DEG}\nlongitude_deg = {LONGITUDE_DEG}\n{zone_line}\n[lighting]"
    );
    std::fs::write(&site, text.replacen("[lighting]", &location, 1)).unwrap();
    site
}

fn study(site: &Path, out: &Path, dates: &str, times: &str, extra: &[&str]) -> Output {
    bin()
        .arg("study")
        .arg(site)
        .args(["--view", "p1", "--dates", dates, "--times", times, "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn a_three_frame_study_equals_single_renders_and_the_spa() {
    let dir = tempfile::tempdir().unwrap();
    let site = zurich_site(dir.path(), Some("Europe/Zurich"), common::SIZE_PX);
    let out = dir.path().join("study");
    let o = study(
        &site,
        &out,
        "2026-06-21",
        "09:00,12:00,15:00",
        &["--json", "--spp-min", "4", "--spp-max", "8", "--seed", "7"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let frames = json["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    let expected_times = [
        "2026-06-21T09:00:00+02:00",
        "2026-06-21T12:00:00+02:00",
        "2026-06-21T15:00:00+02:00",
    ];
    let site_text = std::fs::read_to_string(&site).unwrap();
    for (frame, time) in frames.iter().zip(expected_times) {
        let mut keys: Vec<&str> = frame
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            ["file", "sun_azimuth_deg", "sun_elevation_deg", "time"],
            "{frame}"
        );
        assert_eq!(frame["time"], time);
        let file = frame["file"].as_str().unwrap();
        assert_eq!(
            file,
            format!("p1_2026-06-21_{}.png", &time[11..16].replace(':', ""))
        );
        // The sun is the one `photomontage sun` gives for the same place and instant.
        let sun = bin()
            .args(["sun", "--json", "--elevation-m", "0", "--time", time])
            .arg(format!("--lat={LATITUDE_DEG}"))
            .arg(format!("--lon={LONGITUDE_DEG}"))
            .output()
            .unwrap();
        assert!(sun.status.success(), "{}", stderr(&sun));
        let sun: serde_json::Value = serde_json::from_slice(&sun.stdout).unwrap();
        assert_eq!(frame["sun_azimuth_deg"], sun["azimuth_deg"], "{time}");
        assert_eq!(frame["sun_elevation_deg"], sun["elevation_deg"], "{time}");

        // The frame is the single render of the site at that time, byte for byte.
        let frame_site = dir.path().join(format!("frame_{}.toml", &time[11..13]));
        let lines: String = site_text
            .lines()
            .filter(|l| !l.starts_with("sun_manual"))
            .map(|l| {
                if l == "[lighting]" {
                    format!("[lighting]\ntime = \"{time}\"\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect();
        std::fs::write(&frame_site, lines).unwrap();
        let single = dir.path().join(format!("single_{}.png", &time[11..13]));
        let r = bin()
            .arg("render")
            .arg(&frame_site)
            .args([
                "--view",
                "p1",
                "--spp-min",
                "4",
                "--spp-max",
                "8",
                "--seed",
                "7",
            ])
            .arg("--out")
            .arg(&single)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", stderr(&r));
        assert_eq!(
            std::fs::read(out.join(file)).unwrap(),
            std::fs::read(&single).unwrap(),
            "frame {file} differs from the single render"
        );
    }
    // Shadows move between frames: the three frames are not all the same image.
    let images: Vec<Vec<u8>> = frames
        .iter()
        .map(|f| std::fs::read(out.join(f["file"].as_str().unwrap())).unwrap())
        .collect();
    assert!(images[0] != images[1] && images[1] != images[2]);
    let sheet = image::open(out.join("p1_contact_sheet.png")).unwrap();
    assert!(sheet.width() > 3 * 300, "{}", sheet.width());
    assert_eq!(json["contact_sheet"], "p1_contact_sheet.png");
}

#[test]
fn night_frames_are_skipped_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let site = zurich_site(dir.path(), Some("Europe/Zurich"), common::SIZE_PX);
    let out = dir.path().join("study");
    let o = study(&site, &out, "2026-12-21", "02:00,12:00", &["--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("skipping p1_2026-12-21_0200"),
        "{}",
        stderr(&o)
    );
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["frames"].as_array().unwrap().len(), 1);
    assert!(!out.join("p1_2026-12-21_0200.png").exists());
    assert!(out.join("p1_2026-12-21_1200.png").exists());
}

#[test]
fn bad_studies_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let site = zurich_site(dir.path(), Some("Europe/Zurich"), common::SIZE_PX);
    let out = dir.path().join("study");
    let cases: [(&Path, &str, &str, &[&str]); 4] = [
        // No daylight: Zurich at 01:00 and 23:30 in December.
        (
            &site,
            "2026-12-21",
            "01:00,23:30",
            &["no daylight frame", "nothing written"],
        ),
        (&site, "2026-06-21", "9am", &["--times", "9am"]),
        (&site, "2026-06-31", "12:00", &["--dates", "2026-06-31"]),
        // The hour the clocks skip in spring.
        (
            &site,
            "2026-03-29",
            "02:30",
            &["2026-03-29", "does not exist", "Europe/Zurich"],
        ),
    ];
    for (site, dates, times, needles) in cases {
        let o = study(site, &out, dates, times, &[]);
        assert!(!o.status.success(), "{dates} {times}");
        for needle in needles {
            assert!(stderr(&o).contains(needle), "{needle}: {}", stderr(&o));
        }
        assert!(!out.exists(), "{dates} {times} wrote {}", out.display());
    }

    let no_zone_dir = tempfile::tempdir().unwrap();
    let no_zone = zurich_site(no_zone_dir.path(), None, common::SIZE_PX);
    let o = study(&no_zone, &out, "2026-06-21", "12:00", &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("location.time_zone"), "{}", stderr(&o));
    assert!(!out.exists());

    let typo_dir = tempfile::tempdir().unwrap();
    let typo = zurich_site(typo_dir.path(), Some("Europe/Zurik"), common::SIZE_PX);
    let o = study(&typo, &out, "2026-06-21", "12:00", &[]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("location.time_zone") && e.contains("Europe/Zurik"),
        "{e}"
    );
    assert!(e.contains("did you mean `Europe/Zurich`"), "{e}");
    assert!(!out.exists());
}

#[test]
fn ctrl_c_leaves_no_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let site = zurich_site(dir.path(), Some("Europe/Zurich"), [1200, 800]);
    let out = dir.path().join("study");
    let child = bin()
        .arg("study")
        .arg(&site)
        .args([
            "--view",
            "p1",
            "--dates",
            "2026-03-20,2026-06-21,2026-09-22",
            "--times",
            "09:00,10:00,11:00,12:00,13:00,14:00,15:00",
            "--spp-min",
            "64",
            "--spp-max",
            "64",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (status, rest) = common::interrupt_once_started(child);
    assert!(!status.success(), "{rest:?}");
    assert!(rest.iter().any(|l| l.contains("cancelled")), "{rest:?}");
    assert!(!out.exists(), "a cancelled study wrote {}", out.display());
}

#[test]
fn shadow_maps_are_written_beside_the_frames() {
    let dir = tempfile::tempdir().unwrap();
    let site = zurich_site(dir.path(), Some("Europe/Zurich"), common::SIZE_PX);
    let out = dir.path().join("study");
    let o = study(
        &site,
        &out,
        "2026-06-21",
        "15:00",
        &["--json", "--shadow-maps", "--cell-m", "0.5"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let name = json["frames"][0]["shadow_map"].as_str().unwrap();
    assert_eq!(name, "p1_2026-06-21_1500_shadow.png");
    let map = image::open(out.join(name)).unwrap().to_rgb8();
    // The 20 m ground at 0.5 m cells is 40 cells, drawn at least 480 px wide plus margins.
    assert!(map.width() >= 480, "{}", map.width());
    // The box's shadow: some pixels have the added-shadow colour.
    assert!(map.pixels().any(|p| p.0 == [214, 40, 40]));

    // Shadow maps only: no montage, the map stands for the frame on the contact sheet.
    let maps_only = dir.path().join("maps");
    let o = study(
        &site,
        &maps_only,
        "2026-06-21",
        "15:00",
        &[
            "--json",
            "--shadow-maps",
            "--no-montages",
            "--cell-m",
            "0.5",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(json["frames"][0].get("file").is_none(), "{json}");
    assert_eq!(
        json["frames"][0]["shadow_map"].as_str(),
        Some("p1_2026-06-21_1500_shadow.png")
    );
    assert!(!maps_only.join("p1_2026-06-21_1500.png").exists());
    let again = image::open(maps_only.join("p1_2026-06-21_1500_shadow.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(again, map, "the same map with and without the montage");
    assert!(maps_only.join("p1_contact_sheet.png").exists());
    // --no-montages needs --shadow-maps: nothing would be made.
    let nothing = study(
        &site,
        &dir.path().join("nothing"),
        "2026-06-21",
        "15:00",
        &["--no-montages"],
    );
    assert!(!nothing.status.success());
    assert!(
        stderr(&nothing).contains("--shadow-maps"),
        "{}",
        stderr(&nothing)
    );
    assert!(!dir.path().join("nothing").exists());

    let bad = study(
        &site,
        &dir.path().join("bad"),
        "2026-06-21",
        "15:00",
        &["--shadow-maps", "--cell-m", "0"],
    );
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("--cell-m"), "{}", stderr(&bad));
}
