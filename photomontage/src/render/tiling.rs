//! The tile driver shared by the RGB and spectral renderers, and horizontal bands of a view for
//! rendering one view as several independent jobs (issue 18: render farms).
//!
//! The image is cut into square tiles of [`RenderSettings::tile_size_px`], numbered row-major.
//! Each tile draws its random numbers from its own ChaCha8 stream (seed = render seed, stream =
//! the tile's index in the **whole** image) and keeps its own irradiance cache, so a tile's pixels
//! depend on nothing but the scene, the settings and its index. A [`Band`] is a run of whole tile
//! rows; rendering it renders exactly those tiles, so the band's pixels are bit for bit those of
//! the whole-image render, whatever the band count or the thread count.
//!
//! Tiles start in a fixed shuffled order, so progress counted in tiles is a fair sample of the
//! image's cost and the CLI's and studio's time estimates hold (a scanline order finishes the
//! cheap sky first and then stalls on the building).
//!
//! # Known limitations
//! Bands are whole tile rows: a view can be cut into at most as many bands as it has tile rows
//! (e.g. 23 for 720 px and 32-px tiles). Bands of one view are balanced by rows, not by cost: a
//! band over the sky costs less than one over the planned building.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::output::{LayerSet, OutputLayers};
use super::{RenderError, RenderSettings, RenderedImage, TileProgress, rgb_of};

/// One horizontal band of a view: band `index` (1-based) of `count`, written `I/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Band {
    /// 1-based band number.
    pub index: u32,
    /// Number of bands the view is cut into.
    pub count: u32,
}

/// What is wrong with a band.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BandError {
    /// Not `I/N` with two positive integers.
    #[error("tile `{text}` is not I/N with whole numbers 1 ≤ I ≤ N (e.g. 2/4)")]
    Syntax {
        /// The text given.
        text: String,
    },
    /// I outside 1..=N.
    #[error("tile {index}/{count} is out of range: I must be between 1 and {count}")]
    OutOfRange {
        /// The band number given.
        index: u32,
        /// The band count given.
        count: u32,
    },
    /// More bands than tile rows.
    #[error(
        "{count} tiles are more than the view's {rows} rows of {tile_px}-px render tiles \
         ({height_px} px high); use at most {rows}"
    )]
    TooMany {
        /// The band count given.
        count: u32,
        /// Tile rows of the view.
        rows: u32,
        /// Tile edge, pixels.
        tile_px: u32,
        /// Image height, pixels.
        height_px: u32,
    },
}

impl Band {
    /// The whole image as one band.
    pub const WHOLE: Self = Self { index: 1, count: 1 };

    /// Band `index` of `count`, checked.
    ///
    /// # Errors
    /// [`BandError::OutOfRange`] unless 1 ≤ index ≤ count.
    pub fn new(index: u32, count: u32) -> Result<Self, BandError> {
        if index == 0 || count == 0 || index > count {
            return Err(BandError::OutOfRange { index, count });
        }
        Ok(Self { index, count })
    }

    /// Parses `I/N`.
    ///
    /// # Errors
    /// [`BandError::Syntax`], [`BandError::OutOfRange`].
    pub fn parse(text: &str) -> Result<Self, BandError> {
        let syntax = || BandError::Syntax {
            text: text.to_owned(),
        };
        let (i, n) = text.trim().split_once('/').ok_or_else(syntax)?;
        let i: u32 = i.trim().parse().map_err(|_| syntax())?;
        let n: u32 = n.trim().parse().map_err(|_| syntax())?;
        Self::new(i, n)
    }

    /// The tile rows of this band: rows `⌊(I−1)·R/N⌋ .. ⌊I·R/N⌋` of the `R` tile rows.
    ///
    /// # Errors
    /// [`BandError::TooMany`] when N exceeds the tile rows (a band would be empty).
    pub fn tile_rows(self, height_px: u32, tile_size_px: u32) -> Result<Range<u32>, BandError> {
        let rows = height_px.div_ceil(tile_size_px.max(1));
        if self.count > rows {
            return Err(BandError::TooMany {
                count: self.count,
                rows,
                tile_px: tile_size_px,
                height_px,
            });
        }
        let split = |k: u32| (u64::from(k) * u64::from(rows) / u64::from(self.count)) as u32;
        Ok(split(self.index - 1)..split(self.index))
    }

    /// The pixel rows of this band (`start..end`, end exclusive).
    ///
    /// # Errors
    /// As [`Band::tile_rows`].
    pub fn pixel_rows(self, height_px: u32, tile_size_px: u32) -> Result<Range<u32>, BandError> {
        let rows = self.tile_rows(height_px, tile_size_px)?;
        let ts = tile_size_px.max(1);
        Ok(rows.start * ts..(rows.end * ts).min(height_px))
    }
}

impl std::fmt::Display for Band {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One rendered tile, as both renderers produce it.
pub(crate) struct TileOut {
    pub(crate) rgba: Vec<[f32; 4]>,
    pub(crate) layers: OutputLayers,
    pub(crate) changed: usize,
    pub(crate) rays: u64,
}

/// Renders the tiles of `band` (whole image: [`Band::WHOLE`]) of a `size_px` image with
/// `render_tile(tile_index, origin_px, size_px)` in parallel and assembles them into an image of
/// the band (`size_px[0]` × the band's pixel rows). `on_tile` is called as each tile finishes;
/// raising `cancel` stops at the next tile.
pub(crate) fn drive_tiles(
    size_px: [u32; 2],
    settings: &RenderSettings,
    layers: LayerSet,
    band: Band,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
    render_tile: &(dyn Fn(usize, [u32; 2], [u32; 2]) -> TileOut + Sync),
) -> Result<(RenderedImage, OutputLayers), RenderError> {
    let [w, h] = size_px;
    let ts = settings.tile_size_px;
    let tiles_x = w.div_ceil(ts);
    let tiles_y = h.div_ceil(ts);
    let tile_rows = band.tile_rows(h, ts)?;
    let tile_count = (tiles_x * tiles_y) as usize;
    let first = (tile_rows.start * tiles_x) as usize;
    let last = (tile_rows.end * tiles_x) as usize;
    let y_start = tile_rows.start * ts;
    let y_end = (tile_rows.end * ts).min(h);
    let band_h = y_end - y_start;
    // Tiles are started in a fixed shuffled order (tiles over the planned building cost up to 10×
    // those over the untouched photo), so the tiles finished so far are a fair sample of the whole
    // and elapsed × remaining / done is an honest time estimate. Each tile's pixels depend only on
    // its index, so the order changes nothing in the image.
    let order = shuffled(first..last);
    let mut finished: Vec<(usize, Option<TileOut>)> = order
        .into_par_iter()
        .map(|index| {
            if cancel.load(Ordering::Relaxed) {
                return (index, None);
            }
            #[allow(clippy::cast_possible_truncation)]
            let i = index as u32;
            let origin_px = [(i % tiles_x) * ts, (i / tiles_x) * ts];
            let size_px = [ts.min(w - origin_px[0]), ts.min(h - origin_px[1])];
            let out = render_tile(index, origin_px, size_px);
            on_tile(TileProgress {
                tile_index: index,
                tile_count,
                origin_px,
                size_px,
                rgb_linear: rgb_of(&out.rgba),
            });
            (index, Some(out))
        })
        .collect();
    finished.sort_unstable_by_key(|(index, _)| *index);
    let tiles = finished.into_iter().map(|(_, tile)| tile);
    let len = (w * band_h) as usize;
    let mut rgba = vec![[0.0_f32; 4]; len];
    let mut out_layers = OutputLayers::new(layers, len);
    let (mut changed_pixels, mut primary_rays) = (0, 0);
    for (offset, tile) in tiles.enumerate() {
        let Some(tile) = tile else {
            return Err(RenderError::Cancelled);
        };
        #[allow(clippy::cast_possible_truncation)]
        let i = (first + offset) as u32;
        let (x0, y0) = ((i % tiles_x) * ts, (i / tiles_x) * ts - y_start);
        let tw = ts.min(w - x0);
        for (k, p) in tile.rgba.iter().enumerate() {
            #[allow(clippy::cast_possible_truncation)]
            let k = k as u32;
            let to = ((y0 + k / tw) * w + x0 + k % tw) as usize;
            rgba[to] = *p;
            out_layers.copy_pixel(&tile.layers, k as usize, to);
        }
        changed_pixels += tile.changed;
        primary_rays += tile.rays;
    }
    if cancel.load(Ordering::Relaxed) {
        return Err(RenderError::Cancelled);
    }
    Ok((
        RenderedImage {
            size_px: [w, band_h],
            rgba,
            changed_pixels,
            primary_rays,
        },
        out_layers,
    ))
}

/// The indices of `range` in a fixed pseudo-random order (Fisher–Yates driven by SplitMix64 with a
/// constant seed: the same order on every run and machine).
fn shuffled(range: Range<usize>) -> Vec<usize> {
    let mut order: Vec<usize> = range.collect();
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in (1..order.len()).rev() {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        #[allow(clippy::cast_possible_truncation)]
        let j = (z % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tile_order_is_a_fixed_permutation_that_mixes_the_image() {
        let order = shuffled(10..310);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (10..310).collect::<Vec<_>>(), "a permutation");
        assert_eq!(order, shuffled(10..310), "the same order every time");
        // The first tenth started covers the image: its mean index is near the middle (a
        // scanline order would give 25 % of the range; a fair sample of 30 has σ ≈ 16 % / √30).
        let mean = order[..30].iter().sum::<usize>() as f64 / 30.0;
        assert!((mean - 159.5).abs() < 0.1 * 300.0, "mean index {mean}");
        assert!(shuffled(0..0).is_empty() && shuffled(3..4) == [3]);
    }

    #[test]
    fn bands_parse_and_refuse_bad_text_naming_it() {
        assert_eq!(Band::parse("2/4").unwrap(), Band { index: 2, count: 4 });
        assert_eq!(Band::parse(" 1 / 1 ").unwrap(), Band::WHOLE);
        for bad in ["", "3", "a/4", "2/b", "2/4/5", "-1/4"] {
            let e = Band::parse(bad).unwrap_err();
            assert!(matches!(e, BandError::Syntax { .. }), "{bad}: {e}");
        }
        for (bad, i, n) in [("0/4", 0, 4), ("5/4", 5, 4), ("1/0", 1, 0)] {
            let e = Band::parse(bad).unwrap_err();
            assert_eq!(e, BandError::OutOfRange { index: i, count: n }, "{bad}");
            assert!(e.to_string().contains(&format!("{i}/{n}")), "{e}");
        }
    }

    #[test]
    fn bands_partition_the_rows_exactly_once() {
        for (h, ts) in [(720, 32), (100, 32), (33, 32), (7, 1), (1000, 64)] {
            let rows = u32::div_ceil(h, ts);
            for n in 1..=rows.min(12) {
                let mut next = 0;
                for i in 1..=n {
                    let px = Band::new(i, n).unwrap().pixel_rows(h, ts).unwrap();
                    assert_eq!(px.start, next, "h {h} ts {ts} band {i}/{n}");
                    assert!(px.end > px.start, "empty band {i}/{n}");
                    assert_eq!(px.start % ts, 0);
                    next = px.end;
                }
                assert_eq!(next, h, "bands of {n} cover {h} px");
            }
        }
    }

    #[test]
    fn more_bands_than_tile_rows_is_an_error_naming_the_limit() {
        let e = Band::new(1, 24).unwrap().tile_rows(720, 32).unwrap_err();
        assert!(e.to_string().contains("at most 23"), "{e}");
    }
}
