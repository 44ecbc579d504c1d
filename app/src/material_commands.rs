//! The Materials tab's edits of the site (colour and material design): the site's
//! `[[materials]]` and `[[palette]]`, as one [`MaterialCommand`] carried by
//! `Command::Material` through the one command path; each returns its exact inverse (positions
//! restored, so an undone edit leaves the saved file byte-identical).

use photomontage::site::{PaletteColour, Site, SiteMaterial};

/// What can go wrong applying a material command.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MaterialCommandError {
    /// No site material with this name.
    #[error("no site material `{name}`")]
    NoSuchMaterial { name: String },
}

/// One edit of the site's materials or palette.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialCommand {
    /// Inserts the site material, or replaces the one with the same name in place (`at`: index
    /// of an insertion, end when `None`).
    PutMaterial {
        material: Box<SiteMaterial>,
        at: Option<usize>,
    },
    /// Removes a site material (the library's or CAD file's definition shows again).
    RemoveMaterial { name: String },
    /// Sets the whole palette.
    SetPalette(Vec<PaletteColour>),
}

impl MaterialCommand {
    /// A short human description.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::PutMaterial { material, .. } => format!("material {}", material.material.name),
            Self::RemoveMaterial { name } => format!("remove site material {name}"),
            Self::SetPalette(p) => format!("palette ({} colours)", p.len()),
        }
    }
}

/// Applies `command` to `site` and returns its inverse.
///
/// # Errors
/// [`MaterialCommandError::NoSuchMaterial`] when removing a material the site does not have;
/// the site is unchanged then.
pub fn apply(
    site: &mut Site,
    command: MaterialCommand,
) -> Result<MaterialCommand, MaterialCommandError> {
    Ok(match command {
        MaterialCommand::PutMaterial { material, at } => {
            let name = material.material.name.clone();
            match site.materials.iter().position(|m| m.material.name == name) {
                Some(i) => MaterialCommand::PutMaterial {
                    material: Box::new(std::mem::replace(&mut site.materials[i], *material)),
                    at: Some(i),
                },
                None => {
                    let i = at.map_or(site.materials.len(), |i| i.min(site.materials.len()));
                    site.materials.insert(i, *material);
                    MaterialCommand::RemoveMaterial { name }
                }
            }
        }
        MaterialCommand::RemoveMaterial { name } => {
            let i = site
                .materials
                .iter()
                .position(|m| m.material.name == name)
                .ok_or(MaterialCommandError::NoSuchMaterial { name })?;
            MaterialCommand::PutMaterial {
                material: Box::new(site.materials.remove(i)),
                at: Some(i),
            }
        }
        MaterialCommand::SetPalette(p) => {
            MaterialCommand::SetPalette(std::mem::replace(&mut site.palette, p))
        }
    })
}

#[cfg(test)]
mod tests {
    use photomontage::scene::Material;

    use super::*;

    #[test]
    fn put_and_remove_invert_exactly() {
        let mut site = Site::default();
        site.materials
            .push(SiteMaterial::new(Material::diffuse("a", [0.1; 3]), None));
        site.materials.push(SiteMaterial::new(
            Material::diffuse("b", [0.2; 3]),
            Some("#333333".into()),
        ));
        let before = site.clone();
        let put = MaterialCommand::PutMaterial {
            material: Box::new(SiteMaterial::new(
                Material::diffuse("a", [0.9; 3]),
                Some("#eeeeee".into()),
            )),
            at: None,
        };
        let inverse = apply(&mut site, put).unwrap();
        assert_eq!(site.materials[0].colour.as_deref(), Some("#eeeeee"));
        apply(&mut site, inverse).unwrap();
        assert_eq!(site, before);
        let inverse = apply(
            &mut site,
            MaterialCommand::RemoveMaterial { name: "a".into() },
        )
        .unwrap();
        assert_eq!(site.materials.len(), 1);
        apply(&mut site, inverse).unwrap();
        assert_eq!(site, before);
        assert_eq!(
            apply(
                &mut site,
                MaterialCommand::RemoveMaterial { name: "z".into() }
            ),
            Err(MaterialCommandError::NoSuchMaterial { name: "z".into() })
        );
        let palette = vec![PaletteColour {
            name: "Sienna".into(),
            colour: "#a0522d".into(),
        }];
        let inverse = apply(&mut site, MaterialCommand::SetPalette(palette.clone())).unwrap();
        assert_eq!(site.palette, palette);
        apply(&mut site, inverse).unwrap();
        assert_eq!(site, before);
    }
}
