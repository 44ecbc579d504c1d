//! `[[luminaires]]` through `photomontage render` (issue 4: luminaires as artificial lights,
//! Durisch 1992 §6.2 case D1) and Ctrl-C cancelling a render.
//!
//! A night site (no sun, no sky, ambient radiance k_u only) with a photographed ground plane and
//! the hand-written downlight `tests/fixtures/downlight.ies` (1000 cd flat from nadir to 30°,
//! 0 cd from 60°) hung h metres up. Known answers: the photo inverts to ρ_d = L₀/k_u, so every
//! ground pixel under the lamp grows by exactly ρ_d/π · 1000 cd · scale · colour / h²; a view
//! beyond the 60° cut-off is the photo bit for bit.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod common;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// Lit pixels: the change is computed in f64 and stored as f32 (a few ulps of the value). The
/// pixel footprint (0.2 mm at 20 m) stays at γ < 0.01°, where the web is flat and d² varies by
/// < 1e-8: only the f32 storage remains.
const F32_REL_TOL: f64 = 1e-5;

const DOWNLIGHT_IES: &str = include_str!("fixtures/downlight.ies");
const NADIR_CD: f64 = 1000.0;
const LAMP_HEIGHT_M: f64 = 2.0;
const SCALE: f64 = 1e-4;
const COLOUR: [f64; 3] = [1.0, 0.8, 0.6];
const K_U: f64 = 0.05;
const SIZE_PX: [u32; 2] = [15, 15];
const PHOTO_SRGB8: [u8; 3] = [90, 80, 70];

/// A photo looking straight down from 20 m above (x, 0) (image x = east, image y = south).
fn photo_toml(id: &str, x_m: f64, focal_px: f64, size_px: [u32; 2], file: &str) -> String {
    format!(
        r#"
[[photos]]
id = "{id}"
file = "{file}"

[photos.interior]
focal_px = {focal_px}
image_size_px = [{w}, {h}]

[photos.exterior]
camera_center = [{x_m}, 0.0, 20.0]
rotation_world_from_camera = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
"#,
        w = size_px[0],
        h = size_px[1],
    )
}

fn site_toml(luminaire_file: &str, photos: &str) -> String {
    format!(
        r#"schema_version = 1
name = "night with a downlight"

[lighting]
sky_model = "uniform"
sun_weight = [0.0, 0.0, 0.0]
sky_weight = [0.0, 0.0, 0.0]
ambient_weight = [{K_U}, {K_U}, {K_U}]

[render]
spp_min = 4
spp_max = 4
{photos}
[[control_points]]
id = "a"
xyz = [-50.0, -50.0, 0.0]

[[control_points]]
id = "b"
xyz = [50.0, -50.0, 0.0]

[[control_points]]
id = "c"
xyz = [50.0, 50.0, 0.0]

[[control_points]]
id = "d"
xyz = [-50.0, 50.0, 0.0]

[[polygons]]
id = "ground"
vertices = ["a", "b", "c", "d"]
material = "asphalt"
image = "below"

[[models]]
id = "far_box"
file = "box.obj"

[models.placement]
translation = [40.0, 40.0, 0.0]

[[luminaires]]
id = "porch"
file = "{luminaire_file}"
position_m = [0.0, 0.0, {LAMP_HEIGHT_M}]
colour_rgb = [{c0}, {c1}, {c2}]
scale = {SCALE}
"#,
        c0 = COLOUR[0],
        c1 = COLOUR[1],
        c2 = COLOUR[2],
    )
}

const BOX_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// Writes the night site into `dir`: view `below` under the lamp, view `outside` 10 m east
/// (γ = 78.7°, beyond the cut-off).
fn make_site(dir: &Path, luminaire_file: &str) -> PathBuf {
    image::RgbImage::from_pixel(SIZE_PX[0], SIZE_PX[1], image::Rgb(PHOTO_SRGB8))
        .save(dir.join("p.png"))
        .unwrap();
    std::fs::write(dir.join("box.obj"), BOX_OBJ).unwrap();
    std::fs::write(dir.join("downlight.ies"), DOWNLIGHT_IES).unwrap();
    let photos = photo_toml("below", 0.0, 100_000.0, SIZE_PX, "p.png")
        + &photo_toml("outside", 10.0, 100_000.0, SIZE_PX, "p.png");
    let site = dir.join("site.toml");
    std::fs::write(&site, site_toml(luminaire_file, &photos)).unwrap();
    site
}

fn render(site: &Path, view: &str, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("render")
        .arg(site)
        .args(["--view", view, "--out"])
        .arg(out)
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

#[test]
fn a_site_luminaire_adds_rho_over_pi_times_i_scale_over_h2_below_and_nothing_outside() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path(), "downlight.ies");
    let photo = photomontage::render::linear_photo(
        &photomontage::photo::load(&dir.path().join("p.png")).unwrap(),
    );
    let below = dir.path().join("below.exr");
    let o = render(&site, "below", &below);
    assert!(o.status.success(), "{}", stderr(&o));
    let rgb = ["R", "G", "B"].map(|c| channel(&below, c));
    for (i, p) in photo.pixels().enumerate() {
        for k in 0..3 {
            let l0 = f64::from(p.0[k]);
            let rho = l0 / K_U;
            let expected =
                l0 + rho / PI * NADIR_CD * SCALE * COLOUR[k] / (LAMP_HEIGHT_M * LAMP_HEIGHT_M);
            let got = f64::from(rgb[k][i]);
            assert!(
                (got - expected).abs() <= F32_REL_TOL * expected,
                "pixel {i} channel {k}: {got} vs {expected} (photo {l0})"
            );
            // The lamp's share is far above the tolerance: the test can fail.
            assert!(expected - l0 > 100.0 * F32_REL_TOL * expected);
        }
    }

    let outside = dir.path().join("outside.exr");
    let o = render(&site, "outside", &outside);
    assert!(o.status.success(), "{}", stderr(&o));
    let rgb = ["R", "G", "B"].map(|c| channel(&outside, c));
    for (i, p) in photo.pixels().enumerate() {
        for k in 0..3 {
            assert_eq!(
                rgb[k][i].to_bits(),
                p.0[k].to_bits(),
                "pixel {i} channel {k}"
            );
        }
    }
}

#[test]
fn a_missing_luminaire_file_names_the_luminaire_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path(), "gone.ies");
    let out = dir.path().join("x.exr");
    let o = render(&site, "below", &out);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("luminaire `porch`") && e.contains("gone.ies"),
        "{e}"
    );
    assert!(!out.exists());
}

/// Sends SIGINT to a render that takes far longer than the test (a 1600 × 1200 view at 64 rays
/// per pixel) once it reports that it is rendering; it must stop, say so, exit non-zero and
/// leave no output file.
#[cfg(unix)]
#[test]
fn ctrl_c_cancels_a_render_without_writing_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let big = [1600, 1200];
    image::RgbImage::from_pixel(big[0], big[1], image::Rgb(PHOTO_SRGB8))
        .save(dir.path().join("big.png"))
        .unwrap();
    std::fs::write(dir.path().join("box.obj"), BOX_OBJ).unwrap();
    std::fs::write(dir.path().join("downlight.ies"), DOWNLIGHT_IES).unwrap();
    let site = dir.path().join("site.toml");
    let photos = photo_toml("below", 0.0, 800.0, big, "big.png");
    std::fs::write(&site, site_toml("downlight.ies", &photos)).unwrap();
    let out = dir.path().join("big.exr");
    let child = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("render")
        .arg(&site)
        .args([
            "--view",
            "below",
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
    assert!(!out.exists(), "a cancelled render wrote {}", out.display());
}
