//! Widgets and colours shared by the studio's panels: accessible names for the widgets the
//! kittests (and screen readers) find by label, and the colours of errors and warnings.
//!
//! # Known limitations
//! Only what more than one panel uses lives here; a panel's own widgets stay in its module.

use eframe::egui::{self, Color32};

/// Colour of error messages and flagged rows.
pub const ERROR: Color32 = Color32::from_rgb(255, 90, 90);
/// Colour of warnings.
pub const WARNING: Color32 = Color32::from_rgb(230, 160, 40);

/// Gives a widget an accessible name (for screen readers and the kittest tests).
pub fn name_widget(ui: &egui::Ui, response: &egui::Response, name: &str) {
    ui.ctx().accesskit_node_builder(response.id, |node| {
        node.set_label(name.to_owned());
    });
}
