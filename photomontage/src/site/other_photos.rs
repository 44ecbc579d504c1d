//! The site's other solved photos, for the photo reflectances of the radiosity mode (issue 13
//! item 2: "natural patches take ρ_d from the photo where a solved photo sees them").
//!
//! The rendered photo is read first ([`super::photo_reflectance`]); a natural element it does not
//! see takes its ρ_d from the first other photo (in the site's order) that does. Durisch's second
//! inversion ρ_d = π·L₀ / E_nat needs the light the photo was taken in, and the estimate reads
//! every photo against one solution (the rendered view's lighting), so another photo is read only
//! where it was taken under the same sun: its sun direction ([`super::render::site_sun_dir`])
//! within [`SAME_SUN_DEG`] of the rendered photo's (the same `sun_manual`, or capture times a
//! minute or two apart). The sky, weights and atmosphere are the site's, shared by all photos.
//! Its exposure is checked against the rendered photo's where both see the same points
//! ([`super::photo_reflectance::EXPOSURE_TOLERANCE`]).
//!
//! Nothing here stops a render: a photo that is not solved, was taken under another sun or
//! cannot be read is left out with a note naming it and why.
//!
//! # Known limitations
//! A photo taken at another time is not read (its E_nat would need the solution relit to its
//! sun). Only the rendered photo's own lighting edits (the studio's sun slider) apply: the other
//! photos are compared with the site's sun for the rendered photo.

use std::collections::BTreeMap;
use std::sync::Arc;

use image::Rgb32FImage;
use nalgebra::Vector3;
use rayon::prelude::*;

use super::SiteDocument;
use super::photo_reflectance::{OtherView, PhotoView, PhotoViews};
use super::render::{site_camera, site_photo_linear, site_sun_dir, sun_needed};
use crate::camera::Camera;

/// Another photo is read when its sun direction is within this of the rendered photo's, degrees
/// (the sun moves about 0.25° a minute).
pub const SAME_SUN_DEG: f64 = 0.5;

/// A solved photo decoded: its camera and linear image.
pub struct LoadedPhoto {
    /// The photo's solved camera.
    pub camera: Camera,
    /// The photo, linear RGB, the camera's size.
    pub photo_linear: Rgb32FImage,
}

/// Photos decoded so far, by id (the error's text where that failed): shared by the loads for
/// several rendered photos, so that each photo is decoded once (the fit reads one transfer per
/// photo).
pub type PhotoCache = BTreeMap<String, Result<Arc<LoadedPhoto>, String>>;

fn decode(doc: &SiteDocument, id: &str) -> Result<Arc<LoadedPhoto>, String> {
    let camera = site_camera(doc, id).map_err(|e| e.to_string())?;
    let photo_linear = site_photo_linear(doc, id, &camera).map_err(|e| e.to_string())?;
    Ok(Arc::new(LoadedPhoto {
        camera,
        photo_linear,
    }))
}

/// Photo `id` of `doc` from `cache`, decoded (and kept there) on first use.
///
/// # Errors
/// The camera's or the photo's error, as text.
pub fn cached_photo(
    doc: &SiteDocument,
    id: &str,
    cache: &mut PhotoCache,
) -> Result<Arc<LoadedPhoto>, String> {
    cache
        .entry(id.to_owned())
        .or_insert_with(|| decode(doc, id))
        .clone()
}

/// One other photo, loaded.
struct OtherPhoto {
    id: String,
    photo: Arc<LoadedPhoto>,
}

/// The site's other photos that the photo reflectances can read (module doc), and notes on
/// those left out.
pub struct OtherPhotos {
    photos: Vec<OtherPhoto>,
    /// Per photo left out: its id and why.
    pub notes: Vec<String>,
}

/// The note for photo `id` left out, and why.
fn left_out(id: &str, why: &str) -> String {
    format!("photo reflectance: photo {id} not read: {why}")
}

/// The sun direction of photo `id` where the site's light needs one.
fn sun_of(doc: &SiteDocument, id: &str) -> Result<Option<Vector3<f64>>, String> {
    if !sun_needed(doc) {
        return Ok(None);
    }
    site_sun_dir(doc, id).map(Some).map_err(|e| e.to_string())
}

impl OtherPhotos {
    /// Loads every solved photo of `doc` other than `view` taken under `view`'s sun (module
    /// doc); the others become notes.
    #[must_use]
    pub fn load(doc: &SiteDocument, view: &str) -> Self {
        Self::load_cached(doc, view, &mut PhotoCache::new())
    }

    /// [`OtherPhotos::load`] decoding only the photos `cache` does not hold yet (in parallel),
    /// and keeping them there.
    #[must_use]
    pub fn load_cached(doc: &SiteDocument, view: &str, cache: &mut PhotoCache) -> Self {
        let rendered_sun = sun_of(doc, view);
        // Which photos to read (cheap: no decoding), in the site's order.
        let wanted: Vec<Result<&str, String>> = doc
            .site
            .photos
            .iter()
            .filter(|p| p.id != view)
            .map(|p| {
                let id = p.id.as_str();
                if p.exterior.is_none() {
                    return Err(left_out(id, "it is not solved"));
                }
                let sun = sun_of(doc, id).map_err(|e| left_out(id, &format!("its sun: {e}")))?;
                match (&rendered_sun, sun) {
                    (Ok(Some(a)), Some(b)) => {
                        let angle_deg = a.angle(&b).to_degrees();
                        if angle_deg > SAME_SUN_DEG {
                            return Err(left_out(
                                id,
                                &format!(
                                    "its sun is {angle_deg:.2}° from photo {view}'s (taken at \
                                     another time; only photos within {SAME_SUN_DEG}° are read)"
                                ),
                            ));
                        }
                    }
                    (Ok(None), None) => {}
                    (Err(e), _) => {
                        return Err(left_out(id, &format!("the rendered photo's sun: {e}")));
                    }
                    _ => unreachable!("sun_needed is the site's, the same for every photo"),
                }
                Ok(id)
            })
            .collect();
        let missing: Vec<&str> = wanted
            .iter()
            .filter_map(|w| w.as_ref().ok().copied())
            .filter(|id| !cache.contains_key(*id))
            .collect();
        let decoded: Vec<(String, Result<Arc<LoadedPhoto>, String>)> = missing
            .par_iter()
            .map(|id| ((*id).to_owned(), decode(doc, id)))
            .collect();
        cache.extend(decoded);
        let mut photos = Vec::new();
        let mut notes = Vec::new();
        for w in wanted {
            match w.map(|id| (id, &cache[id])) {
                Ok((id, Ok(photo))) => photos.push(OtherPhoto {
                    id: id.to_owned(),
                    photo: Arc::clone(photo),
                }),
                Ok((id, Err(e))) => notes.push(left_out(id, e)),
                Err(note) => notes.push(note),
            }
        }
        Self { photos, notes }
    }

    /// Number of photos loaded.
    #[must_use]
    pub fn len(&self) -> usize {
        self.photos.len()
    }

    /// Whether none was loaded.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.photos.is_empty()
    }

    /// The rendered photo `rendered` and these, read with the rendered photo's lighting.
    #[must_use]
    pub fn views<'a>(&'a self, rendered: PhotoView<'a>) -> PhotoViews<'a> {
        self.views_with(rendered, |k| &self.photos[k].photo.photo_linear)
    }

    /// As [`OtherPhotos::views`] with each photo's image given by `image` (its linear photo, or
    /// a spectral pass's image of it).
    pub(super) fn views_with<'a>(
        &'a self,
        rendered: PhotoView<'a>,
        image: impl Fn(usize) -> &'a Rgb32FImage,
    ) -> PhotoViews<'a> {
        PhotoViews {
            rendered,
            others: self
                .photos
                .iter()
                .enumerate()
                .map(|(k, p)| OtherView {
                    id: &p.id,
                    view: PhotoView {
                        camera: &p.photo.camera,
                        photo_linear: image(k),
                        lighting: rendered.lighting,
                    },
                })
                .collect(),
            notes: self.notes.clone(),
        }
    }

    /// Each loaded photo's linear image, in order.
    pub(super) fn images(&self) -> impl Iterator<Item = &Rgb32FImage> {
        self.photos.iter().map(|p| &p.photo.photo_linear)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::{OtherPhotos, PhotoCache, cached_photo};
    use crate::site::Location;
    use crate::site::render::tests::fixture;

    /// The fixture with its second photo solved at the first one's pose.
    fn two_solved(dir: &std::path::Path) -> crate::site::SiteDocument {
        let mut doc = fixture(dir);
        doc.site.photos[1].exterior = doc.site.photos[0].exterior.clone();
        doc
    }

    #[test]
    fn a_photo_not_solved_is_left_out_with_a_note() {
        let dir = tempfile::tempdir().unwrap();
        let doc = fixture(dir.path());
        let others = OtherPhotos::load(&doc, "p1");
        assert!(others.is_empty());
        assert_eq!(
            others.notes,
            ["photo reflectance: photo p2 not read: it is not solved"]
        );
    }

    #[test]
    fn a_solved_photo_under_the_same_sun_is_loaded() {
        let dir = tempfile::tempdir().unwrap();
        let doc = two_solved(dir.path());
        let others = OtherPhotos::load(&doc, "p1");
        assert_eq!(others.len(), 1);
        assert!(others.notes.is_empty(), "{:?}", others.notes);
        // And from the other side.
        assert_eq!(OtherPhotos::load(&doc, "p2").len(), 1);
    }

    #[test]
    fn a_photo_taken_at_another_time_is_left_out_with_the_sun_angle() {
        let dir = tempfile::tempdir().unwrap();
        let mut doc = two_solved(dir.path());
        doc.site.lighting.sun_manual = None;
        doc.site.location = Some(Location {
            latitude_deg: 47.37,
            longitude_deg: 8.54,
            elevation_m: 400.0,
            crs: None,
            grid_convergence_deg: 0.0,
            time_zone: None,
        });
        doc.site.photos[0].taken_at = Some("2024-08-21T10:44:00+02:00".into());
        // One minute later: the same sun within SAME_SUN_DEG.
        doc.site.photos[1].taken_at = Some("2024-08-21T10:45:00+02:00".into());
        let others = OtherPhotos::load(&doc, "p1");
        assert_eq!(others.len(), 1, "{:?}", others.notes);
        // An hour later: left out.
        doc.site.photos[1].taken_at = Some("2024-08-21T11:44:00+02:00".into());
        let others = OtherPhotos::load(&doc, "p1");
        assert!(others.is_empty());
        let note = &others.notes[0];
        assert!(
            note.starts_with("photo reflectance: photo p2 not read: its sun is ")
                && note.contains("from photo p1's (taken at another time"),
            "{note}"
        );
        let angle_deg: f64 = note
            .trim_start_matches("photo reflectance: photo p2 not read: its sun is ")
            .split('°')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        // The sun moves ≈ 15° an hour across the sky; here between 10 and 16 in August.
        assert!((10.0..16.0).contains(&angle_deg), "{angle_deg}");
        // No time at all: named.
        doc.site.photos[1].taken_at = None;
        let others = OtherPhotos::load(&doc, "p1");
        assert!(
            others.notes[0].starts_with("photo reflectance: photo p2 not read: its sun: "),
            "{:?}",
            others.notes
        );
    }

    #[test]
    fn a_shared_cache_decodes_each_photo_once() {
        let dir = tempfile::tempdir().unwrap();
        let doc = two_solved(dir.path());
        let mut cache = PhotoCache::new();
        assert_eq!(OtherPhotos::load_cached(&doc, "p1", &mut cache).len(), 1);
        assert_eq!(cache.keys().collect::<Vec<_>>(), ["p2"]);
        // Both photos are the fixture's one file: gone now, p2 still comes from the cache and
        // p1, never decoded, is left out with the decoding error.
        std::fs::remove_file(dir.path().join("p1.png")).unwrap();
        assert!(cached_photo(&doc, "p2", &mut cache).is_ok());
        let others = OtherPhotos::load_cached(&doc, "p2", &mut cache);
        assert!(others.is_empty());
        assert!(
            others.notes[0].starts_with("photo reflectance: photo p1 not read: ")
                && others.notes[0].contains("p1.png"),
            "{:?}",
            others.notes
        );
        assert!(cached_photo(&doc, "p1", &mut cache).is_err());
    }

    #[test]
    fn a_photo_that_cannot_be_read_is_left_out_with_its_error() {
        let dir = tempfile::tempdir().unwrap();
        let mut doc = two_solved(dir.path());
        doc.site.photos[1].file = "missing.png".into();
        let others = OtherPhotos::load(&doc, "p1");
        assert!(others.is_empty());
        assert!(
            others.notes[0].starts_with("photo reflectance: photo p2 not read: ")
                && others.notes[0].contains("missing.png"),
            "{:?}",
            others.notes
        );
    }
}
