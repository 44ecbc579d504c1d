//! The studio's edits of the site's design variants (`[[variants]]`, issue 17 item 4): one
//! [`VariantCommand`] carried by `Command::Variant` through the one command path (this module
//! does not import `commands`: the dependency runs one way). Each edit returns its exact inverse
//! (positions restored, so an undone edit leaves the saved file byte-identical).
//!
//! The Variants tab ([`crate::variants_panel`]) issues them: a variant's visibility, placements
//! and materials are edited as a `Put` of the whole changed variant.
//!
//! # Known limitations
//! A `Put` carries the whole variant, so an undo step of a placement drag holds a copy of it.

use photomontage::site::{Site, Variant};

/// What can go wrong applying a variant command; the site is unchanged then.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VariantCommandError {
    #[error("no variant `{name}`")]
    NoSuchVariant { name: String },
    #[error("a variant named `{name}` exists already")]
    NameTaken { name: String },
    #[error("a variant name must not be empty")]
    EmptyName,
}

/// One edit of the site's variants.
#[derive(Debug, Clone, PartialEq)]
pub enum VariantCommand {
    /// Inserts the variant (at index `at`, the end when `None` or past it), or replaces the one
    /// of the same name in place.
    Put { variant: Variant, at: Option<usize> },
    /// Removes a variant.
    Remove { name: String },
    /// Renames a variant, keeping its place and content.
    Rename { from: String, to: String },
}

impl VariantCommand {
    /// A short human description.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Put { variant, .. } => format!("variant {}", variant.name),
            Self::Remove { name } => format!("remove variant {name}"),
            Self::Rename { from, to } => format!("rename variant {from} to {to}"),
        }
    }
}

fn index_of(site: &Site, name: &str) -> Result<usize, VariantCommandError> {
    site.variants
        .iter()
        .position(|v| v.name == name)
        .ok_or_else(|| VariantCommandError::NoSuchVariant {
            name: name.to_owned(),
        })
}

/// Applies `command` to `site` and returns its inverse.
///
/// # Errors
/// [`VariantCommandError`]: an unknown variant, an empty name, a rename onto a taken name.
pub fn apply(
    site: &mut Site,
    command: VariantCommand,
) -> Result<VariantCommand, VariantCommandError> {
    Ok(match command {
        VariantCommand::Put { variant, at } => {
            if variant.name.trim().is_empty() {
                return Err(VariantCommandError::EmptyName);
            }
            match site.variants.iter().position(|v| v.name == variant.name) {
                Some(i) => VariantCommand::Put {
                    variant: std::mem::replace(&mut site.variants[i], variant),
                    at: Some(i),
                },
                None => {
                    let inverse = VariantCommand::Remove {
                        name: variant.name.clone(),
                    };
                    let i = at.map_or(site.variants.len(), |i| i.min(site.variants.len()));
                    site.variants.insert(i, variant);
                    inverse
                }
            }
        }
        VariantCommand::Remove { name } => {
            let i = index_of(site, &name)?;
            VariantCommand::Put {
                variant: site.variants.remove(i),
                at: Some(i),
            }
        }
        VariantCommand::Rename { from, to } => {
            if to.trim().is_empty() {
                return Err(VariantCommandError::EmptyName);
            }
            let i = index_of(site, &from)?;
            if from != to && site.variants.iter().any(|v| v.name == to) {
                return Err(VariantCommandError::NameTaken { name: to });
            }
            site.variants[i].name.clone_from(&to);
            VariantCommand::Rename { from: to, to: from }
        }
    })
}

/// The first name `PREFIX 1`, `PREFIX 2`, … no variant has.
#[must_use]
pub fn next_variant_name(site: &Site, prefix: &str) -> String {
    (1_usize..)
        .map(|n| format!("{prefix} {n}"))
        .find(|name| !site.variants.iter().any(|v| &v.name == name))
        .unwrap_or_else(|| prefix.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn site_with(names: &[&str]) -> Site {
        Site {
            variants: names.iter().map(|n| Variant::named(n)).collect(),
            ..Site::default()
        }
    }

    #[test]
    fn every_edit_is_undone_exactly() {
        let start = {
            let mut s = site_with(&["a", "b"]);
            s.variants[1].visible_models = Some(vec!["m".into()]);
            s
        };
        let mut red = Variant::named("b");
        red.materials
            .push(photomontage::scene::Material::diffuse("m", [0.7, 0.1, 0.1]));
        for command in [
            VariantCommand::Put {
                variant: Variant::named("c"),
                at: Some(1),
            },
            VariantCommand::Put {
                variant: red,
                at: None,
            },
            VariantCommand::Remove { name: "a".into() },
            VariantCommand::Rename {
                from: "b".into(),
                to: "tall".into(),
            },
        ] {
            let mut s = start.clone();
            let inverse = apply(&mut s, command.clone()).unwrap();
            assert_ne!(s, start, "{command:?} changed nothing");
            apply(&mut s, inverse).unwrap();
            assert_eq!(s, start, "{command:?} not undone exactly");
        }
        let mut s = start.clone();
        apply(
            &mut s,
            VariantCommand::Put {
                variant: Variant::named("c"),
                at: Some(1),
            },
        )
        .unwrap();
        let names: Vec<&str> = s.variants.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["a", "c", "b"]);
    }

    #[test]
    fn bad_edits_are_refused_and_change_nothing() {
        let start = site_with(&["a", "b"]);
        let mut s = start.clone();
        assert_eq!(
            apply(&mut s, VariantCommand::Remove { name: "z".into() }),
            Err(VariantCommandError::NoSuchVariant { name: "z".into() })
        );
        assert_eq!(
            apply(
                &mut s,
                VariantCommand::Rename {
                    from: "a".into(),
                    to: "b".into()
                }
            ),
            Err(VariantCommandError::NameTaken { name: "b".into() })
        );
        assert_eq!(
            apply(
                &mut s,
                VariantCommand::Put {
                    variant: Variant::named(" "),
                    at: None
                }
            ),
            Err(VariantCommandError::EmptyName)
        );
        assert_eq!(s, start);
        assert_eq!(
            next_variant_name(&site_with(&["Variant 1"]), "Variant"),
            "Variant 2"
        );
    }
}
