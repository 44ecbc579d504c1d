//! Picking the lighting fit's samples on the photo (Fit tab; Durisch 1992 §4.2–4.3: a sample is
//! a point on a scene polygon, its colour read from the photo). A click adds a sample at that
//! pixel of the current photo, with the purpose chosen in the tab; its material is the material
//! attribute of the scene polygon under the click, found by the library
//! (`photomontage::fit::pick::PolygonPicker`: the ray through the pixel of the photo's solved
//! camera cast into the site's natural polygons, the same ray `fit_site` casts for a pixel
//! sample). A click on an unsolved photo or on no polygon (sky) gives a message and adds
//! nothing. Shift-drag draws a horizon-sample rectangle (the sky colour L∞). Each addition is one
//! undoable edit through the command path.
//!
//! Drawn over the photo: each sample of the photo as a marker with its id (its median window as
//! a square to scale once the zoom makes it at least [`WINDOW_SQUARE_MIN_POINTS`] wide), coloured
//! by its normalised residual in the last fit (green → yellow → red at the outlier threshold,
//! red with a cross when flagged, cyan for atmosphere samples, which have no normalised residual,
//! grey when not in the fit or disabled), and each horizon rectangle with its id.
//!
//! # Known limitations
//! The natural scene is rebuilt on every click (fine for hundreds of polygons). A click on an
//! existing marker adds another sample rather than selecting it (edit samples in the table).
//! Rectangles are axis-aligned in the photo.

use eframe::egui::{self, Color32, PointerButton, Stroke};
use photomontage::fit::pick::PolygonPicker;
use photomontage::site::{HorizonSample, Sample, stored_camera};

use crate::commands::Command;
use crate::fit_commands::{FitCommand, next_id};
use crate::viewport::ViewTransform;

/// A window square is drawn once it is at least this wide on screen (points).
pub const WINDOW_SQUARE_MIN_POINTS: f64 = 6.0;
/// Largest side of a horizon rectangle (the site schema's limit).
pub const MAX_RECT_SIDE_PX: u32 = 4096;

/// The pixel rectangle (origin, size) covering the photo positions `a` and `b` (pixel-centre
/// convention: pixel i spans i − ½ … i + ½), clipped to a photo of `size_px`. `None` when it
/// lies outside the photo.
#[must_use]
pub fn pixel_rect(a: [f64; 2], b: [f64; 2], size_px: [u32; 2]) -> Option<([u32; 2], [u32; 2])> {
    if !(a.iter().chain(&b).all(|v| v.is_finite())) {
        return None;
    }
    let mut origin = [0_u32; 2];
    let mut size = [0_u32; 2];
    for k in 0..2 {
        let limit = f64::from(size_px[k]) - 1.0;
        if limit < 0.0 {
            return None;
        }
        let lo = a[k].min(b[k]).round();
        let hi = a[k].max(b[k]).round();
        if hi < 0.0 || lo > limit {
            return None;
        }
        // Both clamped into 0 … limit (< 2³²), so the casts are exact.
        let lo = lo.clamp(0.0, limit) as u32;
        let hi = hi.clamp(0.0, limit) as u32;
        origin[k] = lo;
        size[k] = (hi - lo + 1).min(MAX_RECT_SIDE_PX);
    }
    Some((origin, size))
}

/// Marker colour for a sample's largest normalised residual `n` against the outlier
/// `threshold`: green at 0, yellow at half the threshold, red at and above it.
#[must_use]
pub fn residual_colour(n: f64, threshold: f64) -> Color32 {
    let x = (n / threshold.max(1e-9)).clamp(0.0, 1.0);
    // Two linear ramps: green (60, 220, 90) → yellow (255, 220, 0) → red (255, 60, 60).
    let lerp = |a: f64, b: f64, t: f64| (a + (b - a) * t).round().clamp(0.0, 255.0) as u8;
    if x < 0.5 {
        let t = x * 2.0;
        Color32::from_rgb(lerp(60.0, 255.0, t), 220, lerp(90.0, 0.0, t))
    } else {
        let t = (x - 0.5) * 2.0;
        Color32::from_rgb(255, lerp(220.0, 60.0, t), lerp(0.0, 60.0, t))
    }
}

impl crate::Studio {
    /// Fit-tab interaction on the photo: click adds a sample, Shift-drag a horizon rectangle.
    pub(crate) fn fit_pick_interaction(
        &mut self,
        response: &egui::Response,
        t: &ViewTransform,
        photo: &str,
        size_px: [u32; 2],
    ) {
        let shift = response.ctx.input(|i| i.modifiers.shift);
        if response.drag_started_by(PointerButton::Primary)
            && shift
            && let Some(press) = response.ctx.input(|i| i.pointer.press_origin())
        {
            let p = t.photo_from_screen(press);
            self.fit.rect_drag = Some((p, p));
        }
        if let Some((_, now)) = self.fit.rect_drag.as_mut()
            && let Some(p) = response.interact_pointer_pos()
        {
            *now = t.photo_from_screen(p);
        }
        if response.drag_stopped()
            && let Some((a, b)) = self.fit.rect_drag.take()
        {
            self.add_horizon_rect(photo, a, b, size_px);
        }
        if response.clicked_by(PointerButton::Primary)
            && let Some(p) = response.interact_pointer_pos()
        {
            self.add_sample_at(photo, t.photo_from_screen(p));
        }
    }

    /// Adds a sample at `pixel_px` of `photo` on the polygon under it (one undoable edit), or
    /// says why not.
    pub fn add_sample_at(&mut self, photo: &str, pixel_px: [f64; 2]) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let site = &doc.site;
        if stored_camera(site, photo).is_none() {
            self.say(
                format!("photo {photo} is not solved: press Solve before picking samples on it"),
                true,
            );
            return;
        }
        let hit = PolygonPicker::new(site, None).and_then(|p| p.pick(site, photo, pixel_px));
        match hit {
            Ok(hit) => {
                let id = next_id("S", site.samples.iter().map(|s| s.id.as_str()));
                let sample = Sample {
                    id: id.clone(),
                    photo: photo.to_owned(),
                    material: hit.material.clone(),
                    purpose: self.fit.purpose,
                    point: None,
                    x_px: Some(pixel_px[0]),
                    y_px: Some(pixel_px[1]),
                    window_px: self.fit.window_px | 1,
                    enabled: true,
                };
                let text = format!(
                    "sample {id} at ({:.1}, {:.1}) px on polygon {} ({}), {:.1} m from the camera",
                    pixel_px[0], pixel_px[1], hit.polygon, hit.material, hit.distance_m
                );
                self.pending.push((
                    Command::Fit(FitCommand::PutSample { sample, at: None }),
                    None,
                ));
                self.say(text, false);
            }
            Err(e) => self.say(e.to_string(), true),
        }
    }

    fn add_horizon_rect(&mut self, photo: &str, a: [f64; 2], b: [f64; 2], size_px: [u32; 2]) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let Some((origin_px, size)) = pixel_rect(a, b, size_px) else {
            self.say("the horizon rectangle lies outside the photo", true);
            return;
        };
        let id = next_id("H", doc.site.horizon_samples.iter().map(|s| s.id.as_str()));
        self.say(
            format!(
                "horizon sample {id}: {} × {} px at ({}, {})",
                size[0], size[1], origin_px[0], origin_px[1]
            ),
            false,
        );
        self.pending.push((
            Command::Fit(FitCommand::PutHorizonSample {
                sample: HorizonSample {
                    id,
                    photo: photo.to_owned(),
                    origin_px,
                    size_px: size,
                    enabled: true,
                },
                at: None,
            }),
            None,
        ));
    }

    /// Draws the samples and horizon rectangles of `photo` (and the rectangle being drawn).
    pub(crate) fn paint_fit_overlay(
        &self,
        painter: &egui::Painter,
        t: &ViewTransform,
        photo: &str,
    ) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let site = &doc.site;
        let threshold = site.solve.outlier_threshold_sigma;
        let font = egui::FontId::proportional(12.0);
        for h in site.horizon_samples.iter().filter(|h| h.photo == photo) {
            let [x, y] = h.origin_px.map(f64::from);
            let [w, hh] = h.size_px.map(f64::from);
            let r = t.screen_rect([x - 0.5, y - 0.5], [x + w - 0.5, y + hh - 0.5]);
            let colour = if h.enabled {
                Color32::from_rgb(120, 200, 255)
            } else {
                Color32::GRAY
            };
            painter.rect_stroke(r, 0.0, Stroke::new(1.5, colour), egui::StrokeKind::Middle);
            painter.text(
                r.left_top() + egui::vec2(2.0, -2.0),
                egui::Align2::LEFT_BOTTOM,
                &h.id,
                font.clone(),
                colour,
            );
        }
        if let Some((a, b)) = self.fit.rect_drag {
            let r = egui::Rect::from_two_pos(t.screen_from_photo(a), t.screen_from_photo(b));
            painter.rect_stroke(
                r,
                0.0,
                Stroke::new(1.5, Color32::from_rgb(255, 230, 0)),
                egui::StrokeKind::Middle,
            );
        }
        let report = self.fit.report.as_ref();
        for s in site.samples.iter().filter(|s| s.photo == photo) {
            let Some(at_px) = sample_pixel(site, s) else {
                continue;
            };
            let residual = report.and_then(|r| r.residuals.iter().find(|x| x.sample == s.id));
            let (colour, flagged) = match residual {
                _ if !s.enabled => (Color32::GRAY, false),
                Some(r) if r.flagged => (Color32::from_rgb(255, 60, 60), true),
                Some(r) => (
                    crate::fit_panel::max_normalised(r.normalised)
                        .map_or(Color32::from_rgb(60, 220, 255), |n| {
                            residual_colour(n, threshold)
                        }),
                    false,
                ),
                None if report.is_some() => (Color32::GRAY, false),
                None => (Color32::from_rgb(255, 255, 255), false),
            };
            let c = t.screen_from_photo(at_px);
            let stroke = Stroke::new(2.0, colour);
            let half = f64::from(s.window_px) / 2.0;
            if f64::from(s.window_px) * t.zoom >= WINDOW_SQUARE_MIN_POINTS {
                let r = t.screen_rect(
                    [at_px[0] - half, at_px[1] - half],
                    [at_px[0] + half, at_px[1] + half],
                );
                painter.rect_stroke(r, 0.0, stroke, egui::StrokeKind::Middle);
            }
            painter.circle_stroke(c, 5.0, stroke);
            if flagged {
                let d = egui::vec2(4.0, 4.0);
                painter.line_segment([c - d, c + d], stroke);
                painter.line_segment(
                    [c + egui::vec2(-4.0, 4.0), c + egui::vec2(4.0, -4.0)],
                    stroke,
                );
            }
            painter.text(
                c + egui::vec2(7.0, -7.0),
                egui::Align2::LEFT_BOTTOM,
                &s.id,
                font.clone(),
                colour,
            );
        }
    }
}

/// Where a sample is in its photo: its pixel, or its world point projected.
fn sample_pixel(site: &photomontage::site::Site, s: &Sample) -> Option<[f64; 2]> {
    match (s.x_px, s.y_px, s.point) {
        (Some(x), Some(y), _) => Some([x, y]),
        (_, _, Some(p)) => {
            let camera = stored_camera(site, &s.photo)?;
            let q = camera.project(&p.into())?;
            Some([q.x, q.y])
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangles_cover_the_dragged_pixels_and_clip_to_the_photo() {
        // Dragged from (10.4, 20.6) to (3.2, 5.0): pixels 3…10 × 5…21.
        assert_eq!(
            pixel_rect([10.4, 20.6], [3.2, 5.0], [100, 50]),
            Some(([3, 5], [8, 17]))
        );
        // Past the edges: clipped to 0…99 × 0…49.
        assert_eq!(
            pixel_rect([-20.0, -3.0], [150.0, 70.0], [100, 50]),
            Some(([0, 0], [100, 50]))
        );
        assert_eq!(pixel_rect([-20.0, 1.0], [-5.0, 3.0], [100, 50]), None);
        assert_eq!(pixel_rect([f64::NAN, 1.0], [5.0, 3.0], [100, 50]), None);
    }

    #[test]
    fn residual_colours_ramp_green_yellow_red() {
        assert_eq!(residual_colour(0.0, 3.0), Color32::from_rgb(60, 220, 90));
        assert_eq!(residual_colour(1.5, 3.0), Color32::from_rgb(255, 220, 0));
        assert_eq!(residual_colour(3.0, 3.0), Color32::from_rgb(255, 60, 60));
        assert_eq!(residual_colour(9.0, 3.0), Color32::from_rgb(255, 60, 60));
    }
}
