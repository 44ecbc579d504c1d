//! The Render panel's choice of view and paper: the photo as taken, a planar view at a 50 mm or
//! 75 mm equivalent of the current photo, or a cylindrical panorama of listed photos (TGN 06/19;
//! `photomontage::verified::standard_view`, the same call as `photomontage view` and
//! `photomontage sheet`), and the sheet's paper (A3, A2, A1). A re-projected view is made on the
//! render panel's one [`crate::worker::Worker`] with the site's render settings (as the CLI
//! does), shown whole in the viewer, and its sheet carries its own geometry.
//!
//! # Known limitations
//! Re-projected views use the site's `[render]` settings, not the panel's rays-per-pixel and seed,
//! and show no tile-by-tile progress (a spinner only).

use eframe::egui;
use photomontage::render::RenderedImage;
use photomontage::site::SiteDocument;
use photomontage::verified::cylindrical_view::CylindricalOptions;
use photomontage::verified::standard_view::{StandardView, make_view};
use photomontage::verified::{AvrLevel, PaperSize, ViewGeometry, ViewGeometryOptions};
use std::sync::atomic::AtomicBool;

use crate::render_job::RenderPanelError;
use crate::widgets::name_widget;

/// Which view the Start button makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewKind {
    /// The current photo as taken (the montage with tiles streamed).
    #[default]
    Photo,
    /// The current photo re-projected to a 50 mm equivalent.
    Planar50,
    /// The current photo re-projected to a 75 mm equivalent.
    Planar75,
    /// A cylindrical panorama (50 mm equivalent) of the listed photos.
    Cylindrical,
}

impl ViewKind {
    /// The button's label.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Photo => "photo as taken",
            Self::Planar50 => "planar 50 mm",
            Self::Planar75 => "planar 75 mm",
            Self::Cylindrical => "cylindrical",
        }
    }
}

/// The view and paper chosen in the panel.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ViewChoice {
    pub kind: ViewKind,
    /// Photo ids of the panorama, comma-separated (empty: the current photo).
    pub panorama_photos: String,
    /// Paper of the sheet (and of the viewing distance in the report).
    pub paper: PaperSize,
}

impl ViewChoice {
    /// The library's view for `current_photo`, `None` for the photo as taken.
    #[must_use]
    pub fn standard_view(&self, current_photo: &str) -> Option<StandardView> {
        let planar = |mm: f64| StandardView::Planar {
            photo: current_photo.to_owned(),
            focal_equiv_mm: mm,
            size_px: None,
        };
        match self.kind {
            ViewKind::Photo => None,
            ViewKind::Planar50 => Some(planar(50.0)),
            ViewKind::Planar75 => Some(planar(75.0)),
            ViewKind::Cylindrical => {
                let mut photos: Vec<String> = self
                    .panorama_photos
                    .split(',')
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned)
                    .collect();
                if photos.is_empty() {
                    photos.push(current_photo.to_owned());
                }
                Some(StandardView::Cylindrical {
                    photos,
                    options: CylindricalOptions::default(),
                })
            }
        }
    }

    /// The view and paper controls.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label("view");
            for kind in [
                ViewKind::Photo,
                ViewKind::Planar50,
                ViewKind::Planar75,
                ViewKind::Cylindrical,
            ] {
                ui.selectable_value(&mut self.kind, kind, kind.label());
            }
        });
        if self.kind == ViewKind::Cylindrical {
            ui.horizontal(|ui| {
                let r = ui.add(
                    egui::TextEdit::singleline(&mut self.panorama_photos)
                        .hint_text("P1,P2,P3 (taken from one point)")
                        .desired_width(200.0),
                );
                name_widget(ui, &r, "panorama photos");
            });
        }
        ui.horizontal(|ui| {
            ui.label("sheet paper");
            for paper in [PaperSize::A3, PaperSize::A2, PaperSize::A1] {
                let r = ui.selectable_value(&mut self.paper, paper, paper.name());
                name_widget(ui, &r, &format!("paper {}", paper.name()));
            }
        });
    }
}

/// Makes a re-projected view with the proposal at `avr` (the worker's job).
///
/// # Errors
/// [`RenderPanelError::Render`] with the library's message (unsolved photo, no proposal, photos
/// not from one point, ...), [`RenderPanelError::Cancelled`].
pub fn make_reprojected(
    doc: &SiteDocument,
    photo_id: &str,
    view: &StandardView,
    avr: AvrLevel,
    paper: PaperSize,
    cancel: &AtomicBool,
) -> Result<(RenderedImage, ViewGeometry), RenderPanelError> {
    let options = ViewGeometryOptions {
        paper,
        ground_level_m: None,
    };
    match make_view(doc, view, Some(avr), &options, &|_| {}, cancel) {
        Ok(made) => Ok((made.image, made.geometry)),
        Err(_) if cancel.load(std::sync::atomic::Ordering::SeqCst) => {
            Err(RenderPanelError::Cancelled {
                photo: photo_id.to_owned(),
            })
        }
        Err(e) => Err(RenderPanelError::Render {
            photo: photo_id.to_owned(),
            message: e.to_string(),
        }),
    }
}

/// The screen rectangle of a `view_px` image fitted (aspect kept, centred) into `frame`.
#[must_use]
pub fn fitted_rect(frame: egui::Rect, view_px: [u32; 2]) -> egui::Rect {
    #[allow(clippy::cast_precision_loss)]
    let [w, h] = view_px.map(|v| v.max(1) as f32);
    let scale = (frame.width() / w).min(frame.height() / h);
    egui::Rect::from_center_size(frame.center(), egui::vec2(w * scale, h * scale))
}
