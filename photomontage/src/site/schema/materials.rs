//! The site file's material design tables (Tonn & Donath's colour and material design):
//! `[[materials]]`, site definitions of materials that override the material library's and the
//! CAD files' material of the same name, each with an optional designer's colour
//! (`docs/file-formats.md`); and `[[palette]]`, the site's named colours.

use serde::{Deserialize, Serialize};

use crate::scene::Material;

/// A site material: every field of a material-library entry ([`Material`]) plus `colour`, a
/// designer's colour (`#rrggbb`, `lab(L, a, b)`, `lch(L, C, h)`, D65) that, when given, sets the
/// diffuse reflectance (it wins over `diffuse_rgb`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "toml::Table", into = "toml::Table")]
pub struct SiteMaterial {
    /// The material (name, diffuse, specular, glass …), as in the material library.
    pub material: Material,
    /// The designer's colour text, kept as typed.
    pub colour: Option<String>,
}

impl SiteMaterial {
    /// A material with a designer's colour.
    #[must_use]
    pub fn new(material: Material, colour: Option<String>) -> Self {
        Self { material, colour }
    }
}

impl TryFrom<toml::Table> for SiteMaterial {
    type Error = String;

    fn try_from(mut table: toml::Table) -> Result<Self, Self::Error> {
        let name = table
            .get("name")
            .and_then(toml::Value::as_str)
            .unwrap_or("?")
            .to_owned();
        let colour = match table.remove("colour") {
            None => None,
            Some(toml::Value::String(s)) => Some(s),
            Some(other) => {
                return Err(format!(
                    "[[materials]] `{name}`: colour must be a string such as \"#a0522d\", got {other}"
                ));
            }
        };
        let material = Material::deserialize(toml::Value::Table(table))
            .map_err(|e| format!("[[materials]] `{name}`: {e}"))?;
        Ok(Self { material, colour })
    }
}

impl From<SiteMaterial> for toml::Table {
    fn from(m: SiteMaterial) -> Self {
        // A material always serialises to a table (every field is a number, string, array or
        // table; `None` fields are left out).
        let mut table = toml::Table::try_from(&m.material).unwrap_or_default();
        if let Some(c) = m.colour {
            table.insert("colour".to_owned(), toml::Value::String(c));
        }
        table
    }
}

/// A named colour of the site's palette.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaletteColour {
    /// The colour's name (e.g. "Sienna facade").
    pub name: String,
    /// The colour as `#rrggbb`, `lab(L, a, b)` or `lch(L, C, h)` (D65).
    pub colour: String,
}
