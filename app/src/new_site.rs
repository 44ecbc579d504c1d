//! File → New site…: a window where the user chooses the photos (the multi-select dialog of
//! [`crate::dialogs::FilePicker`], or a typed path added one at a time) and where the site file
//! goes (a save dialog or a typed path), then creates the site with the library's
//! [`photomontage::site::new::create_site`] (one photo entry per file, interior orientation from
//! EXIF or the stated fallback, paths relative to the site file, saved atomically and never over
//! an existing file), opens it and puts it in the recent list. The library's warnings (no EXIF
//! focal length, a time without offset) and errors (unreadable image, the same photo twice, the
//! site file exists) are shown in the window and in the message area.
//!
//! # Known limitations
//! Photos are listed by path only (no thumbnails); the window creates the site in one step, so
//! control points are imported afterwards (Points tab or File → Import control points…).

use eframe::egui::{self, Color32};
use std::path::{Path, PathBuf};

use crate::dialogs::DialogPurpose;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// State of the New site window.
#[derive(Debug, Default)]
pub struct NewSiteDialog {
    /// Whether the window is shown.
    pub open: bool,
    /// The photos chosen so far, in order.
    pub photos: Vec<PathBuf>,
    /// A photo path being typed (the fallback of the dialog).
    pub photo_path: String,
    /// Where the site file goes.
    pub site_path: String,
    /// The last error, shown in the window.
    pub error: Option<String>,
}

impl NewSiteDialog {
    /// Adds photos (from the dialog or the typed field), skipping ones already listed.
    pub fn add_photos(&mut self, paths: impl IntoIterator<Item = PathBuf>) {
        for p in paths {
            if !self.photos.contains(&p) {
                self.photos.push(p);
            }
        }
        self.error = None;
    }

    /// Sets the site file path (from the save dialog).
    pub fn set_site_path(&mut self, path: &Path) {
        self.site_path = path.display().to_string();
        self.error = None;
    }
}

impl crate::Studio {
    /// The New site window's state (tests and the File menu fill it).
    pub fn new_site_dialog_mut(&mut self) -> &mut NewSiteDialog {
        &mut self.new_site
    }

    /// Creates the site of the New site window, opens it and closes the window; errors are
    /// shown in the window and the message area, and change nothing.
    pub fn create_new_site(&mut self) {
        let site_path = PathBuf::from(self.new_site.site_path.trim());
        if site_path.as_os_str().is_empty() {
            let e = "choose where the site file goes".to_string();
            self.new_site.error = Some(e.clone());
            self.say(e, true);
            return;
        }
        match photomontage::site::new::create_site(&site_path, &self.new_site.photos) {
            Ok(new) => {
                self.new_site = NewSiteDialog::default();
                self.open(&site_path);
                self.say(
                    format!(
                        "created {} with {} photo(s): import control points next",
                        site_path.display(),
                        new.document.site.photos.len()
                    ),
                    false,
                );
                for w in &new.warnings {
                    self.say(format!("warning: {w}"), false);
                }
            }
            Err(e) => {
                self.new_site.error = Some(e.to_string());
                self.say(e.to_string(), true);
            }
        }
    }
}

impl Panel for NewSiteDialog {
    /// Shows the window (when open) over `ui`'s context.
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        if !self.open {
            return Vec::new();
        }
        let mut open = true;
        let mut create = false;
        let mut dialog = None;
        egui::Window::new("New site")
            .open(&mut open)
            .collapsible(false)
            .default_width(520.0)
            // Right of the photo strip, below the toolbar.
            .default_pos(egui::pos2(170.0, 60.0))
            .show(ui.ctx(), |ui| {
                let busy = ctx.dialog_open;
                let d = &mut *self;
                ui.label("Photos of the site:");
                let mut remove = None;
                for (i, p) in d.photos.iter().enumerate() {
                    ui.horizontal(|ui| {
                        ui.label(p.display().to_string());
                        let r = ui.small_button("remove");
                        name_widget(ui, &r, &format!("remove photo {}", p.display()));
                        if r.clicked() {
                            remove = Some(i);
                        }
                    });
                }
                if let Some(i) = remove {
                    d.photos.remove(i);
                }
                if d.photos.is_empty() {
                    ui.colored_label(Color32::GRAY, "none yet");
                }
                ui.horizontal(|ui| {
                    if ui
                        .add_enabled(!busy, egui::Button::new("Choose photos…"))
                        .clicked()
                    {
                        dialog = Some(DialogPurpose::NewSitePhotos);
                    }
                    let r = ui.add(
                        egui::TextEdit::singleline(&mut d.photo_path)
                            .hint_text("or type a photo path")
                            .desired_width(280.0),
                    );
                    name_widget(ui, &r, "new site photo path");
                    if ui.button("Add photo").clicked() && !d.photo_path.trim().is_empty() {
                        let p = PathBuf::from(d.photo_path.trim());
                        d.photo_path.clear();
                        d.add_photos([p]);
                    }
                });
                ui.separator();
                ui.horizontal(|ui| {
                    ui.label("Site file:");
                    let r = ui.add(
                        egui::TextEdit::singleline(&mut d.site_path)
                            .hint_text("path of the new .toml")
                            .desired_width(300.0),
                    );
                    name_widget(ui, &r, "new site file");
                    if ui
                        .add_enabled(!busy, egui::Button::new("Choose file…"))
                        .clicked()
                    {
                        dialog = Some(DialogPurpose::NewSiteFile);
                    }
                });
                if let Some(e) = &d.error {
                    ui.colored_label(crate::widgets::ERROR, e);
                }
                let ready = !d.photos.is_empty() && !d.site_path.trim().is_empty();
                if ui
                    .add_enabled(ready, egui::Button::new("Create site"))
                    .clicked()
                {
                    create = true;
                }
            });
        if !open {
            self.open = false;
        }
        let mut actions: Vec<Action> = dialog.map(Action::RequestDialog).into_iter().collect();
        if create {
            actions.push(Action::CreateNewSite);
        }
        actions
    }
}
