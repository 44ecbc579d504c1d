//! The comparison sheet of design variants (issue 17 item 4): every variant of one view, rendered
//! under the same light, labelled with its name.
//!
//! - **PDF**: one A3 landscape page per variant, in the order given. The image is as large as
//!   the page allows with a 15 mm margin and a title band above it (`Variant NAME`, then a line
//!   with the site, the view and what was held the same), so pages can be flipped through or
//!   printed and laid side by side at one scale. Same font, encoding and JPEG embedding as the
//!   verified-view sheet ([`super::sheet`]); written atomically by [`super::sheet::write_sheet`].
//! - **PNG**: all variants on one image as a labelled grid (the study's
//!   [`crate::study::contact_sheet`], thumbnails 320 px wide), at most [`PNG_COLUMNS`] per row.
//!
//! # Known limitations
//! The PDF embeds the images as JPEG (quality [`super::sheet::JPEG_QUALITY`]); the exact pixels
//! are in the per-variant PNGs that `photomontage compare --images` writes. Labels outside WinAnsi
//! print as `?` in the PDF and the PNG's bitmap font has ASCII only.

use std::io::Cursor;
use std::path::Path;

use image::RgbImage;
use pdf_writer::{Content, Filter, Finish, Name, Pdf, Rect, Ref};

use super::sheet::{JPEG_QUALITY, SheetError, mm, text, write_font};
use crate::render::RenderSettings;
use crate::study::contact_sheet::{SheetCell, contact_sheet};

/// A3 landscape, millimetres.
pub const PAGE_MM: [f64; 2] = [420.0, 297.0];
/// Margin around the page content, millimetres.
pub const MARGIN_MM: f64 = 15.0;
/// Height of the title band above the image, millimetres.
pub const TITLE_BAND_MM: f64 = 18.0;
/// Most variants per row of the PNG grid.
pub const PNG_COLUMNS: usize = 3;
const TITLE_PT: f32 = 16.0;
const SUBTITLE_PT: f32 = 9.0;

/// One variant's image with its name.
pub struct ComparisonCell<'a> {
    /// The variant's name (the page title and the grid label).
    pub name: String,
    /// The variant's render as 8-bit sRGB.
    pub image: &'a RgbImage,
}

/// The PNG grid: one labelled thumbnail per variant, [`PNG_COLUMNS`] per row at most.
#[must_use]
pub fn comparison_png(cells: &[ComparisonCell<'_>]) -> RgbImage {
    let sheet_cells: Vec<SheetCell<'_>> = cells
        .iter()
        .map(|c| SheetCell {
            image: Some(c.image),
            label: c.name.clone(),
        })
        .collect();
    contact_sheet(&sheet_cells, cells.len().clamp(1, PNG_COLUMNS))
}

/// The line under each page's title: the site, the view and what every variant shares
/// (the seed and the rays per pixel of `settings`; the lighting is the site's).
#[must_use]
pub fn comparison_subtitle(site_name: &str, view: &str, settings: &RenderSettings) -> String {
    format!(
        "{} | view {view} | same lighting, seed {}, {}-{} rays/pixel",
        if site_name.is_empty() {
            "site"
        } else {
            site_name
        },
        settings.seed,
        settings.min_rays_per_pixel,
        settings.max_rays_per_pixel,
    )
}

/// Writes the PNG grid ([`comparison_png`]) to `path` atomically.
///
/// # Errors
/// [`SheetError::Encode`], [`SheetError::Write`].
pub fn write_comparison_png(path: &Path, cells: &[ComparisonCell<'_>]) -> Result<(), SheetError> {
    let sheet = comparison_png(cells);
    let mut bytes = Vec::new();
    sheet
        .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| SheetError::Encode {
            photo: "comparison sheet".into(),
            message: e.to_string(),
        })?;
    super::sheet::write_sheet(path, &bytes)
}

/// The image box on a page: `[x, y, width, height]` in millimetres (PDF origin bottom left) for
/// an image of `w_px` × `h_px`, as large as fits below the title band.
#[must_use]
pub fn image_box_mm(w_px: u32, h_px: u32) -> [f64; 4] {
    let [page_w, page_h] = PAGE_MM;
    let box_w = page_w - 2.0 * MARGIN_MM;
    let box_h = page_h - 2.0 * MARGIN_MM - TITLE_BAND_MM;
    let aspect = f64::from(h_px) / f64::from(w_px.max(1));
    let (w, h) = if box_w * aspect <= box_h {
        (box_w, box_w * aspect)
    } else {
        (box_h / aspect, box_h)
    };
    [MARGIN_MM + (box_w - w) / 2.0, MARGIN_MM + (box_h - h), w, h]
}

/// The PDF: one page per variant, titled `Variant NAME` with `subtitle` under it.
///
/// # Errors
/// [`SheetError::EmptyImage`] for no variants or an empty image, [`SheetError::Encode`].
pub fn comparison_pdf(cells: &[ComparisonCell<'_>], subtitle: &str) -> Result<Vec<u8>, SheetError> {
    if cells.is_empty() {
        return Err(SheetError::EmptyImage {
            photo: "comparison sheet".into(),
            width: 0,
            height: 0,
        });
    }
    let mut jpegs = Vec::with_capacity(cells.len());
    for c in cells {
        let (w, h) = c.image.dimensions();
        if w == 0 || h == 0 {
            return Err(SheetError::EmptyImage {
                photo: format!("variant {}", c.name),
                width: w,
                height: h,
            });
        }
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(Cursor::new(&mut jpeg), JPEG_QUALITY)
            .encode_image(c.image)
            .map_err(|e| SheetError::Encode {
                photo: format!("variant {}", c.name),
                message: e.to_string(),
            })?;
        jpegs.push(jpeg);
    }
    // Objects: 1 catalog, 2 page tree, 3–5 font, then per page: page, content, image.
    let (catalog, tree, font, descriptor, font_file) = (
        Ref::new(1),
        Ref::new(2),
        Ref::new(3),
        Ref::new(4),
        Ref::new(5),
    );
    let per_page = |k: usize, j: i32| {
        let k = i32::try_from(k).unwrap_or(i32::MAX / 4);
        Ref::new(6 + 3 * k + j)
    };
    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    let n = i32::try_from(cells.len()).unwrap_or(i32::MAX);
    pdf.pages(tree)
        .kids((0..cells.len()).map(|k| per_page(k, 0)))
        .count(n);
    write_font(&mut pdf, font, descriptor, font_file);

    let [page_w, page_h] = PAGE_MM;
    let media = Rect::new(0.0, 0.0, mm(page_w), mm(page_h));
    for (k, (cell, jpeg)) in cells.iter().zip(&jpegs).enumerate() {
        let (page, content, image_id) = (per_page(k, 0), per_page(k, 1), per_page(k, 2));
        {
            let mut p = pdf.page(page);
            p.parent(tree).media_box(media).contents(content);
            let mut res = p.resources();
            res.fonts().pair(Name(b"F1"), font);
            res.x_objects().pair(Name(b"Im0"), image_id);
        }
        let (w_px, h_px) = cell.image.dimensions();
        {
            let mut img = pdf.image_xobject(image_id, jpeg);
            img.filter(Filter::DctDecode);
            #[allow(clippy::cast_possible_wrap)]
            img.width(w_px as i32).height(h_px as i32);
            img.color_space().device_rgb();
            img.bits_per_component(8);
            img.finish();
        }
        let [x, y, w, h] = image_box_mm(w_px, h_px);
        let mut c = Content::new();
        c.save_state()
            .transform([mm(w), 0.0, 0.0, mm(h), mm(x), mm(y)])
            .x_object(Name(b"Im0"))
            .restore_state();
        c.set_fill_rgb(0.0, 0.0, 0.0);
        let top = page_h - MARGIN_MM;
        text(
            &mut c,
            MARGIN_MM,
            top - 6.0,
            TITLE_PT,
            &format!("Variant {}", cell.name),
            60,
        );
        text(
            &mut c,
            MARGIN_MM,
            top - 13.0,
            SUBTITLE_PT,
            &format!("{subtitle} | page {} of {}", k + 1, cells.len()),
            150,
        );
        pdf.stream(content, &c.finish());
    }
    Ok(pdf.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_image_box_keeps_the_aspect_and_fits_below_the_title() {
        for (w, h) in [(96, 64), (64, 96), (4000, 1000)] {
            let [x, y, bw, bh] = image_box_mm(w, h);
            let aspect = f64::from(h) / f64::from(w);
            assert!((bh / bw - aspect).abs() < 1e-12);
            assert!(x >= MARGIN_MM - 1e-9 && y >= MARGIN_MM - 1e-9);
            assert!(x + bw <= PAGE_MM[0] - MARGIN_MM + 1e-9);
            assert!(y + bh <= PAGE_MM[1] - MARGIN_MM - TITLE_BAND_MM + 1e-9);
        }
    }

    #[test]
    fn one_page_per_variant_and_no_sheet_of_nothing() {
        let a = RgbImage::from_pixel(8, 6, image::Rgb([255, 0, 0]));
        let cells = [
            ComparisonCell {
                name: "a".into(),
                image: &a,
            },
            ComparisonCell {
                name: "b".into(),
                image: &a,
            },
        ];
        let pdf = comparison_pdf(&cells, "site").unwrap();
        let text = String::from_utf8_lossy(&pdf);
        let pages = text.matches("/Type /Page").count() - text.matches("/Type /Pages").count();
        assert_eq!(pages, 2);
        assert!(text.contains("(Variant a)") && text.contains("(Variant b)"));
        assert!(matches!(
            comparison_pdf(&[], "site"),
            Err(SheetError::EmptyImage { .. })
        ));
        let png = comparison_png(&cells);
        assert!(png.width() > 2 * crate::study::contact_sheet::THUMB_WIDTH_PX);
    }
}
