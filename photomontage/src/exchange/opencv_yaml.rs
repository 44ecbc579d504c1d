//! OpenCV `cv::FileStorage` YAML, one file per photo (`<photo id>.yml`), readable with
//! `cv2.FileStorage(path, cv2.FILE_STORAGE_READ)` and used with `cv2.projectPoints`.
//!
//! Keys: `image_name`, `image_width`, `image_height`, `camera_matrix` (3×3 K),
//! `distortion_coefficients` (1×5: k1, k2, p1, p2, k3 — OpenCV's order), `rvec` and `tvec`
//! (3×1; Rodrigues vector of R_camera_from_world and t = −R·C, as `solvePnP` returns them), `R`
//! (3×3 camera-from-world) and `camera_center` (3×1, world). The pixel convention is ours
//! (OpenCV's: (0, 0) is the centre of the top-left pixel), so nothing is shifted. All five
//! distortion terms of our model are carried.
//!
//! # Known limitations
//! Written only; an OpenCV file is not read back as a site camera (COLMAP and OpenSfM are).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{ExchangeError, ExportCamera, ExportSet, num, write_file};

fn matrix(name: &str, rows: usize, cols: usize, data: &[f64]) -> String {
    let values: Vec<String> = data.iter().map(|v| num(*v)).collect();
    format!(
        "{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {} ]\n",
        values.join(", ")
    )
}

/// The YAML text of one photo.
#[must_use]
pub fn opencv_yaml(c: &ExportCamera) -> String {
    let intr = c.camera.intrinsics;
    let d = intr.distortion;
    let camera_from_world = c.camera.pose.rotation_world_from_camera.inverse();
    let t = -(camera_from_world * c.camera.pose.camera_center_in_world.coords);
    let rvec = camera_from_world.scaled_axis();
    let r = camera_from_world.matrix();
    let centre = c.camera.pose.camera_center_in_world;
    let [cx, cy] = intr.principal_point_px;
    let f = intr.focal_px;
    let mut s = String::from("%YAML:1.0\n---\n");
    let _ = writeln!(
        s,
        "image_name: {}",
        serde_json::to_string(&c.image_name).unwrap_or_else(|_| "\"\"".to_owned())
    );
    let _ = writeln!(s, "image_width: {}", intr.image_size_px[0]);
    let _ = writeln!(s, "image_height: {}", intr.image_size_px[1]);
    s.push_str(&matrix(
        "camera_matrix",
        3,
        3,
        &[f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0],
    ));
    s.push_str(&matrix(
        "distortion_coefficients",
        1,
        5,
        &[d.k1, d.k2, d.p1, d.p2, d.k3],
    ));
    s.push_str(&matrix("rvec", 3, 1, &[rvec.x, rvec.y, rvec.z]));
    s.push_str(&matrix("tvec", 3, 1, &[t.x, t.y, t.z]));
    let rows: Vec<f64> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| r[(i, j)])
        .collect();
    s.push_str(&matrix("R", 3, 3, &rows));
    s.push_str(&matrix(
        "camera_center",
        3,
        1,
        &[centre.x, centre.y, centre.z],
    ));
    s
}

/// Writes one `<photo id>.yml` per solved photo into `dir`.
///
/// # Errors
/// [`ExchangeError::Write`].
pub fn write_opencv(set: &ExportSet, dir: &Path) -> Result<Vec<PathBuf>, ExchangeError> {
    set.cameras
        .iter()
        .map(|c| write_file(dir, &format!("{}.yml", file_stem(&c.id)), &opencv_yaml(c)))
        .collect()
}

/// A file name for a photo id: characters outside `[A-Za-z0-9._-]` become `_`.
#[must_use]
pub fn file_stem(id: &str) -> String {
    id.chars()
        .map(|ch| {
            if ch.is_ascii_alphanumeric() || "._-".contains(ch) {
                ch
            } else {
                '_'
            }
        })
        .collect()
}
