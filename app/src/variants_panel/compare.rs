//! The Variants tab's comparison of the rendered variants: an A/B slider (A left of the split,
//! B right of it, over one picture), A and B side by side, all variants in a grid, and a
//! flicker that alternates A and B every [`FLICKER_PERIOD_S`] or by a button or the space bar.
//! Every picture carries its variant's name drawn on it; the names drawn in the last frame are
//! kept in [`CompareState::drawn_labels`] (tests read them, screen readers get them through the
//! pictures' accessible names).
//!
//! The settings (mode, A and B by variant name, the split, whether the flicker runs) are kept
//! between sessions as [`CompareSettings`] in the studio's UI state file
//! (`crate::state::UiState`), not in the site file: A and B are found again by name after the
//! next "Render all variants".

use eframe::egui::{self, Color32, Rect, pos2, vec2};
use serde::{Deserialize, Serialize};

use super::ShownVariant;
use crate::widgets::name_widget;

/// Seconds each of A and B is shown while flickering (a fixed rate: 1 Hz, a full A-B cycle
/// every 2 s, slow enough to read the labels, fast enough to see what changes).
pub const FLICKER_PERIOD_S: f64 = 1.0;
/// Most grid columns.
pub const GRID_COLUMNS: usize = 3;

/// How the rendered variants are compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CompareMode {
    /// One picture, A left of a movable split and B right of it.
    #[default]
    Slider,
    /// A and B next to each other.
    SideBySide,
    /// Every variant, [`GRID_COLUMNS`] per row at most.
    Grid,
    /// A and B alternating in one place.
    Flicker,
}

/// What of the comparison is kept between sessions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompareSettings {
    /// The mode shown.
    pub mode: CompareMode,
    /// Name of variant A (`None`: the first render).
    pub a: Option<String>,
    /// Name of variant B (`None`: the second render).
    pub b: Option<String>,
    /// Where the A/B slider splits, as a fraction of the width from the left.
    pub split: f32,
    /// Whether the flicker alternates by itself.
    pub flicker_running: bool,
}

impl Default for CompareSettings {
    fn default() -> Self {
        let s = CompareState::default();
        Self {
            mode: s.mode,
            a: None,
            b: None,
            split: s.split,
            flicker_running: s.flicker_running,
        }
    }
}

/// The comparison's state.
#[derive(Debug, Clone)]
pub struct CompareState {
    /// The mode shown.
    pub mode: CompareMode,
    /// Index of variant A in the renders.
    pub a: usize,
    /// Index of variant B in the renders.
    pub b: usize,
    /// Where the A/B slider splits, as a fraction of the width from the left.
    pub split: f32,
    /// Whether the flicker alternates by itself.
    pub flicker_running: bool,
    /// Whether the flicker shows B now.
    pub showing_b: bool,
    last_switch_s: f64,
    /// Names of A and B: those shown last, or those remembered from the last session until
    /// the variants are rendered.
    a_name: Option<String>,
    b_name: Option<String>,
    /// The variant names drawn on the pictures in the last frame, left to right, top down.
    pub drawn_labels: Vec<String>,
}

impl Default for CompareState {
    fn default() -> Self {
        Self {
            mode: CompareMode::Slider,
            a: 0,
            b: 1,
            split: 0.5,
            flicker_running: false,
            showing_b: false,
            last_switch_s: 0.0,
            a_name: None,
            b_name: None,
            drawn_labels: Vec::new(),
        }
    }
}

/// Draws `v`'s picture into `rect` (the part `uv` of it) with its name in a dark box at the
/// top-left (or top-right when `right`).
fn picture(ui: &egui::Ui, v: &mut ShownVariant, rect: Rect, uv: Rect, right: bool) {
    let texture = v.texture(ui.ctx()).id();
    ui.painter().image(texture, rect, uv, Color32::WHITE);
    let font = egui::FontId::proportional(14.0);
    let galley = ui
        .painter()
        .layout_no_wrap(v.name().to_owned(), font, Color32::WHITE);
    let size = galley.size() + vec2(8.0, 4.0);
    let at = if right {
        pos2(rect.right() - size.x - 4.0, rect.top() + 4.0)
    } else {
        rect.left_top() + vec2(4.0, 4.0)
    };
    let label = Rect::from_min_size(at, size);
    ui.painter()
        .rect_filled(label, 3.0, Color32::from_black_alpha(170));
    ui.painter()
        .galley(at + vec2(4.0, 2.0), galley, Color32::WHITE);
}

/// Space for a picture of `aspect` (width / height) at `width`, named for screen readers.
fn allocate(ui: &mut egui::Ui, width: f32, aspect: f32, name: &str) -> egui::Response {
    let size = vec2(width, width / aspect.max(1e-3));
    let (_, r) = ui.allocate_exact_size(size, egui::Sense::click_and_drag());
    name_widget(ui, &r, name);
    r
}

impl CompareState {
    /// The state of a new session with `settings` (A and B are placed by name at the next
    /// [`CompareState::fit_to`]).
    #[must_use]
    pub fn from_settings(settings: &CompareSettings) -> Self {
        Self {
            mode: settings.mode,
            split: settings.split.clamp(0.0, 1.0),
            flicker_running: settings.flicker_running,
            a_name: settings.a.clone(),
            b_name: settings.b.clone(),
            ..Self::default()
        }
    }

    /// What is kept between sessions.
    #[must_use]
    pub fn settings(&self) -> CompareSettings {
        CompareSettings {
            mode: self.mode,
            a: self.a_name.clone(),
            b: self.b_name.clone(),
            split: self.split,
            flicker_running: self.flicker_running,
        }
    }

    /// Places A and B in new renders named `names`: the variants of those names when they
    /// were rendered, else the first and the second.
    pub fn fit_to(&mut self, names: &[String]) {
        let find = |name: &Option<String>| {
            name.as_ref()
                .and_then(|n| names.iter().position(|m| m == n))
        };
        self.a = find(&self.a_name).unwrap_or(0);
        self.b = find(&self.b_name).unwrap_or(usize::from(names.len() > 1));
    }

    /// Shows the other of A and B in the flicker.
    pub fn flip(&mut self) {
        self.showing_b = !self.showing_b;
    }

    fn pick_ui(&mut self, ui: &mut egui::Ui, shown: &[ShownVariant]) {
        ui.horizontal(|ui| {
            for (which, label) in [(0, "Variant A"), (1, "Variant B")] {
                let index = if which == 0 { &mut self.a } else { &mut self.b };
                let current = shown.get(*index).map_or("", ShownVariant::name);
                let r = egui::ComboBox::from_id_salt(label)
                    .selected_text(format!("{}: {current}", &label[8..]))
                    .show_ui(ui, |ui| {
                        for (i, v) in shown.iter().enumerate() {
                            let r = ui.selectable_value(index, i, v.name());
                            name_widget(ui, &r, &format!("{label} {}", v.name()));
                        }
                    });
                name_widget(ui, &r.response, label);
            }
        });
    }

    /// Draws the mode choice and the comparison of `shown`.
    pub fn ui(&mut self, ui: &mut egui::Ui, shown: &mut [ShownVariant]) {
        self.drawn_labels.clear();
        let n = shown.len();
        if n == 0 {
            return;
        }
        self.a = self.a.min(n - 1);
        self.b = self.b.min(n - 1);
        self.a_name = Some(shown[self.a].name().to_owned());
        self.b_name = Some(shown[self.b].name().to_owned());
        ui.horizontal(|ui| {
            for (mode, label) in [
                (CompareMode::Slider, "A/B slider"),
                (CompareMode::SideBySide, "Side by side"),
                (CompareMode::Grid, "Grid"),
                (CompareMode::Flicker, "Flicker"),
            ] {
                let r = ui.selectable_value(&mut self.mode, mode, label);
                name_widget(ui, &r, label);
            }
        });
        if self.mode != CompareMode::Grid {
            self.pick_ui(ui, shown);
            self.a_name = Some(shown[self.a].name().to_owned());
            self.b_name = Some(shown[self.b].name().to_owned());
        }
        let width = ui.available_width().max(50.0);
        let (a, b) = (self.a, self.b);
        match self.mode {
            CompareMode::Slider => {
                let r = ui.add(egui::Slider::new(&mut self.split, 0.0..=1.0).text("split"));
                name_widget(ui, &r, "A/B split");
                let aspect = shown[a].aspect();
                let r = allocate(ui, width, aspect, "A/B comparison");
                if let Some(p) = r.interact_pointer_pos() {
                    self.split = ((p.x - r.rect.left()) / r.rect.width()).clamp(0.0, 1.0);
                }
                let rect = r.rect;
                let x = rect.left() + self.split * rect.width();
                let left = Rect::from_min_max(rect.min, pos2(x, rect.bottom()));
                let right = Rect::from_min_max(pos2(x, rect.top()), rect.max);
                let uv_left = Rect::from_min_max(pos2(0.0, 0.0), pos2(self.split, 1.0));
                let uv_right = Rect::from_min_max(pos2(self.split, 0.0), pos2(1.0, 1.0));
                picture(ui, &mut shown[a], left, uv_left, false);
                picture(ui, &mut shown[b], right, uv_right, true);
                ui.painter()
                    .vline(x, rect.y_range(), egui::Stroke::new(2.0, Color32::WHITE));
                self.drawn_labels = vec![shown[a].name().to_owned(), shown[b].name().to_owned()];
            }
            CompareMode::SideBySide => {
                let half = (width - 8.0) / 2.0;
                ui.horizontal(|ui| {
                    for (i, name) in [(a, "Side A"), (b, "Side B")] {
                        let r = allocate(ui, half, shown[i].aspect(), name);
                        picture(ui, &mut shown[i], r.rect, full_uv(), false);
                        self.drawn_labels.push(shown[i].name().to_owned());
                    }
                });
            }
            CompareMode::Grid => {
                let columns = n.min(GRID_COLUMNS);
                let cell = (width - 4.0 * columns as f32) / columns as f32;
                for row in shown.chunks_mut(columns) {
                    ui.horizontal(|ui| {
                        for v in row {
                            let r = allocate(ui, cell, v.aspect(), &format!("Grid {}", v.name()));
                            picture(ui, v, r.rect, full_uv(), false);
                            self.drawn_labels.push(v.name().to_owned());
                        }
                    });
                }
            }
            CompareMode::Flicker => self.flicker_ui(ui, shown, width),
        }
    }

    fn flicker_ui(&mut self, ui: &mut egui::Ui, shown: &mut [ShownVariant], width: f32) {
        ui.horizontal(|ui| {
            let r = ui.button("Flip A/B");
            name_widget(ui, &r, "Flip A/B");
            let key = !ui.ctx().text_edit_focused()
                && ui.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Space));
            if r.clicked() || key {
                self.flip();
                self.last_switch_s = ui.input(|i| i.time);
            }
            let label = if self.flicker_running {
                "Pause flicker"
            } else {
                "Start flicker"
            };
            let r = ui.button(label);
            name_widget(ui, &r, label);
            if r.clicked() {
                self.flicker_running = !self.flicker_running;
                self.last_switch_s = ui.input(|i| i.time);
            }
            ui.label(format!("{FLICKER_PERIOD_S} s each; space flips"));
        });
        if self.flicker_running {
            let now = ui.input(|i| i.time);
            if now - self.last_switch_s >= FLICKER_PERIOD_S {
                self.flip();
                self.last_switch_s = now;
            }
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_secs_f64(FLICKER_PERIOD_S));
        }
        let i = if self.showing_b { self.b } else { self.a };
        let r = allocate(ui, width, shown[i].aspect(), "Flicker picture");
        picture(ui, &mut shown[i], r.rect, full_uv(), false);
        self.drawn_labels.push(shown[i].name().to_owned());
    }
}

fn full_uv() -> Rect {
    Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0))
}
