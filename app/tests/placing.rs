//! Safer clicking on the photo (issue 17 item 6), driven by labels with egui_kittest: choosing a
//! point arms it, the next click places it and disarms it; a click on another point's mark selects
//! that point and moves nothing; Escape disarms; the residual table sorts by a header click.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, click_photo_px, copy_sample, harness, wait_idle};
use egui_kittest::kittest::Queryable;
use photomontage::site::{Observation, SiteDocument};

type H = egui_kittest::Harness<'static, photomontage_studio::Studio>;

fn observations(h: &H) -> Vec<Observation> {
    h.state()
        .document()
        .expect("open")
        .site
        .observations
        .clone()
}

/// A pixel of photo `photo` at least `clear_px` from every observation on it.
fn empty_spot(obs: &[Observation], photo: &str, size_px: [f64; 2], clear_px: f64) -> [f64; 2] {
    let mut best = ([0.0, 0.0], 0.0);
    for i in 1..20 {
        for j in 1..20 {
            let p = [
                size_px[0] * f64::from(i) / 20.0,
                size_px[1] * f64::from(j) / 20.0,
            ];
            let d = obs
                .iter()
                .filter(|o| o.photo == photo)
                .map(|o| (o.x_px - p[0]).hypot(o.y_px - p[1]))
                .fold(f64::INFINITY, f64::min);
            if d > best.1 {
                best = (p, d);
            }
        }
    }
    assert!(
        best.1 >= clear_px,
        "no spot {clear_px} px clear of the marks"
    );
    best.0
}

#[test]
fn a_chosen_point_is_placed_once_and_a_mark_click_selects_instead_of_moving() {
    let (_dir, site_path) = copy_sample();
    let original = SiteDocument::load(&site_path).expect("sample loads");
    let mut h = harness(&site_path, WINDOW);
    wait_idle(&mut h);
    assert_eq!(h.state().current_photo(), Some("P1"));
    let on_p1: Vec<&Observation> = original
        .site
        .observations
        .iter()
        .filter(|o| o.photo == "P1")
        .collect();
    let (a, b) = (on_p1[0].clone(), on_p1[1].clone());
    let size = [1600.0, 1200.0];
    let spot = empty_spot(&original.site.observations, "P1", size, 80.0);

    // Choosing A arms it.
    h.get_by_label(&a.point).click();
    h.run();
    assert_eq!(h.state().armed_point(), Some(a.point.as_str()));

    // A click on B's mark selects B; A stays where it was, nothing is armed.
    click_photo_px(&mut h, [b.x_px, b.y_px]);
    assert_eq!(h.state().selected_point(), Some(b.point.as_str()));
    assert_eq!(h.state().armed_point(), None);
    assert_eq!(
        observations(&h),
        original.site.observations,
        "nothing moved"
    );

    // Escape disarms: the following click on empty photo changes nothing.
    h.get_by_label(&a.point).click();
    h.run();
    assert_eq!(h.state().armed_point(), Some(a.point.as_str()));
    h.key_press(eframe::egui::Key::Escape);
    h.run();
    assert_eq!(h.state().armed_point(), None);
    click_photo_px(&mut h, spot);
    assert_eq!(
        observations(&h),
        original.site.observations,
        "disarmed click placed nothing"
    );

    // Armed again, a click on empty photo places A there, once.
    h.get_by_label("place selected point").click();
    h.run();
    // "Place again" re-arms the selected point (A was selected by choosing it above).
    assert_eq!(h.state().armed_point(), Some(a.point.as_str()));
    click_photo_px(&mut h, spot);
    assert_eq!(h.state().armed_point(), None, "placing disarms");
    let moved = observations(&h)
        .into_iter()
        .find(|o| o.photo == "P1" && o.point == a.point)
        .expect("A still observed");
    assert!((moved.x_px - spot[0]).abs() < 1e-3 && (moved.y_px - spot[1]).abs() < 1e-3);
    let after_first = observations(&h);
    let spot2 = [spot[0] + 30.0, spot[1]];
    click_photo_px(&mut h, spot2);
    assert_eq!(
        observations(&h),
        after_first,
        "a second click does not move A again"
    );

    // One undo restores the file's observations.
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(observations(&h), original.site.observations);
}

#[test]
fn the_residual_table_sorts_by_a_header_click() {
    let (_dir, site_path) = copy_sample();
    let mut h = harness(&site_path, WINDOW);
    h.get_by_label("Solve").click();
    common::step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Results").click();
    h.run();
    let header = "sort residuals P1 by |v| px";
    assert!(
        h.query_by_label(header).is_some(),
        "residual header is a sort button"
    );
    h.get_by_label(header).click();
    h.run();
    let up = format!("{header} (ascending)");
    assert!(h.query_by_label(&up).is_some(), "sorted ascending");
    let shown = column_on_screen(&h, &up);
    let mut expected = shown.clone();
    expected.sort_by(f64::total_cmp);
    assert_eq!(shown, expected, "rows in ascending |v|");
    assert!(
        shown.first() < shown.last(),
        "the column has distinct values"
    );
    h.get_by_label(&up).click();
    h.run();
    let down = format!("{header} (descending)");
    assert!(h.query_by_label(&down).is_some(), "sorted descending");
    let shown = column_on_screen(&h, &down);
    expected.reverse();
    assert_eq!(shown, expected, "rows in descending |v|");
    h.get_by_label(&down).click();
    h.run();
    assert!(
        h.query_by_label(header).is_some(),
        "third click: the file's order"
    );
    // The file's order again: the residuals as the solve lists them.
    let file_order: Vec<f64> = p1_residuals(&h)
        .iter()
        .map(|r| photomontage_studio::solve::row_numbers(r)[2])
        .map(|v| format!("{v:.3}").parse().unwrap())
        .collect();
    assert_eq!(column_on_screen(&h, header), file_order);
    assert_ne!(
        file_order, expected,
        "the sample's file order is not sorted"
    );
}

fn p1_residuals(h: &H) -> Vec<photomontage::photogrammetry::ObservationResidual> {
    h.state()
        .solution()
        .expect("solved")
        .photos
        .iter()
        .find(|p| p.id == "P1")
        .expect("P1 solved")
        .residuals
        .clone()
}

/// The |v| cells of P1's residual table, top to bottom: the cells that show one of P1's |v|
/// values, left-aligned under the column's header (`header`, its accessible name) and below it.
fn column_on_screen(h: &H, header: &str) -> Vec<f64> {
    let head = h.get_by_label(header).rect();
    let rows = p1_residuals(h);
    let texts: std::collections::BTreeSet<String> = rows
        .iter()
        .map(|r| format!("{:.3}", photomontage_studio::solve::row_numbers(r)[2]))
        .collect();
    let mut cells: Vec<(f32, f64)> = texts
        .iter()
        .flat_map(|t| {
            h.query_all_by_label(t)
                .map(|n| n.rect())
                .filter(|r| (r.min.x - head.min.x).abs() < 2.0 && r.min.y > head.max.y)
                .map(|r| (r.min.y, t.parse::<f64>().unwrap()))
                .collect::<Vec<_>>()
        })
        .collect();
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    // P2's table follows with the same columns: P1's rows are the first ones.
    cells.truncate(rows.len());
    assert_eq!(cells.len(), rows.len(), "every P1 row is on screen");
    cells.into_iter().map(|(_, v)| v).collect()
}
