//! The verified-view sheet as one self-contained HTML file (the "Also HTML"): the same
//! content as the PDF ([`crate::verified::sheet_content`]: view geometry table, methodology, residuals; the
//! AVR level and TGN Type) with the view embedded as a JPEG data URI and sized in CSS millimetres
//! at the report's printed width, so that printing the page at 100 % on the report's paper gives
//! the stated viewing distance (`@page` sets the paper, landscape).
//!
//! # Known limitations
//! Browsers honour CSS millimetres only when printing at 100 % scale ("fit to page" breaks the
//! viewing distance; the page says so); on screen the size depends on the display's pixel
//! density. No map inset (the PDF has one).

use std::io::Cursor;

use image::RgbImage;

use super::{JPEG_QUALITY, SheetError, SheetInput};
use crate::verified::sheet_content::{geometry_rows, residual_lines, viewing_sentence};

const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 with padding (RFC 4648 §4).
#[must_use]
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(char::from(BASE64[((n >> (18 - 6 * i)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Escapes text for HTML element content and attribute values.
#[must_use]
pub fn escape(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '&' => "&amp;".to_owned(),
            '<' => "&lt;".to_owned(),
            '>' => "&gt;".to_owned(),
            '"' => "&quot;".to_owned(),
            c => c.to_string(),
        })
        .collect()
}

fn jpeg_data_uri(image: &RgbImage, photo: &str) -> Result<String, SheetError> {
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(Cursor::new(&mut jpeg), JPEG_QUALITY)
        .encode_image(image)
        .map_err(|e| SheetError::Encode {
            photo: photo.to_owned(),
            message: e.to_string(),
        })?;
    Ok(format!("data:image/jpeg;base64,{}", base64(&jpeg)))
}

/// The sheet as an HTML document.
///
/// # Errors
/// [`SheetError::EmptyImage`], [`SheetError::Encode`].
pub fn sheet_html(input: &SheetInput<'_>) -> Result<String, SheetError> {
    let r = input.report;
    let (w, h) = input.image.dimensions();
    if w == 0 || h == 0 {
        return Err(SheetError::EmptyImage {
            photo: r.photo_id.clone(),
            width: w,
            height: h,
        });
    }
    let [page_w, page_h] = r.paper.size_mm();
    let margin = r.paper.layout().margin_mm;
    let printed_h = r.printed_image_width_mm * f64::from(h) / f64::from(w);
    let mut s = String::new();
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    s.push_str(&format!(
        "<title>Verified view {}</title>\n<style>\n@page {{ size: {page_w}mm {page_h}mm; \
         margin: {margin}mm; }}\nbody {{ font-family: 'DejaVu Sans Mono', monospace; \
         font-size: 8pt; margin: 0; }}\nimg.view {{ display: block; margin: 0 auto; \
         width: {:.3}mm; height: {printed_h:.3}mm; }}\ntable {{ border-collapse: collapse; }}\n\
         td {{ padding: 0 3mm 0 0; }}\n.ruler {{ width: 100mm; border-bottom: 0.3mm solid black; \
         height: 3mm; }}\nsection {{ page-break-before: always; }}\n</style>\n</head>\n<body>\n",
        escape(&r.photo_id),
        r.printed_image_width_mm
    ));
    s.push_str(&format!(
        "<img class=\"view\" alt=\"view {}\" src=\"{}\">\n",
        escape(&r.photo_id),
        jpeg_data_uri(input.image, &r.photo_id)?
    ));
    s.push_str(&format!(
        "<h1>View {} | {}: {} | TGN 06/19 Type 4 (photomontage/photowire, survey/scale \
         verifiable)</h1>\n",
        escape(&r.photo_id),
        input.avr.name(),
        escape(input.avr.description())
    ));
    s.push_str(&format!(
        "<p>{} Print at 100 % (not \"fit to page\"); the ruler below is 100 mm long when the \
         scale is right.</p>\n<div class=\"ruler\"></div>\n",
        escape(&viewing_sentence(r))
    ));
    s.push_str("<table class=\"geometry\">\n");
    for (label, value) in geometry_rows(r) {
        s.push_str(&format!(
            "<tr><td>{}</td><td>{}</td></tr>\n",
            escape(&label),
            escape(&value)
        ));
    }
    s.push_str("</table>\n<section>\n<h2>Methodology</h2>\n");
    for (heading, lines) in &input.methodology {
        s.push_str(&format!("<h3>{}</h3>\n", escape(heading)));
        for line in lines {
            s.push_str(&format!("<p>{}</p>\n", escape(line)));
        }
    }
    s.push_str("<h2>Control-point residuals</h2>\n<pre>\n");
    for line in residual_lines(r) {
        s.push_str(&escape(&line));
        s.push('\n');
    }
    s.push_str("</pre>\n</section>\n</body>\n</html>\n");
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_rfc4648_vectors() {
        // RFC 4648 §10.
        for (plain, encoded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), encoded);
        }
    }

    #[test]
    fn html_escapes() {
        assert_eq!(escape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }
}
