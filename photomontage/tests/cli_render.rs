//! `photomontage render` on a small hand-made site in a temporary folder: a uniform photo of a
//! ground plane taken looking north, a black 1 m box on it lit by a manual sun and ambient light.
//! Checks known answers (untouched pixels are the photo bit for bit, the box is black, the shadow
//! is the ambient share of the photo), thread-count independence and every bad-input message.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::f64::consts::PI;
use std::path::Path;
use std::process::{Command, Output};

/// Shadow pixels: computed in f64, stored as f32 (a few ulps).
const F32_REL_TOL: f64 = 1e-5;

mod common;
use common::{
    CAMERA, FOCAL_PX, K_S, K_U, PHOTO_SRGB8, SIZE_PX, SUN_AZIMUTH_DEG, SUN_ELEVATION_DEG,
};
use common::{make_site, site_toml};

fn render(site: &Path, view: &str, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("render")
        .arg(site)
        .args(["--view", view, "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn channel(path: &Path, name: &str) -> Vec<f32> {
    let img = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let c = img.layer_data[0]
        .channel_data
        .list
        .iter()
        .find(|c| c.name.eq(name))
        .unwrap_or_else(|| panic!("no channel {name}"));
    c.sample_data.values_as_f32().collect()
}

/// The world ray through pixel (x, y) of the test camera (x right = east, y down, looking north).
fn ray(x: f64, y: f64) -> [f64; 3] {
    let (cx, cy) = (
        f64::from(SIZE_PX[0] - 1) / 2.0,
        f64::from(SIZE_PX[1] - 1) / 2.0,
    );
    [(x - cx) / FOCAL_PX, 1.0, -(y - cy) / FOCAL_PX]
}

/// Where the ray through (x, y) meets the ground z = 0, if it points down.
fn ground_point(x: f64, y: f64) -> Option<[f64; 3]> {
    let d = ray(x, y);
    (d[2] < 0.0).then(|| {
        let t = -CAMERA[2] / d[2];
        [CAMERA[0] + t * d[0], CAMERA[1] + t * d[1], 0.0]
    })
}

/// Whether the segment from `p` towards the sun meets the unit box (slab test).
fn in_box_shadow(p: [f64; 3]) -> bool {
    let (az, el) = (SUN_AZIMUTH_DEG.to_radians(), SUN_ELEVATION_DEG.to_radians());
    let d = [az.sin() * el.cos(), az.cos() * el.cos(), el.sin()];
    let (mut t0, mut t1) = (0.0_f64, f64::INFINITY);
    for k in 0..3 {
        let (a, b) = ((0.0 - p[k]) / d[k], (1.0 - p[k]) / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

/// Pixel corners.
fn corners(x: u32, y: u32) -> [(f64, f64); 4] {
    let (x, y) = (f64::from(x), f64::from(y));
    [
        (x - 0.5, y - 0.5),
        (x + 0.5, y - 0.5),
        (x - 0.5, y + 0.5),
        (x + 0.5, y + 0.5),
    ]
}

/// Whether the pixel's image square may show the box (its projected bounding box, 1 px margin).
fn may_show_box(x: u32, y: u32) -> bool {
    let (cx, cy) = (
        f64::from(SIZE_PX[0] - 1) / 2.0,
        f64::from(SIZE_PX[1] - 1) / 2.0,
    );
    let mut r = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for bx in [0.0, 1.0] {
        for by in [0.0, 1.0] {
            for bz in [0.0, 1.0] {
                let depth = by - CAMERA[1];
                let u = cx + FOCAL_PX * (bx - CAMERA[0]) / depth;
                let v = cy - FOCAL_PX * (bz - CAMERA[2]) / depth;
                r = [r[0].min(u), r[1].min(v), r[2].max(u), r[3].max(v)];
            }
        }
    }
    let (x, y) = (f64::from(x), f64::from(y));
    x + 1.5 >= r[0] && x - 1.5 <= r[2] && y + 1.5 >= r[1] && y - 1.5 <= r[3]
}

#[test]
fn exr_keeps_untouched_pixels_bit_identical_and_shadows_are_the_ambient_share() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path());
    let out = dir.path().join("view.exr");
    let o = render(
        &site,
        "p1",
        &out,
        &["--layers", "depth,object_id,shadow_change"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("material `asphalt`"),
        "missing-material warning: {}",
        stderr(&o)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("96×64") && stdout.contains("changed pixels"),
        "{stdout}"
    );

    let photo = photomontage::render::linear_photo(
        &photomontage::photo::load(&dir.path().join("p1.png")).unwrap(),
    );
    let [r, g, b, a] = ["R", "G", "B", "A"].map(|c| channel(&out, c));
    let ids = channel(&out, "object_id");
    let depth = channel(&out, "Z");
    let change = channel(&out, "shadow_change.G");
    let sun_cos = SUN_ELEVATION_DEG.to_radians().sin();
    let ambient_share = PI * K_U / (K_S * sun_cos + PI * K_U);
    let (mut untouched, mut shadow, mut boxed) = (0, 0, 0);
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let i = (y * SIZE_PX[0] + x) as usize;
            let p = photo.get_pixel(x, y).0;
            let hits: Vec<Option<[f64; 3]>> = corners(x, y)
                .iter()
                .map(|&(u, v)| ground_point(u, v))
                .collect();
            let near_box_or_shadow = hits
                .iter()
                .any(|h| h.is_some_and(|q| q[0] > -2.0 && q[0] < 2.0 && q[1] > -1.0 && q[1] < 3.0));
            if !may_show_box(x, y) && !near_box_or_shadow {
                untouched += 1;
                for (k, c) in [&r, &g, &b].iter().enumerate() {
                    assert_eq!(c[i].to_bits(), p[k].to_bits(), "pixel {x},{y}");
                }
                assert_eq!(a[i].to_bits(), 0.0_f32.to_bits());
                assert_eq!(change[i].to_bits(), 0.0_f32.to_bits());
            }
            let fully_in_shadow = hits
                .iter()
                .all(|h| h.is_some_and(|q| q[1] < 10.0 && in_box_shadow(q)));
            if fully_in_shadow && !may_show_box(x, y) {
                shadow += 1;
                for (k, c) in [&r, &g, &b].iter().enumerate() {
                    let expected = f64::from(p[k]) * ambient_share;
                    let got = f64::from(c[i]);
                    assert!(
                        (got - expected).abs() <= F32_REL_TOL * expected,
                        "shadow pixel {x},{y}: {got} vs {expected}"
                    );
                }
                let expected_change = f64::from(p[1]) * (ambient_share - 1.0);
                assert!((f64::from(change[i]) - expected_change).abs() <= 1e-5);
                assert_eq!(ids[i].to_bits(), 0.0_f32.to_bits(), "ground is object 0");
            }
            if a[i] >= 1.0 {
                // A black box (ρ_d = 0 in its MTL) reflects nothing: exactly 0.
                boxed += 1;
                assert_eq!(
                    [r[i], g[i], b[i]].map(f32::to_bits),
                    [0; 3],
                    "box pixel {x},{y}"
                );
                assert_eq!(ids[i].to_bits(), 1.0_f32.to_bits(), "box is object 1");
                assert!(depth[i] > 9.0 && depth[i] < 12.0, "box depth {}", depth[i]);
            }
        }
    }
    println!("{untouched} untouched, {shadow} shadow, {boxed} box pixels");
    assert!(
        untouched > 4000 && shadow > 5 && boxed > 50,
        "{untouched} untouched, {shadow} shadow, {boxed} box pixels"
    );
    let table: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("view.objects.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(table["objects"][0]["name"], "polygon:ground");
    assert_eq!(table["objects"][1]["name"], "model:box");
}

#[test]
fn spectral_mode_renders_the_grey_scene_like_rgb_mode() {
    // A grey photo, grey lights and a black box: Appendix A is linear in the gamut and a grey
    // reflectance is flat, so spectral mode reproduces RGB mode within the round trip
    // (render::spectral module doc): 1e-5 relative covers it and the f32 storage.
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path());
    image::RgbImage::from_pixel(SIZE_PX[0], SIZE_PX[1], image::Rgb([140, 140, 140]))
        .save(dir.path().join("p1.png"))
        .unwrap();
    let (rgb, spec) = (dir.path().join("rgb.exr"), dir.path().join("spec.exr"));
    let o = render(&site, "p1", &rgb, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(&site, "p1", &spec, &["--spectral"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("spectral"));
    for c in ["R", "G", "B", "A"] {
        for (a, b) in channel(&rgb, c).iter().zip(channel(&spec, c)) {
            let (a, b) = (f64::from(*a), f64::from(b));
            assert!((a - b).abs() <= 1e-5 * a.abs().max(1e-3), "{c}: {a} vs {b}");
        }
    }
}

#[test]
fn one_and_two_threads_write_byte_identical_exr() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path());
    let (one, two) = (dir.path().join("t1.exr"), dir.path().join("t2.exr"));
    for (path, threads) in [(&one, "1"), (&two, "2")] {
        let o = render(&site, "p1", path, &["--threads", threads, "--seed", "7"]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for c in ["R", "G", "B", "A"] {
        let (a, b) = (channel(&one, c), channel(&two, c));
        let first_diff = a
            .iter()
            .zip(&b)
            .position(|(x, y)| x.to_bits() != y.to_bits());
        assert_eq!(first_diff, None, "channel {c} differs");
    }
    let same_bytes = std::fs::read(one).unwrap() == std::fs::read(two).unwrap();
    assert!(same_bytes, "same pixels but different EXR bytes");
}

#[test]
fn eight_bit_formats_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path());
    for name in ["v.png", "v.jpg", "v.tiff"] {
        let path = dir.path().join(name);
        let o = render(&site, "p1", &path, &["--exposure", "1"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let img = image::open(&path).unwrap();
        assert_eq!([img.width(), img.height()], SIZE_PX, "{name}");
    }
    // Untouched corner of the PNG: the photo's own 8-bit value back (decode then encode).
    let png = image::open(dir.path().join("v.png")).unwrap().into_rgb8();
    assert_eq!(png.get_pixel(0, 0).0, PHOTO_SRGB8);
}

fn assert_fails(o: &Output, needle: &str) {
    assert!(!o.status.success(), "expected failure mentioning {needle}");
    assert!(
        stderr(o).contains(needle),
        "`{needle}` not in: {}",
        stderr(o)
    );
}

#[test]
fn bad_input_gives_clear_messages() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path());
    let out = dir.path().join("o.exr");
    assert_fails(&render(&site, "p9", &out, &[]), "valid view ids: p1, p2");
    assert_fails(
        &render(&site, "p2", &out, &[]),
        "photo p2 is not solved; run `photomontage solve` first",
    );
    assert_fails(
        &render(&site, "p1", &dir.path().join("o.bmp"), &[]),
        "extension `bmp`",
    );
    assert_fails(
        &render(&site, "p1", &dir.path().join("no/such/dir/o.exr"), &[]),
        "cannot write the output file",
    );
    assert_fails(
        &render(&site, "p1", &out, &["--spectral", "--layers", "depth"]),
        "RGB mode only",
    );
    assert_fails(
        &render(
            &site,
            "p1",
            &dir.path().join("o.png"),
            &["--layers", "depth"],
        ),
        "need an .exr output",
    );
    assert_fails(
        &render(&site, "p1", &out, &["--layers", "normals"]),
        "unknown layer `normals`",
    );
    assert_fails(
        &render(&site, "p1", &out, &["--spp-max", "10"]),
        "multiple of 4",
    );

    std::fs::write(dir.path().join("empty.obj"), "v 0 0 0\nv 1 0 0\n").unwrap();
    std::fs::write(
        dir.path().join("nan.obj"),
        "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
    )
    .unwrap();
    for (file, needle) in [("empty.obj", "no faces"), ("nan.obj", "non-finite")] {
        let bad = dir.path().join(format!("{file}.toml"));
        std::fs::write(&bad, site_toml(file, 1.0)).unwrap();
        assert_fails(&render(&bad, "p1", &out, &[]), needle);
    }
    // 20 km across: rendered, with a warning about units.
    let huge = dir.path().join("huge.toml");
    std::fs::write(&huge, site_toml("box.obj", 2e4)).unwrap();
    let o = render(&huge, "p1", &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("check its units"), "{}", stderr(&o));
}
