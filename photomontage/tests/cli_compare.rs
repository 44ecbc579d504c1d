//! `photomontage compare` and `render --variant` on the small hand-made site of `common` (a black
//! box on a ground plane, 96 × 64 px) with two design variants: `red_box` (the box painted red)
//! and `no_box` (the box hidden). The PDF has one A3 landscape page per variant whose text
//! (read back with poppler's `pdftotext`) names it; every variant's image is byte for byte the
//! single `render --variant`; the variant without the model gives the photo back unchanged; bad
//! variants are refused naming the variant and the model with nothing written; Ctrl-C leaves
//! nothing.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;

/// A3 landscape in PDF points (420 × 297 mm at 72/25.4 pt per mm), as `pdfinfo` prints it.
const A3_PTS: &str = "1190.55 x 841.89 pts";
const OPTIONS: [&str; 6] = ["--spp-min", "4", "--spp-max", "8", "--seed", "7"];

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const VARIANTS: &str = r#"
[[variants]]
name = "red_box"
visible_models = ["box"]

[[variants.materials]]
name = "black"
diffuse_rgb = [0.7, 0.05, 0.05]

[[variants]]
name = "no_box"
visible_models = []
"#;

fn site_with_variants(dir: &Path, size_px: [u32; 2]) -> PathBuf {
    let site = common::make_site_sized(dir, size_px);
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str(VARIANTS);
    std::fs::write(&site, text).unwrap();
    site
}

fn compare(site: &Path, dir: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("compare")
        .arg(site)
        .args(["--view", "p1", "--out"])
        .arg(dir.join("sheet.pdf"))
        .args(OPTIONS)
        .args(extra)
        .output()
        .unwrap()
}

/// Whether poppler-utils is installed; skipped with a notice outside CI, required in CI.
fn have_poppler() -> bool {
    let ok = Command::new("pdftotext").arg("-v").output().is_ok();
    if !ok {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "pdftotext (poppler-utils) is required in CI"
        );
        eprintln!("notice: pdftotext not installed; PDF read-back skipped");
    }
    ok
}

fn run_text(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn compare_writes_one_labelled_page_per_variant_equal_to_single_renders() {
    let dir = tempfile::tempdir().unwrap();
    let site = site_with_variants(dir.path(), common::SIZE_PX);
    let images = dir.path().join("images");
    let o = compare(
        &site,
        dir.path(),
        &[
            "--png",
            dir.path().join("sheet.png").to_str().unwrap(),
            "--images",
            images.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let pdf = dir.path().join("sheet.pdf");

    for name in ["red_box", "no_box"] {
        let single = dir.path().join(format!("single_{name}.png"));
        let r = bin()
            .arg("render")
            .arg(&site)
            .args(["--view", "p1", "--variant", name, "--out"])
            .arg(&single)
            .args(OPTIONS)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", stderr(&r));
        assert!(
            String::from_utf8_lossy(&r.stdout).contains(&format!("variant {name}")),
            "the render report names the variant"
        );
        assert_eq!(
            std::fs::read(images.join(format!("p1_{name}.png"))).unwrap(),
            std::fs::read(&single).unwrap(),
            "{name}: compare's image is the single render, byte for byte"
        );
    }
    // Hiding the model gives the photo back unchanged.
    let no_box = image::open(images.join("p1_no_box.png")).unwrap().to_rgb8();
    assert!(no_box.pixels().all(|p| p.0 == common::PHOTO_SRGB8));
    // The red box changes pixels, and they are redder than they are green.
    let red = image::open(images.join("p1_red_box.png"))
        .unwrap()
        .to_rgb8();
    let changed: Vec<_> = red
        .pixels()
        .filter(|p| p.0 != common::PHOTO_SRGB8)
        .collect();
    assert!(!changed.is_empty());
    assert!(changed.iter().any(|p| p.0[0] > p.0[1] + 20));

    // The PNG grid: two thumbnails side by side.
    let sheet = image::open(dir.path().join("sheet.png")).unwrap().to_rgb8();
    assert!(sheet.width() > 2 * photomontage::study::contact_sheet::THUMB_WIDTH_PX);

    if !have_poppler() {
        return;
    }
    let info = run_text(Command::new("pdfinfo").arg(&pdf));
    assert!(
        info.lines()
            .any(|l| l.starts_with("Pages:") && l.ends_with(" 2")),
        "{info}"
    );
    assert!(info.contains(A3_PTS), "{info}");
    for (page, name) in [("1", "red_box"), ("2", "no_box")] {
        let text = run_text(
            Command::new("pdftotext")
                .args(["-f", page, "-l", page])
                .arg(&pdf)
                .arg("-"),
        );
        assert!(
            text.contains(&format!("Variant {name}")),
            "page {page}: {text}"
        );
        assert!(text.contains("view p1"), "page {page}: {text}");
    }
}

#[test]
fn variants_are_chosen_and_ordered_by_the_list() {
    let dir = tempfile::tempdir().unwrap();
    let site = site_with_variants(dir.path(), [32, 24]);
    let o = compare(&site, dir.path(), &["--variants", "no_box"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("(1 pages: no_box)"), "{out}");
}

#[test]
fn bad_variants_are_refused_by_name_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let site = site_with_variants(dir.path(), [32, 24]);
    let pdf = dir.path().join("sheet.pdf");

    let o = compare(&site, dir.path(), &["--variants", "red_box,tall"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("`tall`"), "{}", stderr(&o));
    assert!(!pdf.exists());

    let r = bin()
        .arg("render")
        .arg(&site)
        .args(["--view", "p1", "--variant", "tall", "--out"])
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    assert!(stderr(&r).contains("red_box, no_box"), "{}", stderr(&r));
    assert!(!dir.path().join("x.png").exists());

    // A variant naming a model the site no longer has.
    let text = std::fs::read_to_string(&site).unwrap();
    let removed = text.replace("visible_models = [\"box\"]", "visible_models = [\"tower\"]");
    std::fs::write(&site, removed).unwrap();
    let o = compare(&site, dir.path(), &[]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("`red_box`") && e.contains("`tower`"), "{e}");
    assert!(!pdf.exists());
    // `render --variant` names it the same way and writes nothing.
    let r = bin()
        .arg("render")
        .arg(&site)
        .args(["--view", "p1", "--variant", "red_box", "--out"])
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    let e = stderr(&r);
    assert!(e.contains("`red_box`") && e.contains("`tower`"), "{e}");
    assert!(!dir.path().join("x.png").exists());

    // Two variants of one name: the site does not load, naming the field.
    std::fs::write(&site, format!("{text}\n[[variants]]\nname = \"no_box\"\n")).unwrap();
    let o = compare(&site, dir.path(), &[]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("variants[2].name") && e.contains("`no_box`"),
        "{e}"
    );
    assert!(!pdf.exists());

    // A site without variants.
    std::fs::write(&site, text.split("[[variants]]").next().unwrap()).unwrap();
    let o = compare(&site, dir.path(), &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no [[variants]]"), "{}", stderr(&o));
    assert!(!pdf.exists());
}

#[test]
fn ctrl_c_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let site = site_with_variants(dir.path(), [1536, 1024]);
    let images = dir.path().join("images");
    let child = bin()
        .arg("compare")
        .arg(&site)
        .args(["--view", "p1", "--threads", "1", "--out"])
        .arg(dir.path().join("sheet.pdf"))
        .arg("--images")
        .arg(&images)
        .args(["--spp-min", "64", "--spp-max", "64"])
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let (status, rest) = common::interrupt_once_started(child);
    assert!(!status.success());
    assert!(
        rest.iter().any(|l| l.contains("nothing written")),
        "{rest:?}"
    );
    assert!(!dir.path().join("sheet.pdf").exists());
    assert!(!images.exists());
}
