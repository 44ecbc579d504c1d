//! Output of a rendered view: linear OpenEXR with coverage alpha and optional auxiliary layers,
//! or 8-bit sRGB PNG, JPEG (quality 92) and TIFF through [`crate::colour::tonemap`]
//! (issue 4 item 6; OpenEXR channel naming after the OpenEXR "Interpreting Deep Pixels" and
//! technical-introduction conventions: `Z` is depth, dotted names group channels into layers).
//!
//! EXR channels (all 32-bit float, one part, the photo's linear units):
//! - `R`, `G`, `B`: the montage; `A`: coverage of artificial objects (fraction of the pixel's rays
//!   whose first hit is artificial). Pixels the renderer left unchanged hold the photo's value
//!   bit for bit and A = 0.
//! - `Z` (layer `depth`): distance in metres from the camera centre along the pixel's **first**
//!   ray to its first hit (natural or artificial); +∞ where that ray hits nothing.
//! - `object_id` (layer `object_id`): index of the object the first ray hits first, −1 for none.
//!   The index → name table is written beside the EXR as `NAME.objects.json`
//!   ([`write_object_table`]).
//! - `shadow_change.R/G/B` (layer `shadow_change`): the change of the pixel caused on
//!   photographed (natural) surfaces — Durisch §6.2 D3 (shadows, negative) plus D1 and the
//!   building's reflected light (positive) — i.e. the sum over the pixel's rays whose first hit is
//!   not artificial of (ray radiance − photo value), divided by the pixel's ray count; 0 in
//!   unchanged pixels.
//!
//! Every file is written atomically ([`crate::atomic_file`]): encoded in memory, written to a
//! temporary file beside the target and renamed, so a killed render leaves the old file or the
//! complete new one.
//!
//! # Known limitations
//! Depth and object id come from one ray per pixel (no antialiasing of those layers). 8-bit
//! outputs drop alpha and the auxiliary layers; EXR is the only lossless output.

use std::path::{Path, PathBuf};

use super::RenderedImage;
use super::differential::PrimaryHit;
use crate::colour::ToneMap;
use crate::colour::tonemap::encode_srgb8;

/// JPEG quality of 8-bit JPEG output (1–100): visually lossless for photographs.
pub const JPEG_QUALITY: u8 = 92;

/// What can go wrong writing a render.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(
        "cannot tell the output format of {path}: extension `{extension}` is not exr, png, jpg, jpeg, tif or tiff"
    )]
    UnknownExtension { path: PathBuf, extension: String },
    #[error("unknown layer `{name}`; the layers are depth, object_id, shadow_change")]
    UnknownLayer { name: String },
    #[error("layers {layers} need an EXR output, not {format:?}")]
    LayersNeedExr {
        layers: String,
        format: OutputFormat,
    },
    #[error("cannot write {path}: {message}")]
    Write { path: PathBuf, message: String },
}

/// An output file format, chosen by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// OpenEXR, linear 32-bit float.
    Exr,
    /// 8-bit sRGB PNG.
    Png,
    /// 8-bit sRGB JPEG, quality [`JPEG_QUALITY`].
    Jpeg,
    /// 8-bit sRGB TIFF.
    Tiff,
}

impl OutputFormat {
    /// The format named by `path`'s extension (case-insensitive).
    ///
    /// # Errors
    /// [`OutputError::UnknownExtension`].
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match extension.as_str() {
            "exr" => Ok(Self::Exr),
            "png" => Ok(Self::Png),
            "jpg" | "jpeg" => Ok(Self::Jpeg),
            "tif" | "tiff" => Ok(Self::Tiff),
            _ => Err(OutputError::UnknownExtension {
                path: path.to_path_buf(),
                extension,
            }),
        }
    }
}

/// Which auxiliary layers to compute.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LayerSet {
    /// Depth along the first ray.
    pub depth: bool,
    /// First-hit object index.
    pub object_id: bool,
    /// Change of natural radiance (shadows and added light on photographed surfaces).
    pub shadow_change: bool,
}

impl LayerSet {
    /// Parses a comma-separated list of `depth`, `object_id`, `shadow_change` (empty: none).
    ///
    /// # Errors
    /// [`OutputError::UnknownLayer`].
    pub fn parse(list: &str) -> Result<Self, OutputError> {
        let mut set = Self::default();
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "depth" => set.depth = true,
                "object_id" => set.object_id = true,
                "shadow_change" => set.shadow_change = true,
                other => {
                    return Err(OutputError::UnknownLayer {
                        name: other.to_owned(),
                    });
                }
            }
        }
        Ok(set)
    }

    /// Whether no layer is chosen.
    #[must_use]
    pub fn is_empty(self) -> bool {
        !(self.depth || self.object_id || self.shadow_change)
    }

    /// The chosen names, comma-separated.
    #[must_use]
    pub fn names(self) -> String {
        [
            (self.depth, "depth"),
            (self.object_id, "object_id"),
            (self.shadow_change, "shadow_change"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect::<Vec<_>>()
        .join(",")
    }
}

/// The auxiliary layers of a render, row-major like [`RenderedImage::rgba`]; `None` when not
/// asked for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OutputLayers {
    /// Distance along the first ray to its first hit, metres; +∞ for none.
    pub depth_m: Option<Vec<f32>>,
    /// Index of the first ray's first-hit object; −1 for none.
    pub object_id: Option<Vec<f32>>,
    /// Change of natural radiance, linear RGB.
    pub shadow_change_rgb: Option<Vec<[f32; 3]>>,
}

impl OutputLayers {
    /// Layers for `set`, each with `len` default values (+∞, −1, 0).
    #[must_use]
    pub fn new(set: LayerSet, len: usize) -> Self {
        Self {
            depth_m: set.depth.then(|| vec![f32::INFINITY; len]),
            object_id: set.object_id.then(|| vec![-1.0; len]),
            shadow_change_rgb: set.shadow_change.then(|| vec![[0.0; 3]; len]),
        }
    }

    /// Appends one pixel: the first ray's hit, the summed natural change over its `rays` rays.
    pub(crate) fn push_pixel(
        &mut self,
        first_hit: Option<PrimaryHit>,
        natural_change_sum: [f64; 3],
        changed: bool,
        rays: u32,
    ) {
        if let Some(d) = &mut self.depth_m {
            #[allow(clippy::cast_possible_truncation)]
            d.push(first_hit.map_or(f32::INFINITY, |h| h.distance_m as f32));
        }
        if let Some(o) = &mut self.object_id {
            #[allow(clippy::cast_precision_loss)]
            o.push(first_hit.map_or(-1.0, |h| h.object.0 as f32));
        }
        if let Some(s) = &mut self.shadow_change_rgb {
            let n = f64::from(rays.max(1));
            #[allow(clippy::cast_possible_truncation)]
            s.push(if changed {
                natural_change_sum.map(|v| (v / n) as f32)
            } else {
                [0.0; 3]
            });
        }
    }

    /// Copies pixel `from_index` of `from` (a tile) to pixel `to_index` of `self`.
    pub(crate) fn copy_pixel(&mut self, from: &Self, from_index: usize, to_index: usize) {
        if let (Some(d), Some(f)) = (&mut self.depth_m, &from.depth_m) {
            d[to_index] = f[from_index];
        }
        if let (Some(d), Some(f)) = (&mut self.object_id, &from.object_id) {
            d[to_index] = f[from_index];
        }
        if let (Some(d), Some(f)) = (&mut self.shadow_change_rgb, &from.shadow_change_rgb) {
            d[to_index] = f[from_index];
        }
    }
}

fn write_error(path: &Path, e: &dyn std::fmt::Display) -> OutputError {
    OutputError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Writes a one-part EXR with `R G B A` and the channels of the present layers (see the module
/// documentation), all 32-bit float, ZIP-compressed scan lines in increasing order (lossless and
/// byte-for-byte reproducible).
///
/// # Errors
/// [`OutputError::Write`].
pub fn write_exr(
    path: &Path,
    image: &RenderedImage,
    layers: &OutputLayers,
) -> Result<(), OutputError> {
    write_exr_with(
        path,
        image,
        layers,
        exr::prelude::LayerAttributes::default(),
    )
}

/// [`write_exr`] with the layer's header `attributes` (owner, comments, capture date, position,
/// custom ones in `other`). Keep at most one entry in `attributes.other`: it is a hash map, and
/// with several the header's byte order would vary from run to run.
///
/// # Errors
/// [`OutputError::Write`].
pub fn write_exr_with(
    path: &Path,
    image: &RenderedImage,
    layers: &OutputLayers,
    attributes: exr::prelude::LayerAttributes,
) -> Result<(), OutputError> {
    use exr::prelude::*;
    let [w, h] = image.size_px;
    let channels = exr_channels(image, layers);
    let layer = Layer::new(
        (w as usize, h as usize),
        attributes,
        // ZIP over scan lines in increasing order: lossless, and the block order (so the file's
        // bytes) does not depend on which compression thread finishes first.
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| write_error(path, &e))?;
    write_file(path, &bytes.into_inner())
}

/// The EXR channels of `image` and `layers` (see the module documentation), unsorted.
pub(crate) fn exr_channels(
    image: &RenderedImage,
    layers: &OutputLayers,
) -> Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>> {
    use exr::prelude::*;
    let channel = |name: &str, values: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(values));
    let rgba = |k: usize| image.rgba.iter().map(|p| p[k]).collect::<Vec<f32>>();
    let mut channels = vec![
        channel("R", rgba(0)),
        channel("G", rgba(1)),
        channel("B", rgba(2)),
        channel("A", rgba(3)),
    ];
    if let Some(d) = &layers.depth_m {
        channels.push(channel("Z", d.clone()));
    }
    if let Some(o) = &layers.object_id {
        channels.push(channel("object_id", o.clone()));
    }
    if let Some(s) = &layers.shadow_change_rgb {
        for (k, name) in ["shadow_change.R", "shadow_change.G", "shadow_change.B"]
            .iter()
            .enumerate()
        {
            channels.push(channel(name, s.iter().map(|p| p[k]).collect()));
        }
    }
    channels
}

/// Writes finished file contents atomically ([`crate::atomic_file`]): a reader sees the old file
/// or the whole new one, never a torn one.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    crate::atomic_file::write_atomically(path, bytes).map_err(|e| write_error(path, &e))
}

/// Writes 8-bit sRGB (alpha dropped) through `tone_map` as PNG, JPEG (quality
/// [`JPEG_QUALITY`]) or TIFF.
///
/// # Errors
/// [`OutputError::Write`]. [`OutputFormat::Exr`] is not 8-bit: it is written as TIFF here; use
/// [`write_exr`] or [`write_output`] for EXR.
pub fn write_8bit(
    path: &Path,
    image: &RenderedImage,
    format: OutputFormat,
    tone_map: &ToneMap,
) -> Result<(), OutputError> {
    let [w, h] = image.size_px;
    let rgb = image::RgbImage::from_fn(w, h, |x, y| {
        let p = image.rgba[(y * w + x) as usize];
        image::Rgb(encode_srgb8([p[0], p[1], p[2]], tone_map))
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    match format {
        OutputFormat::Jpeg => {
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, JPEG_QUALITY)
                .encode_image(&rgb)
                .map_err(|e| write_error(path, &e))?;
        }
        OutputFormat::Png => rgb
            .write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| write_error(path, &e))?,
        OutputFormat::Tiff | OutputFormat::Exr => rgb
            .write_to(&mut bytes, image::ImageFormat::Tiff)
            .map_err(|e| write_error(path, &e))?,
    }
    write_file(path, &bytes.into_inner())
}

/// Writes `image` to `path` in the format its extension names: EXR with `layers`, or 8-bit sRGB
/// through `tone_map`.
///
/// # Errors
/// [`OutputError::UnknownExtension`], [`OutputError::LayersNeedExr`] when layers are present and
/// the format is not EXR, [`OutputError::Write`].
pub fn write_output(
    path: &Path,
    image: &RenderedImage,
    layers: &OutputLayers,
    tone_map: &ToneMap,
) -> Result<OutputFormat, OutputError> {
    let format = OutputFormat::from_path(path)?;
    match format {
        OutputFormat::Exr => write_exr(path, image, layers)?,
        other => {
            let present = LayerSet {
                depth: layers.depth_m.is_some(),
                object_id: layers.object_id.is_some(),
                shadow_change: layers.shadow_change_rgb.is_some(),
            };
            if !present.is_empty() {
                return Err(OutputError::LayersNeedExr {
                    layers: present.names(),
                    format: other,
                });
            }
            write_8bit(path, image, other, tone_map)?;
        }
    }
    Ok(format)
}

/// The sidecar of the `object_id` layer: `NAME.objects.json` beside `exr_path`.
#[must_use]
pub fn object_table_path(exr_path: &Path) -> PathBuf {
    exr_path.with_extension("objects.json")
}

/// Writes the object-id table `{"channel": "object_id", "none": -1, "objects": [{"id": 0,
/// "name": ...}, ...]}` to [`object_table_path`]; returns that path.
///
/// # Errors
/// [`OutputError::Write`].
pub fn write_object_table(exr_path: &Path, names: &[String]) -> Result<PathBuf, OutputError> {
    let path = object_table_path(exr_path);
    let objects: Vec<serde_json::Value> = names
        .iter()
        .enumerate()
        .map(|(id, name)| serde_json::json!({ "id": id, "name": name }))
        .collect();
    let json = serde_json::json!({ "channel": "object_id", "none": -1, "objects": objects });
    let text = serde_json::to_string_pretty(&json).map_err(|e| write_error(&path, &e))?;
    write_file(&path, text.as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image_2x1() -> (RenderedImage, OutputLayers) {
        let image = RenderedImage {
            size_px: [2, 1],
            rgba: vec![[0.25, 0.5, 0.75, 0.0], [1.5, 0.125, 0.0, 1.0]],
            changed_pixels: 1,
            primary_rays: 8,
        };
        let layers = OutputLayers {
            depth_m: Some(vec![f32::INFINITY, 12.5]),
            object_id: Some(vec![-1.0, 3.0]),
            shadow_change_rgb: Some(vec![[0.0; 3], [-0.1, -0.2, -0.3]]),
        };
        (image, layers)
    }

    #[test]
    fn formats_by_extension_and_unknown_ones_named() {
        for (name, f) in [
            ("a.EXR", OutputFormat::Exr),
            ("a.png", OutputFormat::Png),
            ("a.jpg", OutputFormat::Jpeg),
            ("a.jpeg", OutputFormat::Jpeg),
            ("a.tif", OutputFormat::Tiff),
            ("a.tiff", OutputFormat::Tiff),
        ] {
            assert_eq!(OutputFormat::from_path(Path::new(name)).unwrap(), f);
        }
        let err = OutputFormat::from_path(Path::new("a.bmp")).unwrap_err();
        assert!(err.to_string().contains("`bmp`"), "{err}");
    }

    #[test]
    fn layer_lists_parse_and_reject_unknown_names() {
        let s = LayerSet::parse("depth, shadow_change").unwrap();
        assert!(s.depth && s.shadow_change && !s.object_id);
        assert_eq!(s.names(), "depth,shadow_change");
        assert!(LayerSet::parse("").unwrap().is_empty());
        assert!(matches!(
            LayerSet::parse("depth,normals"),
            Err(OutputError::UnknownLayer { .. })
        ));
    }

    #[test]
    fn exr_round_trips_every_channel_exactly() {
        use exr::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("o.exr");
        let (image, layers) = image_2x1();
        write_exr(&path, &image, &layers).unwrap();
        let read = read_all_flat_layers_from_file(&path).unwrap();
        let layer = &read.layer_data[0];
        let get = |name: &str| -> Vec<f32> {
            let c = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.eq(name))
                .unwrap();
            c.sample_data.values_as_f32().collect()
        };
        let bits = |v: Vec<f32>| v.into_iter().map(f32::to_bits).collect::<Vec<_>>();
        assert_eq!(bits(get("R")), bits(vec![0.25, 1.5]));
        assert_eq!(bits(get("A")), bits(vec![0.0, 1.0]));
        assert_eq!(bits(get("Z")), bits(vec![f32::INFINITY, 12.5]));
        assert_eq!(bits(get("object_id")), bits(vec![-1.0, 3.0]));
        assert_eq!(bits(get("shadow_change.B")), bits(vec![0.0, -0.3]));
    }

    #[test]
    fn eight_bit_outputs_encode_srgb_and_refuse_layers() {
        let dir = tempfile::tempdir().unwrap();
        let (image, layers) = image_2x1();
        let tm = ToneMap::clamp();
        for name in ["o.png", "o.tif"] {
            let path = dir.path().join(name);
            write_output(&path, &image, &OutputLayers::default(), &tm).unwrap();
            let back = image::open(&path).unwrap().into_rgb8();
            // Lossless 8-bit: sRGB(0.25) = 137, sRGB(0.5) = 188, sRGB(0.75) = 225 (rounded
            // encode of IEC 61966-2-1), and 1.5 clips to 255.
            assert_eq!(back.get_pixel(0, 0).0, [137, 188, 225]);
            assert_eq!(back.get_pixel(1, 0).0[0], 255);
        }
        let jpg = dir.path().join("o.jpg");
        write_output(&jpg, &image, &OutputLayers::default(), &tm).unwrap();
        assert_eq!(image::open(&jpg).unwrap().width(), 2);
        let err = write_output(&dir.path().join("x.png"), &image, &layers, &tm).unwrap_err();
        assert!(matches!(err, OutputError::LayersNeedExr { .. }), "{err}");
        let err =
            write_output(&dir.path().join("missing/dir/o.exr"), &image, &layers, &tm).unwrap_err();
        assert!(err.to_string().contains("missing/dir/o.exr"), "{err}");
    }

    #[test]
    fn object_table_sits_beside_the_exr() {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("view.exr");
        let p = write_object_table(&exr, &["polygon:ground".into(), "model:box".into()]).unwrap();
        assert_eq!(p, dir.path().join("view.objects.json"));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        assert_eq!(v["objects"][1]["name"], "model:box");
        assert_eq!(v["none"], -1);
    }
}
