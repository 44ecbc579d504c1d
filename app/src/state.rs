//! The studio's persisted UI state (recent sites, view settings, the Variants tab's comparison
//! settings), one serde struct with
//! `#[serde(default)]` in a small TOML file in the user's config folder
//! (`$XDG_CONFIG_HOME/photomontage-studio/state.toml`, else `~/.config/…`), overridable with
//! `PHOTOMONTAGE_STUDIO_CONFIG`. Written atomically; a missing or unreadable file gives the
//! defaults (the state is a convenience, never a reason not to start).
//!
//! # Known limitations
//! Windows and macOS config folders are not special-cased (the XDG rule is used everywhere).

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Most recent sites kept.
pub const MAX_RECENT: usize = 10;

/// Everything the studio remembers between runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct UiState {
    /// Recently opened sites, newest first.
    pub recent_sites: Vec<PathBuf>,
    /// Draw residual vectors on the photo after a solve.
    pub show_residuals: bool,
    /// Magnification of the drawn residual vectors.
    pub residual_exaggeration: f64,
    /// Show the loupe while hovering the photo.
    pub loupe: bool,
    /// Loupe magnification in screen points per photo pixel.
    pub loupe_zoom: f64,
    /// The Variants tab's comparison settings.
    pub variant_compare: crate::variants_panel::CompareSettings,
}

impl Default for UiState {
    fn default() -> Self {
        Self {
            recent_sites: Vec::new(),
            show_residuals: true,
            residual_exaggeration: 200.0,
            loupe: true,
            loupe_zoom: 8.0,
            variant_compare: crate::variants_panel::CompareSettings::default(),
        }
    }
}

impl UiState {
    /// Puts `site` first in the recent list (absolute path), keeping [`MAX_RECENT`].
    pub fn remember(&mut self, site: &Path) {
        let site = std::fs::canonicalize(site).unwrap_or_else(|_| site.to_path_buf());
        self.recent_sites.retain(|p| p != &site);
        self.recent_sites.insert(0, site);
        self.recent_sites.truncate(MAX_RECENT);
    }

    /// Reads the state; defaults when absent or unreadable.
    #[must_use]
    pub fn load(path: &Path) -> Self {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|t| toml::from_str(&t).ok())
            .unwrap_or_default()
    }

    /// Writes the state atomically.
    ///
    /// # Errors
    /// Any I/O or serialisation error, as text for the status line.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let text = toml::to_string_pretty(self).map_err(|e| e.to_string())?;
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        }
        photomontage::site::write_atomically(path, text.as_bytes())
            .map_err(|e| format!("cannot save UI state {}: {e}", path.display()))
    }
}

/// Where the state file lives by default.
#[must_use]
pub fn default_state_path() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PHOTOMONTAGE_STUDIO_CONFIG") {
        return Some(PathBuf::from(p));
    }
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
    Some(base.join("photomontage-studio").join("state.toml"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_recent_order() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("cfg/state.toml");
        assert_eq!(
            UiState::load(&path),
            UiState::default(),
            "absent → defaults"
        );
        let mut s = UiState::default();
        for i in 0..12 {
            s.remember(Path::new(&format!("/nonexistent/{i}.toml")));
        }
        s.remember(Path::new("/nonexistent/3.toml"));
        assert_eq!(s.recent_sites.len(), MAX_RECENT);
        assert_eq!(s.recent_sites[0], PathBuf::from("/nonexistent/3.toml"));
        assert_eq!(s.recent_sites[1], PathBuf::from("/nonexistent/11.toml"));
        s.loupe = false;
        s.save(&path).expect("save");
        assert_eq!(UiState::load(&path), s);
        std::fs::write(&path, "loupe = [").expect("write");
        assert_eq!(
            UiState::load(&path),
            UiState::default(),
            "garbage → defaults"
        );
    }
}
