//! Partial renders: one [`Band`] of a view written as an OpenEXR file whose data window is the
//! band's rows inside the display window of the whole image (OpenEXR "Technical Introduction",
//! data and display windows), and the merge that puts a view's bands back together.
//!
//! A part holds the channels of [`super::output::write_exr`] (R, G, B, A and any layers) over the
//! band's rows, and one string attribute `photomontage.part`: JSON of [`PartInfo`] — the band,
//! the whole image's size, the rows, the **identity** of the job (site content hash, view,
//! settings, seed, exposure, mode: everything the pixels depend on) and the band's statistics.
//! [`merge_parts`] refuses parts of different identities (naming the field that differs and both
//! values), a band given twice, a missing band (naming every one), or rows that do not match the
//! band; it returns the whole image, which is bit for bit the whole-image render because every
//! band holds exactly that render's values ([`super::tiling`]).
//!
//! Parts are written atomically ([`crate::atomic_file`]), so a part that exists is complete: a
//! render farm may treat "the file exists" as "the job is done".
//!
//! # Known limitations
//! The identity covers what the job was asked (site file content, settings), not the content of
//! the photos and models the site refers to: change a photo in place between parts of one job
//! and the merge cannot tell.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use super::output::{LayerSet, OutputError, OutputLayers, write_file};
use super::{Band, RenderedImage};

/// The `format` of [`PartInfo`] this version writes and reads.
pub const PART_FORMAT: &str = "photomontage-part/1";

/// Name of the EXR header attribute holding the [`PartInfo`] JSON.
pub const PART_ATTRIBUTE: &str = "photomontage.part";

/// What a part says about itself.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PartInfo {
    /// [`PART_FORMAT`].
    pub format: String,
    /// The band, `I/N`.
    pub tile: String,
    /// Width and height of the whole image, pixels.
    pub full_size_px: [u32; 2],
    /// The band's pixel rows, `[start, end)`.
    pub rows_px: [u32; 2],
    /// Everything the pixels depend on; parts of one view must agree on every entry.
    pub identity: BTreeMap<String, String>,
    /// Exposure multiplier for 8-bit output of the merged image.
    pub exposure: f64,
    /// Names of the object ids when the `object_id` layer is present.
    pub object_names: Option<Vec<String>>,
    /// Changed pixels in the band.
    pub changed_pixels: usize,
    /// Primary rays shot in the band.
    pub primary_rays: u64,
    /// The view geometry the merged image carries (JSON of `verified::ViewMetadata`, opaque
    /// here): EXIF and XMP in 8-bit outputs, header attributes in EXR, so that a merged file
    /// equals the whole render's byte for byte.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view_json: Option<String>,
}

/// Lower-case hex of `bytes` (content hashes in the job identity).
#[must_use]
pub fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The bytes of lower-case or upper-case hex; `None` if it is not hex.
#[must_use]
pub fn from_hex(text: &str) -> Option<Vec<u8>> {
    if !text.len().is_multiple_of(2) {
        return None;
    }
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(text.get(i..i + 2)?, 16).ok())
        .collect()
}

impl PartInfo {
    /// The band this part holds.
    ///
    /// # Errors
    /// [`super::BandError`] when `tile` is not `I/N`.
    pub fn band(&self) -> Result<Band, super::BandError> {
        Band::parse(&self.tile)
    }
}

/// What is wrong with a set of parts.
#[derive(Debug, thiserror::Error)]
pub enum PartError {
    /// The file could not be read as EXR.
    #[error("cannot read the part {path}: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// An EXR without the part attribute, or with one this version cannot read.
    #[error("{path} is not a photomontage part ({reason})")]
    NotAPart {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The part's pixels do not fit what it says of itself.
    #[error("{path}: {reason}")]
    Inconsistent {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A part of another job (site, view, settings, seed, ...).
    #[error("{path} belongs to another job: its {field} is `{found}` but {first} has `{expected}`")]
    Foreign {
        /// The odd part.
        path: PathBuf,
        /// The first part, whose identity the others must match.
        first: PathBuf,
        /// The field that differs.
        field: String,
        /// This part's value.
        found: String,
        /// The first part's value.
        expected: String,
    },
    /// The same band twice.
    #[error("tile {tile} is given twice: {first} and {second}")]
    Duplicate {
        /// The band.
        tile: String,
        /// One file.
        first: PathBuf,
        /// The other.
        second: PathBuf,
    },
    /// Bands missing.
    #[error("the merge is incomplete: missing tile{} {} of {count}", if missing.len() == 1 { "" } else { "s" }, missing.iter().map(u32::to_string).collect::<Vec<_>>().join(", "))]
    Missing {
        /// The missing band numbers.
        missing: Vec<u32>,
        /// The band count.
        count: u32,
    },
    /// No part given.
    #[error("no parts to merge")]
    NoParts,
    /// Writing failed.
    #[error(transparent)]
    Write(#[from] OutputError),
}

/// JSON with every non-ASCII character escaped (`\uXXXX`), as EXR text attributes are bytes.
fn ascii_json(info: &PartInfo) -> Result<String, serde_json::Error> {
    let text = serde_json::to_string(info)?;
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0_u16; 2];
            for u in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{u:04x}"));
            }
        }
    }
    Ok(out)
}

/// Writes one band as a part (atomically): `image` and `layers` cover `info.rows_px` of an
/// image of `info.full_size_px`.
///
/// # Errors
/// [`OutputError::Write`], also when the band's size does not match `info`.
pub fn write_part(
    path: &Path,
    image: &RenderedImage,
    layers: &OutputLayers,
    info: &PartInfo,
) -> Result<(), OutputError> {
    use exr::prelude::*;
    let fail = |message: String| OutputError::Write {
        path: path.to_path_buf(),
        message,
    };
    let [w, h] = image.size_px;
    let [y0, y1] = info.rows_px;
    if w != info.full_size_px[0] || y1.checked_sub(y0) != Some(h) || y1 > info.full_size_px[1] {
        return Err(fail(format!(
            "band image {w}×{h} px does not fit rows {y0}..{y1} of {}×{} px",
            info.full_size_px[0], info.full_size_px[1]
        )));
    }
    let json = ascii_json(info).map_err(|e| fail(e.to_string()))?;
    let text = Text::new_or_none(&json).ok_or_else(|| fail("unencodable part info".into()))?;
    let mut attributes = LayerAttributes {
        layer_position: Vec2(0, i32::try_from(y0).map_err(|e| fail(e.to_string()))?),
        ..LayerAttributes::default()
    };
    attributes
        .other
        .insert(Text::from(PART_ATTRIBUTE), AttributeValue::Text(text));
    let layer = Layer::new(
        (w as usize, h as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(super::output::exr_channels(
            image, layers,
        ))),
    );
    let display = IntegerBounds::new(
        Vec2(0, 0),
        Vec2(info.full_size_px[0] as usize, info.full_size_px[1] as usize),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::new(ImageAttributes::new(display), layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| fail(e.to_string()))?;
    write_file(path, &bytes.into_inner())
}

/// A part read back: what it says, its band's pixels and layers.
#[derive(Debug, Clone)]
pub struct Part {
    /// The file.
    pub path: PathBuf,
    /// What it says of itself.
    pub info: PartInfo,
    /// The band's pixels (`full width × rows`).
    pub image: RenderedImage,
    /// The band's layers.
    pub layers: OutputLayers,
}

/// Reads the header of a part only (cheap: no pixels), for "is this job done?" checks.
///
/// # Errors
/// [`PartError::Read`], [`PartError::NotAPart`].
pub fn read_part_info(path: &Path) -> Result<PartInfo, PartError> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| PartError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let header = meta.headers.first().ok_or_else(|| PartError::NotAPart {
        path: path.to_path_buf(),
        reason: "no header".into(),
    })?;
    info_of(path, &header.own_attributes.other)
}

fn info_of(
    path: &Path,
    attributes: &HashMap<exr::prelude::Text, exr::prelude::AttributeValue>,
) -> Result<PartInfo, PartError> {
    let not_a_part = |reason: String| PartError::NotAPart {
        path: path.to_path_buf(),
        reason,
    };
    let value = attributes
        .get(&exr::prelude::Text::from(PART_ATTRIBUTE))
        .ok_or_else(|| not_a_part(format!("no `{PART_ATTRIBUTE}` attribute")))?;
    let exr::prelude::AttributeValue::Text(text) = value else {
        return Err(not_a_part(format!("`{PART_ATTRIBUTE}` is not text")));
    };
    let json = String::from_utf8_lossy(text.bytes());
    let info: PartInfo =
        serde_json::from_str(&json).map_err(|e| not_a_part(format!("part info: {e}")))?;
    if info.format != PART_FORMAT {
        return Err(not_a_part(format!(
            "format `{}`, this version reads `{PART_FORMAT}`",
            info.format
        )));
    }
    Ok(info)
}

/// Reads a part with its pixels, checking them against what it says.
///
/// # Errors
/// [`PartError::Read`], [`PartError::NotAPart`], [`PartError::Inconsistent`].
pub fn read_part(path: &Path) -> Result<Part, PartError> {
    use exr::prelude::*;
    let inconsistent = |reason: String| PartError::Inconsistent {
        path: path.to_path_buf(),
        reason,
    };
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| PartError::Read {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let layer = &image.layer_data;
    let info = info_of(path, &layer.attributes.other)?;
    info.band()
        .map_err(|e| inconsistent(format!("tile {}: {e}", info.tile)))?;
    let [w, h] = info.full_size_px;
    let [y0, y1] = info.rows_px;
    let size = layer.size;
    let position = layer.attributes.layer_position;
    if size.0 != w as usize
        || y1 < y0
        || size.1 != (y1 - y0) as usize
        || position.0 != 0
        || i64::from(position.1) != i64::from(y0)
        || y1 > h
    {
        return Err(inconsistent(format!(
            "its pixels ({}×{} px at {},{}) are not rows {y0}..{y1} of {w}×{h} px",
            size.0, size.1, position.0, position.1
        )));
    }
    let channel = |name: &str| -> Option<Vec<f32>> {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.eq(name))
            .map(|c| c.sample_data.values_as_f32().collect())
    };
    let need = |name: &str| channel(name).ok_or_else(|| inconsistent(format!("no {name} channel")));
    let (r, g, b, a) = (need("R")?, need("G")?, need("B")?, need("A")?);
    let rgba = (0..r.len()).map(|i| [r[i], g[i], b[i], a[i]]).collect();
    let shadow = match (
        channel("shadow_change.R"),
        channel("shadow_change.G"),
        channel("shadow_change.B"),
    ) {
        (Some(r), Some(g), Some(b)) => Some((0..r.len()).map(|i| [r[i], g[i], b[i]]).collect()),
        _ => None,
    };
    Ok(Part {
        path: path.to_path_buf(),
        image: RenderedImage {
            size_px: [w, y1 - y0],
            rgba,
            changed_pixels: info.changed_pixels,
            primary_rays: info.primary_rays,
        },
        layers: OutputLayers {
            depth_m: channel("Z"),
            object_id: channel("object_id"),
            shadow_change_rgb: shadow,
        },
        info,
    })
}

/// The merged view.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The whole image.
    pub image: RenderedImage,
    /// Its layers.
    pub layers: OutputLayers,
    /// The first part's info (identity, exposure, object names).
    pub info: PartInfo,
}

fn present_layers(layers: &OutputLayers) -> LayerSet {
    LayerSet {
        depth: layers.depth_m.is_some(),
        object_id: layers.object_id.is_some(),
        shadow_change: layers.shadow_change_rgb.is_some(),
    }
}

/// Checks that `paths` are the complete, consistent set of one view's bands and assembles the
/// whole image.
///
/// # Errors
/// [`PartError::NoParts`], any error of [`read_part`], [`PartError::Foreign`] (the first part
/// sets the identity), [`PartError::Duplicate`], [`PartError::Missing`] (all missing bands named).
pub fn merge_parts(paths: &[PathBuf]) -> Result<Merged, PartError> {
    let first_path = paths.first().ok_or(PartError::NoParts)?;
    // Headers first: a foreign or duplicate part is named before any pixels are decoded.
    let infos = paths
        .iter()
        .map(|p| read_part_info(p))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &infos[0];
    let count = first
        .band()
        .map_err(|e| PartError::Inconsistent {
            path: first_path.clone(),
            reason: format!("tile {}: {e}", first.tile),
        })?
        .count;
    let mut by_index: BTreeMap<u32, &PathBuf> = BTreeMap::new();
    for (path, info) in paths.iter().zip(&infos) {
        let foreign = |field: &str, found: String, expected: String| PartError::Foreign {
            path: path.clone(),
            first: first_path.clone(),
            field: field.to_owned(),
            found,
            expected,
        };
        for key in first.identity.keys().chain(info.identity.keys()) {
            let (a, b) = (info.identity.get(key), first.identity.get(key));
            if a != b {
                let show = |v: Option<&String>| v.cloned().unwrap_or_else(|| "(none)".into());
                return Err(foreign(key, show(a), show(b)));
            }
        }
        if info.full_size_px != first.full_size_px {
            return Err(foreign(
                "image size",
                format!("{:?}", info.full_size_px),
                format!("{:?}", first.full_size_px),
            ));
        }
        let band = info.band().map_err(|e| PartError::Inconsistent {
            path: path.clone(),
            reason: format!("tile {}: {e}", info.tile),
        })?;
        if band.count != count {
            return Err(foreign(
                "tile count",
                band.count.to_string(),
                count.to_string(),
            ));
        }
        if let Some(other) = by_index.insert(band.index, path) {
            return Err(PartError::Duplicate {
                tile: band.to_string(),
                first: other.clone(),
                second: path.clone(),
            });
        }
    }
    let missing: Vec<u32> = (1..=count).filter(|i| !by_index.contains_key(i)).collect();
    if !missing.is_empty() {
        return Err(PartError::Missing { missing, count });
    }
    let [w, h] = first.full_size_px;
    let len = (w as usize) * (h as usize);
    let mut rgba = vec![[0.0_f32; 4]; len];
    let mut layers: Option<OutputLayers> = None;
    let (mut changed_pixels, mut primary_rays) = (0, 0);
    let mut next_row = 0;
    for path in by_index.values() {
        let part = read_part(path)?;
        let [y0, y1] = part.info.rows_px;
        if y0 != next_row {
            return Err(PartError::Inconsistent {
                path: part.path,
                reason: format!("starts at row {y0}, but the tiles before end at row {next_row}"),
            });
        }
        next_row = y1;
        let set = present_layers(&part.layers);
        let merged = layers.get_or_insert_with(|| OutputLayers::new(set, len));
        if present_layers(merged) != set {
            return Err(PartError::Inconsistent {
                path: part.path,
                reason: format!(
                    "has layers `{}` but the first tile has `{}`",
                    set.names(),
                    present_layers(merged).names()
                ),
            });
        }
        let offset = (y0 as usize) * (w as usize);
        rgba[offset..offset + part.image.rgba.len()].copy_from_slice(&part.image.rgba);
        for k in 0..part.image.rgba.len() {
            merged.copy_pixel(&part.layers, k, offset + k);
        }
        changed_pixels += part.image.changed_pixels;
        primary_rays += part.image.primary_rays;
    }
    if next_row != h {
        return Err(PartError::Inconsistent {
            path: first_path.clone(),
            reason: format!("the tiles cover rows 0..{next_row} of {h}"),
        });
    }
    Ok(Merged {
        image: RenderedImage {
            size_px: [w, h],
            rgba,
            changed_pixels,
            primary_rays,
        },
        layers: layers.unwrap_or_default(),
        info: first.clone(),
    })
}

#[cfg(test)]
#[path = "partial_tests.rs"]
mod tests;
