//! Every edit of the user's site is a [`Command`] applied through [`History::apply`], the one
//! path that changes the site. Applying a command returns its exact inverse, which goes on the
//! undo stack; undoing applies the inverse and pushes the inverse's inverse on the redo stack
//! (the command pattern of rerun's `SystemCommand` and egui's undoer, with explicit inverses
//! instead of snapshots so a 24-photo site does not copy itself on every click).
//!
//! Inverses restore positions too: removing the 5th observation and undoing puts it back 5th,
//! so an undone edit leaves the saved file byte-identical.
//!
//! # Known limitations
//! The history lives in memory only; it is not part of the autosave sidecar, so after a crash
//! the restored edits are kept but can no longer be undone one by one.

use photomontage::site::{
    CadModel, ControlPoint, Exterior, Interior, Location, Observation, Placement, Polygon,
    SelfCalibrationFlags, Site, TiePoint,
};

use crate::fit_commands::{self, FitCommand, FitCommandError};
use crate::light_commands::{self, LightCommand, LightCommandError};
use crate::material_commands::{self, MaterialCommand, MaterialCommandError};
use crate::variant_commands::{self, VariantCommand, VariantCommandError};

/// What can go wrong applying a command.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CommandError {
    #[error("no observation of point `{point}` in photo `{photo}`")]
    NoSuchObservation { photo: String, point: String },
    #[error("no control point `{id}`")]
    NoSuchControlPoint { id: String },
    #[error("no photo `{id}`")]
    NoSuchPhoto { id: String },
    #[error("no CAD model `{id}`")]
    NoSuchModel { id: String },
    #[error("no polygon `{id}`")]
    NoSuchPolygon { id: String },
    #[error("nothing to undo")]
    NothingToUndo,
    #[error("nothing to redo")]
    NothingToRedo,
    #[error("no sample `{id}`")]
    NoSuchSample { id: String },
    #[error("no luminaire `{id}`")]
    NoSuchLuminaire { id: String },
    #[error(transparent)]
    Material(#[from] MaterialCommandError),
    #[error(transparent)]
    Variant(#[from] VariantCommandError),
}

impl From<LightCommandError> for CommandError {
    fn from(e: LightCommandError) -> Self {
        match e {
            LightCommandError::NoSuchPhoto { id } => Self::NoSuchPhoto { id },
            LightCommandError::NoSuchLuminaire { id } => Self::NoSuchLuminaire { id },
        }
    }
}

impl From<FitCommandError> for CommandError {
    fn from(e: FitCommandError) -> Self {
        match e {
            FitCommandError::NoSuchSample { id } => Self::NoSuchSample { id },
        }
    }
}

/// One edit of a site.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Inserts the observation of (photo, point), or replaces the existing one in place.
    /// `at` is the index for an insertion (end when `None` or past the end).
    PutObservation {
        observation: Observation,
        at: Option<usize>,
    },
    /// Removes the observation of `point` in `photo`.
    RemoveObservation { photo: String, point: String },
    /// Inserts the control point, or replaces the one with the same id in place.
    PutControlPoint {
        point: ControlPoint,
        at: Option<usize>,
    },
    /// Removes a control point (its observations stay; they refer to it by id).
    RemoveControlPoint { id: String },
    /// Sets a photo's interior and exterior orientation (a solve result).
    SetOrientation {
        photo: String,
        interior: Option<Interior>,
        exterior: Option<Exterior>,
    },
    /// Replaces the tie points.
    SetTiePoints(Vec<TiePoint>),
    /// Sets (or clears) the site's `[location]`.
    SetLocation(Option<Location>),
    /// Inserts the scene polygon, or replaces the one with the same id in place.
    PutPolygon { polygon: Polygon, at: Option<usize> },
    /// Removes a scene polygon.
    RemovePolygon { id: String },
    /// Sets a CAD model's placement (translation, rotation about Z, scale).
    SetModelPlacement { model: String, placement: Placement },
    /// Inserts the CAD model, or replaces the one with the same id in place.
    PutModel { model: CadModel, at: Option<usize> },
    /// Removes a CAD model.
    RemoveModel { id: String },
    /// Sets which interior parameters the solve of a photo may estimate.
    SetSelfCalibration {
        photo: String,
        flags: SelfCalibrationFlags,
    },
    /// Several commands applied in order, undone as one.
    Batch(Vec<Command>),
    /// An edit of the lighting fit's data ([`fit_commands`]).
    Fit(FitCommand),
    /// An edit of the location, light or luminaires ([`light_commands`]).
    Light(LightCommand),
    /// An edit of the site's materials or palette ([`material_commands`]).
    Material(MaterialCommand),
    /// An edit of the design variants ([`variant_commands`]).
    Variant(VariantCommand),
}

impl Command {
    /// A short human description for the status line and the undo menu.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::PutObservation { observation: o, .. } => {
                format!("place {} in {}", o.point, o.photo)
            }
            Self::RemoveObservation { photo, point } => format!("remove {point} in {photo}"),
            Self::PutControlPoint { point, .. } => format!("edit control point {}", point.id),
            Self::RemoveControlPoint { id } => format!("remove control point {id}"),
            Self::SetOrientation { photo, .. } => format!("orientation of {photo}"),
            Self::SetTiePoints(t) => format!("{} tie points", t.len()),
            Self::SetLocation(_) => "site location".to_owned(),
            Self::SetModelPlacement { model, .. } => format!("place model {model}"),
            Self::PutPolygon { polygon, .. } => format!("polygon {}", polygon.id),
            Self::PutModel { model, .. } => format!("model {}", model.id),
            Self::RemoveModel { id } => format!("remove model {id}"),
            Self::SetSelfCalibration { photo, .. } => format!("self-calibration of {photo}"),
            Self::RemovePolygon { id } => format!("remove polygon {id}"),
            Self::Batch(c) => format!("{} edits", c.len()),
            Self::Fit(c) => c.describe(),
            Self::Light(c) => c.describe(),
            Self::Material(c) => c.describe(),
            Self::Variant(c) => c.describe(),
        }
    }
}

fn observation_index(site: &Site, photo: &str, point: &str) -> Option<usize> {
    site.observations
        .iter()
        .position(|o| o.photo == photo && o.point == point)
}

/// Applies `command` to `site` and returns its inverse. On error the site is unchanged (a
/// failing batch is rolled back).
///
/// # Errors
/// [`CommandError`] when the command refers to something the site does not have.
pub fn apply(site: &mut Site, command: Command) -> Result<Command, CommandError> {
    Ok(match command {
        Command::PutObservation { observation, at } => {
            match observation_index(site, &observation.photo, &observation.point) {
                Some(i) => {
                    let old = std::mem::replace(&mut site.observations[i], observation);
                    Command::PutObservation {
                        observation: old,
                        at: Some(i),
                    }
                }
                None => {
                    let inverse = Command::RemoveObservation {
                        photo: observation.photo.clone(),
                        point: observation.point.clone(),
                    };
                    let i = at.map_or(site.observations.len(), |i| i.min(site.observations.len()));
                    site.observations.insert(i, observation);
                    inverse
                }
            }
        }
        Command::RemoveObservation { photo, point } => {
            let i = observation_index(site, &photo, &point)
                .ok_or(CommandError::NoSuchObservation { photo, point })?;
            let old = site.observations.remove(i);
            Command::PutObservation {
                observation: old,
                at: Some(i),
            }
        }
        Command::PutControlPoint { point, at } => {
            match site.control_points.iter().position(|c| c.id == point.id) {
                Some(i) => {
                    let old = std::mem::replace(&mut site.control_points[i], point);
                    Command::PutControlPoint {
                        point: old,
                        at: Some(i),
                    }
                }
                None => {
                    let inverse = Command::RemoveControlPoint {
                        id: point.id.clone(),
                    };
                    let i = at.map_or(site.control_points.len(), |i| {
                        i.min(site.control_points.len())
                    });
                    site.control_points.insert(i, point);
                    inverse
                }
            }
        }
        Command::RemoveControlPoint { id } => {
            let i = site
                .control_points
                .iter()
                .position(|c| c.id == id)
                .ok_or(CommandError::NoSuchControlPoint { id })?;
            let old = site.control_points.remove(i);
            Command::PutControlPoint {
                point: old,
                at: Some(i),
            }
        }
        Command::SetOrientation {
            photo,
            interior,
            exterior,
        } => {
            let p = site
                .photos
                .iter_mut()
                .find(|p| p.id == photo)
                .ok_or(CommandError::NoSuchPhoto { id: photo.clone() })?;
            let old_interior = std::mem::replace(&mut p.interior, interior);
            let old_exterior = std::mem::replace(&mut p.exterior, exterior);
            Command::SetOrientation {
                photo,
                interior: old_interior,
                exterior: old_exterior,
            }
        }
        Command::SetTiePoints(ties) => {
            Command::SetTiePoints(std::mem::replace(&mut site.tie_points, ties))
        }
        Command::SetLocation(location) => {
            Command::SetLocation(std::mem::replace(&mut site.location, location))
        }
        Command::PutPolygon { polygon, at } => {
            match site.polygons.iter().position(|p| p.id == polygon.id) {
                Some(i) => Command::PutPolygon {
                    polygon: std::mem::replace(&mut site.polygons[i], polygon),
                    at: Some(i),
                },
                None => {
                    let inverse = Command::RemovePolygon {
                        id: polygon.id.clone(),
                    };
                    let i = at.map_or(site.polygons.len(), |i| i.min(site.polygons.len()));
                    site.polygons.insert(i, polygon);
                    inverse
                }
            }
        }
        Command::RemovePolygon { id } => {
            let i = site
                .polygons
                .iter()
                .position(|p| p.id == id)
                .ok_or(CommandError::NoSuchPolygon { id })?;
            Command::PutPolygon {
                polygon: site.polygons.remove(i),
                at: Some(i),
            }
        }
        Command::PutModel { model, at } => {
            match site.models.iter().position(|m| m.id == model.id) {
                Some(i) => Command::PutModel {
                    model: std::mem::replace(&mut site.models[i], model),
                    at: Some(i),
                },
                None => {
                    let inverse = Command::RemoveModel {
                        id: model.id.clone(),
                    };
                    let i = at.map_or(site.models.len(), |i| i.min(site.models.len()));
                    site.models.insert(i, model);
                    inverse
                }
            }
        }
        Command::RemoveModel { id } => {
            let i = site
                .models
                .iter()
                .position(|m| m.id == id)
                .ok_or(CommandError::NoSuchModel { id })?;
            Command::PutModel {
                model: site.models.remove(i),
                at: Some(i),
            }
        }
        Command::SetModelPlacement { model, placement } => {
            let m = site
                .models
                .iter_mut()
                .find(|m| m.id == model)
                .ok_or(CommandError::NoSuchModel { id: model.clone() })?;
            let old = std::mem::replace(&mut m.placement, placement);
            Command::SetModelPlacement {
                model,
                placement: old,
            }
        }
        Command::SetSelfCalibration { photo, flags } => {
            let p = site
                .photos
                .iter_mut()
                .find(|p| p.id == photo)
                .ok_or(CommandError::NoSuchPhoto { id: photo.clone() })?;
            let old = std::mem::replace(&mut p.self_calibration, flags);
            Command::SetSelfCalibration { photo, flags: old }
        }
        Command::Batch(commands) => {
            let mut inverses = Vec::with_capacity(commands.len());
            for c in commands {
                match apply(site, c) {
                    Ok(inv) => inverses.push(inv),
                    Err(e) => {
                        // Roll back what was applied so the site is unchanged.
                        for inv in inverses.into_iter().rev() {
                            let _ = apply(site, inv);
                        }
                        return Err(e);
                    }
                }
            }
            inverses.reverse();
            Command::Batch(inverses)
        }
        Command::Fit(c) => Command::Fit(fit_commands::apply(site, c)?),
        Command::Light(c) => Command::Light(light_commands::apply(site, c)?),
        Command::Material(c) => Command::Material(material_commands::apply(site, c)?),
        Command::Variant(c) => Command::Variant(variant_commands::apply(site, c)?),
    })
}

/// The undo and redo stacks over one site.
#[derive(Debug, Default)]
pub struct History {
    undo: Vec<Command>,
    redo: Vec<Command>,
    /// Counts applied edits (including undo/redo); autosave compares it with what it wrote.
    revision: u64,
}

impl History {
    /// Applies a new edit; clears the redo stack.
    ///
    /// # Errors
    /// As [`apply`]; nothing changes then.
    pub fn apply(&mut self, site: &mut Site, command: Command) -> Result<(), CommandError> {
        let inverse = apply(site, command)?;
        self.undo.push(inverse);
        self.redo.clear();
        self.revision += 1;
        Ok(())
    }

    /// Applies an edit that continues the previous one (a drag of one value): the site changes,
    /// but the existing undo entry (which restores the state before the first of them) is kept,
    /// so the whole gesture is one undo step. Falls back to [`Self::apply`] when there is
    /// nothing to merge with.
    ///
    /// # Errors
    /// As [`apply`]; nothing changes then.
    pub fn apply_merged(&mut self, site: &mut Site, command: Command) -> Result<(), CommandError> {
        if self.undo.is_empty() || !self.redo.is_empty() {
            return self.apply(site, command);
        }
        apply(site, command)?;
        self.revision += 1;
        Ok(())
    }

    /// Undoes the last edit.
    ///
    /// # Errors
    /// [`CommandError::NothingToUndo`], or an error from the inverse (the site is unchanged).
    pub fn undo(&mut self, site: &mut Site) -> Result<(), CommandError> {
        let inverse = self.undo.pop().ok_or(CommandError::NothingToUndo)?;
        match apply(site, inverse.clone()) {
            Ok(redo) => {
                self.redo.push(redo);
                self.revision += 1;
                Ok(())
            }
            Err(e) => {
                self.undo.push(inverse);
                Err(e)
            }
        }
    }

    /// Redoes the last undone edit.
    ///
    /// # Errors
    /// [`CommandError::NothingToRedo`], or an error from the command (the site is unchanged).
    pub fn redo(&mut self, site: &mut Site) -> Result<(), CommandError> {
        let command = self.redo.pop().ok_or(CommandError::NothingToRedo)?;
        match apply(site, command.clone()) {
            Ok(undo) => {
                self.undo.push(undo);
                self.revision += 1;
                Ok(())
            }
            Err(e) => {
                self.redo.push(command);
                Err(e)
            }
        }
    }

    /// Whether there is something to undo.
    #[must_use]
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is something to redo.
    #[must_use]
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Number of edits applied so far (new, undone or redone).
    #[must_use]
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Forgets the stacks (a new site was opened).
    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }
}

/// Parses one line of a `--script` file into a command. Lines:
/// `place PHOTO POINT X_PX Y_PX`, `remove PHOTO POINT`,
/// `control ID X Y Z`, `disable PHOTO POINT`, `enable PHOTO POINT`.
/// `site` supplies the existing observation for `enable`/`disable`.
///
/// # Errors
/// A message naming what is wrong with the line.
pub fn parse_script_line(site: &Site, line: &str) -> Result<Option<Command>, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let num = |s: &str| -> Result<f64, String> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{s}` is not a finite number"))
    };
    match words.as_slice() {
        [] => Ok(None),
        [w, ..] if w.starts_with('#') => Ok(None),
        ["place", photo, point, x, y] => Ok(Some(Command::PutObservation {
            observation: Observation {
                photo: (*photo).to_owned(),
                point: (*point).to_owned(),
                x_px: num(x)?,
                y_px: num(y)?,
                sigma_px: 0.5,
                enabled: true,
            },
            at: None,
        })),
        ["remove", photo, point] => Ok(Some(Command::RemoveObservation {
            photo: (*photo).to_owned(),
            point: (*point).to_owned(),
        })),
        ["control", id, x, y, z] => Ok(Some(Command::PutControlPoint {
            point: ControlPoint {
                id: (*id).to_owned(),
                xyz: [num(x)?, num(y)?, num(z)?],
                sigma_m: [0.01; 3],
                crs: None,
                enabled: true,
            },
            at: None,
        })),
        [verb @ ("enable" | "disable"), photo, point] => {
            let i = observation_index(site, photo, point)
                .ok_or_else(|| format!("no observation of {point} in {photo}"))?;
            let mut o = site.observations[i].clone();
            o.enabled = *verb == "enable";
            Ok(Some(Command::PutObservation {
                observation: o,
                at: None,
            }))
        }
        _ => Err(format!("cannot read script line `{line}`")),
    }
}

#[cfg(test)]
#[path = "commands_tests.rs"]
mod tests;
