//! The studio window's eframe options, shared by `photomontage-studio` and the window
//! frame-time bench so that the bench measures the window users get.
//!
//! Dithering is off: egui's glow painter otherwise adds up to half an 8-bit step of noise to
//! every painted pixel (it hides banding in computed gradients), which would alter the photo's
//! own pixel values where users place observations at sub-pixel precision. It is also the most
//! expensive per-pixel step on a CPU rasteriser (docs/benchmarks.md, window frame time).
//!
//! The window clears every frame to the panel colour ([`clear_colour`]) and tells the studio
//! so ([`crate::Studio::set_host_clears_to_panel_fill`]): the panels then leave their
//! backgrounds unpainted, which halves the pixels filled per frame.
//!
//! # Known limitations
//! Gradients that egui computes (shadows of popups) can show banding on 8-bit displays.

use eframe::egui;

/// Native options of the studio window with an inner size in points.
#[must_use]
pub fn native_options(inner_size: [f32; 2], title: &str) -> eframe::NativeOptions {
    eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size(inner_size)
            .with_title(title),
        dithering: false,
        ..Default::default()
    }
}

/// The colour the studio window clears to every frame: the panel fill, so that panels need
/// not paint their backgrounds (for `eframe::App::clear_color`).
#[must_use]
pub fn clear_colour(visuals: &egui::Visuals) -> [f32; 4] {
    visuals.panel_fill.to_normalized_gamma_f32()
}
