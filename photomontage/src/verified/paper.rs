//! Paper sizes of the verified-view sheet and the printed size of the image on them, from which
//! the correct viewing distance follows (Landscape Institute TGN 06/19, *Visual Representation of
//! Development Proposals*, §§ on image size and viewing distance: an image gives the correct
//! perspective when it is viewed from the distance at which it subtends its own horizontal field
//! of view, `d = w / (2·tan(HFoV/2))`).
//!
//! The sheet is landscape ISO 216 paper. The image spans the printable width (paper minus two
//! [`SheetLayout::margin_mm`]) unless its height would leave less than
//! [`SheetLayout::info_band_mm`] for the information band below it; then the height limits it.
//!
//! # Known limitations
//! Only A3, A2 and A1 landscape; the layout is fixed (no user margins). TGN 06/19 prefers a
//! viewing distance of about 550 mm for a single-frame 50 mm image on A3; a wider lens gives a
//! shorter distance here, which the sheet states rather than hides.

use serde::Serialize;

/// Landscape ISO 216 paper for the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum PaperSize {
    /// 420 × 297 mm (the TGN 06/19 default).
    #[default]
    A3,
    /// 594 × 420 mm.
    A2,
    /// 841 × 594 mm.
    A1,
}

impl PaperSize {
    /// Width and height, landscape, millimetres (ISO 216).
    #[must_use]
    pub fn size_mm(self) -> [f64; 2] {
        match self {
            Self::A3 => [420.0, 297.0],
            Self::A2 => [594.0, 420.0],
            Self::A1 => [841.0, 594.0],
        }
    }

    /// `A3`, `A2` or `A1`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::A3 => "A3",
            Self::A2 => "A2",
            Self::A1 => "A1",
        }
    }

    /// The layout of the sheet on this paper: margins and information band scale with the
    /// paper's height (A3 values: 10 mm margin, 60 mm band).
    #[must_use]
    pub fn layout(self) -> SheetLayout {
        let scale = self.size_mm()[1] / 297.0;
        SheetLayout {
            paper: self,
            margin_mm: 10.0 * scale,
            info_band_mm: 60.0 * scale,
        }
    }
}

impl std::str::FromStr for PaperSize {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_uppercase().as_str() {
            "A3" => Ok(Self::A3),
            "A2" => Ok(Self::A2),
            "A1" => Ok(Self::A1),
            _ => Err(format!("paper `{s}` is not A3, A2 or A1")),
        }
    }
}

/// Where the image goes on the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SheetLayout {
    /// The paper.
    pub paper: PaperSize,
    /// White margin on every side, millimetres.
    pub margin_mm: f64,
    /// Height kept below the image for the geometry table, map inset and notes, millimetres.
    pub info_band_mm: f64,
}

impl SheetLayout {
    /// The largest box the image may fill: printable width × (printable height − info band).
    #[must_use]
    pub fn image_box_mm(&self) -> [f64; 2] {
        let [w, h] = self.paper.size_mm();
        [
            w - 2.0 * self.margin_mm,
            h - 2.0 * self.margin_mm - self.info_band_mm,
        ]
    }

    /// Printed width and height of an image of `image_size_px`, aspect kept, as large as the
    /// image box allows.
    #[must_use]
    pub fn printed_image_size_mm(&self, image_size_px: [u32; 2]) -> [f64; 2] {
        let [bw, bh] = self.image_box_mm();
        let (w, h) = (
            f64::from(image_size_px[0].max(1)),
            f64::from(image_size_px[1].max(1)),
        );
        let scale = (bw / w).min(bh / h);
        [w * scale, h * scale]
    }
}

/// The distance at which an image printed `printed_width_mm` wide subtends its horizontal field
/// of view `hfov_deg`: `d = w / (2·tan(HFoV/2))`.
#[must_use]
pub fn viewing_distance_mm(printed_width_mm: f64, hfov_deg: f64) -> f64 {
    printed_width_mm / (2.0 * (hfov_deg.to_radians() / 2.0).tan())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms of the layout are exact up to round-off.
    const MM_TOL: f64 = 1e-9;

    #[test]
    fn a3_box_and_a_wide_image() {
        let layout = PaperSize::A3.layout();
        let [bw, bh] = layout.image_box_mm();
        assert!((bw - 400.0).abs() < MM_TOL && (bh - 217.0).abs() < MM_TOL);
        // A 3:1 panorama is limited by the width, a 4:3 photo by the height.
        let [w, h] = layout.printed_image_size_mm([3000, 1000]);
        assert!((w - 400.0).abs() < MM_TOL && (h - 400.0 / 3.0).abs() < MM_TOL);
        let [w, h] = layout.printed_image_size_mm([1280, 960]);
        assert!((h - 217.0).abs() < MM_TOL && (w - 217.0 * 4.0 / 3.0).abs() < MM_TOL);
    }

    #[test]
    fn tgn_fifty_millimetre_example() {
        // A 50 mm lens on a 36 mm frame: HFoV = 2·atan(18/50) = 39.60°. Printed 390 mm wide it
        // is viewed correctly from 390 · 50/36 = 541.7 mm (the frame scaled 390/36 times, viewed
        // from the focal length scaled the same).
        let hfov = 2.0 * (18.0_f64 / 50.0).atan().to_degrees();
        let d = viewing_distance_mm(390.0, hfov);
        assert!((d - 390.0 * 50.0 / 36.0).abs() < MM_TOL, "{d}");
    }

    #[test]
    fn paper_names_parse() {
        assert_eq!("a2".parse::<PaperSize>(), Ok(PaperSize::A2));
        assert!("A4".parse::<PaperSize>().is_err());
        assert!((PaperSize::A1.layout().margin_mm - 20.0).abs() < MM_TOL);
    }
}
