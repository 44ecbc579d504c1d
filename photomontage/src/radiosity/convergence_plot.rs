//! A labelled PNG plot of a convergence record: log₁₀ of the residual (solid) and of the
//! mean-brightness change (dotted) against the pass, one colour per group, with the stop rule's
//! thresholds as grey lines, a title, axis labels, tick values and a legend in a built-in 5 × 7
//! pixel font (lower-case letters, digits and a few signs; other characters are drawn as blanks).
//!
//! # Known limitations
//! No anti-aliasing; values below 1e-16 are drawn at 1e-16; at most 8 distinct group colours.

use image::{Rgb, RgbImage};

use super::RadiosityError;
use super::convergence::{ConvergenceRow, StopRule};

const WIDTH_PX: u32 = 720;
const HEIGHT_PX: u32 = 440;
const LEFT_PX: i64 = 70;
const RIGHT_PX: i64 = 180;
const TOP_PX: i64 = 36;
const BOTTOM_PX: i64 = 48;
const FLOOR_LOG10: f64 = -16.0;
const COLOURS: [[u8; 3]; 8] = [
    [200, 40, 40],
    [30, 100, 200],
    [20, 150, 60],
    [180, 110, 0],
    [130, 50, 170],
    [0, 150, 150],
    [120, 120, 0],
    [200, 60, 140],
];

/// 5 × 7 glyphs, one row per string, `#` set.
fn glyph(c: char) -> [&'static str; 7] {
    match c {
        '0' => [
            " ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### ",
        ],
        '1' => [
            "  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
        '2' => [
            " ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####",
        ],
        '3' => [
            "#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### ",
        ],
        '4' => [
            "   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # ",
        ],
        '5' => [
            "#####", "#    ", "#### ", "    #", "    #", "#   #", " ### ",
        ],
        '6' => [
            "  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### ",
        ],
        '7' => [
            "#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   ",
        ],
        '8' => [
            " ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### ",
        ],
        '9' => [
            " ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  ",
        ],
        'a' => [
            "     ", "     ", " ### ", "    #", " ####", "#   #", " ####",
        ],
        'b' => [
            "#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#### ",
        ],
        'c' => [
            "     ", "     ", " ### ", "#    ", "#    ", "#   #", " ### ",
        ],
        'd' => [
            "    #", "    #", " ## #", "#  ##", "#   #", "#   #", " ####",
        ],
        'e' => [
            "     ", "     ", " ### ", "#   #", "#####", "#    ", " ### ",
        ],
        'f' => [
            "  ## ", " #  #", " #   ", "###  ", " #   ", " #   ", " #   ",
        ],
        'g' => [
            "     ", " ####", "#   #", "#   #", " ####", "    #", " ### ",
        ],
        'h' => [
            "#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#   #",
        ],
        'i' => [
            "  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
        'j' => [
            "   # ", "     ", "  ## ", "   # ", "   # ", "#  # ", " ##  ",
        ],
        'k' => [
            "#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # ",
        ],
        'l' => [
            " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
        'm' => [
            "     ", "     ", "## # ", "# # #", "# # #", "#   #", "#   #",
        ],
        'n' => [
            "     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #",
        ],
        'o' => [
            "     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### ",
        ],
        'p' => [
            "     ", "     ", "#### ", "#   #", "#### ", "#    ", "#    ",
        ],
        'q' => [
            "     ", "     ", " ## #", "#  ##", " ####", "    #", "    #",
        ],
        'r' => [
            "     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    ",
        ],
        's' => [
            "     ", "     ", " ### ", "#    ", " ### ", "    #", "#### ",
        ],
        't' => [
            " #   ", " #   ", "###  ", " #   ", " #   ", " #  #", "  ## ",
        ],
        'u' => [
            "     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #",
        ],
        'v' => [
            "     ", "     ", "#   #", "#   #", "#   #", " # # ", "  #  ",
        ],
        'w' => [
            "     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # ",
        ],
        'x' => [
            "     ", "     ", "#   #", " # # ", "  #  ", " # # ", "#   #",
        ],
        'y' => [
            "     ", "     ", "#   #", "#   #", " ####", "    #", " ### ",
        ],
        'z' => [
            "     ", "     ", "#####", "   # ", "  #  ", " #   ", "#####",
        ],
        '-' => [
            "     ", "     ", "     ", "#####", "     ", "     ", "     ",
        ],
        '.' => [
            "     ", "     ", "     ", "     ", "     ", " ##  ", " ##  ",
        ],
        '%' => [
            "##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##",
        ],
        '(' => [
            "   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # ",
        ],
        ')' => [
            " #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   ",
        ],
        '/' => [
            "     ", "    #", "   # ", "  #  ", " #   ", "#    ", "     ",
        ],
        '=' => [
            "     ", "     ", "#####", "     ", "#####", "     ", "     ",
        ],
        '<' => [
            "   # ", "  #  ", " #   ", "#    ", " #   ", "  #  ", "   # ",
        ],
        ':' => [
            "     ", "  #  ", "  #  ", "     ", "  #  ", "  #  ", "     ",
        ],
        _ => ["     "; 7],
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, colour: [u8; 3]) {
    if let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y))
        && x < img.width()
        && y < img.height()
    {
        img.put_pixel(x, y, Rgb(colour));
    }
}

/// Draws `s` in the 5 × 7 font (6 px advance) with its top-left corner at (`x`, `y`); characters
/// without a glyph are blank. Also used by the sun-study contact sheet.
pub(crate) fn text(img: &mut RgbImage, x: i64, y: i64, s: &str, colour: [u8; 3]) {
    for (k, c) in s.chars().enumerate() {
        let rows = glyph(c.to_ascii_lowercase());
        for (dy, row) in rows.iter().enumerate() {
            for (dx, b) in row.bytes().enumerate() {
                if b == b'#' {
                    put(img, x + 6 * k as i64 + dx as i64, y + dy as i64, colour);
                }
            }
        }
    }
}

fn line(img: &mut RgbImage, a: (i64, i64), b: (i64, i64), colour: [u8; 3], dotted: bool) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).max(1);
    for i in 0..=steps {
        if dotted && (i / 3) % 2 == 1 {
            continue;
        }
        let x = a.0 + (b.0 - a.0) * i / steps;
        let y = a.1 + (b.1 - a.1) * i / steps;
        put(img, x, y, colour);
    }
}

fn log10_clamped(v: f64) -> f64 {
    if v > 0.0 {
        v.log10().max(FLOOR_LOG10)
    } else {
        FLOOR_LOG10
    }
}

/// The plot (module doc) of `rows`, with `stop`'s thresholds.
#[must_use]
#[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
pub fn plot(rows: &[ConvergenceRow], stop: &StopRule) -> RgbImage {
    let mut img = RgbImage::from_pixel(WIDTH_PX, HEIGHT_PX, Rgb([255, 255, 255]));
    let (w, h) = (i64::from(WIDTH_PX), i64::from(HEIGHT_PX));
    let (x0, x1, y0, y1) = (LEFT_PX, w - RIGHT_PX, TOP_PX, h - BOTTOM_PX);
    let mut groups: Vec<&str> = Vec::new();
    for r in rows {
        if !groups.contains(&r.group.as_str()) {
            groups.push(&r.group);
        }
    }
    let max_pass = rows.iter().map(|r| r.pass).max().unwrap_or(1).max(2);
    let values = rows
        .iter()
        .flat_map(|r| [r.residual, r.mean_change])
        .chain([stop.residual, stop.mean_change])
        .map(log10_clamped);
    let (lo, hi) = values.fold((0.0f64, FLOOR_LOG10), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (lo, hi) = (lo.floor(), hi.ceil().max(lo.floor() + 1.0));
    let px = |pass: u32| {
        x0 + ((f64::from(pass) - 1.0) / f64::from(max_pass - 1) * (x1 - x0) as f64) as i64
    };
    let py = |v: f64| y1 - ((log10_clamped(v) - lo) / (hi - lo) * (y1 - y0) as f64) as i64;
    let black = [0, 0, 0];
    let grey = [170, 170, 170];
    // Axes, ticks and their values.
    line(&mut img, (x0, y1), (x1, y1), black, false);
    line(&mut img, (x0, y0), (x0, y1), black, false);
    let decades = (hi - lo) as i64;
    let step = (decades / 8).max(1);
    let mut d = 0;
    while d <= decades {
        let v = lo + d as f64;
        let y = py(10f64.powf(v));
        line(&mut img, (x0 - 4, y), (x0, y), black, false);
        text(&mut img, x0 - 8 - 6 * 4, y - 3, &format!("{v:>4.0}"), black);
        d += step;
    }
    let pass_step = (max_pass / 8).max(1);
    let mut p = 1;
    while p <= max_pass {
        let x = px(p);
        line(&mut img, (x, y1), (x, y1 + 4), black, false);
        let label = p.to_string();
        text(&mut img, x - 3 * label.len() as i64, y1 + 8, &label, black);
        p += pass_step;
    }
    // Stop-rule thresholds.
    for (v, name) in [
        (stop.residual, "residual limit"),
        (stop.mean_change, "mean change limit"),
    ] {
        let y = py(v);
        line(&mut img, (x0, y), (x1, y), grey, false);
        text(&mut img, x1 + 8, y - 3, name, grey);
    }
    // Curves.
    for (g, name) in groups.iter().enumerate() {
        let colour = COLOURS[g % COLOURS.len()];
        let mine: Vec<&ConvergenceRow> = rows.iter().filter(|r| r.group == *name).collect();
        for pair in mine.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            line(
                &mut img,
                (px(a.pass), py(a.residual)),
                (px(b.pass), py(b.residual)),
                colour,
                false,
            );
            line(
                &mut img,
                (px(a.pass), py(a.mean_change)),
                (px(b.pass), py(b.mean_change)),
                colour,
                true,
            );
        }
        for r in &mine {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    put(&mut img, px(r.pass) + dx, py(r.residual) + dy, colour);
                }
            }
        }
        let ly = y0 + 14 * g as i64;
        line(&mut img, (x1 + 8, ly + 3), (x1 + 24, ly + 3), colour, false);
        text(&mut img, x1 + 28, ly, name, colour);
    }
    text(&mut img, x0, 12, "radiosity convergence (log10)", black);
    text(
        &mut img,
        x0 + 140,
        22,
        "solid = residual  dotted = mean change",
        [90, 90, 90],
    );
    text(&mut img, (x0 + x1) / 2 - 12, h - 18, "pass", black);
    img
}

/// Writes [`plot`] as PNG, atomically.
///
/// # Errors
/// [`RadiosityError::Io`] naming the file.
pub fn write_png(
    path: &std::path::Path,
    rows: &[ConvergenceRow],
    stop: &StopRule,
) -> Result<(), RadiosityError> {
    let io = |source| RadiosityError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    plot(rows, stop)
        .write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| io(std::io::Error::other(e.to_string())))?;
    crate::atomic_file::write_atomically(path, bytes.get_ref()).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(group: &str, pass: u32, residual: f64) -> ConvergenceRow {
        ConvergenceRow {
            group: group.into(),
            pass,
            residual,
            mean_change: residual * 2.0,
            mean_brightness: 1.0,
            interactions: 1,
        }
    }

    #[test]
    fn curves_land_where_their_values_say() {
        let rows: Vec<_> = (1..=5)
            .map(|p| row("sun", p, 10f64.powi(-i32::try_from(p).unwrap_or(0))))
            .chain([row("sky", 1, 0.0)])
            .collect();
        let stop = StopRule::default();
        let img = plot(&rows, &stop);
        assert_eq!(img.dimensions(), (WIDTH_PX, HEIGHT_PX));
        // Axis range: residual 1e-5 ... mean change 0.2 → decades −16 (the zero) … 0.
        let (x0, x1, y0, y1) = (
            LEFT_PX,
            i64::from(WIDTH_PX) - RIGHT_PX,
            TOP_PX,
            i64::from(HEIGHT_PX) - BOTTOM_PX,
        );
        // The sun's pass-3 residual 1e-3 at x = x0 + (2/4)(x1 − x0), y = y1 − (13/16)(y1 − y0).
        let x = x0 + (x1 - x0) / 2;
        #[allow(clippy::cast_possible_truncation)]
        let y = y1 - ((13.0 / 16.0) * (y1 - y0) as f64) as i64;
        let px = img.get_pixel(u32::try_from(x).unwrap_or(0), u32::try_from(y).unwrap_or(0));
        assert_eq!(px.0, COLOURS[0], "at ({x}, {y})");
    }
}
