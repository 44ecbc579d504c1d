//! The studio's Fit tab: the lighting fits of Durisch 1992 §4.2–4.3 (atmosphere eq. 7,
//! daylight eq. 9) on the site's samples, as `photomontage fit` runs them.
//!
//! - The site's `[[samples]]` and `[[horizon_samples]]` in tables (egui_extras): purpose, median
//!   window, on/off, delete, and the `[fit_settings]` toggles; every change is a
//!   [`crate::fit_commands::FitCommand`] through the one command path (undo/redo, autosave).
//!   Samples are picked on the photo ([`crate::fit_pick`]).
//! - **Run fit** runs `photomontage::fit::site::fit_site` on the studio's worker
//!   ([`crate::fit_worker`]); the solver iterations are shown as progress and **Cancel fit**
//!   stops it at its next step. The results panel shows the report's numbers
//!   formatted as the CLI prints them (5 decimals): τₐ over 1 km, L∞, k_s, k_u, k_h with σ,
//!   absolute/relative weights, the sun cross-checks, the warnings and the residual table (flagged
//!   rows in red). Errors (`SiteFitError`) are shown as their messages.
//! - **Apply fit** writes the report into the site with `photomontage::fit::site::apply_fit`
//!   (the CLI's write-back: `[lighting]` and the `[fit]` record) as one undoable edit, so a
//!   later render uses the fitted lighting.
//!
//! # Known limitations
//! **Cancel fit** stops the fit at its next step (before the next sample is read or the next
//! daylight pass), not inside one (a pass of the interreflection gather may take seconds). The
//! report belongs to the site as it was when the fit started; editing samples afterwards does
//! not re-run it.

use eframe::egui::{self, Color32};
use egui_extras::{Column, TableBuilder};
use photomontage::fit::site::{SiteFitReport, apply_fit};
use photomontage::site::SamplePurpose;

use crate::commands::Command;
use crate::fit_commands::FitCommand;
use crate::fit_tables::{horizons_table_ui, purpose_name, samples_table_ui, settings_ui};
use crate::fit_worker::FitWorker;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;
use crate::worker::Poll;

/// Colour of flagged rows and errors.
pub const FLAGGED: Color32 = Color32::from_rgb(230, 60, 60);
/// Colour of warnings.
pub const WARNING: Color32 = crate::widgets::WARNING;

/// An RGB triple as `photomontage fit` prints it.
#[must_use]
pub fn rgb_text(v: [f64; 3]) -> String {
    format!("{:.5} {:.5} {:.5}", v[0], v[1], v[2])
}

/// A σ triple as `photomontage fit` prints it (`—` where it cannot be estimated), after `±`.
#[must_use]
pub fn sigma_text(s: [Option<f64>; 3]) -> String {
    let parts: Vec<String> = s
        .iter()
        .map(|x| x.map_or_else(|| "—".into(), |x| format!("{x:.5}")))
        .collect();
    format!("± {}", parts.join(" "))
}

/// The largest normalised residual |r|/σ̂ over the channels (daylight samples only).
#[must_use]
pub fn max_normalised(n: Option<[f64; 3]>) -> Option<f64> {
    n.map(|n| n.into_iter().fold(0.0_f64, f64::max))
}

/// An RFC 3339 UTC timestamp of now (seconds), as the CLI stamps `[fit].fitted_at`.
#[must_use]
pub fn fitted_at_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    rfc3339_utc(secs)
}

/// Seconds since the Unix epoch as `YYYY-MM-DDThh:mm:ssZ` (proleptic Gregorian; days to civil
/// date by H. Hinnant's `civil_from_days`).
#[must_use]
pub fn rfc3339_utc(secs: u64) -> String {
    let days = i64::try_from(secs / 86_400).unwrap_or(0);
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem % 3600) / 60,
        rem % 60
    )
}

/// State of the Fit tab.
pub struct FitPanel {
    /// Purpose of samples picked on the photo.
    pub purpose: SamplePurpose,
    /// Median window (odd, pixels) of samples picked on the photo.
    pub window_px: u32,
    /// The running fit.
    pub worker: FitWorker,
    /// The last fit's report.
    pub report: Option<SiteFitReport>,
    /// The last fit's error.
    pub error: Option<String>,
    /// A horizon rectangle being drawn: (start, current) photo pixel positions.
    pub(crate) rect_drag: Option<([f64; 2], [f64; 2])>,
}

impl Default for FitPanel {
    fn default() -> Self {
        Self {
            purpose: SamplePurpose::Daylight,
            window_px: 5,
            worker: FitWorker::default(),
            report: None,
            error: None,
            rect_drag: None,
        }
    }
}

impl crate::Studio {
    /// The Fit tab's state.
    pub fn fit_panel_mut(&mut self) -> &mut FitPanel {
        &mut self.fit
    }

    /// The last fit's report.
    #[must_use]
    pub fn fit_report(&self) -> Option<&SiteFitReport> {
        self.fit.report.as_ref()
    }

    /// Starts the lighting fit on the site as it is now (worker thread).
    pub fn start_fit(&mut self, ctx: &egui::Context) {
        let Some(doc) = self.doc.clone() else {
            return;
        };
        if self.fit.worker.start(doc, ctx) {
            self.fit.error = None;
            self.say("fitting the lighting…", false);
        } else {
            self.say("a fit is already running", true);
        }
    }

    /// Applies the last fit's report to the site as `photomontage fit` does (`apply_fit`), as
    /// one undoable edit.
    pub fn apply_fit_report(&mut self) {
        let (Some(report), Some(doc)) = (self.fit.report.as_ref(), self.doc.as_ref()) else {
            self.say("nothing to apply: run the fit first", true);
            return;
        };
        let mut fitted = doc.site.clone();
        apply_fit(&mut fitted, report, &fitted_at_now());
        let command = Command::Fit(FitCommand::SetLighting {
            lighting: Box::new(fitted.lighting),
            record: fitted.fit.map(Box::new),
        });
        self.apply(command, None);
        self.say(
            "fitted lighting written into the site ([lighting], [fit]); Undo restores the previous one",
            false,
        );
    }

    pub(crate) fn poll_fit(&mut self, ctx: &egui::Context) {
        match self.fit.worker.poll() {
            Poll::Done(Ok(report)) => {
                let flagged = report.residuals.iter().filter(|r| r.flagged).count();
                self.say(
                    format!(
                        "fit done: {} sample(s) read, {flagged} flagged, {} warning(s)",
                        report.samples.len(),
                        report.warnings.len()
                    ),
                    false,
                );
                self.fit.report = Some(report);
                self.fit.error = None;
            }
            Poll::Done(Err(e)) | Poll::Failed(e) => {
                self.say(format!("fit failed: {e}"), true);
                self.fit.error = Some(e);
            }
            Poll::Cancelled => {
                self.say("fit cancelled; the site is unchanged", false);
                self.fit.error = Some("the fit was cancelled".into());
            }
            Poll::Idle | Poll::Running(_) => {}
        }
        if self.fit.worker.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
    }
}

impl Panel for FitPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let Some(doc) = ctx.doc else {
            return Vec::new();
        };
        let site = &doc.site;
        let mut commands: Vec<(Command, Option<String>)> = Vec::new();
        let (mut run, mut cancel, mut apply) = (false, false, false);
        ui.horizontal(|ui| {
            let busy = self.worker.busy();
            run = ui
                .add_enabled(!busy, egui::Button::new("Run fit"))
                .clicked();
            cancel = ui
                .add_enabled(
                    busy && !self.worker.cancelling(),
                    egui::Button::new("Cancel fit"),
                )
                .clicked();
            apply = ui
                .add_enabled(
                    !busy && self.report.is_some(),
                    egui::Button::new("Apply fit"),
                )
                .on_hover_text("write the fitted lighting into the site (undoable)")
                .clicked();
            if busy {
                ui.spinner();
            }
        });
        if let Some(p) = self.worker.progress_text() {
            ui.label(p);
        }
        settings_ui(ui, site.fit_settings, &mut commands);
        ui.horizontal(|ui| {
            ui.label("new samples:");
            for p in [SamplePurpose::Daylight, SamplePurpose::Atmosphere] {
                let r = ui.radio_value(&mut self.purpose, p, purpose_name(p));
                name_widget(ui, &r, &format!("pick purpose {}", purpose_name(p)));
            }
            let r = ui.add(
                egui::DragValue::new(&mut self.window_px)
                    .range(1..=101)
                    .suffix(" px"),
            );
            name_widget(ui, &r, "pick window");
            self.window_px |= 1;
        });
        ui.label(
            "click the photo to add a sample on the polygon under the cursor; Shift-drag draws a \
             horizon (sky) rectangle",
        );
        egui::ScrollArea::vertical()
            .auto_shrink([false, false])
            .show(ui, |ui| {
                ui.strong(format!("Samples ({})", site.samples.len()));
                samples_table_ui(ui, site, &mut commands);
                ui.strong(format!("Horizon samples ({})", site.horizon_samples.len()));
                horizons_table_ui(ui, site, &mut commands);
                ui.separator();
                if let Some(e) = &self.error {
                    ui.colored_label(FLAGGED, format!("fit failed: {e}"));
                }
                if let Some(r) = &self.report {
                    report_ui(ui, r, site.solve.outlier_threshold_sigma);
                } else if self.error.is_none() {
                    ui.label("not fitted yet: press Run fit");
                }
            });
        let mut actions: Vec<Action> = commands
            .into_iter()
            .map(|(command, merge_key)| Action::Edit {
                command: Box::new(command),
                merge_key,
            })
            .collect();
        for (asked, action) in [
            (run, Action::StartFit),
            (cancel, Action::CancelFit),
            (apply, Action::ApplyFit),
        ] {
            if asked {
                actions.push(action);
            }
        }
        actions
    }
}

/// The report: fitted values with σ, flags, sun checks, warnings and the residual table.
pub fn report_ui(ui: &mut egui::Ui, r: &SiteFitReport, outlier_threshold: f64) {
    ui.strong("Fit results");
    egui::Grid::new("fit values")
        .num_columns(3)
        .striped(true)
        .show(ui, |ui| {
            ui.label(format!(
                "transmittance τ_a over {:.0} m",
                r.reference_distance_m
            ));
            match r.transmittance {
                Some(t) => {
                    ui.monospace(rgb_text(t));
                    ui.monospace(r.transmittance_sigma.map(sigma_text).unwrap_or_default());
                }
                None => {
                    ui.label("not fitted (kept from the site)");
                    ui.label("");
                }
            }
            ui.end_row();
            ui.label("horizon colour L∞");
            ui.monospace(rgb_text(r.horizon_colour));
            ui.monospace(
                r.horizon_colour_sigma
                    .map(|s| sigma_text(s.map(Some)))
                    .unwrap_or_default(),
            );
            ui.end_row();
            for (name, w, s) in [
                ("sun weight k_s", r.sun_weight, r.sun_weight_sigma),
                (
                    "ambient weight k_u",
                    r.ambient_weight,
                    r.ambient_weight_sigma,
                ),
                ("sky weight k_h", r.sky_weight, r.sky_weight_sigma),
            ] {
                ui.label(name);
                match w {
                    Some(w) => {
                        ui.monospace(rgb_text(w));
                        ui.monospace(s.map(sigma_text).unwrap_or_default());
                    }
                    None => {
                        ui.label("not fitted (kept from the site)");
                        ui.label("");
                    }
                }
                ui.end_row();
            }
        });
    if r.sun_weight.is_some() {
        ui.label(if r.weights_relative {
            "weights relative: the material's reflectance is not in the library (ρ_d = 1 assumed)"
        } else {
            "weights absolute (materials' ρ_d from the library)"
        });
    }
    for c in &r.sun_checks {
        let text = format!(
            "sun check {}: {:.2}° between shadow and SPA sun (elevation {:.2}°, azimuth {:.2}°)",
            c.pair, c.check.angle_deg, c.check.spa_elevation_deg, c.check.spa_azimuth_deg
        );
        if c.check.agrees() {
            ui.label(text);
        } else {
            ui.colored_label(WARNING, text);
        }
    }
    for w in &r.warnings {
        ui.colored_label(WARNING, format!("warning: {w}"));
    }
    if r.residuals.is_empty() {
        return;
    }
    ui.strong("Residuals (model − photo, linear)");
    TableBuilder::new(ui)
        .id_salt("fit residuals")
        .striped(true)
        .column(Column::auto().at_least(70.0))
        .column(Column::auto().at_least(70.0))
        .column(Column::auto().at_least(190.0))
        .column(Column::auto().at_least(50.0))
        .column(Column::remainder().at_least(60.0))
        .max_scroll_height(300.0)
        .header(18.0, |mut h| {
            for t in ["sample", "fit", "residual R G B", "|r|/σ", "flag"] {
                h.col(|ui| {
                    ui.strong(t);
                });
            }
        })
        .body(|mut body| {
            for res in &r.residuals {
                let colour = if res.flagged {
                    FLAGGED
                } else {
                    Color32::from_gray(220)
                };
                body.row(18.0, |mut row| {
                    row.col(|ui| {
                        ui.colored_label(colour, &res.sample);
                    });
                    row.col(|ui| {
                        ui.colored_label(colour, res.fit);
                    });
                    row.col(|ui| {
                        ui.colored_label(colour, rgb_text(res.residual_rgb));
                    });
                    row.col(|ui| {
                        let n = max_normalised(res.normalised)
                            .map_or_else(|| "—".into(), |n| format!("{n:.2}"));
                        let c = if max_normalised(res.normalised)
                            .is_some_and(|n| n > outlier_threshold)
                        {
                            FLAGGED
                        } else {
                            colour
                        };
                        ui.colored_label(c, n);
                    });
                    row.col(|ui| {
                        if res.flagged {
                            ui.colored_label(colour, "OUTLIER");
                        }
                    });
                });
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_match_known_dates() {
        // 1_700_000_000 s is 2023-11-14 22:13:20 UTC; 951_782_400 s is 2000-02-29 00:00 UTC
        // (a leap day of a century leap year).
        assert_eq!(rfc3339_utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339_utc(1_700_000_000), "2023-11-14T22:13:20Z");
        assert_eq!(rfc3339_utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(rfc3339_utc(951_868_799), "2000-02-29T23:59:59Z");
    }

    #[test]
    fn numbers_are_formatted_as_the_cli_prints_them() {
        assert_eq!(rgb_text([1.0, 0.123_456, 2.5]), "1.00000 0.12346 2.50000");
        assert_eq!(
            sigma_text([Some(0.001), None, Some(2.0)]),
            "± 0.00100 — 2.00000"
        );
        assert_eq!(max_normalised(Some([0.5, 3.0, 1.0])), Some(3.0));
        assert_eq!(max_normalised(None), None);
    }
}
