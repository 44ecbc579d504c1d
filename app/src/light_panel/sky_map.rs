//! The sky map of the Site & light tab (issue 17 item 2, its sky-map part): a polar plot of the
//! sky seen from the site (zenith in the middle, horizon on the outer circle, north up, east
//! right: `photomontage::site::sun_path::sky_map_xy`), with the compass points, elevation rings
//! every 30°, the sun's path on the chosen date (hour marks in local time), the sun at the
//! chosen time (or the manual sun, `lighting.sun_manual`, which wins as in the renderer; its
//! marker is named `sun marker (manual) …` for tests and screen readers) and a legend; below it date and time-of-day sliders that change
//! `lighting.time`, one undo step per drag.
//!
//! The date and time are local to the site's `location.time_zone` (or, without one, at the UTC
//! offset of the current sun time). A slider position that is no local time (the hour the
//! clocks skip) or that happens twice is refused with a message and writes nothing.
//!
//! The sliders only edit the site; with the Render tab's **Live** preview on, the preview is
//! relit from them (`render_panel::live`), otherwise a render started afterwards uses the new
//! time.

use chrono::{
    DateTime, Datelike, FixedOffset, NaiveDate, NaiveDateTime, NaiveTime, Offset as _, Timelike,
};
use eframe::egui::{self, Color32, Pos2, Stroke};
use photomontage::site::SiteDocument;
use photomontage::site::site_time::{parse_site_time, site_time_zone};
use photomontage::site::sun_path::{
    SunAngles, SunPathPoint, SunSource, in_site_zone, site_sun_angles, site_sun_path, sky_map_xy,
};
use photomontage::time_zone::SiteTimeZone;

use crate::light_commands::LightCommand;
use crate::light_panel::{LightPanel, edit};
use crate::panel::Action;
use crate::widgets::name_widget;

/// Side of the sky map, screen points.
pub const SKY_MAP_SIZE: f32 = 260.0;
/// Radius of the horizon circle in the sky map, screen points.
#[must_use]
pub fn sky_map_radius() -> f32 {
    SKY_MAP_SIZE * 0.5 - 16.0
}
/// Minutes between samples of the drawn sun path.
const PATH_STEP_MIN: u32 = 10;
const SUN_COLOUR: Color32 = Color32::from_rgb(255, 170, 0);
const PATH_COLOUR: Color32 = Color32::from_rgb(240, 200, 60);
const GRID_COLOUR: Color32 = Color32::from_gray(120);

/// The sliders' state: whether each was held last frame (a new press is a new undo step).
#[derive(Debug, Default)]
pub struct SkyMapState {
    date_down: bool,
    time_down: bool,
    date_gesture: u64,
    time_gesture: u64,
}

/// The local time the map and sliders show: the sun's time for `photo`, else the lighting
/// time, else 21 June 2024 12:00 in the site's zone (UTC without one).
fn shown_time(
    doc: &SiteDocument,
    photo: Option<&str>,
    zone: Option<&SiteTimeZone>,
) -> DateTime<FixedOffset> {
    let utc = chrono::Utc.fix();
    let from_site = photo
        .and_then(|p| site_sun_angles(doc, p).ok())
        .and_then(|s| match s.source {
            SunSource::Computed(t) => Some(t),
            SunSource::Manual => None,
        })
        .or_else(|| {
            doc.site
                .lighting
                .time
                .as_deref()
                .and_then(|t| parse_site_time(t, zone).ok())
        });
    if let Some(t) = from_site {
        return in_site_zone(&t, zone, *t.offset());
    }
    let noon = NaiveDate::from_ymd_opt(2024, 6, 21)
        .and_then(|d| d.and_hms_opt(12, 0, 0))
        .unwrap_or_default();
    zone.and_then(|z| z.resolve(noon).ok())
        .unwrap_or_else(|| noon.and_utc().with_timezone(&utc))
}

/// The instant of local `date` and `minutes` after midnight, in `zone` or at `offset`.
///
/// # Errors
/// The zone's message for a skipped or repeated local time.
pub fn local_instant(
    date: NaiveDate,
    minutes: u32,
    zone: Option<&SiteTimeZone>,
    offset: FixedOffset,
) -> Result<DateTime<FixedOffset>, String> {
    let time = NaiveTime::from_hms_opt(minutes / 60 % 24, minutes % 60, 0)
        .ok_or_else(|| format!("{minutes} minutes is no time of day"))?;
    let local = NaiveDateTime::new(date, time);
    match zone {
        Some(z) => z.resolve(local).map_err(|e| e.to_string()),
        None => local
            .and_local_timezone(offset)
            .single()
            .ok_or_else(|| format!("{local} at {offset} is no instant")),
    }
}

fn day_count(year: i32) -> u32 {
    if NaiveDate::from_ymd_opt(year, 2, 29).is_some() {
        366
    } else {
        365
    }
}

/// Draws the sky map and the sliders; slider changes become `lighting.time` edits.
pub fn sky_map_ui(
    panel: &mut LightPanel,
    ui: &mut egui::Ui,
    doc: &SiteDocument,
    photo: Option<&str>,
    out: &mut Vec<Action>,
) {
    ui.strong("Sky map");
    let manual = doc.site.lighting.sun_manual.as_ref().map(|m| SunAngles {
        azimuth_deg: m.azimuth_deg,
        elevation_deg: m.elevation_deg,
        source: SunSource::Manual,
    });
    let has_location = doc.site.location.is_some();
    if !has_location && manual.is_none() {
        ui.label("set the location to see the sun's path");
        return;
    }
    let zone = site_time_zone(&doc.site).ok().flatten();
    let shown = shown_time(doc, photo, zone.as_ref());
    let date = shown.date_naive();
    let path = has_location.then(|| site_sun_path(&doc.site, date, *shown.offset(), PATH_STEP_MIN));
    // A manual sun is shown whether or not a photo (or a location) gives a computed one.
    let sun = manual.or_else(|| photo.and_then(|p| site_sun_angles(doc, p).ok()));
    let (response, painter) =
        ui.allocate_painter(egui::vec2(SKY_MAP_SIZE, SKY_MAP_SIZE), egui::Sense::hover());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "sky map"));
    name_widget(ui, &response, "sky map");
    let rect = response.rect;
    let centre = rect.center();
    let radius = sky_map_radius();
    let to_screen = |az: f64, el: f64| {
        let [x, y] = sky_map_xy(az, el);
        Pos2::new(centre.x + radius * x as f32, centre.y - radius * y as f32)
    };
    paint_grid(&painter, centre, radius);
    if let Some(Ok(path)) = &path {
        paint_path(&painter, path, &to_screen);
    }
    let kind = |s: &SunAngles| match s.source {
        SunSource::Manual => "manual",
        SunSource::Computed(_) => "computed",
    };
    if let Some(s) = &sun {
        if s.elevation_deg >= 0.0 {
            let p = to_screen(s.azimuth_deg, s.elevation_deg);
            painter.circle_filled(p, 7.0, SUN_COLOUR);
            painter.circle_stroke(p, 7.0, Stroke::new(1.0, Color32::BLACK));
            let marker = ui.interact(
                egui::Rect::from_center_size(p, egui::vec2(14.0, 14.0)),
                egui::Id::unique("sky map sun marker"),
                egui::Sense::hover(),
            );
            marker.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "sun marker"));
            name_widget(
                ui,
                &marker,
                &format!(
                    "sun marker ({}) azimuth {:.3}° elevation {:.3}°",
                    kind(s),
                    s.azimuth_deg,
                    s.elevation_deg
                ),
            );
        } else {
            painter.text(
                centre,
                egui::Align2::CENTER_CENTER,
                "sun below the horizon",
                egui::FontId::proportional(12.0),
                SUN_COLOUR,
            );
        }
    }
    // Legend.
    ui.horizontal(|ui| {
        if has_location {
            legend_swatch(ui, false, PATH_COLOUR);
            ui.label(format!("sun path {date} (hours local)"));
        }
        legend_swatch(ui, true, SUN_COLOUR);
        match &sun {
            Some(s) if matches!(s.source, SunSource::Manual) => {
                ui.label("sun set by hand");
            }
            _ => {
                ui.label(format!("sun at {}", shown.format("%H:%M %:z")));
            }
        }
    });
    match &path {
        Some(Err(e)) => {
            ui.label(format!("no sun path: {e}"));
        }
        None => {
            ui.label("set the location to see the sun's path");
        }
        Some(Ok(_)) => {}
    }
    sliders_ui(panel, ui, doc, &shown, zone.as_ref(), out);
}

/// A legend entry's symbol: a line segment or a disc in `colour`.
pub(crate) fn legend_swatch(ui: &mut egui::Ui, disc: bool, colour: Color32) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(18.0, 12.0), egui::Sense::hover());
    if disc {
        ui.painter().circle_filled(rect.center(), 5.0, colour);
    } else {
        ui.painter().line_segment(
            [rect.left_center(), rect.right_center()],
            Stroke::new(2.0, colour),
        );
    }
}

fn paint_grid(painter: &egui::Painter, centre: Pos2, radius: f32) {
    let grid = Stroke::new(1.0, GRID_COLOUR);
    for el in [0.0_f32, 30.0, 60.0] {
        let r = radius * (90.0 - el) / 90.0;
        painter.circle_stroke(centre, r, grid);
        if el > 0.0 {
            painter.text(
                centre + egui::vec2(3.0, -r),
                egui::Align2::LEFT_BOTTOM,
                format!("{el}°"),
                egui::FontId::proportional(10.0),
                GRID_COLOUR,
            );
        }
    }
    painter.line_segment(
        [
            centre - egui::vec2(radius, 0.0),
            centre + egui::vec2(radius, 0.0),
        ],
        grid,
    );
    painter.line_segment(
        [
            centre - egui::vec2(0.0, radius),
            centre + egui::vec2(0.0, radius),
        ],
        grid,
    );
    for (label, dx, dy) in [
        ("N", 0.0, -1.0),
        ("E", 1.0, 0.0),
        ("S", 0.0, 1.0),
        ("W", -1.0, 0.0),
    ] {
        painter.text(
            centre + egui::vec2(dx, dy) * (radius + 9.0),
            egui::Align2::CENTER_CENTER,
            label,
            egui::FontId::proportional(13.0),
            Color32::WHITE,
        );
    }
}

fn paint_path(
    painter: &egui::Painter,
    path: &[SunPathPoint],
    to_screen: &impl Fn(f64, f64) -> Pos2,
) {
    let stroke = Stroke::new(2.0, PATH_COLOUR);
    let mut run: Vec<Pos2> = Vec::new();
    for p in path {
        if p.elevation_deg >= 0.0 {
            run.push(to_screen(p.azimuth_deg, p.elevation_deg));
            if p.time.minute() == 0 {
                let at = to_screen(p.azimuth_deg, p.elevation_deg);
                painter.circle_filled(at, 2.0, PATH_COLOUR);
                painter.text(
                    at + egui::vec2(0.0, -4.0),
                    egui::Align2::CENTER_BOTTOM,
                    format!("{}", p.time.hour()),
                    egui::FontId::proportional(9.0),
                    PATH_COLOUR,
                );
            }
        } else if !run.is_empty() {
            painter.add(egui::Shape::line(std::mem::take(&mut run), stroke));
        }
    }
    if run.len() >= 2 {
        painter.add(egui::Shape::line(run, stroke));
    }
}

/// A slider's gesture bookkeeping: a new press (or a change without the pointer, e.g. keys)
/// starts a new undo step.
fn gesture(response: &egui::Response, was_down: &mut bool, counter: &mut u64) -> u64 {
    let down = response.is_pointer_button_down_on() || response.dragged();
    if (down && !*was_down) || (response.changed() && !down) {
        *counter += 1;
    }
    *was_down = down;
    *counter
}

fn sliders_ui(
    panel: &mut LightPanel,
    ui: &mut egui::Ui,
    doc: &SiteDocument,
    shown: &DateTime<FixedOffset>,
    zone: Option<&SiteTimeZone>,
    out: &mut Vec<Action>,
) {
    let year = shown.year();
    let mut day = shown.ordinal();
    let mut minutes = shown.hour() * 60 + shown.minute();
    let days = day_count(year);
    let date_r = ui.add(
        egui::Slider::new(&mut day, 1..=days)
            .text("date")
            .custom_formatter(move |v, _| {
                NaiveDate::from_yo_opt(year, v as u32)
                    .map_or_else(|| format!("{v}"), |d| d.format("%d %b").to_string())
            })
            .custom_parser(move |s| {
                NaiveDate::parse_from_str(&format!("{s} {year}"), "%d %b %Y")
                    .ok()
                    .map(|d| f64::from(d.ordinal()))
            }),
    );
    name_widget(ui, &date_r, "date slider");
    let time_r = ui.add(
        egui::Slider::new(&mut minutes, 0..=1439)
            .text("time of day")
            .custom_formatter(|v, _| format!("{:02}:{:02}", v as u32 / 60, v as u32 % 60))
            .custom_parser(|s| {
                let (h, m) = s.trim().split_once(':')?;
                Some(f64::from(
                    h.parse::<u32>().ok()? * 60 + m.parse::<u32>().ok()?,
                ))
            }),
    );
    name_widget(ui, &time_r, "time slider");
    let st = &mut panel.sky_map;
    let date_key = gesture(&date_r, &mut st.date_down, &mut st.date_gesture);
    let time_key = gesture(&time_r, &mut st.time_down, &mut st.time_gesture);
    let key = if date_r.changed() {
        format!("light:date slider:{date_key}")
    } else if time_r.changed() {
        format!("light:time slider:{time_key}")
    } else {
        return;
    };
    let Some(date) = NaiveDate::from_yo_opt(year, day) else {
        return;
    };
    match local_instant(date, minutes, zone, *shown.offset()) {
        Ok(t) => {
            panel.error = None;
            let mut lighting = doc.site.lighting.clone();
            lighting.time = Some(t.to_rfc3339());
            if lighting != doc.site.lighting {
                out.push(edit(
                    LightCommand::SetLighting(Box::new(lighting)),
                    Some(key),
                ));
            }
        }
        Err(e) => panel.error = Some(format!("lighting time: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slider_positions_become_instants_in_the_zone_or_are_refused() {
        let z = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let d = NaiveDate::from_ymd_opt(2024, 6, 21).unwrap();
        let utc = FixedOffset::east_opt(0).unwrap();
        assert_eq!(
            local_instant(d, 15 * 60 + 5, Some(&z), utc)
                .unwrap()
                .to_rfc3339(),
            "2024-06-21T15:05:00+02:00"
        );
        let plus3 = FixedOffset::east_opt(3 * 3600).unwrap();
        assert_eq!(
            local_instant(d, 60, None, plus3).unwrap().to_rfc3339(),
            "2024-06-21T01:00:00+03:00"
        );
        let spring = NaiveDate::from_ymd_opt(2024, 3, 31).unwrap();
        let e = local_instant(spring, 2 * 60 + 30, Some(&z), utc).unwrap_err();
        assert!(e.contains("does not exist"), "{e}");
        assert_eq!(day_count(2024), 366);
        assert_eq!(day_count(2023), 365);
    }
}
