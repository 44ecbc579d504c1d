//! The photo view of the studio: drawing the photo through [`crate::viewport`], zoom about the
//! cursor, pan, the loupe, the observation marks, placing by click, moving by drag, and the
//! residual vectors of the last solve ([`crate::solve::paint_residuals`]). Edits are queued as
//! commands and applied by [`Studio::ui`] through the one command path.
//!
//! # Known limitations
//! Marks are drawn for every observation of the photo each frame (fine for hundreds, not for
//! tens of thousands of points); there is no snapping to image features.

use eframe::egui::{self, Color32, Key, PointerButton, Sense};
use photomontage::site::Observation;

use crate::commands::Command;
use crate::viewport::{self, ViewTransform};
use crate::{PhotoView, Studio, points, solve};

/// Inner margin of the central panel's frame (`egui::Frame::central_panel`).
const CENTRAL_MARGIN: f32 = 8.0;

/// Colour around the photo.
const BACKGROUND: Color32 = Color32::from_gray(20);

impl Studio {
    pub(crate) fn photo_view_ui(&mut self, ui: &mut egui::Ui) {
        let Some(id) = self.current_photo.clone() else {
            ui.label("no photo");
            return;
        };
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        // The central panel has no fill (see `Studio::ui`): paint its margin ring here, unless
        // the window's clear colour already is the panel colour.
        if !self.host_clears_to_panel_fill {
            let panel = rect.expand(CENTRAL_MARGIN);
            for band in viewport::outside(panel, rect) {
                ui.painter()
                    .with_clip_rect(panel)
                    .rect_filled(band, 0.0, ui.visuals().panel_fill);
            }
        }
        if !matches!(self.photos.get(&id), Some(PhotoView::Ready(_))) {
            ui.painter().rect_filled(rect, 0.0, BACKGROUND);
        }
        let size_px = match self.photos.get(&id) {
            Some(PhotoView::Ready(p)) => p.size_px,
            Some(PhotoView::Failed(e)) => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    e,
                    egui::FontId::proportional(14.0),
                    crate::widgets::ERROR,
                );
                return;
            }
            _ => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    format!("decoding {id}…"),
                    egui::FontId::proportional(14.0),
                    Color32::GRAY,
                );
                return;
            }
        };
        if self.viewport.fitted {
            self.viewport.fit(rect, size_px);
        }
        // Zoom about the cursor (wheel, ctrl+wheel, pinch).
        if let Some(hover) = response.hover_pos() {
            let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = f64::from(pinch) * (f64::from(scroll) * 0.0025).exp();
            if (factor - 1.0).abs() > 1e-6 {
                self.viewport.zoom_about(rect, hover, factor);
            }
        }
        let space = ui.input(|i| i.key_down(Key::Space));
        let panning = response.dragged_by(PointerButton::Middle)
            || response.dragged_by(PointerButton::Secondary)
            || (space && response.dragged_by(PointerButton::Primary));
        if panning {
            self.viewport.pan(response.drag_delta());
        }
        let t = self.viewport.transform(rect);
        self.last_transform = Some(t);
        match self.tab {
            crate::SideTab::Scene if !space => self.vertex_pick_interaction(&response, &t, &id),
            crate::SideTab::Fit if !space => {
                self.fit_pick_interaction(&response, &t, &id, size_px);
            }
            crate::SideTab::Light if !space => self.light_pick_interaction(&response, &t, &id),
            // The Tie points tab selects from its list; the photo only shows the tracks.
            crate::SideTab::Scene
            | crate::SideTab::Fit
            | crate::SideTab::Ties
            | crate::SideTab::Light => {}
            crate::SideTab::Materials if !space => {
                self.material_pick_interaction(&response, &t, &id);
            }
            // The Study tab only shows its frames.
            crate::SideTab::Materials | crate::SideTab::Study => {}
            _ => self.observation_interaction(&response, &t, &id, space),
        }

        let painter = ui.painter_at(rect);
        // Background only around the photo: overdraw under it costs fill rate on every frame.
        let photo_rect = t.screen_rect(
            [-0.5, -0.5],
            [f64::from(size_px[0]) - 0.5, f64::from(size_px[1]) - 0.5],
        );
        for band in viewport::outside(rect, photo_rect) {
            painter.rect_filled(band, 0.0, BACKGROUND);
        }
        let ctx = ui.ctx().clone();
        if let Some(PhotoView::Ready(photo)) = self.photos.get_mut(&id)
            && photo.paint(&ctx, &painter, &t)
        {
            ctx.request_repaint();
        }
        if let Some(doc) = self.doc.as_ref() {
            let tone_map = crate::render_panel::site_tone_map(doc);
            self.render
                .paint(&ctx, &painter, &t, &id, size_px, &tone_map);
        }
        self.paint_wireframes(&painter, &t, &id);
        // The Fit tab shows its samples only (the observation marks would hide them).
        let fit_tab = self.tab == crate::SideTab::Fit;
        let marks_hidden = self.tab == crate::SideTab::Render && !self.render.show_marks;
        if !fit_tab && !marks_hidden {
            self.paint_marks(&painter, &t, &id);
        }
        if self.tab == crate::SideTab::Scene {
            self.paint_scene_overlay(&painter, &t, &id, response.hover_pos());
        }
        if self.tab == crate::SideTab::Fit {
            self.paint_fit_overlay(&painter, &t, &id);
        }
        if self.ui_state.show_residuals
            && !fit_tab
            && let (Some(sol), Some(doc)) = (&self.solution, &self.doc)
            && let Some(ps) = sol.photos.iter().find(|p| p.id == id)
        {
            solve::paint_residuals(
                &painter,
                &t,
                &doc.site,
                ps,
                self.ui_state.residual_exaggeration,
            );
        }
        // Loupe for sub-pixel placing.
        if self.ui_state.loupe
            && let Some(hover) = response.hover_pos()
            && let Some(PhotoView::Ready(photo)) = self.photos.get_mut(&id)
        {
            let side = 170.0;
            let mut min = hover + egui::vec2(24.0, -side - 24.0);
            if min.x + side > rect.right() {
                min.x = hover.x - side - 24.0;
            }
            if min.y < rect.top() {
                min.y = hover.y + 24.0;
            }
            let loupe = egui::Rect::from_min_size(min, egui::vec2(side, side));
            let at = t.photo_from_screen(hover);
            let zoom = self
                .ui_state
                .loupe_zoom
                .max(self.viewport.zoom * 4.0)
                .min(64.0);
            viewport::paint_loupe(&ctx, &painter, photo, loupe, at, zoom);
            painter.text(
                loupe.left_bottom() + egui::vec2(4.0, -4.0),
                egui::Align2::LEFT_BOTTOM,
                format!("{:.2}, {:.2}", at[0], at[1]),
                egui::FontId::monospace(11.0),
                Color32::WHITE,
            );
        }
        painter.text(
            rect.right_top() + egui::vec2(-8.0, 8.0),
            egui::Align2::RIGHT_TOP,
            format!("{id} · zoom {:.3}", self.viewport.zoom),
            egui::FontId::proportional(12.0),
            Color32::WHITE,
        );
    }

    fn observation_interaction(
        &mut self,
        response: &egui::Response,
        t: &ViewTransform,
        photo: &str,
        space: bool,
    ) {
        const GRAB_RADIUS_POINTS: f32 = 8.0;
        if space {
            return;
        }
        if response.drag_started_by(PointerButton::Primary)
            && let Some(press) = response.ctx.input(|i| i.pointer.press_origin())
            && let Some(doc) = self.doc.as_ref()
        {
            let nearest = doc
                .site
                .observations
                .iter()
                .filter(|o| o.photo == photo)
                .map(|o| (o, t.screen_from_photo([o.x_px, o.y_px]).distance(press)))
                .filter(|(_, d)| *d <= GRAB_RADIUS_POINTS)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((o, _)) = nearest {
                self.dragging = Some((o.point.clone(), [o.x_px, o.y_px]));
                self.selected_point = Some(o.point.clone());
            }
        }
        if let Some((_, pos)) = self.dragging.as_mut()
            && let Some(p) = response.interact_pointer_pos()
        {
            *pos = t.photo_from_screen(p);
        }
        if response.drag_stopped()
            && let Some((point, pos)) = self.dragging.take()
            && let Some(o) = self.observation(photo, &point)
        {
            let mut moved = o.clone();
            moved.x_px = pos[0];
            moved.y_px = pos[1];
            self.pending.push((
                Command::PutObservation {
                    observation: moved,
                    at: None,
                },
                None,
            ));
        }
        if self.armed_point.is_some()
            && let Some(hover) = response.hover_pos()
        {
            response.ctx.set_cursor_icon(egui::CursorIcon::Crosshair);
            if let Some(point) = self.armed_point.as_deref() {
                let painter = response.ctx.layer_painter(response.layer_id);
                painter.text(
                    hover + egui::vec2(12.0, 12.0),
                    egui::Align2::LEFT_TOP,
                    format!("place {point}"),
                    egui::FontId::proportional(13.0),
                    Color32::from_rgb(255, 230, 0),
                );
            }
        }
        if !response.clicked_by(PointerButton::Primary) {
            return;
        }
        let Some(p) = response.interact_pointer_pos() else {
            return;
        };
        let under_cursor = self.doc.as_ref().and_then(|doc| {
            doc.site
                .observations
                .iter()
                .filter(|o| o.photo == photo)
                .map(|o| (o, t.screen_from_photo([o.x_px, o.y_px]).distance(p)))
                .filter(|(_, d)| *d <= GRAB_RADIUS_POINTS)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(o, _)| o.point.clone())
        });
        match crate::placing::photo_click(self.armed_point.as_deref(), under_cursor.as_deref()) {
            crate::placing::PhotoClick::Ignore => {}
            crate::placing::PhotoClick::Select(point) => {
                self.armed_point = None;
                self.selected_point = Some(point);
            }
            crate::placing::PhotoClick::Place(point) => {
                self.armed_point = None;
                let [x_px, y_px] = t.photo_from_screen(p);
                let old = self.observation(photo, &point);
                let observation = Observation {
                    photo: photo.to_owned(),
                    point,
                    x_px,
                    y_px,
                    sigma_px: old.map_or(points::DEFAULT_SIGMA_PX, |o| o.sigma_px),
                    enabled: old.is_none_or(|o| o.enabled),
                };
                self.pending.push((
                    Command::PutObservation {
                        observation,
                        at: None,
                    },
                    None,
                ));
            }
        }
    }

    fn paint_marks(&self, painter: &egui::Painter, t: &ViewTransform, photo: &str) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let outliers: Vec<&str> = self
            .solution
            .as_ref()
            .and_then(|s| s.photos.iter().find(|p| p.id == photo))
            .map(|p| p.outliers.iter().map(String::as_str).collect())
            .unwrap_or_default();
        for o in doc.site.observations.iter().filter(|o| o.photo == photo) {
            let pos = match &self.dragging {
                Some((p, at)) if *p == o.point => *at,
                _ => [o.x_px, o.y_px],
            };
            let c = t.screen_from_photo(pos);
            let selected = self.selected_point.as_deref() == Some(o.point.as_str());
            let colour = if !o.enabled {
                Color32::GRAY
            } else if outliers.contains(&o.point.as_str()) {
                Color32::from_rgb(255, 60, 60)
            } else if selected {
                Color32::from_rgb(255, 230, 0)
            } else {
                Color32::from_rgb(60, 255, 120)
            };
            let s = egui::Stroke::new(if selected { 2.0 } else { 1.5 }, colour);
            // Matched tie points come by the thousand: a dot each, the selected track marked
            // and labelled like any point.
            if !selected && photomontage::site::tie_points::is_matched(&o.point) {
                painter.circle_filled(c, 2.0, colour);
                continue;
            }
            painter.circle_stroke(c, 6.0, s);
            painter.line_segment([c - egui::vec2(10.0, 0.0), c - egui::vec2(3.0, 0.0)], s);
            painter.line_segment([c + egui::vec2(3.0, 0.0), c + egui::vec2(10.0, 0.0)], s);
            painter.line_segment([c - egui::vec2(0.0, 10.0), c - egui::vec2(0.0, 3.0)], s);
            painter.line_segment([c + egui::vec2(0.0, 3.0), c + egui::vec2(0.0, 10.0)], s);
            painter.text(
                c + egui::vec2(9.0, -9.0),
                egui::Align2::LEFT_BOTTOM,
                &o.point,
                egui::FontId::proportional(12.0),
                colour,
            );
        }
    }
}
