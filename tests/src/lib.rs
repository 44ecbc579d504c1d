//! Helpers shared by the end-to-end tests: where the repository, the sample sites and the
//! shared reference data live, and how a test that needs `../shared` skips or fails.

use std::path::{Path, PathBuf};

pub mod mitsuba_pair;
pub mod street;
pub mod truth;

/// The repository root (the folder holding the workspace `Cargo.toml`).
#[must_use]
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// A bundled sample site folder under `sample_sites/`.
#[must_use]
pub fn sample_site(name: &str) -> PathBuf {
    repo_root().join("sample_sites").join(name)
}

/// The shared folder beside the checkout (`../shared`), or `PHOTOMONTAGE_SHARED` if set.
#[must_use]
pub fn shared_dir() -> PathBuf {
    std::env::var_os("PHOTOMONTAGE_SHARED")
        .map_or_else(|| repo_root().join("..").join("shared"), PathBuf::from)
}

/// Returns the path of `relative` inside the shared folder, or `None` after printing a notice
/// when it is absent. When `CI=true` an absent file is a failure, not a skip.
///
/// # Panics
/// When the file is missing and the environment variable `CI` is `true`.
#[must_use]
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let path = shared_dir().join(relative);
    if path.exists() {
        return Some(path);
    }
    let in_ci = std::env::var("CI").is_ok_and(|v| v == "true");
    assert!(
        !in_ci,
        "CI=true but the shared test data {} is missing",
        path.display()
    );
    eprintln!(
        "NOTICE: skipping, shared test data {} is absent",
        path.display()
    );
    None
}
