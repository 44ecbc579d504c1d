//! The Tie points tab: a site with two matched tracks lists them; Reject disables every
//! observation of a track in one undoable edit (the solve then leaves it out), and undo brings
//! the site back exactly.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use egui_kittest::kittest::Queryable;
use photomontage::site::SiteDocument;
use photomontage::site::tie_points::{TrackObservation, replace_matched_tracks};

fn obs(photo: &str, x: f64, y: f64) -> TrackObservation {
    TrackObservation {
        photo: photo.into(),
        pixel_px: [x, y],
        sigma_px: 0.7,
    }
}

#[test]
fn rejecting_a_track_disables_its_observations_and_undo_restores_them() {
    let (_dir, site) = common::copy_sample();
    let mut doc = SiteDocument::load(&site).expect("sample");
    let photos: Vec<String> = doc.site.photos.iter().map(|p| p.id.clone()).collect();
    assert!(photos.len() >= 2);
    replace_matched_tracks(
        &mut doc.site,
        &[
            vec![obs(&photos[0], 100.0, 120.0), obs(&photos[1], 110.0, 125.0)],
            vec![obs(&photos[0], 300.0, 320.0), obs(&photos[1], 310.0, 330.0)],
        ],
    );
    doc.save().expect("saved");
    let before = SiteDocument::load(&site).expect("reloads").site;

    let mut h = common::harness(&site, common::WINDOW);
    h.get_by_label("Tie points tab").click();
    h.run();
    h.get_by_label("Select sift_00002").click();
    h.run();
    h.get_by_label("Reject sift_00001").click();
    h.run();
    let site_now = &h.state().document().expect("open").site;
    let ties: Vec<_> = site_now
        .observations
        .iter()
        .filter(|o| o.point.starts_with("sift_"))
        .collect();
    assert_eq!(ties.len(), 4);
    for o in &ties {
        assert_eq!(o.enabled, o.point != "sift_00001", "{o:?}");
    }
    // The button now offers to restore it; undo restores the site exactly.
    assert!(h.query_by_label("Restore sift_00001").is_some());
    h.state_mut().undo();
    h.run();
    assert_eq!(h.state().document().expect("open").site, before);
    assert!(h.query_by_label("Reject sift_00001").is_some());
}
