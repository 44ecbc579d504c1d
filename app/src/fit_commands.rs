//! The lighting fit's edits of the site (Durisch 1992 §4.2–4.3: colour samples on scene
//! polygons, horizon rectangles, the `[fit_settings]`, and the fitted lighting written back):
//! one [`FitCommand`] carried by the studio's `Command::Fit` through the one command path
//! (this module does not import `commands`: the dependency runs one way),
//! each returning its exact inverse (positions restored, so an undone edit leaves the saved file
//! byte-identical).
//!
//! # Known limitations
//! Sun/shadow pairs are not edited here (edit the site file).

use photomontage::site::{FitRecord, FitSettings, HorizonSample, Lighting, Sample, Site};

/// What can go wrong applying a fit command (converted into
/// the command path's `CommandError`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FitCommandError {
    /// No sample or horizon sample with this id.
    #[error("no sample `{id}`")]
    NoSuchSample { id: String },
}

/// One edit of the fit's data.
#[derive(Debug, Clone, PartialEq)]
pub enum FitCommand {
    /// Inserts the sample, or replaces the one with the same id in place (`at`: index of an
    /// insertion, end when `None` or past the end).
    PutSample { sample: Sample, at: Option<usize> },
    /// Removes a sample.
    RemoveSample { id: String },
    /// Inserts the horizon sample, or replaces the one with the same id in place.
    PutHorizonSample {
        sample: HorizonSample,
        at: Option<usize>,
    },
    /// Removes a horizon sample.
    RemoveHorizonSample { id: String },
    /// Sets `[fit_settings]`.
    SetFitSettings(FitSettings),
    /// Sets `[lighting]` and the `[fit]` record (a fit applied with
    /// `photomontage::fit::site::apply_fit`, or its undo).
    SetLighting {
        lighting: Box<Lighting>,
        record: Option<Box<FitRecord>>,
    },
}

impl FitCommand {
    /// A short human description.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::PutSample { sample, .. } => format!("sample {}", sample.id),
            Self::RemoveSample { id } => format!("remove sample {id}"),
            Self::PutHorizonSample { sample, .. } => format!("horizon sample {}", sample.id),
            Self::RemoveHorizonSample { id } => format!("remove horizon sample {id}"),
            Self::SetFitSettings(_) => "fit settings".into(),
            Self::SetLighting { .. } => "apply the lighting fit".into(),
        }
    }
}

/// Inserts `item` (or replaces the element with its id) and returns the inverse.
fn put<T>(
    list: &mut Vec<T>,
    item: T,
    at: Option<usize>,
    id_of: impl Fn(&T) -> &str,
    put_back: impl Fn(T, Option<usize>) -> FitCommand,
    remove: impl Fn(String) -> FitCommand,
) -> FitCommand {
    match list.iter().position(|x| id_of(x) == id_of(&item)) {
        Some(i) => put_back(std::mem::replace(&mut list[i], item), Some(i)),
        None => {
            let inverse = remove(id_of(&item).to_owned());
            let i = at.map_or(list.len(), |i| i.min(list.len()));
            list.insert(i, item);
            inverse
        }
    }
}

/// Applies `command` to `site` and returns its inverse.
///
/// # Errors
/// [`FitCommandError::NoSuchSample`] when removing a sample the site does not have; the site is
/// unchanged then.
pub fn apply(site: &mut Site, command: FitCommand) -> Result<FitCommand, FitCommandError> {
    let inverse = match command {
        FitCommand::PutSample { sample, at } => put(
            &mut site.samples,
            sample,
            at,
            |s| s.id.as_str(),
            |sample, at| FitCommand::PutSample { sample, at },
            |id| FitCommand::RemoveSample { id },
        ),
        FitCommand::RemoveSample { id } => {
            let i = site
                .samples
                .iter()
                .position(|s| s.id == id)
                .ok_or(FitCommandError::NoSuchSample { id })?;
            FitCommand::PutSample {
                sample: site.samples.remove(i),
                at: Some(i),
            }
        }
        FitCommand::PutHorizonSample { sample, at } => put(
            &mut site.horizon_samples,
            sample,
            at,
            |s| s.id.as_str(),
            |sample, at| FitCommand::PutHorizonSample { sample, at },
            |id| FitCommand::RemoveHorizonSample { id },
        ),
        FitCommand::RemoveHorizonSample { id } => {
            let i = site
                .horizon_samples
                .iter()
                .position(|s| s.id == id)
                .ok_or(FitCommandError::NoSuchSample { id })?;
            FitCommand::PutHorizonSample {
                sample: site.horizon_samples.remove(i),
                at: Some(i),
            }
        }
        FitCommand::SetFitSettings(settings) => {
            FitCommand::SetFitSettings(std::mem::replace(&mut site.fit_settings, settings))
        }
        FitCommand::SetLighting { lighting, record } => FitCommand::SetLighting {
            lighting: Box::new(std::mem::replace(&mut site.lighting, *lighting)),
            record: std::mem::replace(&mut site.fit, record.map(|r| *r)).map(Box::new),
        },
    };
    Ok(inverse)
}

/// The first id `PREFIX1`, `PREFIX2`, … not in `taken`.
#[must_use]
pub fn next_id<'a>(prefix: &str, taken: impl Iterator<Item = &'a str> + Clone) -> String {
    (1_usize..)
        .map(|n| format!("{prefix}{n}"))
        .find(|id| !taken.clone().any(|t| t == id))
        .unwrap_or_else(|| prefix.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removing_a_missing_sample_is_an_error_and_changes_nothing() {
        let mut s = Site::default();
        assert_eq!(
            apply(&mut s, FitCommand::RemoveHorizonSample { id: "H9".into() }),
            Err(FitCommandError::NoSuchSample { id: "H9".into() })
        );
        assert_eq!(s, Site::default());
    }

    #[test]
    fn next_id_skips_taken_ids() {
        let taken = ["S1", "S3", "S2", "X4"];
        assert_eq!(next_id("S", taken.iter().copied()), "S4");
        assert_eq!(next_id("H", taken.iter().copied()), "H1");
    }
}
