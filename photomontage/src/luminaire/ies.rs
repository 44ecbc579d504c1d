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
    DistributionError, LampGeometry, PhotometricType, PhotometricWeb, Symmetry, TiltTable,
};
use super::{MAX_ANGLES, MAX_INTENSITY_VALUES, decode_text, read_bounded};
use std::path::Path;
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

struct Token<'a> {
    text: &'a str,
    line: usize,
}

struct Tokens<'a> {
    tokens: Vec<Token<'a>>,
    next: usize,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn new(lines: impl Iterator<Item = (usize, &'a str)>) -> Self {
        let mut tokens = Vec::new();
        let mut last_line = 0;
        for (line, text) in lines {
            if last_line == 0 || !text.trim().is_empty() {
                // The last line that holds anything: where an "end of file" error points.
                last_line = line;
            }
            for t in text.split(|c: char| c.is_whitespace() || c == ',') {
                if !t.is_empty() {
                    tokens.push(Token { text: t, line });
                }
            }
        }
        Self {
            tokens,
            next: 0,
            last_line,
        }
    }

    fn remaining(&self) -> usize {
        self.tokens.len() - self.next
    }

    fn line(&self) -> usize {
        self.tokens
            .get(self.next)
            .map_or(self.last_line, |t| t.line)
    }

    fn number(&mut self, field: &str) -> Result<(f64, usize), IesError> {
        let Some(tok) = self.tokens.get(self.next) else {
            return Err(IesError::UnexpectedEnd {
                line: self.last_line,
                expected: field.to_owned(),
            });
        };
        self.next += 1;
        match tok.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((v, tok.line)),
            _ => Err(IesError::BadNumber {
                line: tok.line,
                field: field.to_owned(),
                token: tok.text.chars().take(40).collect(),
            }),
        }
    }

    fn count(&mut self, field: &'static str, max: usize) -> Result<usize, IesError> {
        let (v, line) = self.number(field)?;
        if v < 1.0 || v.fract() != 0.0 || v > max as f64 {
            return Err(IesError::BadCount {
                line,
                field,
                value: v,
                max,
            });
        }
        Ok(v as usize)
    }

    /// Reads `n` angles (`n` already bounded) that must increase strictly.
    fn increasing_angles(&mut self, n: usize, field: &'static str) -> Result<Vec<f64>, IesError> {
        if self.remaining() < n {
            return Err(IesError::UnexpectedEnd {
                line: self.last_line,
                expected: format!("{n} {field}, found only {}", self.remaining()),
            });
        }
        let mut out: Vec<f64> = Vec::with_capacity(n);
        for _ in 0..n {
            let (v, line) = self.number(field)?;
            if let Some(&previous_deg) = out.last()
                && v <= previous_deg
            {
                return Err(IesError::AngleOrder {
                    line,
                    field,
                    previous_deg,
                    next_deg: v,
                });
            }
            out.push(v);
        }
        Ok(out)
    }

    /// Reads `n` numbers; `n` must already be bounded.
    fn numbers(&mut self, n: usize, field: &str) -> Result<Vec<f64>, IesError> {
        if self.remaining() < n {
            return Err(IesError::UnexpectedEnd {
                line: self.last_line,
                expected: format!("{n} {field}, found only {}", self.remaining()),
            });
        }
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            out.push(self.number(field)?.0);
        }
        Ok(out)
    }
}

/// Reads the four tilt records from a token stream.
fn read_tilt(tokens: &mut Tokens<'_>) -> Result<TiltTable, IesError> {
    let (g, line) = tokens.number("lamp-to-luminaire geometry")?;
    let geometry = match g {
        1.0 => LampGeometry::Vertical,
        2.0 => LampGeometry::HorizontalFixed,
        3.0 => LampGeometry::HorizontalTilting,
        _ => {
            return Err(IesError::BadCode {
                line,
                field: "lamp-to-luminaire geometry",
                value: g,
                expected: "1, 2 or 3",
            });
        }
    };
    let n = tokens.count("number of tilt angles", MAX_TILT_PAIRS)?;
    let angles_deg = tokens.numbers(n, "tilt angles")?;
    let multipliers = tokens.numbers(n, "tilt multipliers")?;
    Ok(TiltTable {
        geometry,
        angles_deg,
        multipliers,
    })
}

fn detect_version(first: &str) -> Option<(IesVersion, Option<String>)> {
    let t = first.trim().to_ascii_uppercase();
    let v = if t.starts_with("IESNA:LM-63-2002") {
        IesVersion::Lm63_2002
    } else if t.starts_with("IES:LM-63-2019") || t.starts_with("IESNA:LM-63-2019") {
        IesVersion::Lm63_2019
    } else if t.starts_with("IESNA:LM-63-1995") {
        IesVersion::Lm63_1995
    } else if t.starts_with("IESNA91") || t.starts_with("IESNA:LM-63-1991") {
        IesVersion::Lm63_1991
    } else if t.starts_with("IESNA95") {
        return Some((
            IesVersion::Lm63_1995,
            Some(format!(
                "non-standard version line {:?} read as LM-63-1995",
                first.trim()
            )),
        ));
    } else if t.starts_with("IESNA") || t.starts_with("IES:") {
        return Some((
            IesVersion::Lm63_2002,
            Some(format!(
                "unknown version line {:?} read as LM-63-2002",
                first.trim()
            )),
        ));
    } else {
        return None;
    };
    Some((v, None))
}

impl IesFile {
    /// Parses LM-63 bytes. A `TILT=<file>` statement is an error here (no folder to look in);
    /// use [`IesFile::read`] to load it relative to the file.
    ///
    /// # Errors
    /// [`IesError`] with the line and what was expected.
    pub fn parse(bytes: &[u8]) -> Result<Self, IesError> {
        Self::parse_with_tilt_resolver(bytes, &mut |_| {
            Err("a TILT file needs the folder of the IES file; use IesFile::read".to_owned())
        })
    }

    /// Reads an LM-63 file from disk, loading a `TILT=<file>` from the same folder.
    ///
    /// # Errors
    /// I/O or parse errors.
    pub fn read(path: &Path) -> Result<Self, IesError> {
        let bytes = read_bounded(path).map_err(|message| IesError::Io {
            path: path.display().to_string(),
            message,
        })?;
        let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::parse_with_tilt_resolver(&bytes, &mut |name| read_bounded(&folder.join(name)))
    }

    /// Parses LM-63 bytes, asking `resolve_tilt_file` for the bytes of a `TILT=<file>`.
    ///
    /// # Errors
    /// [`IesError`] with the line and what was expected.
    pub fn parse_with_tilt_resolver(
        bytes: &[u8],
        resolve_tilt_file: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
    ) -> Result<Self, IesError> {
        let (text, latin1) = decode_text(bytes);
        let mut warnings = Vec::new();
        if latin1 {
            warnings.push("not valid UTF-8; decoded as Latin-1".to_owned());
        }
        let mut lines = text
            .split('\n')
            .map(|l| l.strip_suffix('\r').unwrap_or(l))
            .enumerate()
            .map(|(i, l)| (i + 1, l))
            .peekable();

        // Version line.
        let mut version = IesVersion::Lm63_1986;
        if let Some(&(_, first)) = lines.peek()
            && let Some((v, warning)) = detect_version(first)
        {
            version = v;
            warnings.extend(warning);
            lines.next();
        }

        // Labels up to TILT.
        let mut keywords: Vec<(String, String)> = Vec::new();
        let mut free_text = Vec::new();
        let mut tilt_spec = None;
        let mut last_line = 0;
        for (line, raw) in lines.by_ref() {
            last_line = line;
            let t = raw.trim();
            let upper = t.to_ascii_uppercase();
            if let Some(rest) = upper.strip_prefix("TILT")
                && rest.trim_start().starts_with('=')
            {
                let value = t[4..].trim_start()[1..].trim().to_owned();
                tilt_spec = Some((line, value));
                break;
            }
            if let Some(rest) = t.strip_prefix('[')
                && let Some(end) = rest.find(']')
            {
                let key = rest[..end].trim().to_ascii_uppercase();
                let value = rest[end + 1..].trim().to_owned();
                if key == "MORE"
                    && let Some(last) = keywords.last_mut()
                {
                    last.1.push('\n');
                    last.1.push_str(&value);
                    continue;
                }
                keywords.push((key, value));
            } else if !t.is_empty() {
                free_text.push(t.to_owned());
            }
        }
        let Some((tilt_line, tilt_value)) = tilt_spec else {
            return Err(IesError::MissingTilt { line: last_line });
        };
        if version == IesVersion::Lm63_2019 {
            for key in ["TEST", "TESTLAB", "ISSUEDATE", "MANUFAC"] {
                if !keywords.iter().any(|(k, _)| k == key) {
                    warnings.push(format!("LM-63-2019 requires [{key}], which is missing"));
                }
            }
        }

        let mut tokens = Tokens::new(lines);
        let tilt = match tilt_value.to_ascii_uppercase().as_str() {
            "NONE" => None,
            "INCLUDE" => Some(read_tilt(&mut tokens)?),
            _ => {
                let tilt_error = |message: String| IesError::TiltFile {
                    line: tilt_line,
                    file_name: tilt_value.clone(),
                    message,
                };
                if version == IesVersion::Lm63_2019 {
                    return Err(tilt_error(
                        "LM-63-2019 allows only TILT=NONE or TILT=INCLUDE".to_owned(),
                    ));
                }
                let tilt_bytes = resolve_tilt_file(&tilt_value).map_err(tilt_error)?;
                let (tilt_text, _) = decode_text(&tilt_bytes);
                let mut tilt_tokens =
                    Tokens::new(tilt_text.lines().enumerate().map(|(i, l)| (i + 1, l)));
                Some(
                    read_tilt(&mut tilt_tokens)
                        .map_err(|e| tilt_error(format!("in the TILT file: {e}")))?,
                )
            }
        };

        // Record 1.
        let (lamp_count, _) = tokens.number("number of lamps")?;
        let (lumens_per_lamp, _) = tokens.number("lumens per lamp")?;
        let (candela_multiplier, _) = tokens.number("candela multiplier")?;
        let count_line = tokens.line();
        let nv = tokens.count("number of vertical angles", MAX_ANGLES)?;
        let nh = tokens.count("number of horizontal angles", MAX_ANGLES)?;
        if nv + nh > MAX_ANGLES || nv * nh > MAX_INTENSITY_VALUES {
            return Err(IesError::BadCount {
                line: count_line,
                field: "number of vertical × horizontal angles",
                value: (nv * nh) as f64,
                max: MAX_INTENSITY_VALUES,
            });
        }
        let (ptype, ptype_line) = tokens.number("photometric type")?;
        let photometric_type = match ptype {
            1.0 => PhotometricType::C,
            2.0 => PhotometricType::B,
            3.0 => PhotometricType::A,
            _ => {
                return Err(IesError::BadCode {
                    line: ptype_line,
                    field: "photometric type",
                    value: ptype,
                    expected: "1 (C), 2 (B) or 3 (A)",
                });
            }
        };
        let (units, units_line) = tokens.number("units type")?;
        let m_per_unit = match units {
            1.0 => M_PER_FT,
            2.0 => 1.0,
            _ => {
                return Err(IesError::BadCode {
                    line: units_line,
                    field: "units type",
                    value: units,
                    expected: "1 (feet) or 2 (metres)",
                });
            }
        };
        let (width, _) = tokens.number("luminous opening width")?;
        let (length, _) = tokens.number("luminous opening length")?;
        let (height, _) = tokens.number("luminous opening height")?;
        // Record 2.
        let (ballast_factor, _) = tokens.number("ballast factor")?;
        let (file_generation_type, _) = tokens.number("future use / file generation type")?;
        let (input_watts, _) = tokens.number("input watts")?;
        // Data.
        let vertical_deg = tokens.increasing_angles(nv, "vertical angles")?;
        let horizontal_deg = tokens.increasing_angles(nh, "horizontal angles")?;
        let candela = tokens.numbers(nv * nh, "candela values")?;
        let scaled: Vec<f64> = candela.iter().map(|c| c * candela_multiplier).collect();
        warnings.extend(super::intensity_warning(&scaled, "cd"));
        if tokens.remaining() > 0 {
            warnings.push(format!(
                "{} extra values after the candela table (from line {}) ignored",
                tokens.remaining(),
                tokens.line()
            ));
        }
        if lumens_per_lamp < 0.0 && (lumens_per_lamp + 1.0).abs() > 1e-9 {
            warnings.push(format!(
                "lumens per lamp {lumens_per_lamp} is negative but not −1; read as absolute"
            ));
        }
        let file = Self {
            version,
            keywords,
            free_text,
            tilt,
            lamp_count,
            lumens_per_lamp,
            candela_multiplier,
            photometric_type,
            opening_m: [width * m_per_unit, length * m_per_unit, height * m_per_unit],
            ballast_factor,
            file_generation_type,
            input_watts,
            vertical_deg,
            horizontal_deg,
            candela,
            warnings,
        };
        let mut file = file;
        if let Some(w) = file.symmetry_warning() {
            file.warnings.push(w);
        }
        Ok(file)
    }

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
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// A hand-written LM-63-2019 file (lighting.md §4.1): TILT=INCLUDE with geometry 1 and the
    /// 0/45/90/180° → 1.00/0.90/0.80/1.00 table of eulumdat-rs's TILT_TEST_SYNTHETIC, an
    /// isotropic 100 cd lower hemisphere (5 vertical angles, axial), metres, CR LF endings.
    const LM63_2019_TILT: &str = "IES:LM-63-2019\r\n\
        [TEST] PM-2026-001\r\n\
        [TESTLAB] Photomontage test fixture\r\n\
        [ISSUEDATE] 21-NOV-2026\r\n\
        [MANUFAC] Nobody\r\n\
        [LUMINAIRE] Hand-written tilt test\r\n\
        [MORE] second line of the description\r\n\
        TILT=INCLUDE\r\n\
        1\r\n\
        4\r\n\
        0 45 90 180\r\n\
        1.00 0.90 0.80 1.00\r\n\
        1 1000 1 5 1 1 2 0.1 0.1 0\r\n\
        1.0 1.10000 20\r\n\
        0 22.5 45 67.5 90\r\n\
        0\r\n\
        100 100 100 100 100\r\n";

    #[test]
    fn lm63_2019_with_tilt_include_applies_the_tilt() {
        use crate::luminaire::Luminaire;
        use nalgebra::{Point3, Rotation3, Vector3};
        let f = IesFile::parse(LM63_2019_TILT.as_bytes()).unwrap();
        assert_eq!(f.version, IesVersion::Lm63_2019);
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
        assert_eq!(
            f.keyword("luminaire"),
            Some("Hand-written tilt test\nsecond line of the description")
        );
        let tilt = f.tilt.clone().unwrap();
        assert_eq!(tilt.geometry, LampGeometry::Vertical);
        assert_eq!(tilt.angles_deg, vec![0.0, 45.0, 90.0, 180.0]);
        assert_relative_eq!(f.file_generation_type, 1.1);
        let web = f.distribution().unwrap();
        // 100 cd over the lower hemisphere: 200π lm.
        assert_relative_eq!(
            web.total_flux_lm(),
            200.0 * std::f64::consts::PI,
            max_relative = 1e-12
        );
        let mut lum = Luminaire::new(web, Point3::origin());
        lum.tilt = f.tilt.clone();
        // Tilted 45° about x: the multiplier is 0.90 in every direction the web lights.
        lum.world_from_luminaire =
            Rotation3::from_axis_angle(&Vector3::x_axis(), 45f64.to_radians());
        assert_relative_eq!(lum.tilt_deg(), 45.0, epsilon = 1e-9);
        let aim = lum.world_from_luminaire * Vector3::new(0.0, 0.0, -1.0);
        assert_relative_eq!(lum.intensity_toward_cd(&aim), 90.0, epsilon = 1e-9);
        // 67.5° lies halfway between 45° (0.90) and 90° (0.80).
        lum.world_from_luminaire =
            Rotation3::from_axis_angle(&Vector3::x_axis(), 67.5f64.to_radians());
        let aim = lum.world_from_luminaire * Vector3::new(0.0, 0.0, -1.0);
        assert_relative_eq!(lum.intensity_toward_cd(&aim), 85.0, epsilon = 1e-9);
    }

    #[test]
    fn old_style_numbers_split_over_lines() {
        // IESNA91, record 1 split over 4 lines, Fortran numbers, leading spaces, commas.
        let text = "IESNA91\n[TEST] x\n   TILT=NONE\n1 1000. 1\n3 1\n1\n1\n.5 .5 .0\n1 1 10\n\
                    0, 45, 90\n0\n 10 5.\n 0\n";
        let f = IesFile::parse(text.as_bytes()).unwrap();
        assert_eq!(f.version, IesVersion::Lm63_1991);
        assert_relative_eq!(f.opening_m[0], 0.5 * M_PER_FT);
        assert_eq!(f.candela, vec![10.0, 5.0, 0.0]);
        assert_eq!(f.symmetry(), Symmetry::Axial);
    }

    #[test]
    fn latin1_bytes_are_decoded_with_a_warning() {
        let mut bytes =
            b"ERCO 70\xb0 wide\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 1\n0 90\n0\n7 3\n".to_vec();
        bytes.push(b'\n');
        let f = IesFile::parse(&bytes).unwrap();
        assert_eq!(f.version, IesVersion::Lm63_1986);
        assert_eq!(f.free_text, vec!["ERCO 70° wide".to_owned()]);
        assert!(f.is_absolute());
        assert!(f.warnings.iter().any(|w| w.contains("Latin-1")));
    }

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        let missing = IesFile::parse(b"IESNA:LM-63-2002\n[TEST] a\n");
        assert_eq!(missing, Err(IesError::MissingTilt { line: 3 }));
        let bad = IesFile::parse(b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 x 1 1 2 0 0 0\n");
        assert_eq!(
            bad,
            Err(IesError::BadNumber {
                line: 3,
                field: "number of vertical angles".to_owned(),
                token: "x".to_owned()
            })
        );
        let short =
            IesFile::parse(b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 1\n0 45\n");
        assert!(
            matches!(short, Err(IesError::UnexpectedEnd { line: 5, ref expected }) if expected.starts_with("3 vertical angles")),
            "{short:?}"
        );
        let tilt_file = IesFile::parse(b"IESNA:LM-63-2002\nTILT=lamp.tlt\n");
        assert!(matches!(tilt_file, Err(IesError::TiltFile { line: 2, .. })));
    }

    #[test]
    fn tilt_file_is_loaded_through_the_resolver() {
        let text =
            b"IESNA:LM-63-2002\nTILT=lamp.tlt\n1 1000 1 2 1 1 2 0 0 0\n1 1 1\n0 90\n0\n7 3\n";
        let f = IesFile::parse_with_tilt_resolver(text, &mut |name| {
            assert_eq!(name, "lamp.tlt");
            Ok(b"3\n2\n0 90\n1 0.5\n".to_vec())
        })
        .unwrap();
        let t = f.tilt.unwrap();
        assert_eq!(t.geometry, LampGeometry::HorizontalTilting);
        assert_relative_eq!(t.multiplier_at(45.0), 0.75);
    }

    #[test]
    fn absurd_counts_are_refused_before_allocating() {
        let text = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 1000000000 1000000000 1 2 0 0 0\n";
        assert_eq!(
            IesFile::parse(text),
            Err(IesError::BadCount {
                line: 3,
                field: "number of vertical angles",
                value: 1e9,
                max: MAX_ANGLES
            })
        );
        let product = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 50000 50000 1 2 0 0 0\n";
        assert!(matches!(
            IesFile::parse(product),
            Err(IesError::BadCount { line: 3, .. })
        ));
        // Plausible counts but too few numbers: refused by comparing with what is there.
        let few = b"IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 90000 10 1 2 0 0 0\n1 1 1\n0\n";
        assert!(matches!(
            IesFile::parse(few),
            Err(IesError::UnexpectedEnd { .. })
        ));
    }

    proptest! {
        #[test]
        fn never_panics_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
            let _ = IesFile::parse(&bytes);
        }

        #[test]
        fn never_panics_on_mutated_fixture(
            edits in proptest::collection::vec((0usize..600, any::<u8>()), 1..8),
            cut in 0usize..600,
        ) {
            let mut bytes = LM63_2019_TILT.as_bytes().to_vec();
            for (pos, b) in edits {
                let i = pos % bytes.len();
                bytes[i] = b;
            }
            bytes.truncate(cut.max(1).min(bytes.len()));
            if let Ok(f) = IesFile::parse(&bytes) {
                let _ = f.distribution().map(|w| w.total_flux_lm());
            }
        }
    }
}
