//! Site photographs: decoding (JPEG, PNG, TIFF, EXR), the EXIF orientation, EXIF metadata and the
//! initial focal length in pixels.
//!
//! Pixel coordinates always refer to the image **as displayed**: the EXIF Orientation tag is
//! applied on reading, so a portrait photo stored sideways is width < height here.
//!
//! # Known limitations
//! Only the first image of a multi-page TIFF and the first layer of an EXR are read. EXIF is read
//! from JPEG, TIFF and PNG containers (kamadak-exif); HEIC is not supported.

pub mod exif;

pub use exif::{ExifInfo, FocalEstimate, FocalSource, initial_focal_px, read_exif};

use image::{DynamicImage, ImageDecoder, ImageReader, Rgb32FImage};
use std::path::{Path, PathBuf};

/// What can go wrong reading a photo.
#[derive(Debug, thiserror::Error)]
pub enum PhotoError {
    #[error("photo {path} does not exist")]
    Missing { path: PathBuf },
    #[error("cannot read photo {path}: {message}")]
    Decode { path: PathBuf, message: String },
    #[error("cannot read EXIF of {path}: {message}")]
    Exif { path: PathBuf, message: String },
}

/// How the stored pixel values relate to light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transfer {
    /// sRGB-encoded values in 0–1 (JPEG, PNG, TIFF): decode before doing physics with them.
    Srgb,
    /// Linear values (EXR).
    Linear,
}

/// A decoded photo as displayed, in 32-bit float RGB.
#[derive(Debug, Clone)]
pub struct PhotoImage {
    pub pixels: Rgb32FImage,
    pub transfer: Transfer,
}

impl PhotoImage {
    /// Width and height in pixels, as displayed.
    #[must_use]
    pub fn size_px(&self) -> [u32; 2] {
        [self.pixels.width(), self.pixels.height()]
    }
}

fn open_decoder(path: &Path) -> Result<impl ImageDecoder, PhotoError> {
    if !path.exists() {
        return Err(PhotoError::Missing {
            path: path.to_path_buf(),
        });
    }
    let decode_err = |e: &dyn std::fmt::Display| PhotoError::Decode {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    ImageReader::open(path)
        .map_err(|e| decode_err(&e))?
        .with_guessed_format()
        .map_err(|e| decode_err(&e))?
        .into_decoder()
        .map_err(|e| decode_err(&e))
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Width and height of a photo as displayed, without decoding its pixels.
///
/// # Errors
/// [`PhotoError::Missing`] or [`PhotoError::Decode`].
pub fn size_px(path: &Path) -> Result<[u32; 2], PhotoError> {
    let mut decoder = open_decoder(path)?;
    let (w, h) = decoder.dimensions();
    let orientation = decoder
        .orientation()
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    Ok(if swaps_axes(orientation) {
        [h, w]
    } else {
        [w, h]
    })
}

fn swaps_axes(o: image::metadata::Orientation) -> bool {
    use image::metadata::Orientation as O;
    matches!(
        o,
        O::Rotate90 | O::Rotate270 | O::Rotate90FlipH | O::Rotate270FlipH
    )
}

/// Decodes a photo, applies its EXIF orientation and converts it to float RGB.
///
/// # Errors
/// [`PhotoError::Missing`] or [`PhotoError::Decode`].
pub fn load(path: &Path) -> Result<PhotoImage, PhotoError> {
    let mut decoder = open_decoder(path)?;
    let orientation = decoder
        .orientation()
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    let mut img = DynamicImage::from_decoder(decoder).map_err(|e| PhotoError::Decode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    img.apply_orientation(orientation);
    Ok(PhotoImage {
        pixels: img.into_rgb32f(),
        transfer: if is_exr(path) {
            Transfer::Linear
        } else {
            Transfer::Srgb
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_file_is_named() {
        let err = load(Path::new("/nonexistent/p1.jpg")).unwrap_err();
        assert!(matches!(err, PhotoError::Missing { .. }));
        assert!(err.to_string().contains("p1.jpg"));
    }

    #[test]
    fn garbage_is_a_decode_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.jpg");
        std::fs::write(&path, b"\xff\xd8\xff\xe0 not really a jpeg").unwrap();
        assert!(matches!(load(&path), Err(PhotoError::Decode { .. })));
    }

    #[test]
    fn png_round_trip_size_and_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        let img = image::RgbImage::from_fn(5, 3, |x, y| {
            image::Rgb([(x * 50) as u8, (y * 100) as u8, 7])
        });
        img.save(&path).unwrap();
        assert_eq!(size_px(&path).unwrap(), [5, 3]);
        let photo = load(&path).unwrap();
        assert_eq!(photo.size_px(), [5, 3]);
        assert_eq!(photo.transfer, Transfer::Srgb);
        let p = photo.pixels.get_pixel(4, 2);
        assert!((p[0] - 200.0 / 255.0).abs() < 1e-6 && (p[1] - 200.0 / 255.0).abs() < 1e-6);
    }
}
