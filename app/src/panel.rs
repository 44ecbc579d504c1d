//! Panels as types: a panel (side tab, toolbar, menu, window) owns its own state, draws itself from a read-only
//! [`PanelContext`] (the open site, the current photo) and returns the [`Action`]s its widgets
//! asked for; the [`crate::Studio`] applies them after the frame. Edits of the user's data are
//! [`Action::Edit`]s, which go through the one command path (`commands.rs`: undo/redo,
//! autosave); everything else (start or cancel a worker job, export) is a named action, so a
//! panel never reaches into the studio (egui's demo `View` trait, rerun's `ViewerContext` and
//! `SystemCommand`).
//!
//! # Known limitations
//! The six side tabs, the toolbar, the photo strip ([`crate::chrome`]), the File menu and the
//! New site and Camera settings windows are panels; the photo view with its pickers (points,
//! scene vertices, fit samples) is still drawn by `impl Studio` methods.

use eframe::egui;
use photomontage::site::{SiteDocument, SiteSolution};

use crate::commands::Command;

/// What a panel may read while it draws.
#[derive(Clone, Copy)]
pub struct PanelContext<'a> {
    /// The open site.
    pub doc: Option<&'a SiteDocument>,
    /// The photo shown.
    pub current_photo: Option<&'a str>,
    /// The point selected for placing on the photo.
    pub selected_point: Option<&'a str>,
    /// The point the next click on the photo places ([`crate::placing`]).
    pub armed_point: Option<&'a str>,
    /// The last solve's result.
    pub solution: Option<&'a SiteSolution>,
    /// How residual vectors are drawn on the photo (persisted UI state).
    pub residuals: ResidualDisplay,
    /// Whether there is an edit to undo.
    pub can_undo: bool,
    /// Whether there is an undone edit to redo.
    pub can_redo: bool,
    /// Whether a solve is running.
    pub solving: bool,
    /// Whether a file dialog is open (one at a time).
    pub dialog_open: bool,
    /// Whether a finished montage of the current photo exists (Export render…).
    pub has_montage: bool,
    /// The recent sites, newest first.
    pub recent_sites: &'a [std::path::PathBuf],
}

/// How the residual vectors of the last solve are drawn on the photo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualDisplay {
    /// Draw them.
    pub show: bool,
    /// Screen length per pixel of residual.
    pub exaggeration: f64,
}

impl PanelContext<'_> {
    /// Whether the current photo has a solved exterior orientation.
    #[must_use]
    pub fn current_photo_solved(&self) -> bool {
        let (Some(doc), Some(id)) = (self.doc, self.current_photo) else {
            return false;
        };
        doc.site
            .photos
            .iter()
            .any(|p| p.id == id && p.exterior.is_some())
    }
}

/// What a panel asks the studio to do after the frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// An undoable edit of the site; consecutive edits with the same `merge_key` are one undo
    /// step.
    Edit {
        command: Box<Command>,
        merge_key: Option<String>,
    },
    /// Save the site (toolbar).
    Save,
    /// Undo the last edit.
    Undo,
    /// Redo the last undone edit.
    Redo,
    /// Solve the site as it is now (toolbar).
    StartSolve,
    /// Fit the whole photo into the view.
    FitView,
    /// Open a site file.
    OpenSite(std::path::PathBuf),
    /// Show a photo (photo strip).
    SelectPhoto(String),
    /// Open a photo's camera settings window.
    OpenPhotoSettings(String),
    /// Open the file dialog for this purpose (on its worker).
    RequestDialog(crate::dialogs::DialogPurpose),
    /// Show the New site window.
    ShowNewSite,
    /// Create the site of the New site window and open it.
    CreateNewSite,
    /// Change how residual vectors are drawn (Results tab).
    SetResiduals(ResidualDisplay),
    /// Import control points from the Points tab's import path.
    ImportPoints,
    /// Select a point for placing on the photo.
    SelectPoint(String),
    /// Intersect a tie point from its observations (Scene tab).
    IntersectTiePoint(String),
    /// Close the polygon under construction as one undoable edit (Scene tab).
    CreatePolygon,
    /// Import a CAD model file into the site (checked, then one undoable edit).
    ImportModel(std::path::PathBuf),
    /// Render the current photo (Render tab, Start).
    StartRender,
    /// Stop the running render at its next tile.
    CancelRender,
    /// Export the montage to the Render tab's export path.
    ExportRender,
    /// Write the verified-view sheet to the Render tab's sheet path.
    ExportSheet,
    /// Compute the view geometry report of the current photo.
    MakeReport,
    /// Start the lighting fit on the site as it is now.
    StartFit,
    /// Stop the running fit at its next step.
    CancelFit,
    /// Write the last fit's report into the site (one undoable edit).
    ApplyFit,
    /// Run the Study tab's sun study of the current photo.
    StartStudy,
    /// Stop the running study at its next tile.
    CancelStudy,
    /// Write the last study to the Study tab's folder.
    ExportStudy,
    /// Render every variant of the current photo (Variants tab).
    StartVariantRenders,
    /// Stop the variant renders at their next tile.
    CancelVariantRenders,
    /// Write the comparison sheet to the Variants tab's path.
    ExportComparison,
}

/// A side-tab panel.
pub trait Panel {
    /// Draws the panel into `ui` from `ctx`; returns what its widgets asked for.
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action>;
}
