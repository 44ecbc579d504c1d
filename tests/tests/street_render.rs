//! The montage against Mitsuba's truth on the `street` sample site (issue 4 acceptance, "the same
//! measurement on the new sample site's truth images"): the site is solved, each photo (a Mitsuba
//! render without the planned building) gets the building rendered into it through
//! `site::render::prepare_view`, and the result is compared with the Mitsuba render of the same
//! view with the building (`truth/V*.png`) over the building pixels, the pixels of its shadow and
//! the whole image.
//!
//! Photos and truth are 8-bit sRGB PNGs at 256 spp; both are box-filtered 4 × 4 (the solved
//! camera's focal length and principal point scaled to match) to keep the test within seconds in
//! the dev profile and to average the truth's Monte Carlo noise.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::Path;

use photomontage_tests::street::{render_street_view, solved_street};

/// Box-filter factor (`STREET_RENDER_SCALE` overrides it, e.g. 1 for full size).
const DEFAULT_SCALE: u32 = 4;

/// Building pixels, mean relative error per view. Measured (2026-11-21): V1 1.6 %, V2 2.1 %,
/// V3 3.9 %; the bound is the 3 % goal for the Mitsuba pair plus 1.5 % for this site's
/// extra error sources (8-bit sRGB photos and truth, 256-spp truth, light reflected onto the
/// building gathered from a textured photo).
const BUILDING_MEAN_REL_TOL: f64 = 0.045;
/// Shadow pixels, mean relative error per view: a regression bound above the measurement, NOT
/// yet the 3 % goal. Measured (2026-11-28) 7.0 % (V1), 6.6 % (V2), 4.4 % (V3) with the sampling
/// rule's edge pass; (2026-11-21) 9.8 %, 9.2 %, 5.2 % before it; 19.0/18.8/17.0 %
/// before case D gathered the light that the sunlit façades and the wall reflect onto the street
/// (the eq. 10 inversion divided the photo by sun + sky only, so ρ_d came out too large and too
/// much sunlight was removed). What remains: that gather is one bounce on a coarse fixed dome
/// (Durisch m_h = 6), the truth has up to three bounces, and the shadow masks are small (365 px
/// in V1 at 1/4 scale) and sit at façade feet where the photo's texture is darkest.
const SHADOW_MEAN_REL_TOL: f64 = 0.08;
/// A view is only measured where the masks are big enough to mean something (pixels at 1/4
/// scale); the building and its shadow are large in every view by construction of generate.py.
const MIN_MASK_PX: usize = 300;

fn scale() -> u32 {
    std::env::var("STREET_RENDER_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&s| s > 0)
        .unwrap_or(DEFAULT_SCALE)
}

#[test]
fn street_montage_matches_mitsuba_truth() {
    let doc = solved_street();
    let scale = scale();
    let ids: Vec<String> = doc.site.photos.iter().map(|p| p.id.clone()).collect();
    assert!(ids.len() >= 3);
    let mut results = Vec::new();
    for id in &ids {
        let view = render_street_view(&doc, id, scale);
        let (out, photo) = (&view.out, &view.photo);
        if let Some(dir) = std::env::var_os("STREET_RENDER_DUMP") {
            let tone = photomontage::colour::ToneMap::clamp();
            out.write_png(&Path::new(&dir).join(format!("{id}_ours.png")), &tone)
                .unwrap();
        }
        let m = view.measured;
        println!(
            "street {id} {}x{}: building {} px mean rel err {:.4}; shadow {} px mean rel err {:.4}; \
             RMSE {:.5} (photo vs truth {:.5}); changed px {}",
            photo.width(),
            photo.height(),
            m.building_px,
            m.building_mre,
            m.shadow_px,
            m.shadow_mre,
            m.rmse,
            m.rmse_photo,
            out.changed_pixels
        );
        results.push((id.clone(), m));
    }
    // All views are measured and printed before any assertion.
    for (id, m) in &results {
        m.assert_within(id, MIN_MASK_PX, BUILDING_MEAN_REL_TOL, SHADOW_MEAN_REL_TOL);
    }
}
