//! IES LM-63 photometric files: editions 1986, 1991, 1995, 2002 and 2019.
//!
//! Source: IES LM-63-1995/2002 and ANSI/IES LM-63-2019 as summarised in `reference/lighting.md`
//! §4.1 (after Radiance `src/cv/ies2rad.c`, R. Fritz 2018), and the oddities of real files listed
//! in `data/real/SOURCES.md`.
//!
//! Layout: an optional version line (`IESNA:LM-63-1995`, `IESNA:LM-63-2002`, `IES:LM-63-2019`,
//! `IESNA91`; none for 1986), label lines (`[KEYWORD] value` or free text), `TILT=NONE|INCLUDE|
//! <file>`, the tilt records when included (geometry, pair count, angles, multipliers), record 1
//! (`#lamps lumens/lamp multiplier #vertical #horizontal type units width length height`),
//! record 2 (`ballast-factor future/file-generation-type input-watts`), the vertical angles, the
//! horizontal angles, and one candela row per horizontal angle. After `TILT` the file is a stream
//! of numbers separated by blanks or commas, wrapped anywhere.
//!
//! Parsing reads bytes (Latin-1 when not UTF-8), accepts CR LF, leading spaces, tabs, Fortran
//! numbers (`5000.`, `.625`) and numbers split over lines. Counts are bounded
//! ([`super::MAX_ANGLES`], [`super::MAX_INTENSITY_VALUES`]) and checked against the numbers
//! actually present before anything is allocated. Errors carry the line and what was expected.
//!
//! Intensity in cd = file value × candela multiplier × ballast factor (as ies2rad does). With
//! absolute photometry (lumens per lamp = −1) the values are already the luminaire's candela.
//!
//! # Known limitations
//! The 1991 "ballast-lamp photometric factor" and the 2019 file-generation type (record 2, second
//! value) are stored but not applied. Luminous-opening shapes are kept as signed dimensions, not
//! classified. LM-63-1986 used type 1 for both A and C; it is read as C.

use super::distribution::{
    DistributionError, PhotometricType, PhotometricWeb, Symmetry, TiltTable,
};
use thiserror::Error;

/// Most tilt angle pairs accepted (real tables have fewer than 200).
pub const MAX_TILT_PAIRS: usize = 10_000;
/// Metres per foot (units code 1).
const M_PER_FT: f64 = 0.3048;

/// The LM-63 edition, from the first line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IesVersion {
    /// No recognised version line.
    Lm63_1986,
    /// `IESNA91`.
    Lm63_1991,
    /// `IESNA:LM-63-1995` (or the non-standard `IESNA95`).
    Lm63_1995,
    /// `IESNA:LM-63-2002`.
    Lm63_2002,
    /// `IES:LM-63-2019`.
    Lm63_2019,
}

impl IesVersion {
    /// `LM-63-1995` and so on.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Lm63_1986 => "LM-63-1986",
            Self::Lm63_1991 => "LM-63-1991",
            Self::Lm63_1995 => "LM-63-1995",
            Self::Lm63_2002 => "LM-63-2002",
            Self::Lm63_2019 => "LM-63-2019",
        }
    }
}

/// Why an IES file could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IesError {
    /// The file (or its TILT file) could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// No `TILT=` line was found.
    #[error("line {line}: end of file, expected a TILT=NONE, TILT=INCLUDE or TILT=<file> line")]
    MissingTilt {
        /// Last line read.
        line: usize,
    },
    /// `TILT=<file>` was given but the file could not be used.
    #[error("line {line}: TILT={file_name}: {message}")]
    TiltFile {
        /// Line of the TILT statement.
        line: usize,
        /// The file name given.
        file_name: String,
        /// What went wrong.
        message: String,
    },
    /// The numbers ran out.
    #[error("line {line}: end of file, expected {expected}")]
    UnexpectedEnd {
        /// Last line of the file.
        line: usize,
        /// What was still expected.
        expected: String,
    },
    /// A token is not a finite number.
    #[error("line {line}: expected a number for {field}, found {token:?}")]
    BadNumber {
        /// Line of the token.
        line: usize,
        /// The field being read.
        field: String,
        /// The text found.
        token: String,
    },
    /// A count is negative, fractional or too large.
    #[error("line {line}: {field} = {value} is not a count in 1..={max}")]
    BadCount {
        /// Line of the count.
        line: usize,
        /// The field.
        field: &'static str,
        /// The value found.
        value: f64,
        /// Largest accepted.
        max: usize,
    },
    /// A coded value is not one of the allowed codes.
    #[error("line {line}: {field} = {value}, expected {expected}")]
    BadCode {
        /// Line of the value.
        line: usize,
        /// The field.
        field: &'static str,
        /// The value found.
        value: f64,
        /// The allowed codes.
        expected: &'static str,
    },
    /// Angles that do not increase strictly.
    #[error(
        "line {line}: {field} must increase strictly, but {previous_deg}° is followed by {next_deg}°"
    )]
    AngleOrder {
        /// Line of the angle that does not exceed its predecessor.
        line: usize,
        /// "vertical angles" or "horizontal angles".
        field: &'static str,
        /// The earlier angle.
        previous_deg: f64,
        /// The angle that does not exceed it.
        next_deg: f64,
    },
    /// The angles or values do not form a valid web.
    #[error("{0}")]
    Distribution(#[from] DistributionError),
}

/// A parsed LM-63 file. Angles and values are as stored (before symmetry expansion).
#[derive(Debug, Clone, PartialEq)]
pub struct IesFile {
    /// Edition.
    pub version: IesVersion,
    /// `[KEYWORD] value` pairs in file order (`[MORE]` lines appended to the previous value).
    pub keywords: Vec<(String, String)>,
    /// Label lines that are not keywords (1986 free text, SCCS lines, …).
    pub free_text: Vec<String>,
    /// Tilt multipliers (TILT=INCLUDE or a TILT file); `None` for TILT=NONE.
    pub tilt: Option<TiltTable>,
    /// Number of lamps.
    pub lamp_count: f64,
    /// Rated lumens per lamp; −1 for absolute photometry.
    pub lumens_per_lamp: f64,
    /// Candela multiplier.
    pub candela_multiplier: f64,
    /// Photometric type.
    pub photometric_type: PhotometricType,
    /// Luminous opening width, length, height in metres (signed: negative = round shapes).
    pub opening_m: [f64; 3],
    /// Ballast factor.
    pub ballast_factor: f64,
    /// Record 2 second value: ballast-lamp factor (1991), future use (1995/2002), file
    /// generation type (2019).
    pub file_generation_type: f64,
    /// Input watts.
    pub input_watts: f64,
    /// Vertical angles (degrees).
    pub vertical_deg: Vec<f64>,
    /// Horizontal angles (degrees).
    pub horizontal_deg: Vec<f64>,
    /// Candela values as in the file, one row per horizontal angle.
    pub candela: Vec<f64>,
    /// Non-fatal oddities.
    pub warnings: Vec<String>,
}

mod parse;

impl IesFile {
    /// The value of a keyword (first occurrence), without brackets, case-insensitive.
    #[must_use]
    pub fn keyword(&self, key: &str) -> Option<&str> {
        let key = key.to_ascii_uppercase();
        self.keywords
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.as_str())
    }

    /// True for absolute photometry (lumens per lamp negative, normally −1).
    #[must_use]
    pub fn is_absolute(&self) -> bool {
        self.lumens_per_lamp < 0.0
    }

    /// Rated lamp lumens (lamps × lumens per lamp), `None` for absolute photometry.
    #[must_use]
    pub fn rated_lumens(&self) -> Option<f64> {
        (!self.is_absolute()).then_some(self.lamp_count * self.lumens_per_lamp)
    }

    /// The symmetry implied by the horizontal angle range (LM-63-2002 rules).
    #[must_use]
    pub fn symmetry(&self) -> Symmetry {
        let (first, last) = match (self.horizontal_deg.first(), self.horizontal_deg.last()) {
            (Some(&f), Some(&l)) => (f, l),
            _ => return Symmetry::None,
        };
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        match self.photometric_type {
            PhotometricType::C => {
                if self.horizontal_deg.len() == 1 {
                    Symmetry::Axial
                } else if near(first, 0.0) && near(last, 90.0) {
                    Symmetry::Quadrant
                } else if near(first, 0.0) && near(last, 180.0) {
                    Symmetry::C0C180
                } else if near(first, 90.0) && near(last, 270.0) {
                    Symmetry::C90C270
                } else {
                    Symmetry::None
                }
            }
            PhotometricType::A | PhotometricType::B => {
                if near(first, 0.0) {
                    Symmetry::Lateral
                } else {
                    Symmetry::None
                }
            }
        }
    }

    fn symmetry_warning(&self) -> Option<String> {
        let (first, last) = (*self.horizontal_deg.first()?, *self.horizontal_deg.last()?);
        (self.photometric_type == PhotometricType::C
            && self.symmetry() == Symmetry::None
            && (last - first) < 360.0 - 1e-6
            && !(first == 0.0 && last == 0.0))
            .then(|| {
                format!(
                    "horizontal angles {first}°…{last}° match no LM-63 symmetry; \
                     read as a partial asymmetric web (interpolated across the gap)"
                )
            })
    }

    /// The absolute intensity distribution at tilt 0: values × multiplier × ballast factor.
    ///
    /// # Errors
    /// When the angles do not form a valid web (unsorted, out of range).
    pub fn distribution(&self) -> Result<PhotometricWeb, IesError> {
        let factor = self.candela_multiplier * self.ballast_factor;
        let values: Vec<f64> = self.candela.iter().map(|v| v * factor).collect();
        Ok(PhotometricWeb::from_planes(
            self.photometric_type,
            self.symmetry(),
            &self.horizontal_deg,
            &self.vertical_deg,
            &values,
        )?)
    }
}

#[cfg(test)]
#[path = "ies_tests.rs"]
mod tests;
