//! The verified-view sheet as PDF (Landscape Institute TGN 06/19, Type 4 visualisations and its
//! Appendix 1 templates; LVMF SPG 2012 Appendix C): page 1 carries the view printed at the size
//! that gives the correct perspective at the stated viewing distance (image width = viewing
//! distance × 2·tan(HFoV/2), [`super::paper`]), the viewing distance, a 100 mm ruler to check the
//! print scale, the view geometry table, a location map inset (control points, camera, view
//! wedge, proposal outline in plan, grid north up), the AVR level and the TGN Type; page 2 the
//! methodology and the control-point residual table ([`super::sheet_content`]).
//!
//! Written with `pdf-writer` (typst). The text font, DejaVu Sans Mono (Bitstream Vera licence,
//! `photomontage/assets/fonts/`), is embedded whole as a TrueType simple font with WinAnsi
//! encoding; all its glyphs are 1233/2048 em wide. The image is embedded as a baseline JPEG
//! (DCTDecode, quality [`JPEG_QUALITY`]). Content streams are left uncompressed so the image
//! placement can be read back (`w 0 0 h x y cm /Im0 Do`). [`write_sheet`] writes a temporary file
//! beside the target and renames it, so no partial PDF is ever left at the target path.
//!
//! # Known limitations
//! One font, one size per block, no text wrapping (long lines are cut at the page margin); the
//! map inset shows plan positions only (no base map); text outside WinAnsi prints as `?`.

pub mod html;

use std::io::Cursor;
use std::path::Path;

use image::RgbImage;
use pdf_writer::types::FontFlags;
use pdf_writer::{Content, Filter, Finish, Name, Pdf, Rect, Ref, Str};

use super::avr::AvrLevel;
use super::geometry::{ViewGeometry, ViewGeometryError, ViewGeometryOptions, view_geometry};
use super::sheet_content::{
    MapInset, geometry_rows, map_inset, methodology, residual_lines, viewing_sentence,
};
use crate::site::SiteDocument;
use crate::site::render::SiteRenderError;

/// The embedded font (DejaVu Sans Mono 2.37).
const FONT_TTF: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSansMono.ttf");
/// Advance width of every glyph, 1/1000 em (1233/2048).
const GLYPH_WIDTH: f32 = 602.0;
/// JPEG quality of the embedded image (visually lossless for photographs).
pub const JPEG_QUALITY: u8 = 92;
/// Points per millimetre.
const PT_PER_MM: f32 = 72.0 / 25.4;
/// Length of the print-scale ruler, millimetres.
pub const RULER_MM: f64 = 100.0;

/// What can go wrong making a sheet.
#[derive(Debug, thiserror::Error)]
pub enum SheetError {
    #[error("photo {photo}: the sheet image is {width} × {height} px; it must not be empty")]
    EmptyImage {
        photo: String,
        width: u32,
        height: u32,
    },
    #[error("photo {photo}: cannot encode the sheet image: {message}")]
    Encode { photo: String, message: String },
    #[error("view {photo}: the sheet image is {image_px:?} px but the view is {photo_px:?} px")]
    SizeMismatch {
        photo: String,
        image_px: [u32; 2],
        photo_px: [u32; 2],
    },
    #[error(transparent)]
    Geometry(#[from] ViewGeometryError),
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    #[error("cannot write the sheet {path}: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
}

/// Everything page 1 and page 2 show.
#[derive(Debug, Clone)]
pub struct SheetInput<'a> {
    pub report: &'a ViewGeometry,
    /// The view as 8-bit sRGB.
    pub image: &'a RgbImage,
    pub avr: AvrLevel,
    pub map: MapInset,
    /// Methodology sections (heading, lines).
    pub methodology: Vec<(String, Vec<String>)>,
}

/// WinAnsi bytes of a text: Latin-1 characters as themselves, a few names spelt out, the rest `?`.
#[must_use]
pub fn winansi(text: &str) -> Vec<u8> {
    text.chars()
        .flat_map(|c| match c {
            'σ' => b"sigma".to_vec(),
            '°' => vec![0xB0],
            '×' => vec![0xD7],
            c if (' '..='~').contains(&c) => vec![c as u8],
            c if ('\u{a0}'..='\u{ff}').contains(&c) => {
                vec![u8::try_from(u32::from(c)).unwrap_or(b'?')]
            }
            _ => vec![b'?'],
        })
        .collect()
}

pub(crate) fn mm(v: f64) -> f32 {
    #[allow(clippy::cast_possible_truncation)]
    let v = v as f32;
    v * PT_PER_MM
}

/// Writes one line of text at (x, y) mm (baseline), cut to `max_chars`.
pub(crate) fn text(
    content: &mut Content,
    x_mm: f64,
    y_mm: f64,
    size_pt: f32,
    line: &str,
    max_chars: usize,
) {
    let mut bytes = winansi(line);
    bytes.truncate(max_chars);
    content
        .begin_text()
        .set_font(Name(b"F1"), size_pt)
        .next_line(mm(x_mm), mm(y_mm))
        .show(Str(&bytes))
        .end_text();
}

/// `line` broken at spaces into lines of at most `width` characters (a longer word is cut).
#[must_use]
pub fn wrap(line: &str, width: usize) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in line.split(' ') {
        let len = current.chars().count();
        if len > 0 && len + 1 + word.chars().count() > width {
            out.push(std::mem::take(&mut current));
        }
        if !current.is_empty() {
            current.push(' ');
        }
        current.push_str(word);
    }
    out.push(current);
    out
}

/// Characters of `size_pt` that fit in `width_mm`.
fn chars_in(width_mm: f64, size_pt: f32) -> usize {
    let char_mm = f64::from(size_pt * GLYPH_WIDTH / 1000.0) / f64::from(PT_PER_MM);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = (width_mm / char_mm).floor().max(0.0) as usize;
    n
}

fn draw_ruler(content: &mut Content, x_mm: f64, y_mm: f64, scale: f64, size_pt: f32) {
    content.set_line_width(0.5).set_stroke_rgb(0.0, 0.0, 0.0);
    content
        .move_to(mm(x_mm), mm(y_mm))
        .line_to(mm(x_mm + RULER_MM), mm(y_mm));
    for i in 0..=10 {
        let x = x_mm + f64::from(i) * 10.0;
        let tick = if i % 5 == 0 { 4.0 } else { 2.0 } * scale;
        content
            .move_to(mm(x), mm(y_mm))
            .line_to(mm(x), mm(y_mm + tick));
    }
    content.stroke();
    text(
        content,
        x_mm,
        y_mm - 3.5 * scale,
        size_pt,
        "0        50 mm       100 mm: check the print scale",
        200,
    );
}

fn draw_map(
    content: &mut Content,
    map: &MapInset,
    x_mm: f64,
    y_mm: f64,
    size_mm: f64,
    size_pt: f32,
) {
    content.set_line_width(0.5).set_stroke_rgb(0.0, 0.0, 0.0);
    content
        .rect(mm(x_mm), mm(y_mm), mm(size_mm), mm(size_mm))
        .stroke();
    let mut pts: Vec<[f64; 2]> = map.control_points_en.clone();
    pts.push(map.camera_en);
    pts.extend(&map.proposal_hull_en);
    // Fit: the points near the camera (within 3× the camera–proposal distance, so a far-off
    // ground corner does not shrink the map), else all.
    let reach = map
        .proposal_hull_en
        .iter()
        .map(|p| (p[0] - map.camera_en[0]).hypot(p[1] - map.camera_en[1]))
        .fold(0.0, f64::max)
        .max(10.0)
        * 3.0;
    let near: Vec<[f64; 2]> = pts
        .iter()
        .copied()
        .filter(|p| (p[0] - map.camera_en[0]).hypot(p[1] - map.camera_en[1]) <= reach)
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &near {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0);
    let inner = size_mm * 0.9;
    let s = inner / span;
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let to_page = |p: [f64; 2]| {
        [
            x_mm + size_mm / 2.0 + (p[0] - centre[0]) * s,
            y_mm + size_mm / 2.0 + (p[1] - centre[1]) * s,
        ]
    };
    let inside = |q: [f64; 2]| {
        q[0] >= x_mm && q[0] <= x_mm + size_mm && q[1] >= y_mm && q[1] <= y_mm + size_mm
    };
    // Control points: small crosses.
    content.set_line_width(0.3).set_stroke_rgb(0.4, 0.4, 0.4);
    for p in &map.control_points_en {
        let q = to_page(*p);
        if inside(q) {
            content
                .move_to(mm(q[0] - 0.6), mm(q[1]))
                .line_to(mm(q[0] + 0.6), mm(q[1]));
            content
                .move_to(mm(q[0]), mm(q[1] - 0.6))
                .line_to(mm(q[0]), mm(q[1] + 0.6));
        }
    }
    content.stroke();
    // Proposal outline.
    if let Some(first) = map.proposal_hull_en.first() {
        content.set_line_width(0.6).set_stroke_rgb(0.9, 0.1, 0.05);
        let q = to_page(*first);
        content.move_to(mm(q[0]), mm(q[1]));
        for p in &map.proposal_hull_en[1..] {
            let q = to_page(*p);
            content.line_to(mm(q[0]), mm(q[1]));
        }
        content.close_path().stroke();
    }
    // Camera and view wedge.
    let c = to_page(map.camera_en);
    let wedge = size_mm * 0.35;
    content.set_line_width(0.4).set_stroke_rgb(0.0, 0.2, 0.8);
    for side in [-0.5, 0.5] {
        let b = (map.bearing_grid_deg + side * map.hfov_deg).to_radians();
        content
            .move_to(mm(c[0]), mm(c[1]))
            .line_to(mm(c[0] + wedge * b.sin()), mm(c[1] + wedge * b.cos()));
    }
    content.stroke();
    content.set_fill_rgb(0.0, 0.2, 0.8);
    content
        .rect(mm(c[0] - 0.8), mm(c[1] - 0.8), mm(1.6), mm(1.6))
        .fill_nonzero();
    content.set_fill_rgb(0.0, 0.0, 0.0);
    text(
        content,
        x_mm + 1.0,
        y_mm + size_mm - 3.0,
        size_pt,
        "grid N up",
        40,
    );
    text(
        content,
        x_mm + 1.0,
        y_mm + 1.5,
        size_pt,
        &format!("map {:.0} m across", size_mm / s),
        40,
    );
}

/// The sheet as PDF bytes: page 1 the view, page 2 the methodology and residuals.
///
/// # Errors
/// [`SheetError::EmptyImage`], [`SheetError::Encode`].
pub fn sheet_pdf(input: &SheetInput<'_>) -> Result<Vec<u8>, SheetError> {
    let r = input.report;
    let (w_px, h_px) = input.image.dimensions();
    if w_px == 0 || h_px == 0 {
        return Err(SheetError::EmptyImage {
            photo: r.photo_id.clone(),
            width: w_px,
            height: h_px,
        });
    }
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(Cursor::new(&mut jpeg), JPEG_QUALITY)
        .encode_image(input.image)
        .map_err(|e| SheetError::Encode {
            photo: r.photo_id.clone(),
            message: e.to_string(),
        })?;
    let layout = r.paper.layout();
    let [page_w, page_h] = r.paper.size_mm();
    let scale = page_h / 297.0;
    let margin = layout.margin_mm;
    // The image is printed at the report's width (the viewing distance refers to it).
    let img_w = r.printed_image_width_mm;
    let img_h = img_w * f64::from(h_px) / f64::from(w_px);
    let [box_w, _] = layout.image_box_mm();
    let img_x = margin + (box_w - img_w) / 2.0;
    let img_y = page_h - margin - img_h;

    let (catalog, tree, page1, page2, content1, content2) = (
        Ref::new(1),
        Ref::new(2),
        Ref::new(3),
        Ref::new(4),
        Ref::new(5),
        Ref::new(6),
    );
    let (font, descriptor, font_file, image_id) =
        (Ref::new(7), Ref::new(8), Ref::new(9), Ref::new(10));
    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree).kids([page1, page2]).count(2);
    #[allow(clippy::cast_possible_truncation)]
    let media = Rect::new(0.0, 0.0, mm(page_w), mm(page_h));
    for (page, content, with_image) in [(page1, content1, true), (page2, content2, false)] {
        let mut p = pdf.page(page);
        p.parent(tree).media_box(media).contents(content);
        let mut res = p.resources();
        res.fonts().pair(Name(b"F1"), font);
        if with_image {
            res.x_objects().pair(Name(b"Im0"), image_id);
        }
    }
    write_font(&mut pdf, font, descriptor, font_file);
    {
        let mut img = pdf.image_xobject(image_id, &jpeg);
        img.filter(Filter::DctDecode);
        #[allow(clippy::cast_possible_wrap)]
        img.width(w_px as i32).height(h_px as i32);
        img.color_space().device_rgb();
        img.bits_per_component(8);
        img.finish();
    }

    // Page 1.
    let small = (6.5 * scale) as f32;
    let title = (9.0 * scale) as f32;
    let line_mm = f64::from(small) / f64::from(PT_PER_MM) * 1.25;
    let mut c = Content::new();
    c.save_state()
        .transform([mm(img_w), 0.0, 0.0, mm(img_h), mm(img_x), mm(img_y)])
        .x_object(Name(b"Im0"))
        .restore_state();
    c.set_fill_rgb(0.0, 0.0, 0.0);
    let band_top = img_y - 4.0 * scale;
    let usable = page_w - 2.0 * margin;
    text(
        &mut c,
        margin,
        band_top,
        title,
        &format!(
            "View {} | {}: {} | TGN 06/19 Type 4 (photomontage/photowire, survey/scale verifiable)",
            r.photo_id,
            input.avr.name(),
            input.avr.description()
        ),
        chars_in(usable, title),
    );
    text(
        &mut c,
        margin,
        band_top - 4.5 * scale,
        title,
        &viewing_sentence(r),
        chars_in(usable, title),
    );
    // Geometry table: three columns.
    let rows = geometry_rows(r);
    let col_w = 66.0 * scale;
    let rows_per_col = rows.len().div_ceil(3);
    let table_top = band_top - 10.0 * scale;
    for (i, (label, value)) in rows.iter().enumerate() {
        let col = i / rows_per_col;
        #[allow(clippy::cast_precision_loss)]
        let (x, y) = (
            margin + col as f64 * col_w,
            table_top - (i % rows_per_col) as f64 * line_mm,
        );
        text(
            &mut c,
            x,
            y,
            small,
            &format!("{label:<20}{value}"),
            chars_in(col_w - 1.0, small),
        );
    }
    let right = margin + 3.0 * col_w + 4.0 * scale;
    draw_ruler(&mut c, right, margin + 12.0 * scale, scale, small);
    let map_size = (page_w - margin - (right + RULER_MM + 8.0 * scale)).min(50.0 * scale);
    draw_map(
        &mut c,
        &input.map,
        page_w - margin - map_size,
        margin,
        map_size,
        small,
    );
    let content_1 = c.finish();
    pdf.stream(content1, &content_1);

    // Page 2: methodology and residuals.
    let body = (8.0 * scale) as f32;
    let body_mm = f64::from(body) / f64::from(PT_PER_MM) * 1.3;
    let mut c = Content::new();
    c.set_fill_rgb(0.0, 0.0, 0.0);
    let mut y = page_h - margin - 5.0 * scale;
    text(
        &mut c,
        margin,
        y,
        title,
        &format!("Methodology: view {}", r.photo_id),
        200,
    );
    y -= 2.0 * body_mm;
    let half = (page_w - 3.0 * margin) / 2.0;
    let width = chars_in(half - 3.0, body);
    for (heading, lines) in &input.methodology {
        text(&mut c, margin, y, body, heading, chars_in(half, body));
        y -= body_mm;
        for line in lines.iter().flat_map(|l| wrap(l, width)) {
            text(&mut c, margin + 3.0, y, body, &line, width);
            y -= body_mm;
        }
        y -= body_mm * 0.5;
    }
    // Residual table in the right half; rows beyond the page are counted, not drawn.
    let x0 = margin * 2.0 + half;
    let top = page_h - margin - 5.0 * scale;
    text(&mut c, x0, top, title, "Control-point residuals", 200);
    let table = residual_lines(r);
    let row_mm = line_mm;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let fit = ((top - 2.0 * body_mm - margin) / row_mm).floor().max(2.0) as usize;
    let shown = if table.len() > fit {
        fit - 1
    } else {
        table.len()
    };
    for (i, line) in table.iter().take(shown).enumerate() {
        #[allow(clippy::cast_precision_loss)]
        let yy = top - 2.0 * body_mm - i as f64 * row_mm;
        text(&mut c, x0, yy, small, line, chars_in(half, small));
    }
    if shown < table.len() {
        #[allow(clippy::cast_precision_loss)]
        let yy = top - 2.0 * body_mm - shown as f64 * row_mm;
        let more = format!(
            "... {} more rows in `photomontage report --json`",
            table.len() - shown
        );
        text(&mut c, x0, yy, small, &more, chars_in(half, small));
    }
    let content_2 = c.finish();
    pdf.stream(content2, &content_2);
    Ok(pdf.finish())
}

/// The file format of a sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SheetFormat {
    /// PDF ([`sheet_pdf`]).
    Pdf,
    /// One self-contained HTML file ([`html::sheet_html`]).
    Html,
}

impl SheetFormat {
    /// The format a file name's extension names (`.pdf`, `.html`/`.htm`), if any.
    #[must_use]
    pub fn from_path(path: &Path) -> Option<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("pdf") => Some(Self::Pdf),
            Some("html" | "htm") => Some(Self::Html),
            _ => None,
        }
    }
}

/// The sheet of photo `photo_id` showing `image` (the view at `avr`, 8-bit sRGB, the photo's
/// size) as PDF: the report, map and methodology gathered from the site, then [`sheet_pdf`].
///
/// # Errors
/// As [`sheet_for_view_as`].
pub fn sheet_for_view(
    doc: &SiteDocument,
    photo_id: &str,
    image: &RgbImage,
    avr: AvrLevel,
    options: &ViewGeometryOptions,
) -> Result<Vec<u8>, SheetError> {
    sheet_for_view_as(doc, photo_id, image, avr, options, SheetFormat::Pdf)
}

/// The sheet of photo `photo_id` in `format`.
///
/// # Errors
/// The report's errors (unknown or unsolved view, scene), [`SheetError::SizeMismatch`] when the
/// image is not the photo's size, and the writer's.
pub fn sheet_for_view_as(
    doc: &SiteDocument,
    photo_id: &str,
    image: &RgbImage,
    avr: AvrLevel,
    options: &ViewGeometryOptions,
    format: SheetFormat,
) -> Result<Vec<u8>, SheetError> {
    let report = view_geometry(doc, photo_id, options)?;
    sheet_for_geometry(doc, &report, image, avr, format)
}

/// The sheet of the view `report` describes (a photo, or a planar or cylindrical view made from
/// photos: [`super::reprojected_geometry`]) showing `image` (8-bit sRGB, the view's size).
///
/// # Errors
/// [`SheetError::SizeMismatch`] when the image is not the view's size, the scene's errors and
/// the writer's.
pub fn sheet_for_geometry(
    doc: &SiteDocument,
    report: &ViewGeometry,
    image: &RgbImage,
    avr: AvrLevel,
    format: SheetFormat,
) -> Result<Vec<u8>, SheetError> {
    let (w, h) = image.dimensions();
    if [w, h] != report.image_size_px {
        return Err(SheetError::SizeMismatch {
            photo: report.photo_id.clone(),
            image_px: [w, h],
            photo_px: report.image_size_px,
        });
    }
    let map = map_inset(doc, report)?;
    let methodology = methodology(doc, report, avr);
    let input = SheetInput {
        report,
        image,
        avr,
        map,
        methodology,
    };
    match format {
        SheetFormat::Pdf => sheet_pdf(&input),
        SheetFormat::Html => html::sheet_html(&input).map(String::into_bytes),
    }
}

/// Writes `bytes` to `path` through a temporary file beside it and a rename: either the whole
/// new sheet or nothing (the old file, if any) is at `path`.
///
/// # Errors
/// [`SheetError::Write`].
pub fn write_sheet(path: &Path, bytes: &[u8]) -> Result<(), SheetError> {
    crate::site::write_atomically(path, bytes).map_err(|source| SheetError::Write {
        path: path.display().to_string(),
        source,
    })
}

#[cfg(test)]
mod tests;

/// Writes the sheets' font into `pdf`: DejaVu Sans Mono as a TrueType simple font, WinAnsi, every
/// width [`GLYPH_WIDTH`], embedded (objects `font`, `descriptor`, `font_file`).
pub(crate) fn write_font(pdf: &mut Pdf, font: Ref, descriptor: Ref, font_file: Ref) {
    {
        let mut f = pdf.indirect(font).dict();
        f.pair(Name(b"Type"), Name(b"Font"));
        f.pair(Name(b"Subtype"), Name(b"TrueType"));
        f.pair(Name(b"BaseFont"), Name(b"DejaVuSansMono"));
        f.pair(Name(b"FirstChar"), 32);
        f.pair(Name(b"LastChar"), 255);
        f.insert(Name(b"Widths"))
            .array()
            .items(std::iter::repeat_n(GLYPH_WIDTH, 224));
        f.pair(Name(b"FontDescriptor"), descriptor);
        f.pair(Name(b"Encoding"), Name(b"WinAnsiEncoding"));
    }
    pdf.font_descriptor(descriptor)
        .name(Name(b"DejaVuSansMono"))
        .flags(FontFlags::FIXED_PITCH | FontFlags::NON_SYMBOLIC)
        .bbox(Rect::new(-559.0, -375.0, 718.0, 1028.0))
        .italic_angle(0.0)
        .ascent(928.0)
        .descent(-236.0)
        .cap_height(729.0)
        .stem_v(80.0)
        .font_file2(font_file);
    #[allow(clippy::cast_possible_wrap, clippy::cast_possible_truncation)]
    let font_len = FONT_TTF.len() as i32;
    pdf.stream(font_file, FONT_TTF)
        .pair(Name(b"Length1"), font_len);
}
