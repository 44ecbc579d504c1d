//! The montage of the `street` sample site in the radiosity lighting mode against Mitsuba's truth
//! (issue 13 acceptance: "the street site (building and shadow, all three views) at or below
//! today's figures, and street shadows within 5 %"): as `street_render.rs`, with the sky and
//! every bounce taken from the site's radiosity solutions with and without the building
//! (`site::render_radiosity`, the final gather at element vertices) instead of the sky facets
//! and the photo-bounce gathers.
//!
//! The site's 1 km ground takes the element size to 7.1 m under the element budget
//! (`render_radiosity::ELEMENT_BUDGET`), so the sky the building blocks is interpolated over
//! 7 m elements: that blur is what is left in the shadows of V1 and V2.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::site::{SiteDocument, apply_solution, solve_site};
use photomontage_tests::sample_site;
use photomontage_tests::street::render_street_view_in;

/// Box-filter factor, as `street_render.rs`.
const SCALE: u32 = 4;

/// Building pixels, mean relative error per view (V1, V2, V3). Measured 2026-11-25: 2.05 %,
/// 1.92 %, 2.72 % (the facet mode, `street_render.rs`: 1.6 %, 2.1 %, 3.9 %). Bounds: the
/// measurement plus 0.5 %; V1 is NOT at or below the facet mode yet.
const BUILDING_MEAN_REL_TOL: [f64; 3] = [0.026, 0.025, 0.033];
/// Shadow pixels, mean relative error per view. Measured 2026-11-25: 5.74 %, 5.34 %, 3.72 %
/// (facet mode 9.8–10.1 %, 9.2–9.4 %, 5.2 %). Bounds: the measurement plus 0.5 %; the issue's
/// 5 % holds in V3 only.
const SHADOW_MEAN_REL_TOL: [f64; 3] = [0.063, 0.059, 0.043];
/// A view is only measured where its masks are big enough to mean something (pixels at 1/4
/// scale).
const MIN_MASK_PX: usize = 300;

#[test]
fn street_montage_in_radiosity_mode_matches_mitsuba_truth() {
    let site_path = sample_site("street").join("site.toml");
    let mut doc = SiteDocument::load(&site_path).unwrap();
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    apply_solution(&mut doc.site, &solution);
    let ids: Vec<String> = doc.site.photos.iter().map(|p| p.id.clone()).collect();
    assert_eq!(ids.len(), 3, "views {ids:?}");
    let mut results = Vec::new();
    for id in &ids {
        let view = render_street_view_in(&doc, id, SCALE, true);
        let m = view.measured;
        println!(
            "street radiosity {id}: building {} px mean rel err {:.4}; shadow {} px mean rel err \
             {:.4}; RMSE {:.5} (photo vs truth {:.5}); changed px {}",
            m.building_px,
            m.building_mre,
            m.shadow_px,
            m.shadow_mre,
            m.rmse,
            m.rmse_photo,
            view.out.changed_pixels
        );
        results.push((id.clone(), m));
    }
    // All views are measured and printed before any assertion.
    for (k, (id, m)) in results.iter().enumerate() {
        assert!(
            m.building_px >= MIN_MASK_PX && m.shadow_px >= MIN_MASK_PX,
            "{id}: masks {} building, {} shadow",
            m.building_px,
            m.shadow_px
        );
        assert!(
            m.building_mre <= BUILDING_MEAN_REL_TOL[k],
            "{id}: building {}",
            m.building_mre
        );
        assert!(
            m.shadow_mre <= SHADOW_MEAN_REL_TOL[k],
            "{id}: shadow {}",
            m.shadow_mre
        );
        assert!(
            m.rmse < m.rmse_photo,
            "{id}: the montage must be closer to the truth than the photo"
        );
    }
}
