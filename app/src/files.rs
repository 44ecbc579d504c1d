//! The studio's File menu ([`FileMenu`], a panel): the native file dialogs of
//! [`crate::dialogs`] (shown on a worker so that the UI never blocks) and what the studio does
//! with their answers, and the recent-sites list (kept in [`crate::state::UiState`], at most
//! [`crate::state::MAX_RECENT`], files that no longer exist greyed out with a tooltip).
//!
//! The dialog itself is behind the [`crate::dialogs::FilePicker`] trait so that tests (egui_kittest cannot drive
//! a native dialog) substitute a picker that answers with a fixed path. The typed-path fields of
//! the toolbar and panels stay as the fallback.
//!
//! # Known limitations
//! One dialog at a time (a second request while one is open is refused with a message). On
//! macOS, rfd's synchronous dialogs want the main thread; the studio's worker-thread dialogs are
//! only exercised on Linux. File → New site… opens the [`crate::new_site`] window.

use eframe::egui::{self, Color32};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use crate::dialogs::{DialogPurpose, DialogRequest, DialogWorker, FilePicker, NativePicker};
use crate::panel::{Action, Panel, PanelContext};

/// A recent-sites entry as the menu shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecentEntry {
    /// The site file.
    pub path: PathBuf,
    /// Whether the file still exists (missing ones are greyed out).
    pub exists: bool,
}

/// The recent list with each file's existence checked.
#[must_use]
pub fn recent_entries(recent: &[PathBuf]) -> Vec<RecentEntry> {
    recent
        .iter()
        .map(|p| RecentEntry {
            path: p.clone(),
            exists: p.is_file(),
        })
        .collect()
}

/// Label of a recent entry: the site's folder name and file name, then the full path.
#[must_use]
pub fn recent_label(path: &Path) -> String {
    path.display().to_string()
}

impl crate::Studio {
    /// Replaces the file dialog (tests substitute a picker that answers a fixed path).
    pub fn set_file_picker(&mut self, picker: Arc<dyn FilePicker>) {
        self.dialogs = DialogWorker::new(picker);
    }

    /// Opens the file dialog for `purpose` on a worker thread.
    pub fn request_dialog(&mut self, purpose: DialogPurpose, ctx: &egui::Context) {
        let doc_dir = self.doc.as_ref().map(|d| d.base_dir().to_path_buf());
        let file_name = match purpose {
            DialogPurpose::SaveSiteAs => self
                .doc
                .as_ref()
                .and_then(|d| d.path.file_name())
                .map(|n| n.to_string_lossy().into_owned()),
            DialogPurpose::ExportRender => self.current_photo.as_ref().map(|p| format!("{p}.png")),
            DialogPurpose::NewSiteFile => Some("site.toml".into()),
            DialogPurpose::ExportComparison => self
                .current_photo
                .as_ref()
                .map(|p| format!("{p}-variants.pdf")),
            _ => None,
        };
        let request = DialogRequest {
            purpose,
            start_dir: doc_dir,
            file_name,
        };
        if !self.dialogs.start(request, ctx) {
            self.say("a file dialog is already open", true);
        }
    }

    /// Acts on the answer of a closed dialog.
    pub(crate) fn poll_dialogs(&mut self, ctx: &egui::Context) {
        if self.dialogs.busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        let Some((purpose, answer)) = self.dialogs.poll() else {
            return;
        };
        let answer = match answer {
            Ok(a) => a,
            Err(e) => {
                self.say(format!("the {} dialog failed: {e}", purpose.title()), true);
                return;
            }
        };
        if purpose == DialogPurpose::NewSitePhotos {
            self.new_site.add_photos(answer);
            return;
        }
        let Some(path) = answer.into_iter().next() else {
            return;
        };
        match purpose {
            DialogPurpose::OpenSite => self.open(&path),
            DialogPurpose::SaveSiteAs => self.save_as(&path),
            DialogPurpose::ImportPoints => {
                self.set_import_path(&path.to_string_lossy());
                self.import();
            }
            DialogPurpose::ImportModel => self.import_model(&path),
            DialogPurpose::ExportRender => {
                self.render.export_path = path.to_string_lossy().into_owned();
                self.export_render();
            }
            DialogPurpose::NewSiteFile => self.new_site.set_site_path(&path),
            DialogPurpose::NewSitePhotos => {}
            DialogPurpose::ExportComparison => {
                self.variants_panel_mut().export_path = path.to_string_lossy().into_owned();
                self.export_comparison();
            }
        }
    }

    /// Saves the site to `path` (relative file references rebased when the folder changes),
    /// makes it the open site's path and puts it in the recent list.
    pub fn save_as(&mut self, path: &Path) {
        let Some(doc) = self.doc.as_mut() else {
            return;
        };
        let old = doc.path.clone();
        match doc.save_as(path) {
            Ok(()) => {
                if let Err(e) = self.autosave.saved(self.history.revision(), &old) {
                    self.say(e.to_string(), true);
                }
                self.ui_state.remember(path);
                self.persist_ui_state();
                self.say(format!("saved as {}", path.display()), false);
            }
            Err(e) => self.say(e.to_string(), true),
        }
    }

    /// The recent sites as the File menu lists them, newest first.
    #[must_use]
    pub fn recent_sites(&self) -> Vec<RecentEntry> {
        recent_entries(&self.ui_state.recent_sites)
    }
}

/// The File menu: New site…, Open site…, Save, Save as…, the imports, Export render… and the
/// recent sites.
#[derive(Debug, Default)]
pub struct FileMenu;

impl Panel for FileMenu {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        ui.menu_button("File", |ui| {
            let busy = ctx.dialog_open;
            let has_doc = ctx.doc.is_some();
            let mut item = |ui: &mut egui::Ui, enabled: bool, text: &str, action: Action| {
                if ui.add_enabled(enabled, egui::Button::new(text)).clicked() {
                    actions.push(action);
                    ui.close();
                }
            };
            item(ui, true, "New site…", Action::ShowNewSite);
            let dialog = Action::RequestDialog;
            item(ui, !busy, "Open site…", dialog(DialogPurpose::OpenSite));
            item(ui, has_doc, "Save", Action::Save);
            let enabled = has_doc && !busy;
            item(ui, enabled, "Save as…", dialog(DialogPurpose::SaveSiteAs));
            ui.separator();
            let import = dialog(DialogPurpose::ImportPoints);
            item(ui, enabled, "Import control points…", import);
            item(
                ui,
                enabled,
                "Import model…",
                dialog(DialogPurpose::ImportModel),
            );
            let export = dialog(DialogPurpose::ExportRender);
            item(ui, ctx.has_montage && !busy, "Export render…", export);
            ui.separator();
            ui.label("Recent sites");
            let entries = recent_entries(ctx.recent_sites);
            if entries.is_empty() {
                ui.colored_label(Color32::GRAY, "none yet");
            }
            for e in entries {
                let label = recent_label(&e.path);
                let r = ui.add_enabled(e.exists, egui::Button::new(&label));
                let r = if e.exists {
                    r.on_hover_text("open this site")
                } else {
                    r.on_disabled_hover_text("file not found (moved or deleted)")
                };
                if r.clicked() {
                    actions.push(Action::OpenSite(e.path));
                    ui.close();
                }
            }
        });
        actions
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_entries_mark_missing_files() {
        let dir = tempfile::tempdir().expect("tempdir");
        let here = dir.path().join("a.toml");
        std::fs::write(&here, "").expect("write");
        let gone = dir.path().join("gone.toml");
        let e = recent_entries(&[here.clone(), gone.clone()]);
        assert_eq!(
            e,
            vec![
                RecentEntry {
                    path: here,
                    exists: true
                },
                RecentEntry {
                    path: gone,
                    exists: false
                }
            ]
        );
    }
}
