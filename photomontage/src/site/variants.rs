//! Design variants (issue 17 item 4): the site document as one `[[variants]]` entry sees it.
//!
//! [`variant_document`] is the one way a variant is applied, for the CLI's `render --variant`
//! and `compare`, and for the studio: the models' `visible` flags follow the variant's
//! `visible_models`, its placements replace the site's, and the document's `variants` holds only
//! the applied variant (marked [`Variant::applied`]), whose materials
//! [`super::site_scene::site_scene`] applies by name after the site's material library. Lighting,
//! cameras, render settings and the seed are untouched, so every variant of a view is rendered
//! under the same light with the same samples.
//!
//! # Known limitations
//! A variant cannot add a model the site does not list, nor change a model's file, units or up
//! axis. Material overrides act on the rendered scene only (the lighting fits and the radiosity
//! CLI see the site's materials). A variant naming a model that was removed from the site is
//! accepted when the site is loaded (so removing a model loses nothing) and refused when the
//! variant is applied.

use std::collections::HashSet;

use super::{Site, SiteDocument, SiteIssue, Variant};
use crate::scene::MaterialLibrary;
use crate::scene::material::MaterialError;

/// What can be wrong with a variant when it is applied.
#[derive(Debug, thiserror::Error)]
pub enum VariantError {
    #[error("no variant named `{name}` in the site (variants: {known})")]
    UnknownVariant { name: String, known: String },
    #[error(
        "variant `{variant}`: {field} names model `{model}`, which the site does not have (models: {known})"
    )]
    UnknownModel {
        variant: String,
        field: &'static str,
        model: String,
        known: String,
    },
    #[error("the site has no [[variants]] to compare")]
    NoVariants,
    #[error("variant `{name}` is defined more than once")]
    DuplicateName { name: String },
    #[error("variant `{variant}`: material `{material}`: {source}")]
    Material {
        variant: String,
        material: String,
        source: MaterialError,
    },
}

fn list(names: impl Iterator<Item = String>) -> String {
    let v: Vec<String> = names.collect();
    if v.is_empty() {
        "none".to_owned()
    } else {
        v.join(", ")
    }
}

/// Every problem of `site.variants` that does not depend on the models: empty or duplicate
/// names, duplicate or invalid materials. Run by [`Site::validate`] when a site is loaded.
#[must_use]
pub fn variant_issues(site: &Site) -> Vec<SiteIssue> {
    let mut issues = Vec::new();
    let mut names = HashSet::new();
    for (i, v) in site.variants.iter().enumerate() {
        if v.name.trim().is_empty() {
            issues.push(SiteIssue {
                field: format!("variants[{i}].name"),
                message: "must not be empty".into(),
            });
        } else if !names.insert(v.name.as_str()) {
            issues.push(SiteIssue {
                field: format!("variants[{i}].name"),
                message: format!("variant `{}` is defined more than once", v.name),
            });
        }
        let mut materials = HashSet::new();
        for (k, m) in v.materials.iter().enumerate() {
            if let Err(e) = m.validate() {
                issues.push(SiteIssue {
                    field: format!("variants[{i}].materials[{k}]"),
                    message: format!("variant `{}`, material `{}`: {e}", v.name, m.name),
                });
            }
            if !materials.insert(m.name.as_str()) {
                issues.push(SiteIssue {
                    field: format!("variants[{i}].materials[{k}].name"),
                    message: format!(
                        "variant `{}` defines material `{}` more than once",
                        v.name, m.name
                    ),
                });
            }
        }
    }
    issues
}

/// Checks the variant named `name` against the site's models and materials.
///
/// # Errors
/// [`VariantError::UnknownVariant`], [`VariantError::DuplicateName`],
/// [`VariantError::UnknownModel`] (naming the variant, the field and the model),
/// [`VariantError::Material`].
pub fn find_variant<'a>(site: &'a Site, name: &str) -> Result<&'a Variant, VariantError> {
    let mut found = site.variants.iter().filter(|v| v.name == name);
    let Some(variant) = found.next() else {
        return Err(VariantError::UnknownVariant {
            name: name.to_owned(),
            known: list(site.variants.iter().map(|v| v.name.clone())),
        });
    };
    if found.next().is_some() {
        return Err(VariantError::DuplicateName {
            name: name.to_owned(),
        });
    }
    let known_models = || list(site.models.iter().map(|m| m.id.clone()));
    let has_model = |id: &str| site.models.iter().any(|m| m.id == id);
    for model in variant.visible_models.iter().flatten() {
        if !has_model(model) {
            return Err(VariantError::UnknownModel {
                variant: variant.name.clone(),
                field: "visible_models",
                model: model.clone(),
                known: known_models(),
            });
        }
    }
    for p in &variant.placements {
        if !has_model(&p.model) {
            return Err(VariantError::UnknownModel {
                variant: variant.name.clone(),
                field: "placements",
                model: p.model.clone(),
                known: known_models(),
            });
        }
    }
    for m in &variant.materials {
        m.validate().map_err(|source| VariantError::Material {
            variant: variant.name.clone(),
            material: m.name.clone(),
            source,
        })?;
    }
    Ok(variant)
}

/// The site document as variant `name` sees it (see the module documentation). `None` gives
/// the site itself, unchanged.
///
/// # Errors
/// Those of [`find_variant`].
pub fn variant_document(
    doc: &SiteDocument,
    name: Option<&str>,
) -> Result<SiteDocument, VariantError> {
    let Some(name) = name else {
        return Ok(doc.clone());
    };
    let variant = find_variant(&doc.site, name)?;
    let mut out = doc.clone();
    for model in &mut out.site.models {
        if let Some(visible) = &variant.visible_models {
            model.visible = visible.contains(&model.id);
        }
        if let Some(p) = variant.placements.iter().find(|p| p.model == model.id) {
            model.placement = p.placement.clone();
        }
    }
    let mut applied = variant.clone();
    applied.applied = true;
    out.site.variants = vec![applied];
    Ok(out)
}

/// The materials of the variant applied to `doc` (by [`variant_document`]) as a library, if
/// one is applied.
#[must_use]
pub fn applied_variant_materials(doc: &SiteDocument) -> Option<MaterialLibrary> {
    doc.site
        .variants
        .iter()
        .find(|v| v.applied)
        .map(|v| MaterialLibrary {
            materials: v.materials.clone(),
        })
}

/// Every variant name of `requested` (all of the site's, in file order, for `None`) checked
/// with [`find_variant`] before anything is rendered.
///
/// # Errors
/// Those of [`find_variant`]; [`VariantError::NoVariants`] when there is none to render; a
/// name listed twice is [`VariantError::DuplicateName`].
pub fn checked_variant_names(
    site: &Site,
    requested: Option<&[String]>,
) -> Result<Vec<String>, VariantError> {
    let names: Vec<String> = match requested {
        Some(r) => r.to_vec(),
        None => site.variants.iter().map(|v| v.name.clone()).collect(),
    };
    if names.is_empty() {
        return Err(VariantError::NoVariants);
    }
    let mut seen = HashSet::new();
    for n in &names {
        find_variant(site, n)?;
        if !seen.insert(n.as_str()) {
            return Err(VariantError::DuplicateName { name: n.clone() });
        }
    }
    Ok(names)
}

#[cfg(test)]
#[path = "variants_tests.rs"]
mod tests;
