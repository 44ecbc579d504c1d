//! The montage of the `street` sample site in the radiosity lighting mode against Mitsuba's truth
//! (issue 13 acceptance: "the street site (building and shadow, all three views) at or below
//! today's figures, and street shadows within 5 %"): as `street_render.rs`, with the sky and
//! every bounce taken from the site's radiosity solutions with and without the building
//! (`site::render_radiosity`, the final gather at element vertices) instead of the sky facets
//! and the photo-bounce gathers.
//!
//! The site's 1 km ground takes the element size to 7.1 m under the element budget
//! (`render_radiosity::ELEMENT_BUDGET`); elements that a sun shadow edge crosses are split to
//! 1 m (along the shadows of the scene with and without the building). Besides the shadow mask of
//! `street_render.rs` the test measures its **interior** (shadow pixels whose four neighbours are
//! shadow pixels too): in V1 and V2 the shadow is a strip a few pixels tall at this scale, and
//! most of its error sits in the rows along its edges. That is sampling at the edge, not light
//! and not registration: with the true cameras instead of the solved ones the edge error was the
//! same (V1 6.35 %, V2 5.80 %), and with more rays per edge pixel it falls. Since the renderer's
//! second sampling pass gives pixels that differ from a neighbour `spp_max` rays
//! (`render::adaptive`), the site's default 4–16 rays per pixel hold the 5 % in every
//! view (before it: 5.86 %, 5.71 %, 2.84 %).
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::site::SiteDocument;
use photomontage_tests::street::{
    Measured, SHADOW_DARKENING, StreetView, render_street_view_in, solved_street,
};

/// Mean relative error over the interior of the shadow mask (module doc) and its size.
fn interior_shadow_error(view: &StreetView) -> (f64, usize) {
    let (w, h) = view.truth.dimensions();
    let lum = |v: [f32; 3]| v.iter().map(|&c| f64::from(c)).sum::<f64>();
    let in_mask = |x: u32, y: u32| {
        let o = view.out.rgba[(y * w + x) as usize];
        o[3] <= 0.0
            && lum(view.truth.get_pixel(x, y).0)
                < SHADOW_DARKENING * lum(view.photo.get_pixel(x, y).0)
    };
    let (mut sum, mut n) = (0.0, 0);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            if in_mask(x, y)
                && in_mask(x - 1, y)
                && in_mask(x + 1, y)
                && in_mask(x, y - 1)
                && in_mask(x, y + 1)
            {
                let o = view.out.rgba[(y * w + x) as usize];
                let t = view.truth.get_pixel(x, y).0;
                sum += (0..3)
                    .map(|k| (f64::from(o[k]) - f64::from(t[k])).abs() / f64::from(t[k]).max(1e-3))
                    .sum::<f64>()
                    / 3.0;
                n += 1;
            }
        }
    }
    #[allow(clippy::cast_precision_loss)]
    (sum / n.max(1) as f64, n)
}

/// Box-filter factor, as `street_render.rs`.
const SCALE: u32 = 4;

/// Building pixels, mean relative error per view (V1, V2, V3). Measured 2026-11-28: 1.50 %,
/// 1.48 %, 2.13 % (the facet mode, `street_render.rs`: 1.6 %, 2.1 %, 3.9 %; this mode before the
/// edge pass 1.55 %, 1.54 %, 2.18 %, before the shadow-edge refinement 2.05 %, 1.92 %, 2.72 %).
/// Bounds: the measurement plus 0.5 %.
const BUILDING_MEAN_REL_TOL: [f64; 3] = [0.020, 0.020, 0.027];
/// Shadow pixels, mean relative error per view: the 5 %. Measured 2026-11-28: 4.59 %,
/// 4.71 %, 2.67 % (before the edge pass 5.86 %, 5.71 %, 2.84 %; facet mode 9.8 %, 9.2 %, 5.2 %;
/// at 16–64 rays per pixel 3.50 %, 3.57 %, 2.60 %).
const SHADOW_MEAN_REL_TOL: f64 = 0.05;
/// Interior shadow pixels (module doc), mean relative error per view. Measured 2026-11-28:
/// 1.86 %, 1.71 %, 1.79 % (154, 328 and 4 748 pixels); the facet mode gives 4.2 %, 4.0 %, 3.6 %
/// there. Bound: the measurement plus 0.5 % or so, within the 3 %.
const SHADOW_INTERIOR_MEAN_REL_TOL: f64 = 0.025;
/// Interior masks smaller than this are not measured (pixels at 1/4 scale).
const MIN_INTERIOR_PX: usize = 100;
/// A view is only measured where its masks are big enough to mean something (pixels at 1/4
/// scale).
const MIN_MASK_PX: usize = 300;

/// Renders every view of `doc` in the radiosity mode and prints its figures under `label`:
/// per view its id, measurements, interior shadow error and interior pixels.
fn measure_views(doc: &SiteDocument, label: &str) -> Vec<(String, Measured, f64, usize)> {
    let ids: Vec<String> = doc.site.photos.iter().map(|p| p.id.clone()).collect();
    assert_eq!(ids.len(), 3, "views {ids:?}");
    let mut results = Vec::new();
    for id in &ids {
        let view = render_street_view_in(doc, id, SCALE, true);
        let m = view.measured;
        let (interior, interior_px) = interior_shadow_error(&view);
        println!(
            "street radiosity {label} {id}: building {} px mean rel err {:.4}; shadow {} px mean \
             rel err {:.4}, interior {interior_px} px {interior:.4}; RMSE {:.5} (photo vs truth \
             {:.5}); changed px {}",
            m.building_px,
            m.building_mre,
            m.shadow_px,
            m.shadow_mre,
            m.rmse,
            m.rmse_photo,
            view.out.changed_pixels
        );
        results.push((id.clone(), m, interior, interior_px));
    }
    results
}

#[test]
fn street_montage_in_radiosity_mode_matches_mitsuba_truth() {
    let doc = solved_street();
    let results = measure_views(&doc, "spp default");
    // All views are measured and printed before any assertion.
    for (k, (id, m, interior, interior_px)) in results.iter().enumerate() {
        assert!(
            *interior_px >= MIN_INTERIOR_PX,
            "{id}: interior {interior_px} px"
        );
        assert!(
            *interior <= SHADOW_INTERIOR_MEAN_REL_TOL,
            "{id}: shadow interior {interior}"
        );
        m.assert_within(
            id,
            MIN_MASK_PX,
            BUILDING_MEAN_REL_TOL[k],
            SHADOW_MEAN_REL_TOL,
        );
    }
}
