//! Atomic file replacement: every file the product writes goes to a temporary file in the same
//! folder, is flushed to disk and renamed over the target, so a reader (or a render farm that
//! checks whether a job's output exists) sees either the old file or the complete new one, never
//! a torn one — also when the writer is killed (POSIX `rename(2)` is atomic within a file
//! system).
//!
//! Temporaries are named `.NAME.PID.tmp` beside the target; a killed writer leaves one behind,
//! which no reader takes for an output (its name differs) and [`remove_stale_temporaries`]
//! clears.
//!
//! # Known limitations
//! Durability of the rename needs the folder's fsync, which some network file systems ignore.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary file [`write_atomically`] uses for `path` in this process.
#[must_use]
pub fn temporary_path(path: &Path) -> PathBuf {
    let dir = parent_dir(path);
    let file_name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    dir.join(format!(".{file_name}.{}.tmp", std::process::id()))
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes `bytes` to `path` atomically (temporary file beside it, fsync, rename, fsync folder).
///
/// # Errors
/// Any I/O error; the temporary file is removed on failure and `path` is unchanged.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = parent_dir(path);
    let tmp = temporary_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)?;
        // Make the rename itself durable.
        if let Ok(d) = std::fs::File::open(&dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Checks, before any work, that `path` can be written the way [`write_atomically`] will write
/// it: creates and removes its temporary file. The target itself is not touched.
///
/// # Errors
/// The I/O error of creating the temporary file (a missing or read-only folder).
pub fn probe_writable(path: &Path) -> std::io::Result<()> {
    let tmp = temporary_path(path);
    std::fs::File::create(&tmp)?;
    std::fs::remove_file(&tmp)
}

/// Removes temporaries of `path` left by writers that were killed (any process id but this
/// one's); returns how many were removed. Errors reading the folder are ignored (nothing to
/// clean then).
pub fn remove_stale_temporaries(path: &Path) -> usize {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return 0;
    };
    let own = temporary_path(path);
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(parent_dir(path)) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let Some(middle) = file_name
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let is_pid = !middle.is_empty() && middle.bytes().all(|b| b.is_ascii_digit());
        if is_pid && entry.path() != own && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bin");
        std::fs::write(&path, b"old").unwrap();
        write_atomically(&path, b"new contents").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new contents");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "only the output remains");
    }

    #[test]
    fn a_failed_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        // The target is a folder: the rename fails, the temporary goes, the folder stays.
        let path = dir.path().join("taken");
        std::fs::create_dir(&path).unwrap();
        std::fs::write(path.join("inside"), b"x").unwrap();
        assert!(write_atomically(&path, b"data").is_err());
        assert!(path.join("inside").exists());
        assert!(!temporary_path(&path).exists());
    }

    #[test]
    fn probing_touches_nothing_and_fails_in_a_missing_folder() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.exr");
        probe_writable(&path).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        assert!(probe_writable(&dir.path().join("missing/out.exr")).is_err());
    }

    #[test]
    fn stale_temporaries_of_other_processes_are_removed_and_others_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.exr");
        let stale = dir.path().join(".v.exr.4242.tmp");
        let unrelated = dir.path().join(".v.exr.notes.tmp");
        let other = dir.path().join(".w.exr.4242.tmp");
        for p in [&stale, &unrelated, &other] {
            std::fs::write(p, b"x").unwrap();
        }
        assert_eq!(remove_stale_temporaries(&path), 1);
        assert!(!stale.exists() && unrelated.exists() && other.exists());
    }
}
