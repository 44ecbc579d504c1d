//! Picking polygon vertices on the photo (Scene tab; Durisch 1992 §4.1, scene geometry built
//! from surveyed and intersected points): the site's control points and intersected tie points
//! projected into the current photo by the library (`photomontage::site::photo_points`, lens
//! distortion included); a click within [`PICK_RADIUS_POINTS`] of a projected point adds
//! it to the polygon under construction (nearest wins), the polygon's outline is drawn live
//! (with the site's existing polygons in grey), and Enter (or the panel's button) closes it as
//! one undoable edit through the command path ([`crate::Studio::create_polygon`]).
//!
//! While the Scene tab is shown, clicks on the photo pick vertices instead of placing
//! observations (the Points tab places them); zoom and pan work as usual.
//!
//! # Known limitations
//! Only points with world coordinates can be picked (control points and tie points that were
//! intersected or solved); a point observed but not yet intersected is not offered. Points
//! behind the camera or outside the photo are not offered. Polygons are outlined as straight
//! screen segments between projected vertices.

use eframe::egui::{self, Color32, Key, PointerButton, Pos2};
pub use photomontage::site::photo_points::{ProjectedPoint, projected_points};

use crate::viewport::ViewTransform;

/// How close (screen points) a click must be to a projected point to pick it: a little more
/// than the drawn marker's radius, so that a click on the marker always picks it.
pub const PICK_RADIUS_POINTS: f32 = 8.0;

/// The id of the projected point nearest to `screen` under `t`, if within `radius_points`.
#[must_use]
pub fn nearest_point<'a>(
    points: &'a [ProjectedPoint],
    t: &ViewTransform,
    screen: Pos2,
    radius_points: f32,
) -> Option<&'a str> {
    points
        .iter()
        .map(|p| (p, t.screen_from_photo(p.pixel_px).distance(screen)))
        .filter(|(_, d)| *d <= radius_points)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(p, _)| p.id.as_str())
}

impl crate::Studio {
    /// Scene-tab interaction on the photo: a click picks the nearest projected point as the
    /// next vertex; Enter closes the polygon; Backspace removes the last vertex.
    pub(crate) fn vertex_pick_interaction(
        &mut self,
        response: &egui::Response,
        t: &ViewTransform,
        photo: &str,
    ) {
        let (enter, backspace) = response
            .ctx
            .input(|i| (i.key_pressed(Key::Enter), i.key_pressed(Key::Backspace)));
        let typing = response.ctx.text_edit_focused();
        if !typing && enter && !self.scene.vertices.is_empty() {
            self.close_polygon = true;
        }
        if !typing && backspace {
            self.scene.vertices.pop();
        }
        if !response.clicked_by(PointerButton::Primary) {
            return;
        }
        let (Some(doc), Some(at)) = (self.doc.as_ref(), response.interact_pointer_pos()) else {
            return;
        };
        let points = projected_points(&doc.site, photo);
        if points.is_empty() {
            self.say(
                format!("photo {photo} is not solved: solve it to pick vertices on it"),
                true,
            );
            return;
        }
        match nearest_point(&points, t, at, PICK_RADIUS_POINTS) {
            Some(id) => self.scene.vertices.push(id.to_owned()),
            None => self.say(
                "no control or tie point there: click on a point's marker",
                false,
            ),
        }
    }

    /// Draws the pickable points, the site's polygons (grey) and the polygon under
    /// construction (yellow, closing edge dashed) over the photo.
    pub(crate) fn paint_scene_overlay(
        &self,
        painter: &egui::Painter,
        t: &ViewTransform,
        photo: &str,
        hover: Option<Pos2>,
    ) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let points = projected_points(&doc.site, photo);
        let screen_of = |id: &str| {
            points
                .iter()
                .find(|p| p.id == id)
                .map(|p| t.screen_from_photo(p.pixel_px))
        };
        let grey = egui::Stroke::new(1.5, Color32::from_gray(190));
        for poly in &doc.site.polygons {
            let pts: Vec<Pos2> = poly.vertices.iter().filter_map(|v| screen_of(v)).collect();
            if pts.len() == poly.vertices.len() && pts.len() >= 2 {
                painter.add(egui::Shape::closed_line(pts, grey));
            }
        }
        let hot = hover.and_then(|h| nearest_point(&points, t, h, PICK_RADIUS_POINTS));
        for p in &points {
            let c = t.screen_from_photo(p.pixel_px);
            let colour = if hot == Some(p.id.as_str()) {
                Color32::from_rgb(255, 230, 0)
            } else {
                Color32::from_rgb(120, 200, 255)
            };
            painter.circle_stroke(c, 5.0, egui::Stroke::new(1.5, colour));
        }
        let yellow = egui::Stroke::new(2.5, Color32::from_rgb(255, 210, 0));
        let pts: Vec<Pos2> = self
            .scene
            .vertices
            .iter()
            .filter_map(|v| screen_of(v))
            .collect();
        for (i, p) in pts.iter().enumerate() {
            painter.circle_filled(*p, 4.0, yellow.color);
            painter.text(
                *p + egui::vec2(6.0, -6.0),
                egui::Align2::LEFT_BOTTOM,
                format!("{}", i + 1),
                egui::FontId::proportional(12.0),
                yellow.color,
            );
        }
        if pts.len() >= 2 {
            painter.add(egui::Shape::line(pts.clone(), yellow));
        }
        if let (Some(first), Some(last)) = (pts.first(), pts.last())
            && pts.len() >= 3
        {
            painter.extend(egui::Shape::dashed_line(&[*last, *first], yellow, 6.0, 4.0));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewport::Viewport;

    fn at(id: &str, x: f64, y: f64) -> ProjectedPoint {
        ProjectedPoint {
            id: id.into(),
            pixel_px: [x, y],
        }
    }

    #[test]
    fn nearest_within_radius_wins() {
        let rect = egui::Rect::from_min_size(egui::pos2(0.0, 0.0), egui::vec2(100.0, 100.0));
        let mut v = Viewport::default();
        v.fit(rect, [100, 100]);
        let t = v.transform(rect);
        let pts = [
            at("a", 10.0, 10.0),
            at("b", 14.0, 10.0),
            at("c", 60.0, 60.0),
        ];
        let s = |x: f64, y: f64| t.screen_from_photo([x, y]);
        assert_eq!(nearest_point(&pts, &t, s(11.0, 10.0), 8.0), Some("a"));
        assert_eq!(nearest_point(&pts, &t, s(13.0, 10.0), 8.0), Some("b"));
        assert_eq!(nearest_point(&pts, &t, s(40.0, 40.0), 8.0), None);
    }
}
