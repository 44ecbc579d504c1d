//! The contact sheet of a sun study: every daylight frame as a thumbnail in a grid (one row per
//! date, one column per time), each labelled with its date, local time and the SPA sun azimuth
//! and elevation, in the 5 × 7 bitmap font of the convergence plots.
//!
//! Known limitations: labels are ASCII (the font has no `°`); thumbnails are resized with a
//! triangle filter, which is enough to read a shadow's position, not to judge its edge.

use image::{Rgb, RgbImage, imageops};

use crate::radiosity::convergence_plot::text;

/// Width of one thumbnail, pixels.
pub const THUMB_WIDTH_PX: u32 = 320;
/// Gap around thumbnails, pixels.
const GAP_PX: u32 = 8;
/// Height of the label strip under a thumbnail (7-px font plus padding), pixels.
const LABEL_HEIGHT_PX: u32 = 14;
const BACKGROUND: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [0, 0, 0];
const EMPTY_CELL: [u8; 3] = [200, 200, 200];

/// One cell of the sheet: its thumbnail source (`None` for a skipped night frame) and label.
pub struct SheetCell<'a> {
    pub image: Option<&'a RgbImage>,
    pub label: String,
}

/// Lays `cells` out `columns` per row (row-major), thumbnails [`THUMB_WIDTH_PX`] wide with the
/// aspect of the first image; a cell without an image is grey with its label.
#[must_use]
pub fn contact_sheet(cells: &[SheetCell<'_>], columns: usize) -> RgbImage {
    let columns = columns.max(1);
    let rows = cells.len().div_ceil(columns);
    let (w0, h0) = cells
        .iter()
        .find_map(|c| c.image.map(RgbImage::dimensions))
        .unwrap_or((4, 3));
    let thumb_h = (u64::from(THUMB_WIDTH_PX) * u64::from(h0) / u64::from(w0.max(1))).max(1);
    let thumb_h = u32::try_from(thumb_h).unwrap_or(THUMB_WIDTH_PX);
    let cell_w = THUMB_WIDTH_PX + GAP_PX;
    let cell_h = thumb_h + LABEL_HEIGHT_PX + GAP_PX;
    let to_u32 = |n: usize| u32::try_from(n).unwrap_or(u32::MAX / (cell_w + cell_h));
    let mut sheet = RgbImage::from_pixel(
        GAP_PX + to_u32(columns) * cell_w,
        GAP_PX + to_u32(rows) * cell_h,
        Rgb(BACKGROUND),
    );
    for (k, cell) in cells.iter().enumerate() {
        let x = GAP_PX + to_u32(k % columns) * cell_w;
        let y = GAP_PX + to_u32(k / columns) * cell_h;
        let thumb = match cell.image {
            Some(img) => imageops::resize(img, THUMB_WIDTH_PX, thumb_h, imageops::Triangle),
            None => RgbImage::from_pixel(THUMB_WIDTH_PX, thumb_h, Rgb(EMPTY_CELL)),
        };
        imageops::replace(&mut sheet, &thumb, i64::from(x), i64::from(y));
        text(
            &mut sheet,
            i64::from(x),
            i64::from(y + thumb_h + 4),
            &cell.label,
            INK,
        );
    }
    sheet
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_land_in_their_grid_places() {
        let red = RgbImage::from_pixel(64, 48, Rgb([255, 0, 0]));
        let blue = RgbImage::from_pixel(64, 48, Rgb([0, 0, 255]));
        let cells = [
            SheetCell {
                image: Some(&red),
                label: "a 09:00".into(),
            },
            SheetCell {
                image: None,
                label: "night".into(),
            },
            SheetCell {
                image: Some(&blue),
                label: "c".into(),
            },
        ];
        let sheet = contact_sheet(&cells, 2);
        let thumb_h = THUMB_WIDTH_PX * 48 / 64;
        let cell_h = thumb_h + LABEL_HEIGHT_PX + GAP_PX;
        assert_eq!(
            sheet.dimensions(),
            (GAP_PX + 2 * (THUMB_WIDTH_PX + GAP_PX), GAP_PX + 2 * cell_h)
        );
        let centre = |col: u32, row: u32| {
            *sheet.get_pixel(
                GAP_PX + col * (THUMB_WIDTH_PX + GAP_PX) + THUMB_WIDTH_PX / 2,
                GAP_PX + row * cell_h + thumb_h / 2,
            )
        };
        assert_eq!(centre(0, 0), Rgb([255, 0, 0]));
        assert_eq!(centre(1, 0), Rgb(EMPTY_CELL));
        assert_eq!(centre(0, 1), Rgb([0, 0, 255]));
        // The label strip under the first thumbnail has ink.
        let label_y = GAP_PX + thumb_h + 4;
        let inked = (0..7)
            .any(|dy| (GAP_PX..GAP_PX + 60).any(|x| *sheet.get_pixel(x, label_y + dy) == Rgb(INK)));
        assert!(inked);
    }
}
