//! Reading EULUMDAT (`.ldt`) bytes into an [`EulumdatFile`]: the fixed line layout of the
//! header, the lamp sets, the C and γ angles and the intensity rows, each field checked and
//! named by line in errors (see the module doc of [`super`] for the format and what is accepted).

use super::{EulumdatError, EulumdatFile, LampSet, MAX_LAMP_SETS};
use crate::luminaire::{MAX_ANGLES, MAX_INTENSITY_VALUES, decode_text, read_bounded};
use std::path::Path;

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
        warnings.extend(crate::luminaire::intensity_warning(
            &intensity_cd_per_klm,
            "cd/klm",
        ));
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
}
