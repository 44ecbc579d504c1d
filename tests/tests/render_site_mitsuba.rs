//! The Mitsuba pair of `render_mitsuba.rs` again, but built the way a user builds it: a site file
//! (control points, a ground polygon, the box as an OBJ model with its MTL, `[lighting]` with
//! `sun_manual`, `sun_weight` = the sun's normal irradiance, a uniform sky with `sky_weight` =
//! π·L, the horizon colour = L) turned into a render job by `photomontage::site::render`. It checks
//! the site glue and the lighting-unit conventions end to end against the 1024-spp truth.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage_tests::street::downscale;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};
use photomontage::render::{DifferentialTracer, render_view};
use photomontage::site::SiteDocument;
use photomontage::site::render::prepare_view;
use photomontage_tests::shared_file;
use serde_json::Value;

/// Downscale factor (as in `render_mitsuba.rs`, to stay within seconds in the dev profile).
const SCALE: u32 = 4;
/// Box pixels: the issue's 3 % goal, as for the hand-built scene in `render_mitsuba.rs`.
const BOX_MEAN_REL_TOL: f64 = 0.03;
/// Shadow pixels: the issue's 3 % goal.
const SHADOW_MEAN_REL_TOL: f64 = 0.03;

fn vec3(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|k| v[k].as_f64().unwrap())
}

fn arr(v: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

/// Writes the site folder for `spec` with `photo` as its only photo.
fn write_site(dir: &Path, spec: &Value, photo: &image::Rgb32FImage) -> std::path::PathBuf {
    photo.save(dir.join("photo.exr")).unwrap();
    let b = &spec["building"];
    let c: Vec<[f64; 3]> = b["corners"].as_array().unwrap().iter().map(vec3).collect();
    let mut obj = String::from("mtllib box.mtl\nusemtl building\n");
    for p in &c {
        writeln!(obj, "v {:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    // The faces of render_mitsuba.rs (1-based); orientation does not matter to the tracer.
    for f in [
        [1, 2, 4, 3],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [2, 4, 8, 6],
        [4, 3, 7, 8],
        [3, 1, 5, 7],
    ] {
        writeln!(obj, "f {} {} {} {}", f[0], f[1], f[2], f[3]).unwrap();
    }
    std::fs::write(dir.join("box.obj"), obj).unwrap();
    let albedo = vec3(&b["albedo_rgb"]);
    std::fs::write(
        dir.join("box.mtl"),
        format!(
            "newmtl building\nKd {:?} {:?} {:?}\n",
            albedo[0], albedo[1], albedo[2]
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("materials.toml"),
        format!(
            "[[material]]\nname = \"ground\"\ndiffuse_rgb = {}\n",
            arr(vec3(&spec["ground"]["albedo_rgb"]))
        ),
    )
    .unwrap();

    let cam = &spec["camera"];
    let eye = Point3::from(vec3(&cam["position"]));
    let target = Point3::from(vec3(&cam["target"]));
    let f = (target - eye).normalize();
    let r = f.cross(&Vector3::from(vec3(&cam["up"]))).normalize();
    let d = f.cross(&r);
    // Rows of world_from_camera, whose columns are the camera's right, down and forward axes.
    let rows = [0, 1, 2].map(|i| arr([r[i], d[i], f[i]]));
    let h = photo.height();
    let vfov = cam["vfov_deg"].as_f64().unwrap().to_radians();
    let focal_px = f64::from(h) / 2.0 / (vfov / 2.0).tan();
    let sun = &spec["sun"];
    let l_sky = vec3(&spec["sky"]["radiance_rgb"]);
    let k_h = l_sky.map(|l| std::f64::consts::PI * l);
    let mut toml = format!(
        r#"schema_version = 1
name = "mitsuba pair"

[lighting]
sky_model = "uniform"
sun_manual = {{ azimuth_deg = {az:?}, elevation_deg = {el:?} }}
sun_weight = {k_s}
sky_weight = {k_h}
ambient_weight = [0.0, 0.0, 0.0]
material_library = "materials.toml"

[lighting.atmosphere]
extinction_per_m = [0.0, 0.0, 0.0]
horizon_colour = {l_sky}

[[photos]]
id = "view"
file = "photo.exr"

[photos.interior]
focal_px = {focal_px:?}
image_size_px = [{w}, {h}]

[photos.exterior]
camera_center = {eye}
rotation_world_from_camera = [{r0}, {r1}, {r2}]

[[polygons]]
id = "ground"
vertices = ["g0", "g1", "g2", "g3"]
material = "ground"
image = "view"

[[models]]
id = "box"
file = "box.obj"
"#,
        az = sun["azimuth_deg"].as_f64().unwrap(),
        el = sun["elevation_deg"].as_f64().unwrap(),
        k_s = arr(vec3(&sun["irradiance_rgb"])),
        k_h = arr(k_h),
        l_sky = arr(l_sky),
        w = photo.width(),
        eye = arr(eye.coords.into()),
        r0 = rows[0],
        r1 = rows[1],
        r2 = rows[2],
    );
    for (i, g) in spec["ground"]["corners"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        write!(
            toml,
            "\n[[control_points]]\nid = \"g{i}\"\nxyz = {}\n",
            arr(vec3(g))
        )
        .unwrap();
    }
    let path = dir.join("site.toml");
    std::fs::write(&path, toml).unwrap();
    path
}

#[test]
fn site_file_montage_matches_mitsuba_1024spp() {
    let (Some(json), Some(photo_path), Some(truth_path)) = (
        shared_file("bench/data/mitsuba/scene.json"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_without_box.exr"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_with_box.exr"),
    ) else {
        return;
    };
    let spec: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let photo = downscale(
        &photomontage::photo::load(&photo_path).unwrap().pixels,
        SCALE,
    );
    let truth = downscale(
        &photomontage::photo::load(&truth_path).unwrap().pixels,
        SCALE,
    );
    let dir = tempfile::tempdir().unwrap();
    let site = write_site(dir.path(), &spec, &photo);

    let doc = SiteDocument::load(&site).unwrap();
    let job = prepare_view(&doc, "view").unwrap();
    // The photo went through the site file and the EXR reader unchanged.
    assert_eq!(*job.photo_linear, photo);
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .unwrap();
    let out = render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false)).unwrap();

    let (w, h) = (photo.width(), photo.height());
    let (mut box_err, mut box_n, mut shadow_err, mut shadow_n) = (0.0, 0, 0.0, 0);
    for y in 0..h {
        for x in 0..w {
            let ours = out.rgba[(y * w + x) as usize];
            let t = truth.get_pixel(x, y).0;
            let p = photo.get_pixel(x, y).0;
            let rel = (0..3)
                .map(|k| (f64::from(ours[k]) - f64::from(t[k])).abs() / f64::from(t[k]).max(1e-3))
                .sum::<f64>()
                / 3.0;
            let lum = |v: [f32; 3]| v.iter().map(|&c| f64::from(c)).sum::<f64>();
            if ours[3] >= 1.0 {
                box_err += rel;
                box_n += 1;
            } else if ours[3] <= 0.0 && lum(t) < 0.8 * lum(p) {
                shadow_err += rel;
                shadow_n += 1;
            }
        }
    }
    let box_mre = box_err / f64::from(box_n);
    let shadow_mre = shadow_err / f64::from(shadow_n);
    println!(
        "site → mitsuba {w}x{h}: box pixels {box_n} mean rel err {box_mre:.4}; shadow pixels \
         {shadow_n} mean rel err {shadow_mre:.4}; changed pixels {}",
        out.changed_pixels
    );
    assert!(
        box_n > 1000 && shadow_n > 300,
        "{box_n} box, {shadow_n} shadow"
    );
    assert!(box_mre <= BOX_MEAN_REL_TOL, "box {box_mre}");
    assert!(shadow_mre <= SHADOW_MEAN_REL_TOL, "shadow {shadow_mre}");
}
