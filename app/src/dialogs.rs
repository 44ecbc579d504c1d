//! Native file dialogs (the `rfd` crate; on Linux the XDG desktop portal over a dlopened libdbus,
//! else zenity) shown on the studio's [`Worker`] so that the UI never blocks. The dialog itself
//! is behind the [`FilePicker`] trait so that tests (egui_kittest cannot drive a native dialog)
//! substitute a picker that answers with a fixed path.
//!
//! # Known limitations
//! One dialog at a time (a second request while one is open is refused). On macOS, rfd's
//! synchronous dialogs want the main thread; the worker-thread dialogs are only exercised on
//! Linux.

use eframe::egui;
use std::path::PathBuf;
use std::sync::Arc;

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
    /// Export the Variants tab's comparison sheet (.pdf or .png).
    ExportComparison,
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
            Self::ExportComparison => "Export comparison sheet",
        }
    }

    /// Whether the dialog chooses a file to write.
    #[must_use]
    pub fn is_save(self) -> bool {
        matches!(
            self,
            Self::SaveSiteAs | Self::ExportRender | Self::NewSiteFile | Self::ExportComparison
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
            Self::ExportComparison => &[
                ("PDF, one page per variant", &["pdf"]),
                ("PNG grid", &["png"]),
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
}
