//! Reading files the user's data refers to (OBJ and MTL files, glTF buffers, photometric
//! files): only regular files, only up to a size cap, so that a reference to `/dev/zero`, a FIFO
//! or a directory gives an error naming the file instead of reading for ever or allocating
//! gigabytes.
//!
//! The check uses the metadata of the opened handle and the read is limited to cap + 1 bytes, so
//! a file that grows between the check and the read is refused too.
//!
//! # Known limitations
//! Symbolic links are followed (the target must be a regular file). The whole file is read into
//! memory.

use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest model or buffer file read (4 GiB): far above real models, far below the memory of a
/// 24 GB machine.
pub const MAX_MODEL_FILE_BYTES: u64 = 4 << 30;

/// Why a referenced file was not read.
#[derive(Debug, thiserror::Error)]
pub enum BoundedReadError {
    #[error(
        "{path} is not a regular file ({kind}); a model, buffer or photometric file must be one"
    )]
    NotRegularFile { path: PathBuf, kind: &'static str },
    #[error("{path} is {size_bytes} bytes, more than the {max_bytes} accepted")]
    TooLarge {
        path: PathBuf,
        size_bytes: u64,
        max_bytes: u64,
    },
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

fn kind_of(file_type: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if file_type.is_dir() {
        "a directory"
    } else if file_type.is_char_device() {
        "a character device"
    } else if file_type.is_block_device() {
        "a block device"
    } else if file_type.is_fifo() {
        "a FIFO"
    } else if file_type.is_socket() {
        "a socket"
    } else {
        "not a plain file"
    }
}

/// Reads the regular file `path` if it holds at most `max_bytes`.
///
/// # Errors
/// [`BoundedReadError::NotRegularFile`] for devices, FIFOs, directories and sockets,
/// [`BoundedReadError::TooLarge`] above the cap, [`BoundedReadError::Io`] otherwise.
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, BoundedReadError> {
    let io = |source| BoundedReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Opening a FIFO for reading blocks until a writer appears: check the path first.
    let before = std::fs::metadata(path).map_err(io)?;
    if !before.is_file() {
        return Err(BoundedReadError::NotRegularFile {
            path: path.to_path_buf(),
            kind: kind_of(before.file_type()),
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(BoundedReadError::NotRegularFile {
            path: path.to_path_buf(),
            kind: kind_of(meta.file_type()),
        });
    }
    let too_large = |size_bytes| BoundedReadError::TooLarge {
        path: path.to_path_buf(),
        size_bytes,
        max_bytes,
    };
    if meta.len() > max_bytes {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Checks, without reading, that `path` is a regular file of at most `max_bytes`.
///
/// # Errors
/// As [`read_bounded`].
pub fn check_regular_file(path: &Path, max_bytes: u64) -> Result<(), BoundedReadError> {
    let meta = std::fs::metadata(path).map_err(|source| BoundedReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if !meta.is_file() {
        return Err(BoundedReadError::NotRegularFile {
            path: path.to_path_buf(),
            kind: kind_of(meta.file_type()),
        });
    }
    if meta.len() > max_bytes {
        return Err(BoundedReadError::TooLarge {
            path: path.to_path_buf(),
            size_bytes: meta.len(),
            max_bytes,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn device_files_and_directories_are_refused() {
        let err = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(
            matches!(
                err,
                BoundedReadError::NotRegularFile {
                    kind: "a character device",
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("/dev/zero"), "{err}");
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(
            read_bounded(dir.path(), 1 << 20),
            Err(BoundedReadError::NotRegularFile {
                kind: "a directory",
                ..
            })
        ));
        assert!(matches!(
            check_regular_file(Path::new("/dev/zero"), 1 << 20),
            Err(BoundedReadError::NotRegularFile { .. })
        ));
    }

    #[test]
    fn size_cap_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.bin");
        std::fs::write(&path, [7u8; 100]).unwrap();
        assert_eq!(read_bounded(&path, 100).unwrap().len(), 100);
        assert!(matches!(
            read_bounded(&path, 99),
            Err(BoundedReadError::TooLarge {
                size_bytes: 100,
                max_bytes: 99,
                ..
            })
        ));
    }
}
