//! The studio's frame around the side tabs, as panels ([`crate::panel::Panel`]): the toolbar
//! (Save, Undo, Redo, Solve, Fit view, a typed site path with Open), the photo strip (one entry
//! per photo with its observations and RMS, Camera settings) and the message area. They draw
//! from the [`PanelContext`] and return [`Action`]s like the tabs.
//!
//! # Known limitations
//! The File menu (native dialogs, recent sites) is drawn by `crate::files` beside the toolbar,
//! not by it.

use eframe::egui;
use std::path::PathBuf;

use crate::Message;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::{ERROR, name_widget};

/// The toolbar; its own state is the typed site path.
#[derive(Debug, Default)]
pub struct Toolbar {
    /// Site file path typed by the user (the fallback of File → Open).
    pub open_path: String,
}

impl Panel for Toolbar {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        let name = ctx
            .doc
            .map_or_else(|| "no site".into(), |d| d.site.name.clone());
        ui.strong(name);
        ui.separator();
        if ui.button("Save").clicked() {
            actions.push(Action::Save);
        }
        if ui
            .add_enabled(ctx.can_undo, egui::Button::new("Undo"))
            .clicked()
        {
            actions.push(Action::Undo);
        }
        if ui
            .add_enabled(ctx.can_redo, egui::Button::new("Redo"))
            .clicked()
        {
            actions.push(Action::Redo);
        }
        if ui
            .add_enabled(!ctx.solving, egui::Button::new("Solve"))
            .clicked()
        {
            actions.push(Action::StartSolve);
        }
        if ctx.solving {
            ui.spinner();
        }
        if ui
            .button("Fit view")
            .on_hover_text("fit the whole photo into the view")
            .clicked()
        {
            actions.push(Action::FitView);
        }
        ui.separator();
        let r = ui.add(
            egui::TextEdit::singleline(&mut self.open_path)
                .hint_text("site file path")
                .desired_width(220.0),
        );
        name_widget(ui, &r, "site path");
        if ui.button("Open").clicked() && !self.open_path.trim().is_empty() {
            actions.push(Action::OpenSite(PathBuf::from(self.open_path.trim())));
        }
        actions
    }
}

/// The photo strip (left).
#[derive(Debug, Default)]
pub struct PhotoStrip;

impl Panel for PhotoStrip {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        ui.strong("Photos");
        let Some(doc) = ctx.doc else {
            return actions;
        };
        for p in &doc.site.photos {
            let solved = p.exterior.as_ref().map_or_else(
                || "not solved".to_string(),
                |e| format!("RMS {:.2} px", e.rms_px),
            );
            let n = doc
                .site
                .observations
                .iter()
                .filter(|o| o.photo == p.id)
                .count();
            let text = format!("{}\n{n} obs · {solved}", p.id);
            let sel = ctx.current_photo == Some(p.id.as_str());
            let r = ui.selectable_label(sel, text);
            name_widget(ui, &r, &format!("photo {}", p.id));
            if r.clicked() {
                actions.push(Action::SelectPhoto(p.id.clone()));
            }
        }
        if let Some(id) = ctx.current_photo
            && ui.button("Camera settings").clicked()
        {
            actions.push(Action::OpenPhotoSettings(id.to_owned()));
        }
        actions
    }
}

/// The message area (bottom): errors in red, newest at the bottom.
pub fn messages_ui(ui: &mut egui::Ui, messages: &[Message]) {
    egui::ScrollArea::vertical()
        .stick_to_bottom(true)
        .auto_shrink([false, false])
        .show(ui, |ui| {
            for m in messages {
                if m.is_error {
                    ui.colored_label(ERROR, &m.text);
                } else {
                    ui.label(&m.text);
                }
            }
        });
}
