//! Montage helpers for the `street` sample site (Mitsuba photos and truth): box-filtered
//! downscaling, rendering a solved view into its downscaled photo, and the error measures against
//! the truth render (building pixels, shadow pixels, whole image). Shared by `street_render.rs`,
//! `street_render_radiosity.rs` and `street_fit.rs`.
//!
//! Photos and truth are 8-bit sRGB PNGs at 256 spp; both are box-filtered `scale` × `scale` (the
//! solved camera's focal length and principal point scaled to match) to keep the tests within
//! seconds in the dev profile and to average the truth's Monte Carlo noise.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;
use photomontage::render::{DifferentialTracer, RenderedImage, render_view};
use photomontage::site::photo_reflectance::PhotoView;
use photomontage::site::render::prepare_view;
use photomontage::site::render_radiosity::site_radiosity_arc;
use photomontage::site::{SiteDocument, apply_solution, solve_site};

use crate::sample_site;

/// The `street` sample site with every photo solved (its cameras applied).
///
/// # Panics
/// When the site does not load or a photo fails to solve (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn solved_street() -> SiteDocument {
    let mut doc = SiteDocument::load(&sample_site("street").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    apply_solution(&mut doc.site, &solution);
    doc
}

/// A pixel is in the building's shadow when the truth is darker than the photo by this factor
/// (summed RGB), as in `render_mitsuba.rs`.
pub const SHADOW_DARKENING: f64 = 0.8;

/// Box-filters `img` by `scale` in both directions (partial edge blocks dropped).
#[must_use]
pub fn downscale(img: &Rgb32FImage, scale: u32) -> Rgb32FImage {
    let (w, h) = (img.width() / scale, img.height() / scale);
    Rgb32FImage::from_fn(w, h, |x, y| {
        let mut s = [0.0_f64; 3];
        for dy in 0..scale {
            for dx in 0..scale {
                let p = img.get_pixel(x * scale + dx, y * scale + dy).0;
                for k in 0..3 {
                    s[k] += f64::from(p[k]);
                }
            }
        }
        let n = f64::from(scale * scale);
        #[allow(clippy::cast_possible_truncation)]
        image::Rgb(s.map(|v| (v / n) as f32))
    })
}

/// Loads a photo file as linear RGB.
///
/// # Panics
/// When the file cannot be read (a test helper).
#[must_use]
pub fn load_linear(path: &Path) -> Rgb32FImage {
    #[allow(clippy::unwrap_used)]
    photomontage::render::linear_photo(&photomontage::photo::load(path).unwrap())
}

/// Errors of a montage against the truth.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Pixels of the planned building.
    pub building_px: usize,
    /// Mean relative error (mean over RGB) over the building pixels.
    pub building_mre: f64,
    /// Pixels of the building's shadow (truth darker than the photo, outside the building).
    pub shadow_px: usize,
    /// Mean relative error over the shadow pixels.
    pub shadow_mre: f64,
    /// RMSE of the montage vs the truth over the whole image (linear units).
    pub rmse: f64,
    /// RMSE of the photo vs the truth (what the montage has to beat).
    pub rmse_photo: f64,
}

impl Measured {
    /// Asserts the checks every street montage test makes on view `id`: both masks at least
    /// `min_mask_px`, building and shadow mean relative errors within their bounds, and the
    /// montage closer to the truth than the photo.
    ///
    /// # Panics
    /// When a check fails (a test helper).
    pub fn assert_within(&self, id: &str, min_mask_px: usize, building_tol: f64, shadow_tol: f64) {
        assert!(
            self.building_px >= min_mask_px && self.shadow_px >= min_mask_px,
            "{id}: masks {} building, {} shadow",
            self.building_px,
            self.shadow_px
        );
        assert!(
            self.building_mre <= building_tol,
            "{id}: building {}",
            self.building_mre
        );
        assert!(
            self.shadow_mre <= shadow_tol,
            "{id}: shadow {}",
            self.shadow_mre
        );
        assert!(
            self.rmse < self.rmse_photo,
            "{id}: the montage must be closer to the truth than the photo"
        );
    }
}

/// Measures a montage `out` against `truth`, the shadow mask taken from `truth` vs `photo`.
#[must_use]
pub fn measure(out: &RenderedImage, truth: &Rgb32FImage, photo: &Rgb32FImage) -> Measured {
    let (mut b_err, mut b_n, mut s_err, mut s_n, mut sq, mut sq_photo) = (0.0, 0, 0.0, 0, 0.0, 0.0);
    let rel = |a: [f32; 3], t: [f32; 3]| {
        (0..3)
            .map(|k| (f64::from(a[k]) - f64::from(t[k])).abs() / f64::from(t[k]).max(1e-3))
            .sum::<f64>()
            / 3.0
    };
    let sq_err = |a: [f32; 3], t: [f32; 3]| {
        (0..3)
            .map(|k| (f64::from(a[k]) - f64::from(t[k])).powi(2))
            .sum::<f64>()
    };
    let lum = |v: [f32; 3]| v.iter().map(|&c| f64::from(c)).sum::<f64>();
    for ((o, t), p) in out.rgba.iter().zip(truth.pixels()).zip(photo.pixels()) {
        let ours = [o[0], o[1], o[2]];
        sq += sq_err(ours, t.0);
        sq_photo += sq_err(p.0, t.0);
        if o[3] >= 1.0 {
            b_err += rel(ours, t.0);
            b_n += 1;
        } else if o[3] <= 0.0 && lum(t.0) < SHADOW_DARKENING * lum(p.0) {
            s_err += rel(ours, t.0);
            s_n += 1;
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let n = (3 * out.rgba.len()) as f64;
    #[allow(clippy::cast_precision_loss)]
    Measured {
        building_px: b_n,
        building_mre: b_err / b_n.max(1) as f64,
        shadow_px: s_n,
        shadow_mre: s_err / s_n.max(1) as f64,
        rmse: (sq / n).sqrt(),
        rmse_photo: (sq_photo / n).sqrt(),
    }
}

/// A rendered montage with the downscaled photo and truth it was made from and measured on.
pub struct StreetView {
    /// The montage.
    pub out: RenderedImage,
    /// The downscaled linear photo.
    pub photo: Rgb32FImage,
    /// The downscaled linear truth (`truth/<id>.png`).
    pub truth: Rgb32FImage,
    /// Errors of `out` against `truth`.
    pub measured: Measured,
}

/// Renders the planned building into photo `id` of the solved street site `doc`, box-filtered by
/// `scale`, and measures it against the truth.
///
/// # Panics
/// When the view cannot be prepared or rendered (a test helper).
#[must_use]
pub fn render_street_view(doc: &SiteDocument, id: &str, scale: u32) -> StreetView {
    render_street_view_in(doc, id, scale, false)
}

/// [`render_street_view`], in the radiosity lighting mode when `radiosity` is set (the site's
/// solutions with and without the building, as `render --radiosity` solves them).
///
/// # Panics
/// When the view cannot be prepared, solved or rendered (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn render_street_view_in(
    doc: &SiteDocument,
    id: &str,
    scale: u32,
    radiosity: bool,
) -> StreetView {
    let mut job = prepare_view(doc, id).unwrap();
    if radiosity {
        // The natural surfaces' reflectances from the full-size photo, as `render --radiosity`.
        let photo = PhotoView {
            camera: &job.camera,
            photo_linear: &job.photo_linear,
            lighting: &job.lighting,
        };
        let (light, _report) = site_radiosity_arc(
            doc,
            &job.scene.scene,
            id,
            doc.site.render.photo_reflectance.then_some(&photo),
            &AtomicBool::new(false),
        )
        .unwrap();
        job.lighting.radiosity = Some(light);
    }
    let photo = downscale(&job.photo_linear, scale);
    let truth_full = load_linear(&sample_site("street").join(format!("truth/{id}.png")));
    let truth = downscale(&truth_full, scale);
    // The camera of the box-filtered image: pixel centres x' = (x + 0.5) / s − 0.5.
    let s = f64::from(scale);
    let k = &mut job.camera.intrinsics;
    k.focal_px /= s;
    k.principal_point_px = k.principal_point_px.map(|c| (c + 0.5) / s - 0.5);
    k.image_size_px = [photo.width(), photo.height()];
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &photo,
        job.settings.max_depth,
    )
    .unwrap();
    let out = render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false)).unwrap();
    let measured = measure(&out, &truth, &photo);
    StreetView {
        out,
        photo,
        truth,
        measured,
    }
}
