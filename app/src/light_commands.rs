//! The Site & light panel's edits of the site ([`crate::light_panel`]): `[location]`,
//! `[lighting]`, `[render] exposure`, a photo's `taken_at` and the `[[luminaires]]`, carried by
//! the studio's `Command::Light` through the one command path (this module does not import
//! `commands`: the dependency runs one way). Each edit replaces one whole value and returns the
//! value it replaced, so the inverse is exact and an undone edit leaves the saved file
//! byte-identical.

use photomontage::site::{Lighting, Location, Site, SiteLuminaire};

/// What can go wrong applying a light command (converted into the command path's
/// `CommandError`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LightCommandError {
    /// No photo with this id.
    #[error("no photo `{id}`")]
    NoSuchPhoto { id: String },
    /// No luminaire with this id.
    #[error("no luminaire `{id}`")]
    NoSuchLuminaire { id: String },
}

/// One edit of the site's location, light or luminaires.
#[derive(Debug, Clone, PartialEq)]
pub enum LightCommand {
    /// Sets (or clears) `[location]`.
    SetLocation(Option<Box<Location>>),
    /// Sets `[lighting]` (time, sun, sky, weights, atmosphere, ground).
    SetLighting(Box<Lighting>),
    /// Sets `[render] exposure`.
    SetExposure(f64),
    /// Sets `[render] radiosity` (sky and interreflected light from the site's radiosity
    /// solutions) and `[render] photo_reflectance` (the photographed surfaces' ρ_d read off the
    /// photo in that mode).
    SetRadiosity {
        radiosity: bool,
        photo_reflectance: bool,
    },
    /// Sets (or clears) a photo's capture time `taken_at`.
    SetTakenAt {
        photo: String,
        taken_at: Option<String>,
    },
    /// Inserts the luminaire, or replaces the one with the same id in place (`at`: index of an
    /// insertion, end when `None` or past the end).
    PutLuminaire {
        luminaire: Box<SiteLuminaire>,
        at: Option<usize>,
    },
    /// Removes a luminaire.
    RemoveLuminaire { id: String },
}

impl LightCommand {
    /// A short human description.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::SetLocation(_) => "site location".into(),
            Self::SetLighting(_) => "lighting".into(),
            Self::SetExposure(e) => format!("exposure {e}"),
            Self::SetRadiosity {
                radiosity,
                photo_reflectance,
            } => match (radiosity, photo_reflectance) {
                (false, _) => "radiosity off".into(),
                (true, true) => "radiosity on, reflectance from the photo".into(),
                (true, false) => "radiosity on, library reflectance".into(),
            },
            Self::SetTakenAt { photo, .. } => format!("capture time of {photo}"),
            Self::PutLuminaire { luminaire, .. } => format!("luminaire {}", luminaire.id),
            Self::RemoveLuminaire { id } => format!("remove luminaire {id}"),
        }
    }
}

/// Applies `command` to `site` and returns its inverse.
///
/// # Errors
/// [`LightCommandError`] when the photo or luminaire does not exist; the site is unchanged then.
pub fn apply(site: &mut Site, command: LightCommand) -> Result<LightCommand, LightCommandError> {
    Ok(match command {
        LightCommand::SetLocation(location) => LightCommand::SetLocation(
            std::mem::replace(&mut site.location, location.map(|l| *l)).map(Box::new),
        ),
        LightCommand::SetLighting(lighting) => {
            LightCommand::SetLighting(Box::new(std::mem::replace(&mut site.lighting, *lighting)))
        }
        LightCommand::SetExposure(e) => {
            LightCommand::SetExposure(std::mem::replace(&mut site.render.exposure, e))
        }
        LightCommand::SetRadiosity {
            radiosity,
            photo_reflectance,
        } => LightCommand::SetRadiosity {
            radiosity: std::mem::replace(&mut site.render.radiosity, radiosity),
            photo_reflectance: std::mem::replace(
                &mut site.render.photo_reflectance,
                photo_reflectance,
            ),
        },
        LightCommand::SetTakenAt { photo, taken_at } => {
            let p = site
                .photos
                .iter_mut()
                .find(|p| p.id == photo)
                .ok_or_else(|| LightCommandError::NoSuchPhoto { id: photo.clone() })?;
            let old = std::mem::replace(&mut p.taken_at, taken_at);
            LightCommand::SetTakenAt {
                photo,
                taken_at: old,
            }
        }
        LightCommand::PutLuminaire { luminaire, at } => {
            match site.luminaires.iter().position(|l| l.id == luminaire.id) {
                Some(i) => LightCommand::PutLuminaire {
                    luminaire: Box::new(std::mem::replace(&mut site.luminaires[i], *luminaire)),
                    at: Some(i),
                },
                None => {
                    let inverse = LightCommand::RemoveLuminaire {
                        id: luminaire.id.clone(),
                    };
                    let i = at.map_or(site.luminaires.len(), |i| i.min(site.luminaires.len()));
                    site.luminaires.insert(i, *luminaire);
                    inverse
                }
            }
        }
        LightCommand::RemoveLuminaire { id } => {
            let i = site
                .luminaires
                .iter()
                .position(|l| l.id == id)
                .ok_or(LightCommandError::NoSuchLuminaire { id })?;
            LightCommand::PutLuminaire {
                luminaire: Box::new(site.luminaires.remove(i)),
                at: Some(i),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use photomontage::site::{Photo, SelfCalibrationFlags, SkyModelName, SunManual};

    fn luminaire(id: &str) -> SiteLuminaire {
        SiteLuminaire {
            id: id.into(),
            file: "downlight.ies".into(),
            position_m: [1.0, 2.0, 3.0],
            rotation_z_deg: 0.0,
            tilt_deg: 0.0,
            colour_rgb: [1.0; 3],
            scale: 1e-3,
            enabled: true,
        }
    }

    fn site() -> Site {
        Site {
            photos: vec![Photo {
                id: "P1".into(),
                file: "p1.jpg".into(),
                taken_at: None,
                interior: None,
                profile: None,
                self_calibration: SelfCalibrationFlags::default(),
                exterior: None,
            }],
            luminaires: vec![luminaire("L1"), luminaire("L2"), luminaire("L3")],
            ..Site::default()
        }
    }

    #[test]
    #[allow(clippy::float_cmp)] // values are moved, never computed: exact
    fn every_light_edit_undoes_to_the_exact_site() {
        let original = site();
        let mut s = original.clone();
        let mut lighting = s.lighting.clone();
        lighting.sky_model = SkyModelName::CieOvercast;
        lighting.sun_manual = Some(SunManual {
            azimuth_deg: 120.0,
            elevation_deg: 30.0,
        });
        let mut dimmed = luminaire("L2");
        dimmed.scale = 5e-4;
        let commands = vec![
            LightCommand::SetLocation(Some(Box::new(Location {
                latitude_deg: 47.0,
                longitude_deg: 8.0,
                elevation_m: 400.0,
                crs: None,
                grid_convergence_deg: 0.0,
                time_zone: Some("Europe/Zurich".into()),
            }))),
            LightCommand::SetLighting(Box::new(lighting)),
            LightCommand::SetExposure(2.0),
            LightCommand::SetRadiosity {
                radiosity: !original.render.radiosity,
                photo_reflectance: !original.render.photo_reflectance,
            },
            LightCommand::SetTakenAt {
                photo: "P1".into(),
                taken_at: Some("2024-06-21T15:00".into()),
            },
            LightCommand::RemoveLuminaire { id: "L1".into() },
            LightCommand::PutLuminaire {
                luminaire: Box::new(dimmed),
                at: None,
            },
            LightCommand::PutLuminaire {
                luminaire: Box::new(luminaire("L9")),
                at: None,
            },
        ];
        let mut inverses = Vec::new();
        for c in commands {
            inverses.push(apply(&mut s, c).expect("applies"));
        }
        assert_eq!(s.render.exposure, 2.0);
        assert_eq!(s.render.radiosity, !original.render.radiosity);
        assert_eq!(
            s.render.photo_reflectance,
            !original.render.photo_reflectance
        );
        assert_eq!(
            s.luminaires
                .iter()
                .map(|l| l.id.as_str())
                .collect::<Vec<_>>(),
            ["L2", "L3", "L9"]
        );
        assert_eq!(s.luminaires[0].scale, 5e-4);
        for inv in inverses.into_iter().rev() {
            apply(&mut s, inv).expect("inverse applies");
        }
        assert_eq!(s, original, "order and values restored");
    }

    #[test]
    fn missing_photo_or_luminaire_is_an_error_and_changes_nothing() {
        let original = site();
        let mut s = original.clone();
        assert_eq!(
            apply(&mut s, LightCommand::RemoveLuminaire { id: "L7".into() }),
            Err(LightCommandError::NoSuchLuminaire { id: "L7".into() })
        );
        assert_eq!(
            apply(
                &mut s,
                LightCommand::SetTakenAt {
                    photo: "P9".into(),
                    taken_at: None
                }
            ),
            Err(LightCommandError::NoSuchPhoto { id: "P9".into() })
        );
        assert_eq!(s, original);
    }
}
