//! The site file's design variants (`[[variants]]`, issue 17 item 4): named alternatives of the
//! proposal that are rendered under the same light and compared side by side. A variant says
//! which models are visible, where some of them are placed, and which materials it redefines;
//! everything else (photos, cameras, lighting, render settings, seed) is the site's.
//! Applying one is [`crate::site::variants::variant_document`].

use serde::{Deserialize, Serialize};

use super::Placement;
use crate::scene::Material;

/// One design variant of the site.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Unique, non-empty name (shown on the comparison sheet).
    pub name: String,
    /// Ids of the models shown in this variant; every other model is hidden. Absent: the
    /// site's own `visible` flags.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible_models: Option<Vec<String>>,
    /// Placements replacing the site's placement of a model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub placements: Vec<VariantPlacement>,
    /// Materials replacing, by name, those of the scene (applied after the site's material
    /// library): same fields as a material library's `[[material]]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<Material>,
    /// Set only on the variant of a document made by
    /// [`crate::site::variants::variant_document`]: the scene builder applies its materials.
    /// Never read from or written to a file.
    #[serde(skip)]
    pub applied: bool,
}

impl Variant {
    /// A variant with the site's own visibility, placements and materials.
    #[must_use]
    pub fn named(name: &str) -> Self {
        Self {
            name: name.to_owned(),
            visible_models: None,
            placements: Vec::new(),
            materials: Vec::new(),
            applied: false,
        }
    }
}

/// A model's placement in one variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantPlacement {
    /// The model's id.
    pub model: String,
    /// The placement that replaces the site's (same fields as `[models.placement]`).
    #[serde(default)]
    pub placement: Placement,
}
