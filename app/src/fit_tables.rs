//! The Fit tab's editable tables: the `[fit_settings]` toggles, the site's `[[samples]]` and
//! `[[horizon_samples]]` (purpose, median window, on/off, delete), each change a
//! [`FitCommand`] returned for the one command path (undo/redo, autosave).
//!
//! # Known limitations
//! Sample positions are not edited here (pick them again on the photo).

use eframe::egui;
use egui_extras::{Column, TableBuilder};
use photomontage::site::{FitSettings, SamplePurpose, Site};

use crate::commands::Command;
use crate::fit_commands::FitCommand;
use crate::table_sort::{self, SortKey, SortState, sorted_rows};
use crate::widgets::name_widget;

/// Name of a sample purpose as the tables show it.
#[must_use]
pub fn purpose_name(p: SamplePurpose) -> &'static str {
    match p {
        SamplePurpose::Daylight => "daylight",
        SamplePurpose::Atmosphere => "atmosphere",
    }
}

pub(crate) fn settings_ui(
    ui: &mut egui::Ui,
    settings: FitSettings,
    commands: &mut Vec<(Command, Option<String>)>,
) {
    ui.horizontal(|ui| {
        let mut s = settings;
        let r = ui
            .checkbox(&mut s.interreflection, "interreflection E_r")
            .on_hover_text("subtract the light the photographed surroundings reflect onto each daylight sample");
        name_widget(ui, &r, "interreflection");
        let r2 = ui
            .checkbox(&mut s.ambient, "fit ambient k_u")
            .on_hover_text("off: k_u = 0 (the sky model carries all diffuse light)");
        name_widget(ui, &r2, "fit ambient");
        if s != settings {
            commands.push((Command::Fit(FitCommand::SetFitSettings(s)), None));
        }
    });
}

pub(crate) fn samples_table_ui(
    ui: &mut egui::Ui,
    site: &Site,
    commands: &mut Vec<(Command, Option<String>)>,
) {
    if site.samples.is_empty() {
        ui.label("none: click the photo to add one");
        return;
    }
    let sort_id = egui::Id::unique("fit samples sort");
    let mut sort = SortState::load(ui, sort_id);
    let order = sorted_rows(&site.samples, sort, |s, column| match column {
        0 => SortKey::Text(s.id.clone()),
        1 => SortKey::Text(s.photo.clone()),
        2 => SortKey::Text(s.material.clone()),
        3 => SortKey::Number(s.x_px.unwrap_or(f64::NAN)),
        4 => SortKey::Text(purpose_name(s.purpose).to_owned()),
        5 => SortKey::Number(f64::from(s.window_px)),
        _ => SortKey::Number(f64::from(u8::from(s.enabled))),
    });
    TableBuilder::new(ui)
        .id_salt("fit samples")
        .striped(true)
        .column(Column::auto().at_least(40.0))
        .column(Column::auto().at_least(36.0))
        .column(Column::auto().at_least(90.0))
        .column(Column::auto().at_least(110.0))
        .column(Column::auto().at_least(74.0))
        .column(Column::auto().at_least(56.0))
        .column(Column::auto().at_least(24.0))
        .column(Column::remainder().at_least(30.0))
        .max_scroll_height(220.0)
        .header(20.0, |mut h| {
            for (column, t) in ["id", "photo", "material", "at", "purpose", "window", "on"]
                .into_iter()
                .enumerate()
            {
                h.col(|ui| {
                    if let Some(next) = table_sort::header(ui, "samples", sort, column, t) {
                        sort = next;
                    }
                });
            }
            h.col(|_| {});
        })
        .body(|mut body| {
            for s in order.iter().map(|&i| &site.samples[i]) {
                body.row(22.0, |mut row| {
                    row.col(|ui| {
                        ui.label(&s.id);
                    });
                    row.col(|ui| {
                        ui.label(&s.photo);
                    });
                    row.col(|ui| {
                        ui.label(&s.material);
                    });
                    row.col(|ui| {
                        let at = match (s.point, s.x_px, s.y_px) {
                            (_, Some(x), Some(y)) => format!("{x:.1}, {y:.1} px"),
                            (Some(_), _, _) => "world point".into(),
                            _ => "—".into(),
                        };
                        ui.label(at);
                    });
                    row.col(|ui| {
                        let r = ui.button(purpose_name(s.purpose));
                        name_widget(ui, &r, &format!("purpose {}", s.id));
                        if r.on_hover_text("click to switch").clicked() {
                            let mut c = s.clone();
                            c.purpose = match s.purpose {
                                SamplePurpose::Daylight => SamplePurpose::Atmosphere,
                                SamplePurpose::Atmosphere => SamplePurpose::Daylight,
                            };
                            commands.push((put(c), None));
                        }
                    });
                    row.col(|ui| {
                        let mut w = s.window_px;
                        let r = ui.add(egui::DragValue::new(&mut w).range(1..=101).speed(0.2));
                        name_widget(ui, &r, &format!("window {}", s.id));
                        let w = w | 1;
                        if r.changed() && w != s.window_px {
                            let mut c = s.clone();
                            c.window_px = w;
                            commands.push((put(c), Some(format!("sample window {}", s.id))));
                        }
                    });
                    row.col(|ui| {
                        let mut on = s.enabled;
                        let r = ui.checkbox(&mut on, "");
                        name_widget(ui, &r, &format!("use sample {}", s.id));
                        if r.changed() {
                            let mut c = s.clone();
                            c.enabled = on;
                            commands.push((put(c), None));
                        }
                    });
                    row.col(|ui| {
                        let r = ui.small_button("del");
                        name_widget(ui, &r, &format!("delete sample {}", s.id));
                        if r.clicked() {
                            commands.push((
                                Command::Fit(FitCommand::RemoveSample { id: s.id.clone() }),
                                None,
                            ));
                        }
                    });
                });
            }
        });
    sort.store(ui, sort_id);
}

fn put(sample: photomontage::site::Sample) -> Command {
    Command::Fit(FitCommand::PutSample { sample, at: None })
}

pub(crate) fn horizons_table_ui(
    ui: &mut egui::Ui,
    site: &Site,
    commands: &mut Vec<(Command, Option<String>)>,
) {
    if site.horizon_samples.is_empty() {
        ui.label("none: Shift-drag a rectangle of sky at the horizon on the photo");
        return;
    }
    let sort_id = egui::Id::unique("fit horizon samples sort");
    let mut sort = SortState::load(ui, sort_id);
    let order = sorted_rows(&site.horizon_samples, sort, |s, column| match column {
        0 => SortKey::Text(s.id.clone()),
        1 => SortKey::Text(s.photo.clone()),
        2 => SortKey::Number(f64::from(s.origin_px[1]) * 1e6 + f64::from(s.origin_px[0])),
        3 => SortKey::Number(f64::from(s.size_px[0]) * f64::from(s.size_px[1])),
        _ => SortKey::Number(f64::from(u8::from(s.enabled))),
    });
    TableBuilder::new(ui)
        .id_salt("fit horizon samples")
        .striped(true)
        .column(Column::auto().at_least(40.0))
        .column(Column::auto().at_least(36.0))
        .column(Column::auto().at_least(90.0))
        .column(Column::auto().at_least(80.0))
        .column(Column::auto().at_least(24.0))
        .column(Column::remainder().at_least(30.0))
        .max_scroll_height(140.0)
        .header(20.0, |mut h| {
            for (column, t) in ["id", "photo", "origin px", "size px", "on"]
                .into_iter()
                .enumerate()
            {
                h.col(|ui| {
                    if let Some(next) = table_sort::header(ui, "horizon samples", sort, column, t) {
                        sort = next;
                    }
                });
            }
            h.col(|_| {});
        })
        .body(|mut body| {
            for s in order.iter().map(|&i| &site.horizon_samples[i]) {
                body.row(22.0, |mut row| {
                    row.col(|ui| {
                        ui.label(&s.id);
                    });
                    row.col(|ui| {
                        ui.label(&s.photo);
                    });
                    row.col(|ui| {
                        ui.label(format!("{}, {}", s.origin_px[0], s.origin_px[1]));
                    });
                    row.col(|ui| {
                        ui.label(format!("{} × {}", s.size_px[0], s.size_px[1]));
                    });
                    row.col(|ui| {
                        let mut on = s.enabled;
                        let r = ui.checkbox(&mut on, "");
                        name_widget(ui, &r, &format!("use horizon {}", s.id));
                        if r.changed() {
                            let mut c = s.clone();
                            c.enabled = on;
                            commands.push((
                                Command::Fit(FitCommand::PutHorizonSample {
                                    sample: c,
                                    at: None,
                                }),
                                None,
                            ));
                        }
                    });
                    row.col(|ui| {
                        let r = ui.small_button("del");
                        name_widget(ui, &r, &format!("delete horizon {}", s.id));
                        if r.clicked() {
                            commands.push((
                                Command::Fit(FitCommand::RemoveHorizonSample { id: s.id.clone() }),
                                None,
                            ));
                        }
                    });
                });
            }
        });
    sort.store(ui, sort_id);
}
