//! `photomontage elevation` on the small test site with a 10 × 6 × 8 m block in place of the box
//! (manual sun az 135°, el 40°: the south and east façades are sunlit, north and west shaded):
//! façade widths in pixels, the site `[[materials]]` colour on the panels, the warning for a site
//! material that matches nothing, and the irradiance view against `irradiance_at`.
#![allow(clippy::unwrap_used)]

mod common;

use std::process::Command;

use photomontage::design::unfolded::ramp;

const BLOCK_OBJ: &str = "mtllib box.mtl\nusemtl facade\n\
v 0 0 0\nv 10 0 0\nv 10 6 0\nv 0 6 0\nv 0 0 8\nv 10 0 8\nv 10 6 8\nv 0 6 8\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

fn site(dir: &std::path::Path) -> std::path::PathBuf {
    let path = common::make_site(dir);
    std::fs::write(dir.join("box.obj"), BLOCK_OBJ).unwrap();
    std::fs::write(dir.join("box.mtl"), "newmtl facade\nKd 0.5 0.5 0.5\n").unwrap();
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str(
        "\n[[materials]]\nname = \"facade\"\ncolour = \"#a0522d\"\n\n[[materials]]\nname = \"ghost\"\ncolour = \"#ffffff\"\n",
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn elevation(
    site: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> (serde_json::Value, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .arg("elevation")
        .arg(site)
        .args(["--model", "box", "--px-per-m", "10", "--json", "--out"])
        .arg(out)
        .args(extra)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{stderr}");
    (serde_json::from_slice(&o.stdout).unwrap(), stderr)
}

#[test]
fn elevation_widths_colours_and_warning() {
    let dir = tempfile::tempdir().unwrap();
    let site = site(dir.path());
    let out = dir.path().join("colour.png");
    let (report, stderr) = elevation(&site, &out, &[]);
    assert!(
        stderr.contains("`ghost`") && stderr.contains("no polygon or CAD model"),
        "{stderr}"
    );
    let facades = report["facades"].as_array().unwrap();
    let widths: Vec<u64> = facades
        .iter()
        .map(|f| f["width_px"].as_u64().unwrap())
        .collect();
    assert_eq!(widths, [100, 60, 100, 60], "{report}");
    let img = image::open(&out).unwrap().to_rgb8();
    for f in facades {
        let c = f["centre_px"].as_array().unwrap();
        let (x, y) = (c[0].as_u64().unwrap() as u32, c[1].as_u64().unwrap() as u32);
        assert_eq!(img.get_pixel(x, y).0, [0xa0, 0x52, 0x2d]);
    }
}

#[test]
fn elevation_irradiance_sunlit_above_shaded_and_equal_to_irradiance_at() {
    let dir = tempfile::tempdir().unwrap();
    let site = site(dir.path());
    let out = dir.path().join("irradiance.png");
    let (report, _) = elevation(&site, &out, &["--irradiance", "--element-edge-m", "2"]);
    let facades = report["facades"].as_array().unwrap();
    let e = |k: usize| facades[k]["centre_irradiance_y"].as_f64().unwrap();
    // Panels are N, E, S, W. The sun (az 135°) lights E and S at cos 45° · cos 40°.
    let (n, east, s, w) = (e(0), e(1), e(2), e(3));
    assert!(
        east > n && east > w && s > n && s > w,
        "N {n} E {east} S {s} W {w}"
    );
    let sunlit_direct = common::K_S * 40f64.to_radians().cos() * 45f64.to_radians().cos();
    assert!(
        east > sunlit_direct * 0.99 && s > sunlit_direct * 0.99,
        "E {east} S {s} direct {sunlit_direct}"
    );
    // The centre pixel is the ramp of irradiance_at's value over the drawing's maximum.
    let max_y = report["max_irradiance_y"].as_f64().unwrap();
    let img = image::open(&out).unwrap().to_rgb8();
    for f in facades {
        let c = f["centre_px"].as_array().unwrap();
        let (x, y) = (c[0].as_u64().unwrap() as u32, c[1].as_u64().unwrap() as u32);
        let want = ramp(f["centre_irradiance_y"].as_f64().unwrap() / max_y);
        assert_eq!(img.get_pixel(x, y).0, want, "{f}");
    }
}
