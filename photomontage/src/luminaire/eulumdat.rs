//! EULUMDAT (`.ldt`) photometric files.
//!
//! Source: the EULUMDAT format (Stockmar 1990, 1998) as summarised in `reference/lighting.md`
//! §4.2 (AGi32 Photometric Toolbox docs, helios32.com, DIAL support), stored-plane counts after
//! eulumdat-rs `Symmetry::calc_mc`, and the oddities of real files in `data/real/SOURCES.md`.
//!
//! Layout, one value per line: lines 1–25 header (company, Ityp, Isym, Mc, Dc, Ng, Dg, five text
//! lines, luminaire and luminous-area dimensions in mm, DFF, LOR, conversion factor, tilt), line
//! 26 the number n of lamp sets, then n × 6 lamp-set lines, 10 direct ratios, Mc C angles, Ng γ
//! angles and the intensities in cd/klm of the stored planes only: Isym 0 → Mc planes, 1 → 1,
//! 2 → Mc/2 + 1 (C0…C180), 3 → Mc/2 + 1 (C270…C360/C0…C90), 4 → Mc/4 + 1 (C0…C90).
//!
//! Isym 3 (mirror symmetry about the C90–C270 plane): the stored half starts at **C270** and
//! runs through C0 to C90, as the EULUMDAT/DIAL description has it and as Relux reads it (the
//! `relux_reference.json` luminance tables of sample_03/07/08 match only this reading);
//! `reference/lighting.md` §4.2 summarises it as "C90…C270", which is the same half only if the
//! order is reversed.
//!
//! The parser accepts CR LF, leading/trailing blanks, comma decimal separators, Dc/Dg = 0
//! (non-equidistant angles: the listed angles are always used) and several lamp sets. From the
//! angle lists on, values are read as a blank-separated stream, so a writer that puts several
//! numbers on a line is read too. Counts are bounded before allocating.
//!
//! Absolute intensity (cd) = value × Φ/1000 × conversion factor, Φ the total lamp flux of the
//! chosen lamp set (the first by default, as Relux and DIALux do). A negative lamp count marks
//! absolute photometry (Aardvark `LDTLampData`); the same formula applies with Φ as given.
//!
//! # Known limitations
//! The direct ratios and Ityp are stored, not used. [`EulumdatFile::luminance_cd_per_m2`]
//! follows the projected-area model of eulumdat-luminance (bottom face plus the four side
//! heights), which is what the Relux reference tables in the tests were made with.

use super::distribution::{DistributionError, PhotometricType, PhotometricWeb, Symmetry};
use thiserror::Error;

/// Most lamp sets accepted (the format allows 20; real files have 1–3).
pub const MAX_LAMP_SETS: usize = 100;

/// Why an EULUMDAT file could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EulumdatError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The file ended early.
    #[error("line {line}: end of file, expected {expected}")]
    UnexpectedEnd {
        /// The line that would have held it.
        line: usize,
        /// What was expected.
        expected: String,
    },
    /// A number could not be read.
    #[error("line {line}: expected a number for {field}, found {found:?}")]
    BadNumber {
        /// Line number.
        line: usize,
        /// The field.
        field: String,
        /// The text found.
        found: String,
    },
    /// A count is out of range.
    #[error("line {line}: {field} = {value} is not a count in {min}..={max}")]
    BadCount {
        /// Line number.
        line: usize,
        /// The field.
        field: &'static str,
        /// The value found.
        value: f64,
        /// Smallest accepted.
        min: usize,
        /// Largest accepted.
        max: usize,
    },
    /// Isym is not 0–4.
    #[error("line 3: symmetry indicator Isym = {value}, expected 0, 1, 2, 3 or 4")]
    BadSymmetry {
        /// The value found.
        value: f64,
    },
    /// The C angles do not cover the range the symmetry stores.
    #[error(
        "line {line}: Isym {isym} stores C {expected_from_deg}°…{expected_to_deg}°, \
         but the stored planes run {found_from_deg}°…{found_to_deg}°"
    )]
    PlaneRange {
        /// Line of the first stored C angle.
        line: usize,
        /// Symmetry indicator.
        isym: u8,
        /// Expected first stored angle.
        expected_from_deg: f64,
        /// Expected last stored angle.
        expected_to_deg: f64,
        /// Found first stored angle.
        found_from_deg: f64,
        /// Found last stored angle.
        found_to_deg: f64,
    },
    /// The requested lamp set does not exist.
    #[error("lamp set {index} requested, the file has {count}")]
    NoLampSet {
        /// Requested index (0-based).
        index: usize,
        /// Sets present.
        count: usize,
    },
    /// The web could not be built.
    #[error("{0}")]
    Distribution(#[from] DistributionError),
}

/// One lamp set (lines 26a–26f).
#[derive(Debug, Clone, PartialEq)]
pub struct LampSet {
    /// Number of lamps (negative: absolute photometry).
    pub lamp_count: f64,
    /// Lamp type text.
    pub lamp_type: String,
    /// Total luminous flux of the lamps (lm).
    pub total_flux_lm: f64,
    /// Colour appearance / temperature text.
    pub colour_temperature: String,
    /// Colour rendering text.
    pub colour_rendering: String,
    /// Wattage including ballast, when it is a number.
    pub power_w: Option<f64>,
}

/// A parsed EULUMDAT file. Intensities are as stored (cd/klm, stored planes only).
#[derive(Debug, Clone, PartialEq)]
pub struct EulumdatFile {
    /// Line 1: company / databank / version.
    pub company: String,
    /// Line 2: type indicator Ityp.
    pub type_indicator: f64,
    /// Line 3: symmetry indicator Isym (0–4).
    pub symmetry_code: u8,
    /// Line 4: number of C planes Mc over 0–360°.
    pub c_plane_count: usize,
    /// Line 5: C step Dc (0 = non-equidistant).
    pub c_step_deg: f64,
    /// Line 6: number of γ angles Ng.
    pub gamma_count: usize,
    /// Line 7: γ step Dg (0 = non-equidistant).
    pub gamma_step_deg: f64,
    /// Lines 8–12: report number, luminaire name, luminaire number, file name, date/user.
    pub text_fields: [String; 5],
    /// Lines 13–15: luminaire length/diameter, width (0 = round), height (mm).
    pub luminaire_size_mm: [f64; 3],
    /// Lines 16–17: luminous area length/diameter, width (0 = round) (mm).
    pub luminous_area_mm: [f64; 2],
    /// Lines 18–21: luminous heights at C0, C90, C180, C270 (mm).
    pub luminous_height_mm: [f64; 4],
    /// Line 22: downward flux fraction (%).
    pub downward_flux_fraction_percent: f64,
    /// Line 23: light output ratio of the luminaire (%).
    pub light_output_ratio_percent: f64,
    /// Line 24: intensity conversion factor.
    pub conversion_factor: f64,
    /// Line 25: tilt of the luminaire during measurement (degrees).
    pub measurement_tilt_deg: f64,
    /// Lamp sets (line 26 on).
    pub lamp_sets: Vec<LampSet>,
    /// Direct ratios for room indices 0.6 … 5.
    pub direct_ratios: [f64; 10],
    /// All Mc C angles (degrees).
    pub c_angles_deg: Vec<f64>,
    /// All Ng γ angles (degrees).
    pub gamma_deg: Vec<f64>,
    /// C angles of the stored planes.
    pub stored_c_deg: Vec<f64>,
    /// Stored intensities, cd/klm, `[plane * Ng + γ]`.
    pub intensity_cd_per_klm: Vec<f64>,
    /// Non-fatal oddities.
    pub warnings: Vec<String>,
}

mod parse;

impl EulumdatFile {
    /// The symmetry of the stored data.
    #[must_use]
    pub fn symmetry(&self) -> Symmetry {
        match self.symmetry_code {
            0 => Symmetry::None,
            1 => Symmetry::Axial,
            2 => Symmetry::C0C180,
            3 => Symmetry::C90C270,
            _ => Symmetry::Quadrant,
        }
    }

    /// True when the first lamp set has a negative lamp count (absolute photometry).
    #[must_use]
    pub fn is_absolute(&self) -> bool {
        self.lamp_sets.first().is_some_and(|s| s.lamp_count < 0.0)
    }

    /// The intensity distribution in cd for the first lamp set.
    ///
    /// # Errors
    /// When the angles do not form a valid web.
    pub fn distribution(&self) -> Result<PhotometricWeb, EulumdatError> {
        self.distribution_for_lamp_set(0)
    }

    /// The intensity distribution in cd for lamp set `index` (0-based).
    ///
    /// # Errors
    /// A missing lamp set, or angles that do not form a valid web.
    pub fn distribution_for_lamp_set(&self, index: usize) -> Result<PhotometricWeb, EulumdatError> {
        let set = self.lamp_sets.get(index).ok_or(EulumdatError::NoLampSet {
            index,
            count: self.lamp_sets.len(),
        })?;
        let factor = set.total_flux_lm / 1000.0 * self.conversion_factor;
        let values: Vec<f64> = self
            .intensity_cd_per_klm
            .iter()
            .map(|v| v * factor)
            .collect();
        Ok(PhotometricWeb::from_planes(
            PhotometricType::C,
            self.symmetry(),
            &self.stored_c_deg,
            &self.gamma_deg,
            &values,
        )?)
    }

    /// Projected luminous area (m²) seen from (C, γ): bottom face × cos γ plus the side faces
    /// (luminous heights at C0/C90/C180/C270 by quadrant) × sin γ. A zero width means round.
    #[must_use]
    pub fn projected_luminous_area_m2(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        let length = self.luminous_area_mm[0] / 1000.0;
        let width = self.luminous_area_mm[1] / 1000.0;
        let [h0, h90, h180, h270] = self.luminous_height_mm.map(|h| h / 1000.0);
        let (c, g) = (c_deg.rem_euclid(360.0), gamma_deg.to_radians());
        if width == 0.0 {
            let bottom = std::f64::consts::PI * (length / 2.0).powi(2);
            return bottom * g.cos() + length * h0 * g.sin();
        }
        let (h_length, h_width) = if c < 90.0 {
            (h0, h90)
        } else if c < 180.0 {
            (h180, h90)
        } else if c < 270.0 {
            (h180, h270)
        } else {
            (h0, h270)
        };
        let cr = c.to_radians();
        let side = length * cr.cos().abs() * h_length + width * cr.sin().abs() * h_width;
        length * width * g.cos() + side * g.sin()
    }

    /// Luminance (cd/m²) at (C, γ): intensity of the first lamp set over the projected luminous
    /// area; `None` when that area is not positive or the web is invalid.
    #[must_use]
    pub fn luminance_cd_per_m2(&self, c_deg: f64, gamma_deg: f64) -> Option<f64> {
        let area = self.projected_luminous_area_m2(c_deg, gamma_deg);
        if area <= 0.0 {
            return None;
        }
        let web = self.distribution().ok()?;
        Some(web.intensity_cd(c_deg, gamma_deg) / area)
    }
}

#[cfg(test)]
#[path = "eulumdat_tests.rs"]
mod tests;
