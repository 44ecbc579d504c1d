//! The Tie points tab: the site's tie points (tracks of a feature match, `photomontage match`,
//! or hand-picked) with their photos and reprojection RMS in the stored cameras
//! ([`photomontage::site::tie_points::track_summaries`]), a Reject button per track (its
//! observations disabled in one undoable edit; Restore undoes it the same way), and selection:
//! the selected track's observations are highlighted on the photo view.
//!
//! Works on the tie points in the site, without OpenCV; only finding them (`match`) needs the
//! library's `opencv` feature.
//!
//! # Known limitations
//! The list is recomputed every frame (projection of each tie point into each solved photo:
//! fine for thousands of points, not for hundreds of thousands) and shows at most
//! [`MAX_ROWS`] rows, worst RMS first.

use eframe::egui;
use photomontage::site::Site;
use photomontage::site::tie_points::{TrackSummary, track_summaries};

use crate::commands::Command;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// Rows listed (worst RMS first, rejected tracks last).
pub const MAX_ROWS: usize = 500;

/// The Tie points tab.
#[derive(Debug, Default)]
pub struct TiePointsPanel;

/// The edit that rejects (or restores) a track: every observation of it put back with
/// `enabled` changed, as one batch (one undo step).
#[must_use]
pub fn set_rejected_command(site: &Site, id: &str, rejected: bool) -> Option<Command> {
    let commands: Vec<Command> = site
        .observations
        .iter()
        .filter(|o| o.point == id && o.enabled == rejected)
        .map(|o| Command::PutObservation {
            observation: photomontage::site::Observation {
                enabled: !rejected,
                ..o.clone()
            },
            at: None,
        })
        .collect();
    (!commands.is_empty()).then_some(Command::Batch(commands))
}

/// Tracks in display order: worst RMS first, then unsolved, rejected last.
#[must_use]
pub fn ordered(mut tracks: Vec<TrackSummary>) -> Vec<TrackSummary> {
    tracks.sort_by(|a, b| {
        a.rejected
            .cmp(&b.rejected)
            .then(
                b.rms_px
                    .unwrap_or(-1.0)
                    .total_cmp(&a.rms_px.unwrap_or(-1.0)),
            )
            .then(a.id.cmp(&b.id))
    });
    tracks
}

impl Panel for TiePointsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        let Some(doc) = ctx.doc else {
            ui.label("No site open.");
            return actions;
        };
        let tracks = ordered(track_summaries(&doc.site));
        let rejected = tracks.iter().filter(|t| t.rejected).count();
        ui.label(format!(
            "{} tie points ({} rejected). Find them with `photomontage match` (OpenCV build); Solve uses them.",
            tracks.len(),
            rejected
        ));
        ui.separator();
        egui::ScrollArea::vertical().show(ui, |ui| {
            egui::Grid::new("tie_points_grid")
                .striped(true)
                .show(ui, |ui| {
                    ui.strong("Track");
                    ui.strong("Photos");
                    ui.strong("RMS px");
                    ui.strong("");
                    ui.end_row();
                    for t in tracks.iter().take(MAX_ROWS) {
                        let selected = ctx.selected_point == Some(t.id.as_str());
                        let r = ui.selectable_label(selected, &t.id);
                        name_widget(ui, &r, &format!("Select {}", t.id));
                        if r.clicked() {
                            actions.push(Action::SelectPoint(t.id.clone()));
                        }
                        ui.label(if t.rejected {
                            "rejected".to_owned()
                        } else {
                            t.photos.join(", ")
                        });
                        ui.label(
                            t.rms_px
                                .map_or_else(|| "–".to_owned(), |v| format!("{v:.2}")),
                        );
                        let (text, name) = if t.rejected {
                            ("Restore", format!("Restore {}", t.id))
                        } else {
                            ("Reject", format!("Reject {}", t.id))
                        };
                        let b = ui.button(text);
                        name_widget(ui, &b, &name);
                        if b.clicked()
                            && let Some(command) =
                                set_rejected_command(&doc.site, &t.id, !t.rejected)
                        {
                            actions.push(Action::Edit {
                                command: Box::new(command),
                                merge_key: None,
                            });
                        }
                        ui.end_row();
                    }
                });
            if tracks.len() > MAX_ROWS {
                ui.label(format!("… {} more", tracks.len() - MAX_ROWS));
            }
        });
        actions
    }
}
