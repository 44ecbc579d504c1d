//! The closed sets of names the site file uses: a CAD model's length unit and up axis, and the
//! sky model of the lighting fit, each parsed from and written as the short name the file holds
//! (`docs/site-format.md`).

use serde::{Deserialize, Serialize};

/// Length unit of a CAD model's coordinates, as the site file names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ModelUnits {
    /// Metres (`m`).
    #[default]
    #[serde(rename = "m")]
    Metre,
    /// Centimetres (`cm`).
    #[serde(rename = "cm")]
    Centimetre,
    /// Millimetres (`mm`).
    #[serde(rename = "mm")]
    Millimetre,
    /// International inches (`in`).
    #[serde(rename = "in")]
    Inch,
    /// International feet (`ft`).
    #[serde(rename = "ft")]
    Foot,
}

impl ModelUnits {
    /// Every unit, in the order the studio lists them.
    pub const ALL: [Self; 5] = [
        Self::Metre,
        Self::Centimetre,
        Self::Millimetre,
        Self::Inch,
        Self::Foot,
    ];

    /// The name in the site file (`m`, `cm`, …).
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Metre => "m",
            Self::Centimetre => "cm",
            Self::Millimetre => "mm",
            Self::Inch => "in",
            Self::Foot => "ft",
        }
    }

    /// The importer's unit.
    #[must_use]
    pub fn length_unit(self) -> crate::scene::LengthUnit {
        use crate::scene::LengthUnit as L;
        match self {
            Self::Metre => L::Metre,
            Self::Centimetre => L::Centimetre,
            Self::Millimetre => L::Millimetre,
            Self::Inch => L::Inch,
            Self::Foot => L::Foot,
        }
    }
}

impl std::str::FromStr for ModelUnits {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|u| u.as_str() == name)
            .ok_or_else(|| format!("`{name}` is not one of m, cm, mm, in, ft"))
    }
}

impl std::fmt::Display for ModelUnits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Which axis of a CAD model's file points up, as the site file names it (`z` or `y`; the
/// capitals are read too).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ModelUpAxis {
    /// +Z up (`z`).
    #[default]
    #[serde(rename = "z", alias = "Z")]
    Z,
    /// +Y up (`y`).
    #[serde(rename = "y", alias = "Y")]
    Y,
}

impl ModelUpAxis {
    /// The name in the site file.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Z => "z",
            Self::Y => "y",
        }
    }

    /// The importer's axis.
    #[must_use]
    pub fn up_axis(self) -> crate::scene::UpAxis {
        match self {
            Self::Z => crate::scene::UpAxis::Z,
            Self::Y => crate::scene::UpAxis::Y,
        }
    }
}

impl std::str::FromStr for ModelUpAxis {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        match name {
            "z" | "Z" => Ok(Self::Z),
            "y" | "Y" => Ok(Self::Y),
            _ => Err(format!("`{name}` is not `z` or `y`")),
        }
    }
}

impl std::fmt::Display for ModelUpAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The sky model of `[lighting]`: `uniform`, `cie_overcast`, `cie_general:N` (N = 1–15) or
/// `perez` (its inputs in `[lighting.perez]`); a closed set, checked when the file is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum SkyModelName {
    /// Constant luminance.
    Uniform,
    /// The traditional CIE overcast sky.
    CieOvercast,
    /// CIE standard general sky of this type (1–15).
    CieGeneral(u8),
    /// The Perez all-weather sky of `[lighting.perez]`.
    Perez,
}

impl SkyModelName {
    /// Whether the sky's distribution depends on the sun's position.
    #[must_use]
    pub fn needs_sun(self) -> bool {
        matches!(self, Self::CieGeneral(_) | Self::Perez)
    }
}

impl std::str::FromStr for SkyModelName {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        match name {
            "uniform" => Ok(Self::Uniform),
            "cie_overcast" => Ok(Self::CieOvercast),
            "perez" => Ok(Self::Perez),
            other => other
                .strip_prefix("cie_general:")
                .and_then(|n| n.parse::<u8>().ok())
                .filter(|n| (1..=15).contains(n))
                .map(Self::CieGeneral)
                .ok_or_else(|| {
                    format!(
                        "`{name}` is not `uniform`, `cie_overcast`, `cie_general:N` (N = 1–15) \
                         or `perez`"
                    )
                }),
        }
    }
}

impl TryFrom<String> for SkyModelName {
    type Error = String;

    fn try_from(name: String) -> Result<Self, String> {
        name.parse()
    }
}

impl From<SkyModelName> for String {
    fn from(name: SkyModelName) -> Self {
        name.to_string()
    }
}

impl std::fmt::Display for SkyModelName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Uniform => f.write_str("uniform"),
            Self::CieOvercast => f.write_str("cie_overcast"),
            Self::CieGeneral(n) => write!(f, "cie_general:{n}"),
            Self::Perez => f.write_str("perez"),
        }
    }
}
