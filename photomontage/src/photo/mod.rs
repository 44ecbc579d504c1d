//! Site photographs: decoding (JPEG, PNG, TIFF, EXR), the EXIF orientation, EXIF metadata and the
//! initial focal length in pixels.
//!
//! Pixel coordinates always refer to the image **as displayed**: the EXIF Orientation tag is
//! applied on reading, so a portrait photo stored sideways is width < height here.
//!
//! # Known limitations
//! Only the first image of a multi-page TIFF and the first layer of an EXR are read. EXIF is read
//! from JPEG, TIFF and PNG containers (kamadak-exif); HEIC is not supported.

pub mod capture_time;
pub mod exif;
pub mod sensor_table;

pub use capture_time::{CaptureTime, CaptureTimeSource};
pub use exif::{
    ExifInfo, FocalEstimate, FocalMissing, FocalSource, focal_px_from_exif, initial_focal_px,
    read_exif,
};

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
    #[error(
        "photo {path} declares {width}×{height} px ({:.0} MP, {} bytes to decode), over the limit of {:.0} MP / {} bytes",
        megapixels(*width, *height),
        decode_bytes(*width, *height),
        limits.max_pixels as f64 / 1e6,
        limits.max_bytes
    )]
    TooLarge {
        path: PathBuf,
        width: u32,
        height: u32,
        limits: DecodeLimits,
    },
    #[error(
        "photo decoding limits must be positive: {} MP, {} bytes",
        limits.max_pixels as f64 / 1e6,
        limits.max_bytes
    )]
    BadLimits { limits: DecodeLimits },
}

/// Caps on decoding a photo, checked against the header before any pixel is allocated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DecodeLimits {
    /// Most pixels (width × height) a photo may have.
    pub max_pixels: u64,
    /// Most bytes the decoder and the float RGB copy may need together.
    pub max_bytes: u64,
}

/// The limits a program set for itself with [`DecodeLimits::set_for_process`].
static PROCESS_LIMITS: std::sync::RwLock<Option<DecodeLimits>> = std::sync::RwLock::new(None);

impl DecodeLimits {
    /// 250 MP and 8 GiB: a 250 MP photo needs at most 2 GB (16-bit RGBA) + 3 GB (float RGB), so
    /// these leave room for rendering on a 24 GB machine.
    pub const BUILT_IN: Self = Self {
        max_pixels: 250_000_000,
        max_bytes: 8 << 30,
    };

    /// Makes `limits` what [`DecodeLimits::default`] gives in this process (the CLI's
    /// `--max-photo-megapixels` and `--max-decode-memory-mib`, the studio's same options).
    ///
    /// # Errors
    /// [`PhotoError::BadLimits`] for a zero cap.
    pub fn set_for_process(limits: Self) -> Result<(), PhotoError> {
        if limits.max_pixels == 0 || limits.max_bytes == 0 {
            return Err(PhotoError::BadLimits { limits });
        }
        *PROCESS_LIMITS
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(limits);
        Ok(())
    }

    /// Limits from a cap in megapixels and one in MiB, as the command-line options give them.
    ///
    /// # Errors
    /// [`PhotoError::BadLimits`] for a cap that is not positive and finite.
    pub fn from_megapixels_and_mib(megapixels: f64, mib: u64) -> Result<Self, PhotoError> {
        let limits = Self {
            max_pixels: if megapixels.is_finite() && megapixels > 0.0 {
                (megapixels * 1e6).round().min(u64::MAX as f64) as u64
            } else {
                0
            },
            max_bytes: mib.saturating_mul(1 << 20),
        };
        if limits.max_pixels == 0 || limits.max_bytes == 0 {
            return Err(PhotoError::BadLimits { limits });
        }
        Ok(limits)
    }
}

impl Default for DecodeLimits {
    /// The limits set for this process ([`DecodeLimits::set_for_process`]), else
    /// [`DecodeLimits::BUILT_IN`].
    fn default() -> Self {
        PROCESS_LIMITS
            .read()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .unwrap_or(Self::BUILT_IN)
    }
}

/// Bytes of the float RGB copy [`load`] keeps per pixel.
const FLOAT_RGB_BYTES_PER_PIXEL: u64 = 12;
/// Most bytes per pixel a decoder needs (16-bit RGBA).
const MAX_DECODED_BYTES_PER_PIXEL: u64 = 8;

fn megapixels(width: u32, height: u32) -> f64 {
    f64::from(width) * f64::from(height) / 1e6
}

/// Bytes the decoded image and its float RGB copy need together (an upper bound).
fn decode_bytes(width: u32, height: u32) -> u64 {
    (u64::from(width) * u64::from(height))
        .saturating_mul(MAX_DECODED_BYTES_PER_PIXEL + FLOAT_RGB_BYTES_PER_PIXEL)
}

fn check_limits(
    path: &Path,
    width: u32,
    height: u32,
    limits: &DecodeLimits,
) -> Result<(), PhotoError> {
    if u64::from(width) * u64::from(height) > limits.max_pixels
        || decode_bytes(width, height) > limits.max_bytes
    {
        return Err(PhotoError::TooLarge {
            path: path.to_path_buf(),
            width,
            height,
            limits: *limits,
        });
    }
    Ok(())
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

fn open_decoder(
    path: &Path,
    limits: &DecodeLimits,
) -> Result<impl ImageDecoder + use<>, PhotoError> {
    if !path.exists() {
        return Err(PhotoError::Missing {
            path: path.to_path_buf(),
        });
    }
    let decode_err = |e: &dyn std::fmt::Display| PhotoError::Decode {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut reader = ImageReader::open(path)
        .map_err(|e| decode_err(&e))?
        .with_guessed_format()
        .map_err(|e| decode_err(&e))?;
    // The decoders' own allocations (e.g. PNG's text chunks, EXR's buffers) stay under the cap
    // too; the header check below names the declared size.
    let mut image_limits = image::Limits::default();
    image_limits.max_alloc = Some(limits.max_bytes);
    reader.limits(image_limits);
    let decoder = reader.into_decoder().map_err(|e| decode_err(&e))?;
    let (width, height) = decoder.dimensions();
    check_limits(path, width, height, limits)?;
    Ok(decoder)
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Width and height of a photo as displayed, without decoding its pixels.
///
/// # Errors
/// [`PhotoError::Missing`], [`PhotoError::Decode`], or [`PhotoError::TooLarge`] over the
/// default [`DecodeLimits`].
pub fn size_px(path: &Path) -> Result<[u32; 2], PhotoError> {
    let mut decoder = open_decoder(path, &DecodeLimits::default())?;
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

/// Decodes a photo, applies its EXIF orientation and converts it to float RGB, within the
/// default [`DecodeLimits`].
///
/// # Errors
/// [`PhotoError::Missing`], [`PhotoError::Decode`] or [`PhotoError::TooLarge`].
pub fn load(path: &Path) -> Result<PhotoImage, PhotoError> {
    load_with_limits(path, &DecodeLimits::default())
}

/// [`load`] with caps of the caller's choice.
///
/// # Errors
/// [`PhotoError::Missing`], [`PhotoError::Decode`] or [`PhotoError::TooLarge`] when the header
/// declares more pixels or bytes than `limits` allow (checked before any pixel is allocated).
pub fn load_with_limits(path: &Path, limits: &DecodeLimits) -> Result<PhotoImage, PhotoError> {
    let mut decoder = open_decoder(path, limits)?;
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

    /// A valid PNG signature and IHDR declaring `width`×`height` 8-bit RGB, then a short IDAT:
    /// a tiny file whose header lies about its size.
    pub(crate) fn lying_png(width: u32, height: u32) -> Vec<u8> {
        fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
            out.extend_from_slice(&u32::try_from(data.len()).unwrap().to_be_bytes());
            let start = out.len();
            out.extend_from_slice(kind);
            out.extend_from_slice(data);
            let crc = crc32(&out[start..]);
            out.extend_from_slice(&crc.to_be_bytes());
        }
        fn crc32(bytes: &[u8]) -> u32 {
            let mut crc = 0xffff_ffff_u32;
            for &b in bytes {
                crc ^= u32::from(b);
                for _ in 0..8 {
                    crc = if crc & 1 == 1 {
                        (crc >> 1) ^ 0xedb8_8320
                    } else {
                        crc >> 1
                    };
                }
            }
            !crc
        }
        let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&width.to_be_bytes());
        ihdr.extend_from_slice(&height.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
        chunk(&mut out, b"IHDR", &ihdr);
        chunk(
            &mut out,
            b"IDAT",
            &[0x78, 0x9c, 0x63, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01],
        );
        chunk(&mut out, b"IEND", &[]);
        out
    }

    #[test]
    fn lying_header_is_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        std::fs::write(&path, lying_png(100_000, 100_000)).unwrap();
        for result in [load(&path).map(|p| p.size_px()), size_px(&path)] {
            let err = result.unwrap_err();
            assert!(
                matches!(
                    err,
                    PhotoError::TooLarge {
                        width: 100_000,
                        height: 100_000,
                        ..
                    }
                ),
                "{err}"
            );
            let message = err.to_string();
            assert!(
                message.contains("huge.png") && message.contains("100000×100000"),
                "{message}"
            );
        }
    }

    #[test]
    fn limits_are_configurable() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        image::RgbImage::new(40, 30).save(&path).unwrap();
        let small = DecodeLimits {
            max_pixels: 1000,
            ..DecodeLimits::default()
        };
        assert!(matches!(
            load_with_limits(&path, &small),
            Err(PhotoError::TooLarge { .. })
        ));
        assert_eq!(load(&path).unwrap().size_px(), [40, 30]);
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
