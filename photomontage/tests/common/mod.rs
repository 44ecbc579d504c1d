//! The small hand-made site of the CLI tests: a uniform photo of a ground plane taken looking
//! north, a black 1 m box on it lit by a manual sun and ambient light.
#![allow(dead_code, clippy::unwrap_used)] // each test binary uses part of it

use std::path::{Path, PathBuf};

pub const SIZE_PX: [u32; 2] = [96, 64];
pub const FOCAL_PX: f64 = 160.0;
pub const CAMERA: [f64; 3] = [0.5, -10.0, 1.5];
pub const PHOTO_SRGB8: [u8; 3] = [150, 140, 130];
pub const K_S: f64 = 2.0;
pub const K_U: f64 = 0.1;
pub const SUN_AZIMUTH_DEG: f64 = 135.0;
pub const SUN_ELEVATION_DEG: f64 = 40.0;

pub const BOX_OBJ: &str = "mtllib box.mtl\nusemtl black\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

pub fn site_toml(model_file: &str, scale: f64) -> String {
    site_toml_sized(model_file, scale, SIZE_PX)
}

/// [`site_toml`] with another image size (the camera stays centred).
pub fn site_toml_sized(model_file: &str, scale: f64, size_px: [u32; 2]) -> String {
    format!(
        r#"schema_version = 1
name = "cli render test"

[lighting]
sky_model = "uniform"
sun_weight = [{K_S}, {K_S}, {K_S}]
ambient_weight = [{K_U}, {K_U}, {K_U}]
sky_weight = [0.0, 0.0, 0.0]
sun_manual = {{ azimuth_deg = {SUN_AZIMUTH_DEG}, elevation_deg = {SUN_ELEVATION_DEG} }}

[render]
spp_min = 4
spp_max = 8

[[photos]]
id = "p1"
file = "p1.png"

[photos.interior]
focal_px = {FOCAL_PX}
image_size_px = [{w}, {h}]

[photos.exterior]
camera_center = [{cx}, {cy}, {cz}]
rotation_world_from_camera = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]

[[photos]]
id = "p2"
file = "p1.png"

[[control_points]]
id = "a"
xyz = [-10.0, -10.0, 0.0]

[[control_points]]
id = "b"
xyz = [10.0, -10.0, 0.0]

[[control_points]]
id = "c"
xyz = [10.0, 10.0, 0.0]

[[control_points]]
id = "d"
xyz = [-10.0, 10.0, 0.0]

[[polygons]]
id = "ground"
vertices = ["a", "b", "c", "d"]
material = "asphalt"
image = "p1"

[[models]]
id = "box"
file = "{model_file}"

[models.placement]
scale = {scale}
"#,
        w = size_px[0],
        h = size_px[1],
        cx = CAMERA[0],
        cy = CAMERA[1],
        cz = CAMERA[2],
    )
}

/// Writes the site, photo and box into `dir`; returns the site path.
pub fn make_site(dir: &Path) -> PathBuf {
    make_site_sized(dir, SIZE_PX)
}

/// [`make_site`] with another image size.
pub fn make_site_sized(dir: &Path, size_px: [u32; 2]) -> PathBuf {
    image::RgbImage::from_pixel(size_px[0], size_px[1], image::Rgb(PHOTO_SRGB8))
        .save(dir.join("p1.png"))
        .unwrap();
    std::fs::write(dir.join("box.obj"), BOX_OBJ).unwrap();
    std::fs::write(dir.join("box.mtl"), "newmtl black\nKd 0 0 0\n").unwrap();
    let site = dir.join("site.toml");
    std::fs::write(&site, site_toml_sized("box.obj", 1.0, size_px)).unwrap();
    site
}

/// Waits until `child` (stderr piped) prints its "Ctrl-C cancels" line, sends it SIGINT, and
/// returns its exit status with the stderr lines that came after the signal.
pub fn interrupt_once_started(
    mut child: std::process::Child,
) -> (std::process::ExitStatus, Vec<String>) {
    use std::io::{BufRead, BufReader};
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        let started = line.contains("Ctrl-C cancels");
        seen.push(line);
        if started {
            break;
        }
    }
    assert!(
        seen.last().is_some_and(|l| l.contains("Ctrl-C cancels")),
        "{seen:?}"
    );
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let rest: Vec<String> = lines.map(Result::unwrap).collect();
    (child.wait().unwrap(), rest)
}
