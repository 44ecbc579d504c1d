//! What the two frame-time benches share: the generated 24 MP photo, its one-photo site and
//! the timing summary.

use photomontage::site::{Interior, Photo, Site};
use std::path::{Path, PathBuf};
use std::time::Duration;

pub const WIDTH_PX: u32 = 6000;
pub const HEIGHT_PX: u32 = 4000;
/// Frames timed while zooming fit → 16:1 → fit.
pub const FRAMES: usize = 240;
/// Window size in points.
pub const WINDOW: [f32; 2] = [1600.0, 1000.0];

/// Writes a 6000×4000 PNG into `dir/photos/big.png` and a site holding it as photo `BIG` into
/// `dir/site.toml`; returns the site file. Smooth gradients, a fine checker and a 100 px grid:
/// compressible enough to write quickly, detailed enough that every zoom level shows something.
pub fn photo_site(dir: &Path, name: &str) -> PathBuf {
    std::fs::create_dir(dir.join("photos")).expect("mkdir");
    let img = image::RgbImage::from_fn(WIDTH_PX, HEIGHT_PX, |x, y| {
        let grid = x % 100 == 0 || y % 100 == 0;
        let checker = ((x / 4) + (y / 4)) % 2 == 0;
        if grid {
            image::Rgb([255, 255, 255])
        } else {
            image::Rgb([
                (x * 255 / WIDTH_PX) as u8,
                (y * 255 / HEIGHT_PX) as u8,
                if checker { 160 } else { 90 },
            ])
        }
    });
    img.save(dir.join("photos/big.png")).expect("write photo");
    let site = Site {
        name: name.into(),
        photos: vec![Photo {
            id: "BIG".into(),
            file: "photos/big.png".into(),
            taken_at: None,
            profile: None,
            interior: Some(Interior {
                focal_px: 5000.0,
                principal_point_px: None,
                distortion: Default::default(),
                image_size_px: Some([WIDTH_PX, HEIGHT_PX]),
            }),
            self_calibration: Default::default(),
            exterior: None,
        }],
        ..Site::default()
    };
    let site_path = dir.join("site.toml");
    site.save(&site_path).expect("site");
    site_path
}

/// Prints the median, 95th percentile and worst of `v`.
pub fn stats(name: &str, mut v: Vec<Duration>) {
    v.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let median = ms(v[v.len() / 2]);
    let p95 = ms(v[(v.len() * 95) / 100]);
    let worst = ms(v[v.len() - 1]);
    println!("{name:<26} median {median:7.2} ms   p95 {p95:7.2} ms   worst {worst:7.2} ms");
}
