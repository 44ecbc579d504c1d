//! OpenSfM `reconstruction.json` (OpenSfM documentation, "Reconstruction file format";
//! `opensfm/features.py` for normalised image coordinates; `opensfm/types.py` for shots).
//!
//! Conventions: the file is a list of reconstructions, each with `cameras` (by id) and `shots`
//! (by image name, `camera`, `rotation`, `translation`). `rotation` is the axis-angle vector of
//! R_camera_from_world, `translation` is t with `x_camera = R·X + t` in the OpenCV camera frame.
//! Camera parameters are normalised by s = max(width, height): pixel = s·n + (width/2 − 0.5,
//! height/2 − 0.5) with our pixel-centre convention (OpenSfM's
//! `normalized_image_coordinates`). `perspective` (focal, k1, k2), `simple_radial`
//! (focal_x, focal_y, c_x, c_y, k1), `radial` (… k1, k2) and `brown` (focal_x, focal_y, c_x, c_y,
//! k1, k2, k3, p1, p2; OpenCV's Brown–Conrady) are read; fisheye, spherical, equirectangular
//! and dual cameras are refused by name, as is focal_x ≠ focal_y.
//!
//! # Known limitations
//! OpenSfM's world frame is topocentric (east-north-up about `reference_lla.json`), not the
//! site's CRS: poses are imported only on request, for reconstructions already in the site frame.

use std::path::Path;

use nalgebra::{Point3, Rotation3, Vector3};
use serde_json::Value;

use super::ExchangeError;
use super::colmap::ImportedCamera;
use crate::camera::{BrownConrady, Camera, Intrinsics, Pose};

/// Relative difference of focal_x and focal_y beyond which the pixels are not square.
const SQUARE_PIXEL_TOLERANCE: f64 = 1e-6;
/// Largest `reconstruction.json` read (bytes).
const MAX_FILE_BYTES: u64 = 1 << 30;

fn field(file: &str, camera: &str, v: &Value, key: &str) -> Result<f64, ExchangeError> {
    v.get(key)
        .and_then(Value::as_f64)
        .filter(|x| x.is_finite())
        .ok_or_else(|| ExchangeError::UnsupportedModel {
            file: file.to_owned(),
            camera: camera.to_owned(),
            model: v
                .get("projection_type")
                .and_then(Value::as_str)
                .unwrap_or("?")
                .to_owned(),
            reason: format!("`{key}` is missing or not a finite number"),
        })
}

fn intrinsics(file: &str, id: &str, c: &Value) -> Result<Intrinsics, ExchangeError> {
    let model = c
        .get("projection_type")
        .and_then(Value::as_str)
        .unwrap_or("perspective");
    let get = |key: &str| field(file, id, c, key);
    let size = [get("width")?, get("height")?];
    if size
        .iter()
        .any(|v| *v < 1.0 || *v > f64::from(u32::MAX) || v.fract() != 0.0)
    {
        return Err(ExchangeError::UnsupportedModel {
            file: file.to_owned(),
            camera: id.to_owned(),
            model: model.to_owned(),
            reason: "width and height must be positive integers".to_owned(),
        });
    }
    let (w, h) = (size[0], size[1]);
    let s = w.max(h);
    let mut d = BrownConrady::default();
    let (fx, fy, cx, cy) = match model {
        "perspective" => {
            d.k1 = get("k1")?;
            d.k2 = get("k2")?;
            (get("focal")?, get("focal")?, 0.0, 0.0)
        }
        "simple_radial" | "radial" | "brown" => {
            d.k1 = get("k1")?;
            if model != "simple_radial" {
                d.k2 = get("k2")?;
            }
            if model == "brown" {
                d.k3 = get("k3")?;
                d.p1 = get("p1")?;
                d.p2 = get("p2")?;
            }
            (get("focal_x")?, get("focal_y")?, get("c_x")?, get("c_y")?)
        }
        other => {
            return Err(ExchangeError::UnsupportedModel {
                file: file.to_owned(),
                camera: id.to_owned(),
                model: other.to_owned(),
                reason: "not a pinhole with Brown–Conrady distortion".to_owned(),
            });
        }
    };
    if (fx - fy).abs() > SQUARE_PIXEL_TOLERANCE * fx.abs().max(fy.abs()) {
        return Err(ExchangeError::NonSquarePixels {
            file: file.to_owned(),
            camera: id.to_owned(),
            fx_px: fx * s,
            fy_px: fy * s,
        });
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // checked above
    let image_size_px = [w as u32, h as u32];
    Ok(Intrinsics {
        focal_px: 0.5 * (fx + fy) * s,
        principal_point_px: [s * cx + w / 2.0 - 0.5, s * cy + h / 2.0 - 0.5],
        distortion: d,
        image_size_px,
    })
}

fn vector3(file: &str, shot: &str, v: &Value, key: &str) -> Result<Vector3<f64>, ExchangeError> {
    let a = v
        .get(key)
        .and_then(Value::as_array)
        .filter(|a| a.len() == 3)
        .and_then(|a| {
            let x: Vec<f64> = a
                .iter()
                .filter_map(Value::as_f64)
                .filter(|x| x.is_finite())
                .collect();
            (x.len() == 3).then(|| Vector3::new(x[0], x[1], x[2]))
        });
    a.ok_or_else(|| ExchangeError::Parse {
        file: file.to_owned(),
        line: 0,
        message: format!("shot {shot}: `{key}` must be three finite numbers"),
    })
}

/// Reads the cameras of every shot of every reconstruction in a `reconstruction.json` text.
///
/// # Errors
/// [`ExchangeError::Parse`] (JSON errors carry their line), [`ExchangeError::UnsupportedModel`],
/// [`ExchangeError::NonSquarePixels`], [`ExchangeError::UnknownCamera`].
pub fn parse_opensfm(text: &str, file: &str) -> Result<Vec<ImportedCamera>, ExchangeError> {
    let root: Value = serde_json::from_str(text).map_err(|e| ExchangeError::Parse {
        file: file.to_owned(),
        line: e.line(),
        message: e.to_string(),
    })?;
    let list = match &root {
        Value::Array(a) => a.clone(),
        Value::Object(_) => vec![root.clone()],
        _ => {
            return Err(ExchangeError::Parse {
                file: file.to_owned(),
                line: 1,
                message: "expected a list of reconstructions".to_owned(),
            });
        }
    };
    let mut out = Vec::new();
    for rec in &list {
        let cameras = rec.get("cameras").and_then(Value::as_object);
        let Some(shots) = rec.get("shots").and_then(Value::as_object) else {
            continue;
        };
        for (name, shot) in shots {
            let camera_id = shot.get("camera").and_then(Value::as_str).unwrap_or("");
            let c = cameras.and_then(|m| m.get(camera_id)).ok_or_else(|| {
                ExchangeError::UnknownCamera {
                    file: file.to_owned(),
                    image: name.clone(),
                    camera: camera_id.to_owned(),
                }
            })?;
            let intr = intrinsics(file, camera_id, c)?;
            let rotation = vector3(file, name, shot, "rotation")?;
            let translation = vector3(file, name, shot, "translation")?;
            let camera_from_world = Rotation3::new(rotation);
            let world_from_camera = camera_from_world.inverse();
            out.push(ImportedCamera {
                image_name: name.clone(),
                camera: Camera {
                    intrinsics: intr,
                    pose: Pose {
                        rotation_world_from_camera: world_from_camera,
                        camera_center_in_world: Point3::from(-(world_from_camera * translation)),
                    },
                },
            });
        }
    }
    Ok(out)
}

/// Reads a `reconstruction.json` file.
///
/// # Errors
/// [`ExchangeError::Read`] and those of [`parse_opensfm`].
pub fn read_opensfm(path: &Path) -> Result<Vec<ImportedCamera>, ExchangeError> {
    let read_err = |source| ExchangeError::Read {
        path: path.to_path_buf(),
        source,
    };
    let bytes = std::fs::metadata(path).map_err(read_err)?.len();
    if bytes > MAX_FILE_BYTES {
        return Err(ExchangeError::Parse {
            file: path.display().to_string(),
            line: 0,
            message: format!("{bytes} bytes is more than the {MAX_FILE_BYTES} read"),
        });
    }
    let text = std::fs::read_to_string(path).map_err(read_err)?;
    parse_opensfm(&text, &path.display().to_string())
}
