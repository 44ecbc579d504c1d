//! Helpers shared by the fuzz targets: a scratch folder per process for the parsers that read
//! files (OBJ + MTL, glTF, DXF, EXIF, photo decoding), and the checks every parsed model and
//! photometric web must pass.
//!
//! The targets call the library exactly as the CLI and studio do: the in-memory entry point where
//! there is one (site TOML, control points, IES, EULUMDAT), otherwise the loader on a file written
//! from the fuzzer's bytes.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A scratch folder private to this process (in `/dev/shm` when it exists, so the file writes
/// stay in memory), created on first use.
///
/// # Panics
/// When the folder cannot be created: the harness cannot run then.
pub fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let shm = Path::new("/dev/shm");
        let base = if shm.is_dir() {
            shm.to_path_buf()
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!("photomontage-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("create the fuzz scratch folder");
        dir
    })
}

/// Writes `bytes` to `name` inside [`scratch_dir`] and returns its path.
///
/// # Panics
/// When the write fails (the scratch folder is the harness's, not the input's).
pub fn write_scratch(name: &str, bytes: &[u8]) -> PathBuf {
    let path = scratch_dir().join(name);
    std::fs::write(&path, bytes).expect("write a fuzz scratch file");
    path
}

/// Removes the files of one iteration so the next one starts from an empty folder.
pub fn clear_scratch() {
    if let Ok(entries) = std::fs::read_dir(scratch_dir()) {
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                let _ = std::fs::remove_dir_all(&path);
            } else {
                let _ = std::fs::remove_file(&path);
            }
        }
    }
}

/// What every successfully imported model must satisfy: one material index per triangle, each in
/// range, and finite world coordinates (the importers promise to refuse non-finite vertices).
///
/// # Panics
/// When the importer broke one of those promises: that is a finding.
pub fn check_model(model: &photomontage::scene::ImportedModel) {
    assert_eq!(
        model.triangles_in_world_m.len(),
        model.triangle_materials.len(),
        "one material index per triangle"
    );
    for &m in &model.triangle_materials {
        assert!(
            (m as usize) < model.materials.len(),
            "material index {m} out of range ({} materials)",
            model.materials.len()
        );
    }
    for t in &model.triangles_in_world_m {
        for p in t {
            assert!(
                p.iter().all(|c| c.is_finite()),
                "non-finite vertex {p:?} accepted"
            );
        }
    }
}

/// Builds the photometric web of a parsed luminaire file as the renderer does, and queries it
/// in a few directions: none of this may panic, and a web that was built must give a finite
/// flux and finite intensities.
///
/// # Panics
/// When the web gives a non-finite or negative answer: that is a finding.
pub fn exercise_photometry(file: &photomontage::luminaire::PhotometricFile) {
    let _ = file.format_label();
    let _ = file.warnings();
    if let Ok(web) = file.distribution() {
        let flux_lm = web.total_flux_lm();
        assert!(flux_lm.is_finite(), "total flux {flux_lm} not finite");
        for (c_deg, gamma_deg) in [
            (0.0, 0.0),
            (45.0, 30.0),
            (90.0, 90.0),
            (270.0, 135.0),
            (359.0, 180.0),
        ] {
            let cd = web.intensity_c_gamma_cd(c_deg, gamma_deg);
            assert!(
                cd.is_finite(),
                "intensity {cd} cd at C{c_deg} γ{gamma_deg} not finite"
            );
        }
        let _ = web.max_intensity_cd();
    }
}
