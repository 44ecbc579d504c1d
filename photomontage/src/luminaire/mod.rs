//! Luminaire photometry: IES LM-63 and EULUMDAT files, the photometric web they describe, a
//! luminaire as a light source, a least-squares curve fit of intensity curves and a polar plot.
//!
//! Sources: IES LM-63-1986/1991/1995/2002 and ANSI/IES LM-63-2019 (summarised in
//! `reference/lighting.md` §4.1, after Radiance `ies2rad.c`); EULUMDAT (Stockmar 1990/1998,
//! lighting.md §4.2); Üncü & Kayakuş, goniophotometric data and polynomial least squares (§2.1);
//! Durisch 1992 §3.2 for luminaires as light sources in a photomontage.
//!
//! - [`ies`]: LM-63 parser (all editions, TILT, types A/B/C, absolute photometry).
//! - [`eulumdat`]: `.ldt` parser (Isym 0–4, lamp sets, comma decimals, non-equidistant angles).
//! - [`distribution`]: [`PhotometricWeb`] (I(C, γ), flux, max), tilt tables.
//! - [`source`]: [`Luminaire`], a positioned and aimed light source.
//! - [`curve_fit`]: polynomial least-squares fit of intensity curves.
//! - [`polar_plot`]: polar intensity diagram as an image.
//!
//! # Known limitations
//! Text is read as UTF-8 or, failing that, Latin-1; other code pages (e.g. CP1252 punctuation)
//! decode as the corresponding Latin-1 characters. Format detection by [`PhotometricFile::parse`]
//! looks at the content (an `.ldt` has no magic line), so a file that is neither may be reported
//! as a failed EULUMDAT parse.

pub mod curve_fit;
pub mod distribution;
pub mod eulumdat;
pub mod ies;
pub mod polar_plot;
pub mod source;

pub use distribution::{
    DistributionError, LampGeometry, PhotometricType, PhotometricWeb, Symmetry, TiltTable,
};
pub use eulumdat::{EulumdatError, EulumdatFile};
pub use ies::{IesError, IesFile, IesVersion};
pub use source::Luminaire;

use std::path::Path;
use thiserror::Error;

/// Intensities above this are implausible for any luminaire (the brightest searchlights reach
/// ~10⁹ cd; floodlights ~10⁶ cd) and usually mean a wrong multiplier or a corrupt file.
pub const IMPLAUSIBLE_INTENSITY: f64 = 1e9;

/// A warning for negative or implausibly large values in an intensity table, naming the first
/// offender; `None` when all values are plausible.
pub(crate) fn intensity_warning(values: &[f64], unit: &str) -> Option<String> {
    let negative = values.iter().filter(|v| **v < 0.0).count();
    let huge = values
        .iter()
        .filter(|v| **v > IMPLAUSIBLE_INTENSITY)
        .count();
    let first = |pred: &dyn Fn(f64) -> bool| values.iter().position(|v| pred(*v)).unwrap_or(0);
    match (negative, huge) {
        (0, 0) => None,
        (n, 0) => {
            let i = first(&|v| v < 0.0);
            Some(format!(
                "{n} negative intensities (the first, value {} of the table, is {} {unit}); read as given",
                i + 1,
                values[i]
            ))
        }
        (_, h) => {
            let i = first(&|v| v > IMPLAUSIBLE_INTENSITY);
            Some(format!(
                "{h} intensities above {IMPLAUSIBLE_INTENSITY:e} {unit} (the first, value {} of the table, is {:e} {unit}): check the multiplier and the file; {negative} negative",
                i + 1,
                values[i]
            ))
        }
    }
}

/// Most angles (horizontal + vertical) a parser accepts from a header before allocating.
pub const MAX_ANGLES: usize = 100_000;
/// Most intensity values (planes × angles) a parser accepts from a header before allocating.
pub const MAX_INTENSITY_VALUES: usize = 2_000_000;
/// Largest photometric file read from disk (bytes); real files are below 2 MB.
pub const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// Decodes bytes as UTF-8, or as Latin-1 when they are not valid UTF-8 (the second value is
/// `true` then). A leading UTF-8 byte-order mark is dropped.
#[must_use]
pub fn decode_text(bytes: &[u8]) -> (String, bool) {
    let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => (s.to_owned(), false),
        Err(_) => (bytes.iter().map(|&b| char::from(b)).collect(), true),
    }
}

/// Reads a whole file, refusing files larger than [`MAX_FILE_BYTES`] and anything but a regular
/// file (a TILT or photometric path naming `/dev/zero` would otherwise read for ever).
pub(crate) fn read_bounded(path: &Path) -> Result<Vec<u8>, String> {
    crate::bounded_read::read_bounded(path, MAX_FILE_BYTES).map_err(|e| match e {
        crate::bounded_read::BoundedReadError::Io { source, .. } => source.to_string(),
        other => other.to_string(),
    })
}

/// Either kind of photometric file.
#[derive(Debug, Clone, PartialEq)]
pub enum PhotometricFile {
    /// An IES LM-63 file (boxed, like the other variant, to keep the enum small).
    Ies(Box<IesFile>),
    /// An EULUMDAT file.
    Eulumdat(Box<EulumdatFile>),
}

/// Why a photometric file could not be read.
#[derive(Debug, Error)]
pub enum LuminaireError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// An IES parse error.
    #[error(transparent)]
    Ies(#[from] IesError),
    /// An EULUMDAT parse error.
    #[error(transparent)]
    Eulumdat(#[from] EulumdatError),
    /// The photometric web could not be built.
    #[error(transparent)]
    Distribution(#[from] DistributionError),
}

/// True when the text looks like LM-63: a `TILT=` line within the first 200 lines, or an
/// `IES`-tagged first line.
fn looks_like_ies(text: &str) -> bool {
    text.lines().take(200).any(|l| {
        let t = l.trim_start().to_ascii_uppercase();
        t.starts_with("TILT") && t.contains('=') || t.starts_with("IESNA") || t.starts_with("IES:")
    })
}

impl PhotometricFile {
    /// Parses bytes as IES LM-63 when they look like it, else as EULUMDAT.
    ///
    /// # Errors
    /// The chosen parser's error.
    pub fn parse(bytes: &[u8]) -> Result<Self, LuminaireError> {
        let (text, _) = decode_text(bytes);
        if looks_like_ies(&text) {
            Ok(Self::Ies(Box::new(IesFile::parse(bytes)?)))
        } else {
            Ok(Self::Eulumdat(Box::new(EulumdatFile::parse(bytes)?)))
        }
    }

    /// Reads a file; `.ies` / `.ldt` extensions choose the parser, otherwise the content does.
    /// An IES `TILT=<file>` is loaded relative to the file's folder.
    ///
    /// # Errors
    /// I/O or parse errors.
    pub fn read(path: &Path) -> Result<Self, LuminaireError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("ies") => Ok(Self::Ies(Box::new(IesFile::read(path)?))),
            Some("ldt") => Ok(Self::Eulumdat(Box::new(EulumdatFile::read(path)?))),
            _ => {
                let bytes = read_bounded(path).map_err(|message| LuminaireError::Io {
                    path: path.display().to_string(),
                    message,
                })?;
                Self::parse(&bytes)
            }
        }
    }

    /// A format label: `ies:LM-63-2002`, `eulumdat`, ….
    #[must_use]
    pub fn format_label(&self) -> String {
        match self {
            Self::Ies(f) => format!("ies:{}", f.version.label()),
            Self::Eulumdat(_) => "eulumdat".to_owned(),
        }
    }

    /// The absolute intensity distribution (first lamp set for EULUMDAT; tilt 0 for IES).
    ///
    /// # Errors
    /// When the angles or values cannot form a web.
    pub fn distribution(&self) -> Result<PhotometricWeb, LuminaireError> {
        Ok(match self {
            Self::Ies(f) => f.distribution()?,
            Self::Eulumdat(f) => f.distribution()?,
        })
    }

    /// Non-fatal oddities found while parsing.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        match self {
            Self::Ies(f) => &f.warnings,
            Self::Eulumdat(f) => &f.warnings,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An IESNA91 file with 3 vertical angles on line 10, one horizontal angle on line 11 and
    /// candela values on line 12.
    fn ies(vertical: &str, candela: &str) -> String {
        format!(
            "IESNA91\n[TEST] x\n   TILT=NONE\n1 1000. 1\n3 1\n1\n1\n.5 .5 .0\n1 1 10\n{vertical}\n0\n{candela}\n"
        )
    }

    #[test]
    fn ies_angle_order_error_names_its_line() {
        let err = IesFile::parse(ies("0, 90, 45", "10 5 0").as_bytes()).unwrap_err();
        assert!(
            matches!(
                err,
                IesError::AngleOrder {
                    line: 10,
                    field: "vertical angles",
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(
            err.to_string().starts_with("line 10: vertical angles"),
            "{err}"
        );
    }

    #[test]
    fn negative_and_huge_candela_warn() {
        let plain = IesFile::parse(ies("0 45 90", "10 5 0").as_bytes()).unwrap();
        assert!(plain.warnings.is_empty(), "{:?}", plain.warnings);
        let huge = IesFile::parse(ies("0 45 90", "1e308 5 0").as_bytes()).unwrap();
        assert!(
            huge.warnings.iter().any(|w| w.contains("1e308")),
            "{:?}",
            huge.warnings
        );
        let negative = IesFile::parse(ies("0 45 90", "10 -5 0").as_bytes()).unwrap();
        assert!(
            negative
                .warnings
                .iter()
                .any(|w| w.contains("1 negative") && w.contains("value 2")),
            "{:?}",
            negative.warnings
        );
    }

    #[test]
    fn a_device_file_is_refused_naming_it() {
        let err = PhotometricFile::read(Path::new("/dev/zero")).unwrap_err();
        assert!(
            err.to_string().contains("/dev/zero") && err.to_string().contains("regular file"),
            "{err}"
        );
    }

    #[test]
    fn intensity_warning_counts_and_names_the_first() {
        assert_eq!(intensity_warning(&[0.0, 10.0, 1e6], "cd"), None);
        let w = intensity_warning(&[1.0, -2.0, -3.0], "cd/klm").unwrap();
        assert!(
            w.starts_with("2 negative") && w.contains("-2 cd/klm"),
            "{w}"
        );
        let w = intensity_warning(&[1.0, 2e9, -1.0], "cd").unwrap();
        assert!(
            w.starts_with("1 intensities above") && w.contains("2e9"),
            "{w}"
        );
    }
}
