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
use super::{MAX_ANGLES, MAX_INTENSITY_VALUES, decode_text, read_bounded};
use std::path::Path;
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

fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim();
    let v = if t.contains(',') && !t.contains('.') {
        t.replace(',', ".").parse::<f64>().ok()
    } else {
        t.parse::<f64>().ok()
    }?;
    v.is_finite().then_some(v)
}

struct Lines<'a> {
    lines: Vec<&'a str>,
}

impl<'a> Lines<'a> {
    /// Line `n` (1-based).
    fn text(&self, n: usize, expected: &str) -> Result<&'a str, EulumdatError> {
        self.lines
            .get(n - 1)
            .copied()
            .ok_or_else(|| EulumdatError::UnexpectedEnd {
                line: n,
                expected: expected.to_owned(),
            })
    }

    fn number(&self, n: usize, field: &str) -> Result<f64, EulumdatError> {
        let t = self.text(n, field)?;
        parse_number(t).ok_or_else(|| EulumdatError::BadNumber {
            line: n,
            field: field.to_owned(),
            found: t.trim().chars().take(40).collect(),
        })
    }

    fn count(
        &self,
        n: usize,
        field: &'static str,
        min: usize,
        max: usize,
    ) -> Result<usize, EulumdatError> {
        let v = self.number(n, field)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(EulumdatError::BadCount {
                line: n,
                field,
                value: v,
                min,
                max,
            });
        }
        Ok(v as usize)
    }
}

impl EulumdatFile {
    /// Reads an `.ldt` file.
    ///
    /// # Errors
    /// I/O or parse errors.
    pub fn read(path: &Path) -> Result<Self, EulumdatError> {
        let bytes = read_bounded(path).map_err(|message| EulumdatError::Io {
            path: path.display().to_string(),
            message,
        })?;
        Self::parse(&bytes)
    }

    /// Parses EULUMDAT bytes.
    ///
    /// # Errors
    /// [`EulumdatError`] naming the line and what was expected.
    pub fn parse(bytes: &[u8]) -> Result<Self, EulumdatError> {
        let (text, latin1) = decode_text(bytes);
        let mut warnings = Vec::new();
        if latin1 {
            warnings.push("not valid UTF-8; decoded as Latin-1".to_owned());
        }
        let lines = Lines {
            lines: text
                .split('\n')
                .map(|l| l.strip_suffix('\r').unwrap_or(l))
                .collect(),
        };
        let text_line = |n: usize, what: &str| -> Result<String, EulumdatError> {
            Ok(lines.text(n, what)?.trim().to_owned())
        };
        let company = text_line(1, "company identification")?;
        let type_indicator = lines.number(2, "type indicator Ityp")?;
        let isym = lines.number(3, "symmetry indicator Isym")?;
        let symmetry_code = match isym {
            0.0 => 0,
            1.0 => 1,
            2.0 => 2,
            3.0 => 3,
            4.0 => 4,
            _ => return Err(EulumdatError::BadSymmetry { value: isym }),
        };
        let mc = lines.count(4, "number of C planes Mc", 1, MAX_ANGLES)?;
        let c_step_deg = lines.number(5, "C-plane step Dc")?;
        let ng = lines.count(6, "number of gamma angles Ng", 1, MAX_ANGLES)?;
        let gamma_step_deg = lines.number(7, "gamma step Dg")?;
        if mc + ng > MAX_ANGLES {
            return Err(EulumdatError::BadCount {
                line: 6,
                field: "Mc + Ng",
                value: (mc + ng) as f64,
                min: 2,
                max: MAX_ANGLES,
            });
        }
        let text_fields = [
            text_line(8, "measurement report number")?,
            text_line(9, "luminaire name")?,
            text_line(10, "luminaire number")?,
            text_line(11, "file name")?,
            text_line(12, "date/user")?,
        ];
        let n = |line: usize, field: &str| lines.number(line, field);
        let luminaire_size_mm = [
            n(13, "luminaire length/diameter")?,
            n(14, "luminaire width")?,
            n(15, "luminaire height")?,
        ];
        let luminous_area_mm = [
            n(16, "luminous area length/diameter")?,
            n(17, "luminous area width")?,
        ];
        let luminous_height_mm = [
            n(18, "luminous height C0")?,
            n(19, "luminous height C90")?,
            n(20, "luminous height C180")?,
            n(21, "luminous height C270")?,
        ];
        let downward_flux_fraction_percent = n(22, "downward flux fraction DFF")?;
        let light_output_ratio_percent = n(23, "light output ratio LORL")?;
        let conversion_factor = n(24, "intensity conversion factor")?;
        let measurement_tilt_deg = n(25, "tilt during measurement")?;
        let n_sets = lines.count(26, "number of lamp sets", 1, MAX_LAMP_SETS)?;
        let mut lamp_sets = Vec::with_capacity(n_sets);
        for s in 0..n_sets {
            let base = 27 + 6 * s;
            let power_text = lines.text(base + 5, "lamp wattage")?;
            let power_w = parse_number(power_text);
            if power_w.is_none() {
                warnings.push(format!(
                    "line {}: lamp wattage {:?} is not a number",
                    base + 5,
                    power_text.trim()
                ));
            }
            lamp_sets.push(LampSet {
                lamp_count: n(base, "number of lamps")?,
                lamp_type: text_line(base + 1, "lamp type")?,
                total_flux_lm: n(base + 2, "total luminous flux of lamps")?,
                colour_temperature: text_line(base + 3, "colour temperature")?,
                colour_rendering: text_line(base + 4, "colour rendering")?,
                power_w,
            });
        }
        let dr_line = 27 + 6 * n_sets;
        let mut direct_ratios = [0.0; 10];
        for (k, dr) in direct_ratios.iter_mut().enumerate() {
            *dr = n(dr_line + k, "direct ratio")?;
        }

        // From here: a stream of numbers.
        let first_data_line = dr_line + 10;
        let tokens: Vec<(usize, &str)> = lines
            .lines
            .iter()
            .enumerate()
            .skip(first_data_line - 1)
            .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)))
            .collect();
        let last_line = lines.lines.len();
        let (n_planes, from_deg, to_deg, first_plane) = match symmetry_code {
            0 => (mc, 0.0, 360.0, 0),
            1 => (1, 0.0, 360.0, 0),
            2 => (mc / 2 + 1, 0.0, 180.0, 0),
            3 => (mc / 2 + 1, 270.0, 450.0, 3 * mc / 4),
            _ => (mc / 4 + 1, 0.0, 90.0, 0),
        };
        let n_values = n_planes.saturating_mul(ng);
        if n_values > MAX_INTENSITY_VALUES {
            return Err(EulumdatError::BadCount {
                line: 4,
                field: "stored planes × Ng",
                value: n_values as f64,
                min: 1,
                max: MAX_INTENSITY_VALUES,
            });
        }
        let needed = mc + ng + n_values;
        if tokens.len() < needed {
            return Err(EulumdatError::UnexpectedEnd {
                line: last_line,
                expected: format!(
                    "{mc} C angles, {ng} gamma angles and {n_values} intensities \
                     ({needed} numbers from line {first_data_line}), found {}",
                    tokens.len()
                ),
            });
        }
        let read =
            |range: std::ops::Range<usize>, field: &str| -> Result<Vec<f64>, EulumdatError> {
                tokens[range]
                    .iter()
                    .map(|&(line, t)| {
                        parse_number(t).ok_or_else(|| EulumdatError::BadNumber {
                            line,
                            field: field.to_owned(),
                            found: t.chars().take(40).collect(),
                        })
                    })
                    .collect()
            };
        let c_angles_deg = read(0..mc, "C angle")?;
        let gamma_deg = read(mc..mc + ng, "gamma angle")?;
        let intensity_cd_per_klm = read(mc + ng..needed, "intensity (cd/klm)")?;
        warnings.extend(super::intensity_warning(&intensity_cd_per_klm, "cd/klm"));
        if tokens.len() > needed {
            warnings.push(format!(
                "{} extra values after the intensities ignored",
                tokens.len() - needed
            ));
        }
        let stored_c_deg: Vec<f64> = if symmetry_code == 1 {
            vec![c_angles_deg.first().copied().unwrap_or(0.0)]
        } else {
            // Isym 3 starts at C270 and wraps through C0 to C90 (+360° after the wrap).
            (0..n_planes)
                .map(|k| {
                    let i = first_plane + k;
                    if i < mc {
                        c_angles_deg[i]
                    } else {
                        c_angles_deg[i % mc] + 360.0
                    }
                })
                .collect()
        };
        if symmetry_code >= 2 {
            let first = stored_c_deg.first().copied().unwrap_or(f64::NAN);
            let last = stored_c_deg.last().copied().unwrap_or(f64::NAN);
            let ok = stored_c_deg.len() == n_planes
                && (first - from_deg).abs() < 1e-6
                && (last - to_deg).abs() < 1e-6;
            if !ok {
                return Err(EulumdatError::PlaneRange {
                    line: first_data_line + first_plane,
                    isym: symmetry_code,
                    expected_from_deg: from_deg,
                    expected_to_deg: to_deg,
                    found_from_deg: first,
                    found_to_deg: last,
                });
            }
        }
        Ok(Self {
            company,
            type_indicator,
            symmetry_code,
            c_plane_count: mc,
            c_step_deg,
            gamma_count: ng,
            gamma_step_deg,
            text_fields,
            luminaire_size_mm,
            luminous_area_mm,
            luminous_height_mm,
            downward_flux_fraction_percent,
            light_output_ratio_percent,
            conversion_factor,
            measurement_tilt_deg,
            lamp_sets,
            direct_ratios,
            c_angles_deg,
            gamma_deg,
            stored_c_deg,
            intensity_cd_per_klm,
            warnings,
        })
    }

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
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// Builds a small LDT text: Isym 4, Mc 4 (C 0/90/180/270), Ng 3 (γ 0/90/180 given as
    /// non-equidistant Dg = 0), two lamp sets, comma decimals, CR LF.
    fn quadrant_fixture() -> String {
        let mut l: Vec<String> = vec![
            "Fixture company".into(),
            "1".into(),
            "4".into(),
            "4".into(),
            "90".into(),
            "3".into(),
            "0".into(),
            "R1".into(),
            "Test luminaire".into(),
            "T-1".into(),
            "t.ldt".into(),
            "2026-11-21".into(),
        ];
        for v in [
            "600", "600", "50", "500", "400", "10", "20", "10", "20", "100", "95,5", "1,0", "0",
        ] {
            l.push(v.into());
        }
        l.push("2".into());
        for v in ["1", "LED A", "2000", "3000K", "80", "20,5"] {
            l.push(v.into());
        }
        for v in ["1", "LED B", "3000", "4000K", "80", "n/a"] {
            l.push(v.into());
        }
        for _ in 0..10 {
            l.push("0".into());
        }
        for v in ["0", "90", "180", "270", "0", "90", "180"] {
            l.push(v.into());
        }
        // Stored planes C0 and C90: I(γ) = 100, 50, 0 cd/klm; C90: 200, 60, 0.
        for v in ["100", "50", "0", "200", "60", "0"] {
            l.push(format!("  {v} "));
        }
        l.join("\r\n") + "\r\n"
    }

    #[test]
    fn fixture_parses_with_comma_decimals_and_two_lamp_sets() {
        let f = EulumdatFile::parse(quadrant_fixture().as_bytes()).unwrap();
        assert_eq!(f.symmetry(), Symmetry::Quadrant);
        assert_eq!(f.lamp_sets.len(), 2);
        assert_relative_eq!(f.light_output_ratio_percent, 95.5);
        assert_eq!(f.lamp_sets[0].power_w, Some(20.5));
        assert_eq!(f.lamp_sets[1].power_w, None);
        assert_eq!(f.stored_c_deg, vec![0.0, 90.0]);
        let web = f.distribution().unwrap();
        // 100 cd/klm × 2 klm at nadir; C270 mirrors C90: 60 × 2 at γ 90.
        assert_relative_eq!(web.intensity_cd(0.0, 0.0), 200.0);
        assert_relative_eq!(web.intensity_cd(270.0, 90.0), 120.0);
        assert_relative_eq!(web.intensity_cd(180.0, 45.0), 150.0);
        let second = f.distribution_for_lamp_set(1).unwrap();
        assert_relative_eq!(second.intensity_cd(90.0, 0.0), 600.0);
        assert!(matches!(
            f.distribution_for_lamp_set(2),
            Err(EulumdatError::NoLampSet { index: 2, count: 2 })
        ));
    }

    #[test]
    fn projected_area_of_a_flat_rectangle_and_a_disc() {
        let mut f = EulumdatFile::parse(quadrant_fixture().as_bytes()).unwrap();
        // 0.5 × 0.4 m bottom; side heights 10/20 mm at C0/C90.
        assert_relative_eq!(f.projected_luminous_area_m2(0.0, 0.0), 0.2, epsilon = 1e-12);
        assert_relative_eq!(
            f.projected_luminous_area_m2(90.0, 90.0),
            0.4 * 0.02,
            epsilon = 1e-12
        );
        f.luminous_area_mm = [400.0, 0.0];
        let disc = std::f64::consts::PI * 0.04;
        assert_relative_eq!(
            f.projected_luminous_area_m2(33.0, 60.0),
            disc * 0.5 + 0.4 * 0.01 * 60f64.to_radians().sin(),
            epsilon = 1e-12
        );
    }

    #[test]
    fn errors_name_line_and_field() {
        let text = quadrant_fixture().replace(
            "Fixture company\r\n1\r\n4\r\n4\r\n",
            "Fixture company\r\n1\r\n4\r\nfour\r\n",
        );
        assert_eq!(
            EulumdatFile::parse(text.as_bytes()),
            Err(EulumdatError::BadNumber {
                line: 4,
                field: "number of C planes Mc".to_owned(),
                found: "four".to_owned()
            })
        );
        let absurd = quadrant_fixture().replace("4\r\n90\r\n3\r\n", "4\r\n90\r\n1000000000\r\n");
        assert_eq!(
            EulumdatFile::parse(absurd.as_bytes()),
            Err(EulumdatError::BadCount {
                line: 6,
                field: "number of gamma angles Ng",
                value: 1e9,
                min: 1,
                max: MAX_ANGLES
            })
        );
        let bad_sym = quadrant_fixture().replacen("\r\n4\r\n", "\r\n7\r\n", 1);
        assert_eq!(
            EulumdatFile::parse(bad_sym.as_bytes()),
            Err(EulumdatError::BadSymmetry { value: 7.0 })
        );
        let truncated: String = quadrant_fixture()
            .lines()
            .take(20)
            .collect::<Vec<_>>()
            .join("\n");
        assert!(matches!(
            EulumdatFile::parse(truncated.as_bytes()),
            Err(EulumdatError::UnexpectedEnd { line: 21, .. })
        ));
    }

    proptest! {
        #[test]
        fn never_panics_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
            let _ = EulumdatFile::parse(&bytes);
        }

        #[test]
        fn never_panics_on_mutated_fixture(
            edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..8),
            cut in 0usize..400,
        ) {
            let mut bytes = quadrant_fixture().into_bytes();
            for (pos, b) in edits {
                let i = pos % bytes.len();
                bytes[i] = b;
            }
            bytes.truncate(cut.max(1).min(bytes.len()));
            if let Ok(f) = EulumdatFile::parse(&bytes) {
                let _ = f.distribution().map(|w| w.total_flux_lm());
                let _ = f.luminance_cd_per_m2(10.0, 70.0);
            }
        }
    }
}
