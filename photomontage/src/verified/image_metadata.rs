//! Output images that carry their view ([`super::view_metadata`]): JPEG (EXIF APP1 and XMP
//! APP1), PNG (`eXIf` and XMP `iTXt`), TIFF (IFD0 with the Exif and GPS IFDs and XMP in tag 700,
//! written here: the `image` crate's TIFF encoder takes no metadata) and OpenEXR (standard header
//! attributes and `photomontage.view`). Every file is written through a temporary file and a
//! rename ([`crate::atomic_file`]): never a partial image at the target path.
//!
//! # Known limitations
//! TIFF output is uncompressed (one strip); the EXR attributes are single-precision floats where
//! OpenEXR defines them so (the `photomontage.view` JSON keeps full precision).

use std::path::Path;

use image::ImageEncoder;

use super::tiff_ifd::{BYTE, RgbStrip, XMP_TAG, bytes, tiff_bytes};
use super::view_metadata::{ViewMetadata, exif_block, exif_ifds, exr_attributes};
use super::xmp::{insert_into_jpeg, insert_into_png, xmp_packet};

/// What can go wrong writing an image with metadata.
#[derive(Debug, thiserror::Error)]
pub enum ImageMetadataError {
    #[error("{path}: only .jpg/.jpeg, .png and .tif/.tiff are 8-bit images carrying the view")]
    UnsupportedFormat { path: String },
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
}

/// The view metadata of `photo_id` (default options: A3 sheet).
///
/// # Errors
/// Any [`super::ViewGeometryError`] (an unsolved photo, ...).
pub fn view_metadata(
    doc: &crate::site::SiteDocument,
    photo_id: &str,
) -> Result<ViewMetadata, super::ViewGeometryError> {
    super::view_geometry(doc, photo_id, &super::ViewGeometryOptions::default())
        .map(|r| ViewMetadata::from(&r))
}

/// Writes a render as [`crate::render::output::write_output`] does, except that, when `view` is
/// given, JPEG, PNG and TIFF carry it as EXIF and XMP and EXR as header attributes.
///
/// # Errors
/// [`ImageMetadataError::Write`].
pub fn write_render(
    path: &Path,
    image: &crate::render::RenderedImage,
    layers: &crate::render::OutputLayers,
    tone_map: &crate::colour::ToneMap,
    view: Option<&ViewMetadata>,
) -> Result<(), ImageMetadataError> {
    use crate::render::output::{JPEG_QUALITY, OutputFormat, write_exr_with, write_output};
    let fail = |message: String| ImageMetadataError::Write {
        path: path.display().to_string(),
        message,
    };
    let format = OutputFormat::from_path(path).map_err(|e| fail(e.to_string()))?;
    match (format, view) {
        (OutputFormat::Exr, Some(view)) => {
            write_exr_with(path, image, layers, exr_attributes(view))
                .map_err(|e| fail(e.to_string()))
        }
        (OutputFormat::Jpeg | OutputFormat::Png | OutputFormat::Tiff, Some(view)) => {
            let [w, h] = image.size_px;
            let rgb = image::RgbImage::from_fn(w, h, |x, y| {
                let p = image.rgba[(y * w + x) as usize];
                image::Rgb(crate::colour::encode_srgb8([p[0], p[1], p[2]], tone_map))
            });
            write_8bit_with_view(path, &rgb, view, JPEG_QUALITY)
        }
        _ => write_output(path, image, layers, tone_map)
            .map(|_| ())
            .map_err(|e| fail(e.to_string())),
    }
}

/// Writes `rgb` as JPEG (`quality`), PNG or TIFF (by the extension of `path`) carrying `view` as
/// EXIF and XMP, through a temporary file and a rename.
///
/// # Errors
/// [`ImageMetadataError::UnsupportedFormat`] for other extensions, [`ImageMetadataError::Write`].
pub fn write_8bit_with_view(
    path: &Path,
    rgb: &image::RgbImage,
    view: &ViewMetadata,
    quality: u8,
) -> Result<(), ImageMetadataError> {
    let bytes = encode_8bit_with_view(path, rgb, view, quality)?;
    crate::site::write_atomically(path, &bytes).map_err(|e| ImageMetadataError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// The file bytes [`write_8bit_with_view`] writes.
///
/// # Errors
/// As [`write_8bit_with_view`].
pub fn encode_8bit_with_view(
    path: &Path,
    rgb: &image::RgbImage,
    view: &ViewMetadata,
    quality: u8,
) -> Result<Vec<u8>, ImageMetadataError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let fail = |message: String| ImageMetadataError::Write {
        path: path.display().to_string(),
        message,
    };
    let packet = xmp_packet(view);
    let mut out = Vec::new();
    let (w, h) = rgb.dimensions();
    match ext.as_deref() {
        Some("jpg" | "jpeg") => {
            let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality);
            enc.set_exif_metadata(exif_block(view))
                .map_err(|e| fail(e.to_string()))?;
            enc.write_image(rgb.as_raw(), w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| fail(e.to_string()))?;
            insert_into_jpeg(&out, &packet).map_err(|e| fail(e.to_string()))
        }
        Some("png") => {
            let mut enc = image::codecs::png::PngEncoder::new(&mut out);
            enc.set_exif_metadata(exif_block(view))
                .map_err(|e| fail(e.to_string()))?;
            enc.write_image(rgb.as_raw(), w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| fail(e.to_string()))?;
            insert_into_png(&out, &packet).map_err(|e| fail(e.to_string()))
        }
        Some("tif" | "tiff") => {
            let mut ifds = exif_ifds(view);
            ifds.ifd0.push(bytes(XMP_TAG, BYTE, packet.as_bytes()));
            Ok(tiff_bytes(
                &ifds,
                Some(RgbStrip {
                    size_px: [w, h],
                    samples: rgb.as_raw(),
                }),
            ))
        }
        _ => Err(ImageMetadataError::UnsupportedFormat {
            path: path.display().to_string(),
        }),
    }
}
