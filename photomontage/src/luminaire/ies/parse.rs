//! Reading LM-63 bytes into an [`IesFile`]: the version line, labels and keywords, the `TILT`
//! statement and records, records 1 and 2, the angles and the candela rows, read as a stream of
//! numbers with line numbers kept for errors (IES LM-63-1995/2002, ANSI/IES LM-63-2019; see the
//! module doc of [`super`] for the layout and the oddities accepted).
//!
//! # Known limitations
//! See [`super`]: record 2's second value is stored, not applied.

use super::{IesError, IesFile, IesVersion, M_PER_FT, MAX_TILT_PAIRS};
use crate::luminaire::distribution::{LampGeometry, PhotometricType, TiltTable};
use crate::luminaire::{MAX_ANGLES, MAX_INTENSITY_VALUES, decode_text, read_bounded};
use std::path::Path;

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
        warnings.extend(crate::luminaire::intensity_warning(&scaled, "cd"));
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
}
