//! The studio's File menu: native file dialogs (the `rfd` crate; on Linux the XDG desktop
//! portal over a dlopened libdbus, else zenity) shown on a worker thread so that the UI never
//! blocks, and the recent-sites list (kept in [`crate::state::UiState`], at most
//! [`crate::state::MAX_RECENT`], files that no longer exist greyed out with a tooltip).
//!
//! The dialog itself is behind the [`FilePicker`] trait so that tests (egui_kittest cannot drive
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

use crate::panel::{Action, Panel, PanelContext};
use crate::worker::{Poll, Worker};

/// What a dialog is for (decides its title, filters and what happens with the answer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    /// Open a site file.
    OpenSite,
    /// Save the site under a new name.
    SaveSiteAs,
    /// Import control points (CSV or OpenDroneMap gcp_list.txt).
    ImportPoints,
    /// Add a CAD model (OBJ, glTF/GLB, DXF) to the site.
    ImportModel,
    /// Export the rendered montage (.exr, .png, .jpg, .tif).
    ExportRender,
    /// Choose the photos of a new site (several at once).
    NewSitePhotos,
    /// Choose where a new site file goes.
    NewSiteFile,
}

impl DialogPurpose {
    /// Title of the dialog window.
    #[must_use]
    pub fn title(self) -> &'static str {
        match self {
            Self::OpenSite => "Open site",
            Self::SaveSiteAs => "Save site as",
            Self::ImportPoints => "Import control points",
            Self::ImportModel => "Import model",
            Self::ExportRender => "Export render",
            Self::NewSitePhotos => "Photos of the new site",
            Self::NewSiteFile => "New site file",
        }
    }

    /// Whether the dialog chooses a file to write.
    #[must_use]
    pub fn is_save(self) -> bool {
        matches!(
            self,
            Self::SaveSiteAs | Self::ExportRender | Self::NewSiteFile
        )
    }

    /// Whether the dialog lets the user choose several files.
    #[must_use]
    pub fn is_multi(self) -> bool {
        matches!(self, Self::NewSitePhotos)
    }

    /// File filters offered: (name, extensions without the dot).
    #[must_use]
    pub fn filters(self) -> &'static [(&'static str, &'static [&'static str])] {
        match self {
            Self::OpenSite | Self::SaveSiteAs | Self::NewSiteFile => &[("Site file", &["toml"])],
            Self::NewSitePhotos => &[
                (
                    "Photos (JPEG, PNG, TIFF, EXR)",
                    &["jpg", "jpeg", "JPG", "JPEG", "png", "tif", "tiff", "exr"],
                ),
                ("All files", &["*"]),
            ],
            Self::ImportPoints => &[
                ("Control points (CSV, gcp_list.txt)", &["csv", "txt"]),
                ("All files", &["*"]),
            ],
            Self::ImportModel => &[
                ("CAD model (OBJ, glTF, DXF)", &["obj", "gltf", "glb", "dxf"]),
                ("All files", &["*"]),
            ],
            Self::ExportRender => &[
                ("OpenEXR (linear)", &["exr"]),
                ("PNG", &["png"]),
                ("JPEG", &["jpg", "jpeg"]),
                ("TIFF", &["tif", "tiff"]),
            ],
        }
    }
}

/// A request for a file dialog.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DialogRequest {
    /// What it is for.
    pub purpose: DialogPurpose,
    /// Folder to start in.
    pub start_dir: Option<PathBuf>,
    /// File name suggested (save dialogs).
    pub file_name: Option<String>,
}

/// Shows a file dialog and returns the chosen path (`None`: cancelled). Called on a worker
/// thread, never on the UI thread.
pub trait FilePicker: Send + Sync {
    /// Asks the user for a file.
    fn pick(&self, request: &DialogRequest) -> Option<PathBuf>;

    /// Asks the user for several files ([`DialogPurpose::is_multi`]); `None`: cancelled. By
    /// default the single-file dialog.
    fn pick_many(&self, request: &DialogRequest) -> Option<Vec<PathBuf>> {
        self.pick(request).map(|p| vec![p])
    }
}

/// The native dialog of the `rfd` crate.
#[derive(Debug, Default, Clone, Copy)]
pub struct NativePicker;

impl FilePicker for NativePicker {
    fn pick(&self, request: &DialogRequest) -> Option<PathBuf> {
        let mut dialog = rfd::FileDialog::new().set_title(request.purpose.title());
        for (name, extensions) in request.purpose.filters() {
            dialog = dialog.add_filter(*name, extensions);
        }
        if let Some(dir) = &request.start_dir {
            dialog = dialog.set_directory(dir);
        }
        if let Some(name) = &request.file_name {
            dialog = dialog.set_file_name(name);
        }
        if request.purpose.is_save() {
            dialog.save_file()
        } else {
            dialog.pick_file()
        }
    }

    fn pick_many(&self, request: &DialogRequest) -> Option<Vec<PathBuf>> {
        let mut dialog = rfd::FileDialog::new().set_title(request.purpose.title());
        for (name, extensions) in request.purpose.filters() {
            dialog = dialog.add_filter(*name, extensions);
        }
        if let Some(dir) = &request.start_dir {
            dialog = dialog.set_directory(dir);
        }
        dialog.pick_files()
    }
}

/// Runs one dialog at a time on the studio's [`Worker`] and hands its answer back.
pub struct DialogWorker {
    picker: Arc<dyn FilePicker>,
    /// The open dialog's purpose; its answer (empty: cancelled) comes from `worker`.
    purpose: Option<DialogPurpose>,
    worker: Worker<Vec<PathBuf>>,
}

impl Default for DialogWorker {
    fn default() -> Self {
        Self::new(Arc::new(NativePicker))
    }
}

impl DialogWorker {
    /// A worker that asks `picker`.
    #[must_use]
    pub fn new(picker: Arc<dyn FilePicker>) -> Self {
        Self {
            picker,
            purpose: None,
            worker: Worker::new("file-dialog"),
        }
    }

    /// Whether a dialog is open.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Opens a dialog on a worker thread; `false` when one is already open.
    pub fn start(&mut self, request: DialogRequest, ctx: &egui::Context) -> bool {
        let picker = Arc::clone(&self.picker);
        let purpose = request.purpose;
        let started = self.worker.spawn(ctx, move |_| {
            if request.purpose.is_multi() {
                picker.pick_many(&request).unwrap_or_default()
            } else {
                picker.pick(&request).into_iter().collect()
            }
        });
        if started {
            self.purpose = Some(purpose);
        }
        started
    }

    /// The answer of the open dialog once it is closed: (purpose, chosen paths — empty when
    /// cancelled — or the message of a dialog that failed, e.g. panicked).
    pub fn poll(&mut self) -> Option<(DialogPurpose, Result<Vec<PathBuf>, String>)> {
        let answer = match self.worker.poll() {
            Poll::Idle | Poll::Running(_) => return None,
            Poll::Done(a) => Ok(a),
            Poll::Cancelled => Ok(Vec::new()),
            Poll::Failed(e) => Err(e),
        };
        Some((self.purpose.take()?, answer))
    }
}

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

    struct Fixed(PathBuf);
    impl FilePicker for Fixed {
        fn pick(&self, _: &DialogRequest) -> Option<PathBuf> {
            Some(self.0.clone())
        }
    }

    #[test]
    fn worker_hands_back_the_pickers_answer_once() {
        let ctx = egui::Context::default();
        let mut w = DialogWorker::new(Arc::new(Fixed(PathBuf::from("/x/site.toml"))));
        let req = DialogRequest {
            purpose: DialogPurpose::OpenSite,
            start_dir: None,
            file_name: None,
        };
        assert!(w.start(req.clone(), &ctx));
        assert!(
            !w.start(req, &ctx),
            "second dialog refused while one is open"
        );
        let start = std::time::Instant::now();
        let answer = loop {
            if let Some(a) = w.poll() {
                break a;
            }
            assert!(start.elapsed().as_secs() < 10, "worker never answered");
            std::thread::sleep(std::time::Duration::from_millis(5));
        };
        assert_eq!(
            answer,
            (
                DialogPurpose::OpenSite,
                Ok(vec![PathBuf::from("/x/site.toml")])
            )
        );
        assert!(!w.busy());
        assert!(w.poll().is_none());
    }

    #[test]
    fn a_multi_select_dialog_falls_back_to_the_single_pick() {
        let ctx = egui::Context::default();
        let mut w = DialogWorker::new(Arc::new(Fixed(PathBuf::from("/x/p1.jpg"))));
        let req = DialogRequest {
            purpose: DialogPurpose::NewSitePhotos,
            start_dir: None,
            file_name: None,
        };
        assert!(req.purpose.is_multi() && !req.purpose.is_save());
        assert!(w.start(req, &ctx));
        let start = std::time::Instant::now();
        let answer = loop {
            if let Some(a) = w.poll() {
                break a;
            }
            assert!(start.elapsed().as_secs() < 10, "worker never answered");
            std::thread::sleep(std::time::Duration::from_millis(5));
        };
        assert_eq!(
            answer,
            (
                DialogPurpose::NewSitePhotos,
                Ok(vec![PathBuf::from("/x/p1.jpg")])
            )
        );
    }

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
