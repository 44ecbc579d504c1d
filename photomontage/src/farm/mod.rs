//! Scale-out: a site's views cut into bands ([`crate::render::Band`]) as independent jobs for an
//! existing cluster scheduler — Slurm job arrays ([`slurm`]), Kubernetes Indexed Jobs ([`k8s`]),
//! Blender's Flamenco ([`flamenco`]) — rather than a scheduler of our own (issue 18).
//!
//! Every scheduler runs the same two commands over one [`jobs::JobList`]:
//! `photomontage run-job LIST --index K` (render band K, skipped when its part is already there)
//! and `photomontage run-job LIST --merge` (assemble every view; missing, duplicate or foreign
//! parts are named). A band is bit for bit the whole-image render's rows
//! ([`crate::render::tiling`]), so the merged image equals a single-machine render byte for byte.
//!
//! # Known limitations
//! Variants and sun studies are not listed (the site format has neither yet). Resource requests
//! are estimates from the image size ([`resources`]), not measurements of the scene.

pub mod flamenco;
pub mod jobs;
pub mod k8s;
pub mod slurm;

pub use jobs::{
    FarmError, Job, JobList, JobOptions, JobOutcome, JobRender, Merge, relative_to as relative_path,
};

/// Resources one job asks of a scheduler.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resources {
    /// CPUs (threads) per task.
    pub cpus: u32,
    /// Memory per task, MiB.
    pub memory_mib: u64,
}

/// Fixed memory of a render process (program, scene, BVH of a sample-size site), MiB.
pub const BASE_MEMORY_MIB: u64 = 256;

/// Bytes per pixel of the whole image a render holds at its peak: the linear photo (12), the
/// result (16), the layers (20) and the decoded photo (12) in RGB mode; spectral mode keeps
/// three more linear photos (36).
fn bytes_per_pixel(spectral: bool) -> u64 {
    if spectral { 96 } else { 60 }
}

/// The resources of one job of `list`: `cpus` as given, memory from the largest view's size
/// ([`BASE_MEMORY_MIB`] + the per-pixel buffers, doubled for headroom), or `memory_mib` when
/// the user set it.
#[must_use]
pub fn resources(list: &JobList, cpus: u32, memory_mib: Option<u64>) -> Resources {
    let pixels = list
        .views
        .iter()
        .map(|(_, [w, h])| u64::from(*w) * u64::from(*h))
        .max()
        .unwrap_or(0);
    let estimate =
        BASE_MEMORY_MIB + (2 * pixels * bytes_per_pixel(list.render.spectral)).div_ceil(1 << 20);
    Resources {
        cpus: cpus.max(1),
        memory_mib: memory_mib.unwrap_or(estimate),
    }
}

/// Quotes `s` for a POSIX shell (single quotes).
#[must_use]
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_./=:,+@%".contains(&b))
    {
        return s.to_owned();
    }
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// Writes `(file name, contents, executable)` files into `dir` atomically.
///
/// # Errors
/// [`FarmError::Folder`].
pub fn write_files(
    dir: &std::path::Path,
    files: &[(String, String, bool)],
) -> Result<Vec<std::path::PathBuf>, FarmError> {
    let folder = |e: &dyn std::fmt::Display| FarmError::Folder {
        path: dir.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| folder(&e))?;
    let mut written = Vec::new();
    for (name, text, executable) in files {
        let path = dir.join(name);
        crate::atomic_file::write_atomically(&path, text.as_bytes()).map_err(|e| folder(&e))?;
        #[cfg(unix)]
        if *executable {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755))
                .map_err(|e| folder(&e))?;
        }
        #[cfg(not(unix))]
        let _ = executable;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_quoting_keeps_plain_words_and_quotes_the_rest() {
        assert_eq!(
            shell_quote("/opt/bin/photomontage"),
            "/opt/bin/photomontage"
        );
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(shell_quote(""), "''");
    }
}
