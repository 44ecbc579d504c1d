//! Blender: a Python script that creates one camera per solved photo, with the photo as its
//! background image.
//!
//! Conventions (Blender Python API `bpy.types.Camera`; `BKE_camera_params_compute_viewplane`):
//! - `sensor_fit = 'HORIZONTAL'`, `sensor_width` = [`SENSOR_WIDTH_MM`] (Blender only uses the
//!   ratio `lens / sensor_width`), `lens = focal_px · sensor_width / width_px`.
//! - `shift_x`, `shift_y` are in units of the image *width* (horizontal fit): the optical axis
//!   meets the image `shift_x · W` left of and `shift_y · W` below the centre, measured from the
//!   image corner (our pixel centre + 0.5): `shift_x = (W/2 − (cx + 0.5)) / W`,
//!   `shift_y = ((cy + 0.5) − H/2) / W`.
//! - Blender's camera looks down −Z with +Y up: `matrix_world` = [R_world_from_camera ·
//!   diag(1, −1, −1) | C − WORLD_OFFSET]. Survey coordinates (10⁶ m) are beyond Blender's 32-bit
//!   object locations (0.25 m steps at 2.6·10⁶ m), so the script subtracts `WORLD_OFFSET` (the
//!   rounded mean camera centre), states it, and stores it on the scene as a custom property.
//! - Distortion cannot live on a Blender camera. The script loads the photo also as a movie clip
//!   and sets its tracking camera to the Brown model (`brown_k1..k3`, `brown_p1`, `brown_p2`),
//!   focal length and principal point in pixels, for the compositor's Movie (Un)Distortion node.
//!   Blender's clip frame has y up, which flips the sign of p1 (`brown_p1 = −p1`) and measures
//!   the principal point from the bottom-left corner.
//!
//! # Known limitations
//! One render resolution per scene: the script sets it for the first photo, and `use_photo(name)`
//! in the script switches the scene camera and resolution. Not run in Blender here (the numbers
//! are checked by parsing them back from the script).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};

use super::{ExchangeError, ExportSet, num, write_file};

/// Nominal sensor width written to Blender (only `lens / sensor_width` matters).
pub const SENSOR_WIDTH_MM: f64 = 36.0;
/// Clip start as a fraction of the nearest observed point's depth (never above 0.1 m).
const CLIP_START_FRACTION: f64 = 0.1;
/// Clip end as a multiple of the farthest observed point's depth (at least 1000 m).
const CLIP_END_FACTOR: f64 = 10.0;

/// The numbers the script gives one Blender camera (also what a reader of the script recovers).
#[derive(Debug, Clone, PartialEq)]
pub struct BlenderCamera {
    pub name: String,
    pub image_path: PathBuf,
    pub image_size_px: [u32; 2],
    pub lens_mm: f64,
    pub sensor_width_mm: f64,
    pub shift_x: f64,
    pub shift_y: f64,
    pub clip_start_m: f64,
    pub clip_end_m: f64,
    /// Rows of the 4×4 `matrix_world` (location relative to the world offset).
    pub matrix_world: [[f64; 4]; 4],
    /// Tracking-camera Brown coefficients in Blender's y-up clip frame: k1, k2, k3, p1, p2.
    pub brown: [f64; 5],
    /// Tracking-camera principal point in pixels from the bottom-left corner.
    pub principal_point_pixels: [f64; 2],
}

/// The Blender cameras of an export set and the world offset they are relative to.
#[must_use]
pub fn blender_cameras(set: &ExportSet) -> (Vector3<f64>, Vec<BlenderCamera>) {
    let n = set.cameras.len().max(1) as f64;
    let mean = set.cameras.iter().fold(Vector3::zeros(), |a, c| {
        a + c.camera.pose.camera_center_in_world.coords
    }) / n;
    let offset = mean.map(f64::round);
    let flip = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    let cameras = set
        .cameras
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let intr = c.camera.intrinsics;
            let [w, h] = intr.image_size_px.map(f64::from);
            let [cx, cy] = intr.principal_point_px;
            let r = c.camera.pose.rotation_world_from_camera.matrix() * flip;
            let t = c.camera.pose.camera_center_in_world.coords - offset;
            let mut m = [[0.0; 4]; 4];
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] = r[(i, j)];
                }
                m[i][3] = t[i];
            }
            m[3][3] = 1.0;
            let depths: Vec<f64> = set
                .points
                .iter()
                .filter(|p| p.observations.iter().any(|(i, _)| *i == k))
                .map(|p| c.camera.pose.camera_from_world(&p.point_in_world).z)
                .filter(|z| *z > 0.0)
                .collect();
            let nearest = depths.iter().copied().fold(f64::INFINITY, f64::min);
            let farthest = depths.iter().copied().fold(0.0, f64::max);
            let d = intr.distortion;
            BlenderCamera {
                name: c.id.clone(),
                image_path: c.image_path.clone(),
                image_size_px: intr.image_size_px,
                lens_mm: intr.focal_px * SENSOR_WIDTH_MM / w,
                sensor_width_mm: SENSOR_WIDTH_MM,
                shift_x: (w / 2.0 - (cx + 0.5)) / w,
                shift_y: ((cy + 0.5) - h / 2.0) / w,
                clip_start_m: if nearest.is_finite() {
                    (CLIP_START_FRACTION * nearest).min(0.1)
                } else {
                    0.1
                },
                clip_end_m: (CLIP_END_FACTOR * farthest).max(1000.0),
                matrix_world: m,
                brown: [d.k1, d.k2, d.k3, -d.p1, d.p2],
                principal_point_pixels: [cx + 0.5, h - (cy + 0.5)],
            }
        })
        .collect();
    (offset, cameras)
}

/// A Python string literal (JSON's escapes are valid Python).
fn py_str(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".to_owned())
}

fn py_tuple(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|v| num(*v)).collect();
    format!("({},)", parts.join(", "))
}

const SCRIPT_FUNCTIONS: &str = r#"import bpy
from mathutils import Matrix

CAMERAS = {}


def add_photo_camera(name, image_path, image_size_px, lens_mm, sensor_width_mm, shift_x,
                     shift_y, clip_start_m, clip_end_m, matrix_world, brown,
                     principal_point_pixels):
    data = bpy.data.cameras.new(name)
    data.type = 'PERSP'
    data.sensor_fit = 'HORIZONTAL'
    data.sensor_width = sensor_width_mm
    data.lens_unit = 'MILLIMETERS'
    data.lens = lens_mm
    data.shift_x = shift_x
    data.shift_y = shift_y
    data.clip_start = clip_start_m
    data.clip_end = clip_end_m
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.matrix_world = Matrix(matrix_world)
    obj["photomontage_image_size_px"] = list(image_size_px)
    try:
        image = bpy.data.images.load(image_path, check_existing=True)
        data.show_background_images = True
        background = data.background_images.new()
        background.image = image
        background.frame_method = 'FIT'
        background.alpha = 1.0
        clip = bpy.data.movieclips.load(image_path)
        clip.name = name
        tracking_camera = clip.tracking.camera
        tracking_camera.sensor_width = sensor_width_mm
        tracking_camera.units = 'PIXELS'
        tracking_camera.focal_length_pixels = lens_mm / sensor_width_mm * image_size_px[0]
        tracking_camera.distortion_model = 'BROWN'
        (tracking_camera.brown_k1, tracking_camera.brown_k2, tracking_camera.brown_k3,
         tracking_camera.brown_p1, tracking_camera.brown_p2) = brown
        if hasattr(tracking_camera, "principal_point_pixels"):
            tracking_camera.principal_point_pixels = principal_point_pixels
        else:
            tracking_camera.principal = principal_point_pixels
    except RuntimeError as error:
        print(f"photomontage: {name}: photo {image_path} not loaded ({error})")
    CAMERAS[name] = obj
    return obj


def use_photo(name):
    """Makes the photo's camera the scene camera and sets the render size to the photo's."""
    obj = CAMERAS[name]
    scene = bpy.context.scene
    scene.camera = obj
    scene.render.resolution_x, scene.render.resolution_y = obj["photomontage_image_size_px"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0

"#;

/// The Python script text.
#[must_use]
pub fn blender_script(set: &ExportSet) -> String {
    let (offset, cameras) = blender_cameras(set);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Cameras of the photomontage site {} (written by `photomontage export-cameras --format blender`).",
        py_str(&set.site_name)
    );
    s.push_str(
        "# Run inside Blender: `blender --python cameras.py`, or Scripting → Open → Run Script.\n\
         # Every location is the site's world coordinate minus WORLD_OFFSET (metres, Z up):\n\
         # Blender keeps object locations in 32-bit floats. Cameras look down -Z, +Y up.\n\
         # The photo's lens distortion is on the movie clip of the same name (tracking camera,\n\
         # Brown model, y up) for the compositor's Movie Distortion node.\n",
    );
    s.push_str(SCRIPT_FUNCTIONS);
    let _ = writeln!(
        s,
        "WORLD_OFFSET = {}",
        py_tuple(&[offset.x, offset.y, offset.z])
    );
    s.push_str("bpy.context.scene[\"photomontage_world_offset\"] = list(WORLD_OFFSET)\n\n");
    for c in &cameras {
        let rows: Vec<String> = c.matrix_world.iter().map(|r| py_tuple(r)).collect();
        let _ = writeln!(s, "add_photo_camera(");
        let _ = writeln!(s, "    name={},", py_str(&c.name));
        let _ = writeln!(
            s,
            "    image_path={},",
            py_str(&c.image_path.to_string_lossy())
        );
        let _ = writeln!(
            s,
            "    image_size_px=({}, {}),",
            c.image_size_px[0], c.image_size_px[1]
        );
        let _ = writeln!(s, "    lens_mm={},", num(c.lens_mm));
        let _ = writeln!(s, "    sensor_width_mm={},", num(c.sensor_width_mm));
        let _ = writeln!(s, "    shift_x={},", num(c.shift_x));
        let _ = writeln!(s, "    shift_y={},", num(c.shift_y));
        let _ = writeln!(s, "    clip_start_m={},", num(c.clip_start_m));
        let _ = writeln!(s, "    clip_end_m={},", num(c.clip_end_m));
        let _ = writeln!(s, "    matrix_world=({},),", rows.join(", "));
        let _ = writeln!(s, "    brown={},", py_tuple(&c.brown));
        let _ = writeln!(
            s,
            "    principal_point_pixels={},",
            py_tuple(&c.principal_point_pixels)
        );
        let _ = writeln!(s, ")");
    }
    if let Some(first) = cameras.first() {
        let _ = writeln!(s, "\nuse_photo({})", py_str(&first.name));
    }
    s
}

/// Writes `cameras.py` into `dir`; returns its path.
///
/// # Errors
/// [`ExchangeError::Write`].
pub fn write_blender(set: &ExportSet, dir: &Path) -> Result<Vec<PathBuf>, ExchangeError> {
    Ok(vec![write_file(dir, "cameras.py", &blender_script(set))?])
}
