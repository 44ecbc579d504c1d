//! Solving in the studio: [`photomontage::site::solve_site`] (resection of every photo, then the
//! bundle adjustment; Durisch 1992 §4.1) on the studio's [`crate::worker::Worker`] (a panic in
//! the solver becomes a message); the Results tab ([`ResultsPanel`]) with the residual table,
//! the residual vectors drawn on the photo with a scale bar, and the warnings and failures as
//! readable messages.
//!
//! The table shows the numbers exactly as `photomontage solve` prints them (same rounding), so
//! the two can be compared by eye and by the tests.
//!
//! # Known limitations
//! A solve cannot be cancelled once started (the library solver has no cancellation hook); a
//! second request while one runs is refused with a message rather than queued.

use eframe::egui::{self, Color32, Pos2, Stroke};
use egui_extras::{Column, TableBuilder};
use photomontage::site::{SiteDocument, SiteSolution, solve::PhotoSolution};

use crate::panel::{Action, Panel, PanelContext};
use crate::table_sort::{self, SortKey, SortState, sorted_rows};
use crate::viewport::ViewTransform;
use crate::widgets::{ERROR, WARNING, name_widget};
use crate::worker::Worker;

/// The solve's worker: [`photomontage::site::solve_site`] on a snapshot of the site.
pub type SolveWorker = Worker<SiteSolution>;

/// A worker for solves, named `solve`.
#[must_use]
pub fn solve_worker() -> SolveWorker {
    Worker::new("solve")
}

/// Starts solving a snapshot of the site. Returns false when a solve is already running.
pub fn start_solve(worker: &mut SolveWorker, doc: SiteDocument, ctx: &egui::Context) -> bool {
    worker.spawn(ctx, move |_| photomontage::site::solve_site(&doc))
}

/// `|v|` and `|v|/σ` of a residual row, as the CLI computes them.
#[must_use]
pub fn row_numbers(r: &photomontage::photogrammetry::ObservationResidual) -> [f64; 4] {
    [
        r.residual_px[0],
        r.residual_px[1],
        r.residual_px[0].hypot(r.residual_px[1]),
        r.normalised[0].hypot(r.normalised[1]),
    ]
}

/// The text of one residual row's cells, as `photomontage solve` prints them.
#[must_use]
pub fn row_cells(r: &photomontage::photogrammetry::ObservationResidual) -> [String; 4] {
    let [vx, vy, n, w] = row_numbers(r);
    [
        format!("{vx:.3}"),
        format!("{vy:.3}"),
        format!("{n:.3}"),
        format!("{w:.2}"),
    ]
}

/// Summary lines and the residual table of one photo's solution.
pub fn photo_solution_ui(ui: &mut egui::Ui, s: &PhotoSolution) {
    let c = s.camera.pose.camera_center_in_world;
    ui.label(format!(
        "{}: {} · RMS {:.3} px · focal {:.2} px",
        s.id, s.solved_by, s.rms_px, s.camera.intrinsics.focal_px
    ));
    ui.label(format!(
        "centre X {:.4} Y {:.4} Z {:.4} (σ {:.4} {:.4} {:.4} m)",
        c.x, c.y, c.z, s.sigma_center_m[0], s.sigma_center_m[1], s.sigma_center_m[2]
    ));
    for w in &s.warnings {
        ui.colored_label(crate::widgets::WARNING, format!("warning: {w}"));
    }
    let sort_id = egui::Id::unique(("residuals sort", &s.id));
    let mut sort = SortState::load(ui, sort_id);
    let order = sorted_rows(&s.residuals, sort, |r, column| match column {
        0 => SortKey::Text(r.point_id.clone()),
        1..=4 => SortKey::Number(row_numbers(r)[column - 1]),
        _ => SortKey::Number(f64::from(u8::from(r.outlier))),
    });
    TableBuilder::new(ui)
        .id_salt(("residuals", &s.id))
        .striped(true)
        .column(Column::auto().at_least(60.0))
        .columns(Column::auto().at_least(55.0), 4)
        .column(Column::remainder())
        .max_scroll_height(260.0)
        .header(18.0, |mut h| {
            for (column, t) in ["point", "vx px", "vy px", "|v| px", "|v|/σ", "flag"]
                .into_iter()
                .enumerate()
            {
                h.col(|ui| {
                    if let Some(next) =
                        table_sort::header(ui, &format!("residuals {}", s.id), sort, column, t)
                    {
                        sort = next;
                    }
                });
            }
        })
        .body(|mut body| {
            for r in order.iter().map(|&i| &s.residuals[i]) {
                body.row(18.0, |mut row| {
                    let colour = if r.outlier {
                        Color32::from_rgb(230, 60, 60)
                    } else {
                        ui_text_colour()
                    };
                    row.col(|ui| {
                        ui.colored_label(colour, &r.point_id);
                    });
                    for cell in row_cells(r) {
                        row.col(|ui| {
                            ui.colored_label(colour, cell);
                        });
                    }
                    row.col(|ui| {
                        if r.outlier {
                            ui.colored_label(colour, "OUTLIER");
                        }
                    });
                });
            }
        });
    sort.store(ui, sort_id);
}

fn ui_text_colour() -> Color32 {
    Color32::from_gray(220)
}

/// A round residual length (1, 2 or 5 × 10ⁿ px) whose bar is about `target_points` long.
#[must_use]
pub fn scale_bar_px(points_per_residual_px: f64, target_points: f64) -> f64 {
    let raw = target_points / points_per_residual_px.max(1e-12);
    let decade = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .rfind(|v| *v <= raw)
        .unwrap_or(decade)
}

/// Draws residual vectors (magnified `exaggeration` times) from each observation of the photo,
/// and a scale bar in the lower-left corner of the view.
pub fn paint_residuals(
    painter: &egui::Painter,
    t: &ViewTransform,
    site: &photomontage::site::Site,
    solution: &PhotoSolution,
    exaggeration: f64,
) {
    let ok = Stroke::new(2.0, Color32::from_rgb(40, 220, 255));
    let bad = Stroke::new(2.0, Color32::from_rgb(255, 60, 60));
    for r in &solution.residuals {
        let Some(o) = site
            .observations
            .iter()
            .find(|o| o.photo == solution.id && o.point == r.point_id)
        else {
            continue;
        };
        if !(r.residual_px[0].is_finite() && r.residual_px[1].is_finite()) {
            continue;
        }
        let from = t.screen_from_photo([o.x_px, o.y_px]);
        let to = t.screen_from_photo([
            o.x_px + r.residual_px[0] * exaggeration,
            o.y_px + r.residual_px[1] * exaggeration,
        ]);
        painter.arrow(from, to - from, if r.outlier { bad } else { ok });
    }
    // Scale bar: a residual of `len_px` drawn at this zoom and exaggeration.
    let points_per_px = t.zoom * exaggeration;
    let len_px = scale_bar_px(points_per_px, 120.0);
    let bar = (len_px * points_per_px) as f32;
    let origin = Pos2::new(t.rect.left() + 16.0, t.rect.bottom() - 20.0);
    painter.rect_filled(
        egui::Rect::from_min_max(
            origin - egui::vec2(8.0, 22.0),
            origin + egui::vec2(bar + 8.0, 10.0),
        ),
        3.0,
        Color32::from_black_alpha(170),
    );
    painter.line_segment([origin, origin + egui::vec2(bar, 0.0)], ok);
    painter.text(
        origin - egui::vec2(0.0, 4.0),
        egui::Align2::LEFT_BOTTOM,
        format!("{len_px} px residual (×{exaggeration})"),
        egui::FontId::proportional(12.0),
        Color32::WHITE,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_bar_is_a_round_length_near_the_target() {
        // 3 points per residual px, 120 points wanted: 40 px → 20 (1-2-5 series, not above).
        assert!((scale_bar_px(3.0, 120.0) - 20.0).abs() < 1e-12);
        assert!((scale_bar_px(120.0, 120.0) - 1.0).abs() < 1e-12);
        assert!((scale_bar_px(500.0, 120.0) - 0.2).abs() < 1e-12);
    }
}

/// The Results tab: residual-vector display, the solve's summary, failures, warnings and each
/// photo's residual table (the current photo first).
#[derive(Debug, Default)]
pub struct ResultsPanel;

impl Panel for ResultsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut residuals = ctx.residuals;
        ui.horizontal(|ui| {
            let r = ui.checkbox(&mut residuals.show, "residual vectors");
            name_widget(ui, &r, "residual vectors");
            let r = ui.add(
                egui::Slider::new(&mut residuals.exaggeration, 1.0..=5000.0)
                    .logarithmic(true)
                    .text("×"),
            );
            name_widget(ui, &r, "residual exaggeration");
        });
        let actions: Vec<Action> = (residuals != ctx.residuals)
            .then_some(Action::SetResiduals(residuals))
            .into_iter()
            .collect();
        let Some(solution) = ctx.solution else {
            ui.label("not solved yet: press Solve");
            return actions;
        };
        if let Some(r) = solution.bundle_rms_px {
            ui.strong(format!("bundle adjustment RMS {r:.3} px"));
        }
        for f in &solution.failures {
            ui.colored_label(ERROR, format!("{}: {}", f.id, f.error));
        }
        for w in &solution.warnings {
            ui.colored_label(WARNING, format!("warning: {w}"));
        }
        egui::ScrollArea::vertical().show(ui, |ui| {
            // The current photo first, then the others.
            let mut order: Vec<_> = solution.photos.iter().collect();
            order.sort_by_key(|p| Some(p.id.as_str()) != ctx.current_photo);
            for p in order {
                ui.separator();
                photo_solution_ui(ui, p);
            }
        });
        actions
    }
}
