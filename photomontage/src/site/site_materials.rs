//! The site's `[[materials]]` resolved into material-library entries: a designer's colour is
//! converted to linear sRGB ([`crate::colour::designer`]), colours outside the sRGB gamut and
//! reflectances above 1 are clamped with a warning, and the result overlays the site's material
//! library, so every caller of [`super::site_scene::site_material_library`] (renderer, fits,
//! picker, radiosity, studio) sees the same materials.

use super::SiteMaterial;
use super::render_error::{SiteRenderError, SiteWarning};
use crate::colour::designer::{ColourSpec, parse_colour, resolve_linear};
use crate::scene::{Material, MaterialLibrary};

/// A site material resolved for the renderer, with what was changed on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedSiteMaterial {
    /// The material as the renderer uses it (reflectances clamped into [0, 1]).
    pub material: Material,
    /// The parsed colour, when one was given.
    pub colour: Option<ColourSpec>,
    /// Warnings (clamping) for this material.
    pub warnings: Vec<SiteWarning>,
}

fn fmt3(v: [f64; 3]) -> String {
    format!("[{:.4}, {:.4}, {:.4}]", v[0], v[1], v[2])
}

/// Resolves one site material.
///
/// # Errors
/// [`SiteRenderError::SiteMaterial`] for an unparsable colour (naming the entry and the text)
/// or a material the library would refuse (e.g. glass IOR < 1).
pub fn resolve_site_material(
    entry: &SiteMaterial,
) -> Result<ResolvedSiteMaterial, SiteRenderError> {
    let name = entry.material.name.clone();
    let mut material = entry.material.clone();
    let mut warnings = Vec::new();
    let mut colour = None;
    if let Some(text) = &entry.colour {
        let spec = parse_colour(text).map_err(|e| SiteRenderError::SiteMaterial {
            material: name.clone(),
            reason: e.to_string(),
        })?;
        let resolved = spec.resolve();
        if resolved.out_of_gamut {
            warnings.push(SiteWarning::SiteMaterial {
                material: name.clone(),
                message: format!(
                    "colour `{text}` is outside the sRGB gamut (linear {}); clamped to {} ({})",
                    fmt3(resolved.unclamped_rgb),
                    fmt3(resolved.linear_rgb),
                    crate::colour::designer::hex_from_linear(resolved.linear_rgb)
                ),
            });
        }
        material.diffuse_rgb = resolved.linear_rgb;
        material.diffuse_spectrum = None;
        colour = Some(spec);
    } else {
        let resolved = resolve_linear(material.diffuse_rgb);
        if material
            .diffuse_rgb
            .iter()
            .any(|c| !(0.0..=1.0).contains(c))
        {
            warnings.push(SiteWarning::SiteMaterial {
                material: name.clone(),
                message: format!(
                    "diffuse reflectance {} is outside [0, 1]; clamped to {}",
                    fmt3(material.diffuse_rgb),
                    fmt3(resolved.linear_rgb)
                ),
            });
            material.diffuse_rgb = resolved.linear_rgb;
        }
    }
    material
        .validate()
        .map_err(|e| SiteRenderError::SiteMaterial {
            material: name.clone(),
            reason: e.to_string(),
        })?;
    Ok(ResolvedSiteMaterial {
        material,
        colour,
        warnings,
    })
}

/// The material library overlaid with the site's materials (a site material replaces the
/// library's entry of the same name), and the clamping warnings. `None` when the site has
/// neither a library nor site materials.
///
/// # Errors
/// As [`resolve_site_material`]; a name given twice in `[[materials]]`.
pub fn overlay_site_materials(
    library: Option<MaterialLibrary>,
    entries: &[SiteMaterial],
) -> Result<(Option<MaterialLibrary>, Vec<SiteWarning>), SiteRenderError> {
    if entries.is_empty() {
        return Ok((library, Vec::new()));
    }
    let mut lib = library.unwrap_or_default();
    let mut warnings = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for entry in entries {
        if !seen.insert(entry.material.name.as_str()) {
            return Err(SiteRenderError::SiteMaterial {
                material: entry.material.name.clone(),
                reason: "defined twice".to_owned(),
            });
        }
        let resolved = resolve_site_material(entry)?;
        warnings.extend(resolved.warnings);
        match lib
            .materials
            .iter_mut()
            .find(|m| m.name == resolved.material.name)
        {
            Some(m) => *m = resolved.material,
            None => lib.materials.push(resolved.material),
        }
    }
    Ok((Some(lib), warnings))
}

/// A warning for every site material whose name no scene material has.
#[must_use]
pub fn unmatched_site_materials(
    entries: &[SiteMaterial],
    scene_materials: &[Material],
) -> Vec<SiteWarning> {
    entries
        .iter()
        .filter(|e| !scene_materials.iter().any(|m| m.name == e.material.name))
        .map(|e| SiteWarning::SiteMaterial {
            material: e.material.name.clone(),
            message: "no polygon or CAD model in the scene uses this material name; it changes \
                      nothing"
                .to_owned(),
        })
        .collect()
}

#[cfg(test)]
#[path = "site_materials_tests.rs"]
mod tests;
