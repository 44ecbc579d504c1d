//! Crash safety: after each batch of edits (debounced, at most [`DEBOUNCE`] after the last
//! edit) and on a timer, the site is written atomically to a sidecar `<stem>.autosave.toml`
//! beside the site file; an explicit save writes the site atomically and removes the sidecar.
//! On open, a sidecar newer than the site is restored (and the user told so).
//!
//! The sidecar is a complete site file in the same folder, so its relative photo paths
//! resolve the same way; it is written with [`photomontage::site::write_atomically`] (temp file,
//! fsync, rename), so a kill at any instant leaves either the previous or the new sidecar.
//!
//! # Known limitations
//! Newer-than is decided by file modification times, so a site edited by another program within
//! the file system's timestamp resolution of the sidecar's write can be shadowed by the sidecar.

use photomontage::site::{Site, SiteDocument, SiteError};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// Longest wait between the last edit and the sidecar write.
pub const DEBOUNCE: Duration = Duration::from_millis(500);
/// Dirty sites are also written at least this often while edits keep coming.
pub const PERIOD: Duration = Duration::from_secs(5);

/// What can go wrong autosaving or restoring.
#[derive(Debug, thiserror::Error)]
pub enum AutosaveError {
    #[error("cannot write the autosave {path}: {source}")]
    Write { path: PathBuf, source: SiteError },
    #[error("cannot read the autosave {path}: {source}")]
    Read { path: PathBuf, source: SiteError },
    #[error(transparent)]
    Site(#[from] SiteError),
    #[error("cannot remove the autosave {path}: {source}")]
    Remove {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The sidecar path of a site: `site.toml` → `site.autosave.toml` in the same folder.
#[must_use]
pub fn sidecar_path(site_path: &Path) -> PathBuf {
    let stem = site_path
        .file_stem()
        .map_or_else(|| "site".into(), |s| s.to_string_lossy().into_owned());
    site_path.with_file_name(format!("{stem}.autosave.toml"))
}

fn modified(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

/// What [`open_with_recovery`] did with the sidecar.
#[derive(Debug, Clone, PartialEq)]
pub enum Recovery {
    /// No sidecar newer than the site: the site was opened.
    None,
    /// The newer sidecar was restored.
    Restored,
    /// A newer sidecar exists but does not load (the message says why); the site was opened
    /// and the sidecar left in place for the user to inspect.
    Unreadable(String),
}

/// Opens a site, preferring a sidecar newer than it. Returns the document (its path is always
/// the site's own path) and what happened to the sidecar.
///
/// # Errors
/// [`AutosaveError::Site`] when the site does not load and no sidecar could stand in.
pub fn open_with_recovery(site_path: &Path) -> Result<(SiteDocument, Recovery), AutosaveError> {
    let sidecar = sidecar_path(site_path);
    let sidecar_newer = match (modified(&sidecar), modified(site_path)) {
        (Some(s), Some(p)) => s >= p,
        (Some(_), None) => true,
        _ => false,
    };
    if !sidecar_newer {
        return Ok((SiteDocument::load(site_path)?, Recovery::None));
    }
    match SiteDocument::load(&sidecar) {
        Ok(mut doc) => {
            doc.path = site_path.to_path_buf();
            Ok((doc, Recovery::Restored))
        }
        Err(source) => {
            let why = AutosaveError::Read {
                path: sidecar,
                source,
            }
            .to_string();
            Ok((SiteDocument::load(site_path)?, Recovery::Unreadable(why)))
        }
    }
}

/// Debounce and timer state of one open site.
#[derive(Debug)]
pub struct Autosave {
    written_revision: u64,
    first_unsaved_edit: Option<Instant>,
    last_edit: Option<Instant>,
    seen_revision: u64,
}

impl Autosave {
    /// State for a site just opened at `revision` (nothing to write yet).
    #[must_use]
    pub fn new(revision: u64) -> Self {
        Self {
            written_revision: revision,
            first_unsaved_edit: None,
            last_edit: None,
            seen_revision: revision,
        }
    }

    /// Whether edits after `revision` are not yet in the sidecar.
    #[must_use]
    pub fn is_dirty(&self, revision: u64) -> bool {
        revision != self.written_revision
    }

    /// Called every frame with the history's revision; writes the sidecar when the edits have
    /// rested for [`DEBOUNCE`] or have been pending for [`PERIOD`]. Returns whether it wrote.
    ///
    /// # Errors
    /// [`AutosaveError::Write`]; the next call tries again.
    pub fn tick(
        &mut self,
        now: Instant,
        revision: u64,
        site: &Site,
        site_path: &Path,
    ) -> Result<bool, AutosaveError> {
        if revision != self.seen_revision {
            self.seen_revision = revision;
            self.last_edit = Some(now);
            self.first_unsaved_edit.get_or_insert(now);
        }
        if !self.is_dirty(revision) {
            return Ok(false);
        }
        let rested = self
            .last_edit
            .is_some_and(|t| now.duration_since(t) >= DEBOUNCE);
        let overdue = self
            .first_unsaved_edit
            .is_some_and(|t| now.duration_since(t) >= PERIOD);
        if !(rested || overdue) {
            return Ok(false);
        }
        self.write_now(revision, site, site_path)?;
        Ok(true)
    }

    /// Writes the sidecar now.
    ///
    /// # Errors
    /// [`AutosaveError::Write`].
    pub fn write_now(
        &mut self,
        revision: u64,
        site: &Site,
        site_path: &Path,
    ) -> Result<(), AutosaveError> {
        let path = sidecar_path(site_path);
        site.save(&path)
            .map_err(|source| AutosaveError::Write { path, source })?;
        self.written_revision = revision;
        self.first_unsaved_edit = None;
        Ok(())
    }

    /// Time until the next write is due, for scheduling a repaint; `None` when clean.
    #[must_use]
    pub fn due_in(&self, now: Instant, revision: u64) -> Option<Duration> {
        if !self.is_dirty(revision) && self.seen_revision == revision {
            return None;
        }
        let from_rest = self
            .last_edit
            .map_or(Duration::ZERO, |t| DEBOUNCE.saturating_sub(now - t));
        Some(from_rest)
    }

    /// An explicit save happened: the site file holds `revision`; the sidecar is removed.
    ///
    /// # Errors
    /// [`AutosaveError::Remove`] when the sidecar exists and cannot be removed.
    pub fn saved(&mut self, revision: u64, site_path: &Path) -> Result<(), AutosaveError> {
        self.written_revision = revision;
        self.seen_revision = revision;
        self.first_unsaved_edit = None;
        let path = sidecar_path(site_path);
        match std::fs::remove_file(&path) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
            Err(source) => Err(AutosaveError::Remove { path, source }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidecar_sits_beside_the_site() {
        assert_eq!(
            sidecar_path(Path::new("/a/b/site.toml")),
            PathBuf::from("/a/b/site.autosave.toml")
        );
    }

    #[test]
    fn debounce_then_write_then_restore_then_save_removes() {
        let dir = tempfile::tempdir().expect("tempdir");
        let site_path = dir.path().join("site.toml");
        let mut site = Site {
            name: "before".into(),
            ..Site::default()
        };
        site.save(&site_path).expect("save");
        let mut a = Autosave::new(0);
        let t0 = Instant::now();
        site.name = "after".into();
        assert!(!a.tick(t0, 1, &site, &site_path).expect("tick"), "too soon");
        assert!(a.is_dirty(1));
        assert!(a.tick(t0 + DEBOUNCE, 1, &site, &site_path).expect("tick"));
        assert!(!a.is_dirty(1));
        let (doc, recovery) = open_with_recovery(&site_path).expect("open");
        assert_eq!(recovery, Recovery::Restored);
        assert_eq!(doc.site.name, "after");
        assert_eq!(doc.path, site_path);
        site.save(&site_path).expect("explicit save");
        a.saved(1, &site_path).expect("remove sidecar");
        assert!(!sidecar_path(&site_path).exists());
        let (_, recovery) = open_with_recovery(&site_path).expect("open");
        assert_eq!(recovery, Recovery::None);
        // A torn or foreign sidecar does not lock the user out of the site.
        std::fs::write(sidecar_path(&site_path), "schema_version = [").expect("write");
        let (doc, recovery) = open_with_recovery(&site_path).expect("open");
        assert!(matches!(recovery, Recovery::Unreadable(ref m) if m.contains("autosave")));
        assert_eq!(doc.site.name, "after", "the saved site");
    }

    #[test]
    fn a_stream_of_edits_is_still_written_every_period() {
        let dir = tempfile::tempdir().expect("tempdir");
        let site_path = dir.path().join("site.toml");
        let site = Site::default();
        let mut a = Autosave::new(0);
        let t0 = Instant::now();
        let step = DEBOUNCE / 2;
        let mut wrote = false;
        let mut revision = 0;
        let mut t = t0;
        while t <= t0 + PERIOD {
            revision += 1;
            wrote |= a.tick(t, revision, &site, &site_path).expect("tick");
            t += step;
        }
        assert!(
            wrote,
            "continuous editing must not postpone the autosave forever"
        );
    }
}
