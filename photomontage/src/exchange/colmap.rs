//! COLMAP text model: `cameras.txt`, `images.txt`, `points3D.txt` (COLMAP documentation,
//! "Output format"; camera models in `src/colmap/sensor/models.h`).
//!
//! Conventions:
//! - `images.txt`: `IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME`, then a line of
//!   `X Y POINT3D_ID` triples. (QW, QX, QY, QZ) is the Hamilton unit quaternion of
//!   R_camera_from_world and T = −R·C, so `x_camera = R·X_world + T` in the OpenCV camera frame.
//! - Pixels: COLMAP puts the centre of the top-left pixel at (0.5, 0.5); ours is at (0, 0), so
//!   principal points and observations are written +0.5 and read −0.5.
//! - Models written (the smallest that carries the photo's distortion, unless one is chosen):
//!   `SIMPLE_PINHOLE` (f, cx, cy), `SIMPLE_RADIAL` (f, cx, cy, k), `RADIAL` (f, cx, cy, k1, k2),
//!   `OPENCV` (fx, fy, cx, cy, k1, k2, p1, p2), `FULL_OPENCV` (…, k3, k4, k5, k6; here k4–k6 = 0,
//!   which makes its rational radial factor our polynomial). A chosen model that lacks a
//!   non-zero term of the photo is refused naming the term.
//! - Read: the same models plus `PINHOLE`; `fx ≠ fy`, k4–k6 ≠ 0 and the fisheye and thin-prism
//!   models are refused by name (our camera has square pixels and Brown–Conrady distortion).
//! - `points3D.txt` holds the control and tie points observed in the exported photos, numbered
//!   1…n; `point_names.txt` maps those numbers to the site's point ids. ERROR is the RMS
//!   reprojection error of the point's observations in our cameras (pixels).
//!
//! # Known limitations
//! Binary models (`.bin`) are not read. One COLMAP camera is written per photo (each photo of a
//! site has its own solved interior).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Point2, Point3, Quaternion, Rotation3, UnitQuaternion, Vector3};

use super::{ExchangeError, ExportSet, num, write_file};
use crate::camera::{BrownConrady, Camera, Intrinsics, Pose};

/// The COLMAP camera models we write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColmapModel {
    /// The smallest model that carries each photo's distortion.
    #[default]
    Auto,
    SimplePinhole,
    SimpleRadial,
    Radial,
    Opencv,
    FullOpencv,
}

impl ColmapModel {
    /// COLMAP's name of the model.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::SimplePinhole => "SIMPLE_PINHOLE",
            Self::SimpleRadial => "SIMPLE_RADIAL",
            Self::Radial => "RADIAL",
            Self::Opencv => "OPENCV",
            Self::FullOpencv => "FULL_OPENCV",
        }
    }

    /// Parses `auto` or a COLMAP model name (case-insensitive).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        [
            Self::Auto,
            Self::SimplePinhole,
            Self::SimpleRadial,
            Self::Radial,
            Self::Opencv,
            Self::FullOpencv,
        ]
        .into_iter()
        .find(|m| m.name().eq_ignore_ascii_case(name))
    }

    /// The distortion terms the model carries (k1, k2, k3, p1, p2).
    fn carries(self) -> [bool; 5] {
        match self {
            Self::Auto | Self::FullOpencv => [true; 5],
            Self::SimplePinhole => [false; 5],
            Self::SimpleRadial => [true, false, false, false, false],
            Self::Radial => [true, true, false, false, false],
            Self::Opencv => [true, true, false, true, true],
        }
    }

    /// The smallest model carrying `d`.
    fn smallest_for(d: &BrownConrady) -> Self {
        if d.k3 != 0.0 {
            Self::FullOpencv
        } else if d.p1 != 0.0 || d.p2 != 0.0 {
            Self::Opencv
        } else if d.k2 != 0.0 {
            Self::Radial
        } else if d.k1 != 0.0 {
            Self::SimpleRadial
        } else {
            Self::SimplePinhole
        }
    }
}

/// The model for one photo, or the term the chosen model cannot carry.
fn model_for(
    photo: &str,
    intr: &Intrinsics,
    chosen: ColmapModel,
) -> Result<ColmapModel, ExchangeError> {
    let d = intr.distortion;
    if chosen == ColmapModel::Auto {
        return Ok(ColmapModel::smallest_for(&d));
    }
    let terms = [
        ("k1", d.k1),
        ("k2", d.k2),
        ("k3", d.k3),
        ("p1", d.p1),
        ("p2", d.p2),
    ];
    for ((term, value), carried) in terms.into_iter().zip(chosen.carries()) {
        if value != 0.0 && !carried {
            return Err(ExchangeError::TermNotCarried {
                format: format!("COLMAP's {} model", chosen.name()),
                photo: photo.to_owned(),
                term,
                value,
                hint: format!(
                    " (use --colmap-model {} or auto)",
                    ColmapModel::smallest_for(&d).name()
                ),
            });
        }
    }
    Ok(chosen)
}

/// The `cameras.txt` parameters of one photo.
fn params(intr: &Intrinsics, model: ColmapModel) -> Vec<f64> {
    let f = intr.focal_px;
    let cx = intr.principal_point_px[0] + 0.5;
    let cy = intr.principal_point_px[1] + 0.5;
    let d = intr.distortion;
    match model {
        ColmapModel::SimplePinhole => vec![f, cx, cy],
        ColmapModel::SimpleRadial => vec![f, cx, cy, d.k1],
        ColmapModel::Radial => vec![f, cx, cy, d.k1, d.k2],
        ColmapModel::Opencv => vec![f, f, cx, cy, d.k1, d.k2, d.p1, d.p2],
        ColmapModel::Auto | ColmapModel::FullOpencv => {
            vec![f, f, cx, cy, d.k1, d.k2, d.p1, d.p2, d.k3, 0.0, 0.0, 0.0]
        }
    }
}

/// (QW, QX, QY, QZ) of R_camera_from_world with QW ≥ 0, and T = −R·C.
#[must_use]
pub fn qvec_tvec(pose: &Pose) -> ([f64; 4], [f64; 3]) {
    let r = pose.rotation_world_from_camera.inverse();
    let q = UnitQuaternion::from_rotation_matrix(&r);
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    let t = -(r * pose.camera_center_in_world.coords);
    ([s * q.w, s * q.i, s * q.j, s * q.k], [t.x, t.y, t.z])
}

/// The three files' text: (cameras.txt, images.txt, points3D.txt, point_names.txt).
///
/// # Errors
/// [`ExchangeError::TermNotCarried`] when `model` lacks a non-zero term of a photo.
pub fn colmap_text(set: &ExportSet, model: ColmapModel) -> Result<[String; 4], ExchangeError> {
    let mut cameras = String::from(
        "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n",
    );
    let _ = writeln!(cameras, "# Number of cameras: {}", set.cameras.len());
    for (k, c) in set.cameras.iter().enumerate() {
        let intr = &c.camera.intrinsics;
        let m = model_for(&c.id, intr, model)?;
        let p: Vec<String> = params(intr, m).into_iter().map(num).collect();
        let _ = writeln!(
            cameras,
            "{} {} {} {} {}",
            k + 1,
            m.name(),
            intr.image_size_px[0],
            intr.image_size_px[1],
            p.join(" ")
        );
    }
    // Per photo: its observations as (point number, pixel).
    let mut per_photo: Vec<Vec<(usize, Point2<f64>)>> = vec![Vec::new(); set.cameras.len()];
    let mut points = String::from(
        "# 3D point list with one line of data per point:\n#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n",
    );
    let mut names = String::from("# POINT3D_ID site point id\n");
    let _ = writeln!(points, "# Number of points: {}", set.points.len());
    let mut tracks: Vec<Vec<(usize, usize)>> = Vec::with_capacity(set.points.len());
    for (n, p) in set.points.iter().enumerate() {
        let mut track = Vec::new();
        for (k, px) in &p.observations {
            track.push((*k, per_photo[*k].len()));
            per_photo[*k].push((n + 1, *px));
        }
        tracks.push(track);
    }
    for (n, p) in set.points.iter().enumerate() {
        let (mut sum, mut count) = (0.0, 0usize);
        for (k, px) in &p.observations {
            if let Some(q) = set.cameras[*k].camera.project(&p.point_in_world) {
                sum += (q - px).norm_squared();
                count += 1;
            }
        }
        let error = if count > 0 {
            (sum / count as f64).sqrt()
        } else {
            0.0
        };
        let track: Vec<String> = tracks[n]
            .iter()
            .map(|(k, idx)| format!("{} {idx}", k + 1))
            .collect();
        let x = p.point_in_world;
        let _ = writeln!(
            points,
            "{} {} {} {} 128 128 128 {} {}",
            n + 1,
            num(x.x),
            num(x.y),
            num(x.z),
            num(error),
            track.join(" ")
        );
        let _ = writeln!(names, "{} {}", n + 1, p.id);
    }
    let mut images = String::from(
        "# Image list with two lines of data per image:\n#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n#   POINTS2D[] as (X, Y, POINT3D_ID)\n",
    );
    let _ = writeln!(images, "# Number of images: {}", set.cameras.len());
    for (k, c) in set.cameras.iter().enumerate() {
        let (q, t) = qvec_tvec(&c.camera.pose);
        let numbers: Vec<String> = q.iter().chain(&t).map(|v| num(*v)).collect();
        let _ = writeln!(
            images,
            "{} {} {} {}",
            k + 1,
            numbers.join(" "),
            k + 1,
            c.image_name
        );
        let obs: Vec<String> = per_photo[k]
            .iter()
            .map(|(n, px)| format!("{} {} {n}", num(px.x + 0.5), num(px.y + 0.5)))
            .collect();
        let _ = writeln!(images, "{}", obs.join(" "));
    }
    Ok([cameras, images, points, names])
}

/// Writes `cameras.txt`, `images.txt`, `points3D.txt` and `point_names.txt` into `dir`.
///
/// # Errors
/// [`ExchangeError::TermNotCarried`] or [`ExchangeError::Write`].
pub fn write_colmap(
    set: &ExportSet,
    model: ColmapModel,
    dir: &Path,
) -> Result<Vec<PathBuf>, ExchangeError> {
    let [cameras, images, points, names] = colmap_text(set, model)?;
    Ok(vec![
        write_file(dir, "cameras.txt", &cameras)?,
        write_file(dir, "images.txt", &images)?,
        write_file(dir, "points3D.txt", &points)?,
        write_file(dir, "point_names.txt", &names)?,
    ])
}

/// A camera read from another program, named by its image.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedCamera {
    /// The image name as the file gives it.
    pub image_name: String,
    pub camera: Camera,
}

/// Relative difference of fx and fy beyond which the pixels are not square.
const SQUARE_PIXEL_TOLERANCE: f64 = 1e-6;

fn parse_err(file: &str, line: usize, message: impl Into<String>) -> ExchangeError {
    ExchangeError::Parse {
        file: file.to_owned(),
        line,
        message: message.into(),
    }
}

fn numbers(
    file: &str,
    line: usize,
    fields: &[&str],
    what: &str,
) -> Result<Vec<f64>, ExchangeError> {
    fields
        .iter()
        .map(|f| {
            f.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    parse_err(file, line, format!("{what}: `{f}` is not a finite number"))
                })
        })
        .collect()
}

/// Intrinsics from a COLMAP camera line's model and parameters.
fn intrinsics_from_colmap(
    file: &str,
    camera: &str,
    model: &str,
    size: [u32; 2],
    p: &[f64],
) -> Result<Intrinsics, ExchangeError> {
    let expected = match model {
        "SIMPLE_PINHOLE" => 3,
        "PINHOLE" | "SIMPLE_RADIAL" => 4,
        "RADIAL" => 5,
        "OPENCV" => 8,
        "FULL_OPENCV" => 12,
        "OPENCV_FISHEYE"
        | "SIMPLE_RADIAL_FISHEYE"
        | "RADIAL_FISHEYE"
        | "THIN_PRISM_FISHEYE"
        | "FOV"
        | "RAD_TAN_THIN_PRISM_FISHEYE" => {
            return Err(ExchangeError::UnsupportedModel {
                file: file.to_owned(),
                camera: camera.to_owned(),
                model: model.to_owned(),
                reason: "a fisheye/field-of-view projection, not a pinhole with Brown–Conrady distortion"
                    .to_owned(),
            });
        }
        other => {
            return Err(ExchangeError::UnsupportedModel {
                file: file.to_owned(),
                camera: camera.to_owned(),
                model: other.to_owned(),
                reason: "unknown model".to_owned(),
            });
        }
    };
    if p.len() != expected {
        return Err(ExchangeError::UnsupportedModel {
            file: file.to_owned(),
            camera: camera.to_owned(),
            model: model.to_owned(),
            reason: format!("{} parameters given, {expected} expected", p.len()),
        });
    }
    let (fx, fy, cx, cy, rest) = match model {
        "SIMPLE_PINHOLE" | "SIMPLE_RADIAL" | "RADIAL" => (p[0], p[0], p[1], p[2], &p[3..]),
        _ => (p[0], p[1], p[2], p[3], &p[4..]),
    };
    if (fx - fy).abs() > SQUARE_PIXEL_TOLERANCE * fx.abs().max(fy.abs()) {
        return Err(ExchangeError::NonSquarePixels {
            file: file.to_owned(),
            camera: camera.to_owned(),
            fx_px: fx,
            fy_px: fy,
        });
    }
    let mut d = BrownConrady::default();
    match model {
        "SIMPLE_RADIAL" => d.k1 = rest[0],
        "RADIAL" => (d.k1, d.k2) = (rest[0], rest[1]),
        "OPENCV" | "FULL_OPENCV" => {
            (d.k1, d.k2, d.p1, d.p2) = (rest[0], rest[1], rest[2], rest[3]);
            if model == "FULL_OPENCV" {
                d.k3 = rest[4];
                for (term, value) in [("k4", rest[5]), ("k5", rest[6]), ("k6", rest[7])] {
                    if value != 0.0 {
                        return Err(ExchangeError::TermNotModelled {
                            file: file.to_owned(),
                            camera: camera.to_owned(),
                            term,
                            value,
                        });
                    }
                }
            }
        }
        _ => {}
    }
    Ok(Intrinsics {
        focal_px: 0.5 * (fx + fy),
        principal_point_px: [cx - 0.5, cy - 0.5],
        distortion: d,
        image_size_px: size,
    })
}

/// Reads a COLMAP text model's `cameras.txt` and `images.txt`.
///
/// # Errors
/// [`ExchangeError::Parse`] naming the file and line, [`ExchangeError::UnsupportedModel`],
/// [`ExchangeError::NonSquarePixels`], [`ExchangeError::TermNotModelled`],
/// [`ExchangeError::UnknownCamera`].
pub fn parse_colmap(
    cameras_txt: &str,
    cameras_name: &str,
    images_txt: &str,
    images_name: &str,
) -> Result<Vec<ImportedCamera>, ExchangeError> {
    let mut intrinsics: HashMap<String, Intrinsics> = HashMap::new();
    for (i, line) in cameras_txt.lines().enumerate() {
        let line_no = i + 1;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        if f.len() < 4 {
            return Err(parse_err(
                cameras_name,
                line_no,
                "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS…",
            ));
        }
        let size = [f[2], f[3]].map(|s| s.parse::<u32>().ok().filter(|v| *v > 0));
        let [Some(w), Some(h)] = size else {
            return Err(parse_err(
                cameras_name,
                line_no,
                "WIDTH and HEIGHT must be positive integers",
            ));
        };
        let p = numbers(cameras_name, line_no, &f[4..], "camera parameter")?;
        let intr = intrinsics_from_colmap(cameras_name, f[0], f[1], [w, h], &p)?;
        intrinsics.insert(f[0].to_owned(), intr);
    }
    let mut out = Vec::new();
    let mut expect_points = false;
    for (i, line) in images_txt.lines().enumerate() {
        let line_no = i + 1;
        let t = line.trim();
        if t.starts_with('#') {
            continue;
        }
        if expect_points {
            // The POINTS2D line (possibly empty) that follows every image line.
            expect_points = false;
            continue;
        }
        if t.is_empty() {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        if f.len() < 10 {
            return Err(parse_err(
                images_name,
                line_no,
                "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME",
            ));
        }
        let v = numbers(images_name, line_no, &f[1..8], "pose")?;
        let name = f[9..].join(" ");
        let q = Quaternion::new(v[0], v[1], v[2], v[3]);
        if !(q.norm() > 0.5 && q.norm() < 2.0) {
            return Err(parse_err(
                images_name,
                line_no,
                "the quaternion is not a rotation",
            ));
        }
        let camera_from_world: Rotation3<f64> =
            UnitQuaternion::from_quaternion(q).to_rotation_matrix();
        let t_vec = Vector3::new(v[4], v[5], v[6]);
        let world_from_camera = camera_from_world.inverse();
        let centre = -(world_from_camera * t_vec);
        let intr = intrinsics
            .get(f[8])
            .ok_or_else(|| ExchangeError::UnknownCamera {
                file: images_name.to_owned(),
                image: name.clone(),
                camera: f[8].to_owned(),
            })?;
        out.push(ImportedCamera {
            image_name: name,
            camera: Camera {
                intrinsics: *intr,
                pose: Pose {
                    rotation_world_from_camera: world_from_camera,
                    camera_center_in_world: Point3::from(centre),
                },
            },
        });
        expect_points = true;
    }
    Ok(out)
}

/// Reads `cameras.txt` and `images.txt` from a COLMAP text-model folder (or the folder of a
/// given `images.txt`/`cameras.txt`).
///
/// # Errors
/// [`ExchangeError::Read`] and those of [`parse_colmap`].
pub fn read_colmap(path: &Path) -> Result<Vec<ImportedCamera>, ExchangeError> {
    let dir = if path.is_dir() {
        path.to_path_buf()
    } else {
        path.parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    };
    let read = |name: &str| {
        let p = dir.join(name);
        std::fs::read_to_string(&p)
            .map(|text| (text, p.display().to_string()))
            .map_err(|source| ExchangeError::Read { path: p, source })
    };
    let (cameras, cameras_name) = read("cameras.txt")?;
    let (images, images_name) = read("images.txt")?;
    parse_colmap(&cameras, &cameras_name, &images, &images_name)
}

/// World-from-camera rotation of a COLMAP quaternion (for checks).
#[must_use]
pub fn rotation_from_qvec(q: [f64; 4]) -> Matrix3<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
        .to_rotation_matrix()
        .inverse()
        .into_inner()
}
