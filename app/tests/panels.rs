//! Panels as types, driven on their own (no `Studio`): a panel draws from a read-only
//! `PanelContext` and returns `Action`s; it never edits the site itself. Each test builds the
//! context from the courtyard sample, clicks the panel's widgets by their AccessKit labels and
//! checks the exact actions that come back — and that applying the returned edit through the
//! command path is what the click meant.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::site::SiteDocument;
use photomontage_studio::chrome::Toolbar;
use photomontage_studio::commands::History;
use photomontage_studio::panel::{Action, Panel, PanelContext, ResidualDisplay};
use photomontage_studio::points::PointsPanel;

/// A panel, the site it is shown, and what it returned so far.
struct Shown<P> {
    panel: P,
    doc: SiteDocument,
    can_undo: bool,
    actions: Vec<Action>,
}

/// `row`: draw the panel in a horizontal row, as the studio draws its toolbar.
fn harness<P: Panel + 'static>(panel: P, can_undo: bool, row: bool) -> Harness<'static, Shown<P>> {
    let doc = SiteDocument::load(&common::sample_dir().join("site.toml")).expect("sample site");
    let shown = Shown {
        panel,
        doc,
        can_undo,
        actions: Vec::new(),
    };
    Harness::builder()
        .with_size(egui::vec2(900.0, 900.0))
        .build_ui_state(
            move |ui, s: &mut Shown<P>| {
                let ctx = PanelContext {
                    doc: Some(&s.doc),
                    current_photo: Some("P1"),
                    selected_point: None,
                    armed_point: None,
                    solution: None,
                    residuals: ResidualDisplay {
                        show: true,
                        exaggeration: 200.0,
                    },
                    can_undo: s.can_undo,
                    can_redo: false,
                    solving: false,
                    dialog_open: false,
                    has_montage: false,
                    recent_sites: &[],
                };
                let actions = if row {
                    ui.horizontal(|ui| s.panel.ui(ui, &ctx)).inner
                } else {
                    s.panel.ui(ui, &ctx)
                };
                s.actions.extend(actions);
            },
            shown,
        )
}

#[test]
fn the_points_panel_returns_a_selection_and_an_undoable_edit() {
    let mut h = harness(PointsPanel::default(), false, false);
    h.run();
    assert!(
        h.state().actions.is_empty(),
        "drawing alone asks for nothing"
    );
    h.get_by_label("point id").click();
    h.run();
    h.get_by_label("point id").type_text("T9");
    h.run();
    h.get_by_label("Pick id").click();
    h.run();
    assert_eq!(h.state().actions, [Action::SelectPoint("T9".into())]);

    // Unticking a control point's "use" box returns the edit; the site is untouched until the
    // studio applies it.
    let first = h.state().doc.site.control_points[0].clone();
    assert!(first.enabled);
    h.state_mut().actions.clear();
    h.get_by_label(&format!("use {}", first.id)).click();
    h.run();
    let before = h.state().doc.site.clone();
    let edits: Vec<_> = h
        .state()
        .actions
        .iter()
        .filter_map(|a| match a {
            Action::Edit { command, .. } => Some((**command).clone()),
            _ => None,
        })
        .collect();
    assert_eq!(edits.len(), 1, "{:?}", h.state().actions);
    let mut site = before.clone();
    let mut history = History::default();
    history.apply(&mut site, edits[0].clone()).unwrap();
    let mut expected = before.clone();
    expected.control_points[0].enabled = false;
    assert_eq!(
        site, expected,
        "the edit disables {} and nothing else",
        first.id
    );
    history.undo(&mut site).unwrap();
    assert_eq!(site, before);
}

#[test]
fn the_toolbar_returns_its_buttons_and_undo_follows_the_context() {
    // Nothing to undo: the Undo button is disabled and a click returns nothing.
    let mut h = harness(Toolbar::default(), false, true);
    h.run();
    h.get_by_label("Undo").click();
    h.run();
    assert!(h.state().actions.is_empty(), "{:?}", h.state().actions);
    h.get_by_label("Save").click();
    h.run();
    h.get_by_label("Solve").click();
    h.run();
    assert_eq!(h.state().actions, [Action::Save, Action::StartSolve]);

    let mut h = harness(Toolbar::default(), true, true);
    h.run();
    h.get_by_label("Undo").click();
    h.run();
    h.get_by_label("site path").click();
    h.run();
    h.get_by_label("site path")
        .type_text("/tmp/other/site.toml");
    h.run();
    assert_eq!(h.state().panel.open_path, "/tmp/other/site.toml");
    h.get_by_label("Open").click();
    h.run();
    assert_eq!(
        h.state().actions,
        [
            Action::Undo,
            Action::OpenSite("/tmp/other/site.toml".into()),
        ]
    );
}
