//! The site's other solved photos, for the photo reflectances of the radiosity mode (issue 13
//! item 2: "natural patches take ρ_d from the photo where a solved photo sees them").
//!
//! The rendered photo is read first ([`super::photo_reflectance`]); a natural element it does not
//! see takes its ρ_d from the first other photo (in the site's order) that does. Durisch's second
//! inversion ρ_d = π·L₀ / E_nat needs the light each photo was taken in, so the photos are
//! grouped by *sun*: a photo whose sun direction ([`super::render::site_sun_dir`]) is within
//! [`SAME_SUN_DEG`] of the rendered photo's (the same `sun_manual`, or capture times a minute or
//! two apart) is read under the rendered photo's light (sun 0); the others form further suns,
//! each the sun of the first photo (in the site's order) taken then, the photos within
//! [`SAME_SUN_DEG`] of it joining it. Each other sun has its lighting: the rendered view's with
//! that sun ([`OtherPhotos::reading_lightings`], for the shadow rays at the samples) and the
//! site's radiosity lighting at that time ([`OtherPhotos::sun_transfer_lightings`]: the sky that
//! follows the sun, for the solution E_rad is read from). The sky's weights and the atmosphere
//! are the site's, shared by all photos. Each photo's exposure is checked against the rendered
//! photo's where both see the same points
//! ([`super::photo_reflectance::EXPOSURE_TOLERANCE`]).
//!
//! Nothing here stops a render: a photo that is not solved, was taken with the sun below the
//! horizon or cannot be read is left out with a note naming it and why.
//!
//! # Known limitations
//! Only the rendered photo's own lighting edits (the studio's sun slider) move its sun; the other
//! photos keep the suns of their capture times.

use std::collections::BTreeMap;
use std::sync::Arc;

use image::Rgb32FImage;
use nalgebra::Vector3;
use rayon::prelude::*;

use super::SiteDocument;
use super::photo_reflectance::{OtherView, PhotoView, PhotoViews};
use super::radiosity_lighting::site_transfer_lighting;
use super::render::{site_camera, site_photo_linear, site_sun_dir, sun_needed};
use super::render_error::SiteRenderError;
use crate::camera::Camera;
use crate::radiosity::TransferLighting;
use crate::render::{DistantLight, Lighting};
use crate::scene::Scene;

/// Photos whose sun directions are within this of each other are read under one sun, degrees
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
    /// Its sun: 0 the rendered photo's, k the k-th of [`OtherPhotos::sun_photos`].
    sun: usize,
}

/// The site's other photos that the photo reflectances can read (module doc), and notes on
/// those left out.
pub struct OtherPhotos {
    photos: Vec<OtherPhoto>,
    /// Per other sun (1, 2, …): the photo whose capture time gives it, and its direction.
    suns: Vec<(String, Vector3<f64>)>,
    /// The site's `sun_weight`.
    sun_weight: [f64; 3],
    /// Per photo left out: its id and why.
    pub notes: Vec<String>,
}

/// The lightings of the other suns ([`OtherPhotos::sun_lights`]).
#[derive(Debug, Clone, Default)]
pub struct OtherSunLights {
    /// Per other sun, the site's radiosity lighting at its time (the solution its photos are
    /// read against).
    pub transfer: Vec<TransferLighting>,
    /// Per other sun, the lighting its photos are read in.
    pub reading: Vec<Lighting>,
}

/// The site's other photos for the photo reflectances of `photo` (the rendered photo of view
/// `view`, `doc`'s scene `scene`) with their suns' lightings; `None` without a photo.
///
/// # Errors
/// As [`site_transfer_lighting`].
pub fn other_photos_for(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
    photo: Option<&PhotoView<'_>>,
) -> Result<Option<(OtherPhotos, OtherSunLights)>, SiteRenderError> {
    photo
        .map(|p| {
            let others = OtherPhotos::load(doc, view);
            let lights = others.sun_lights(doc, scene, p.lighting)?;
            Ok((others, lights))
        })
        .transpose()
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

/// The index (1, 2, …) of the other sun within [`SAME_SUN_DEG`] of `dir` in `suns`, or of a new
/// one given by photo `id`; a note where the sun is below the horizon.
fn sun_index(
    id: &str,
    dir: Vector3<f64>,
    suns: &mut Vec<(String, Vector3<f64>)>,
) -> Result<usize, String> {
    if dir.z <= 0.0 {
        return Err(left_out(
            id,
            &format!(
                "its sun is {:.1}° below the horizon",
                dir.z.clamp(-1.0, 1.0).asin().to_degrees().abs()
            ),
        ));
    }
    if let Some(k) = suns
        .iter()
        .position(|(_, d)| d.angle(&dir).to_degrees() <= SAME_SUN_DEG)
    {
        return Ok(k + 1);
    }
    suns.push((id.to_owned(), dir));
    Ok(suns.len())
}

impl OtherPhotos {
    /// Loads every solved photo of `doc` other than `view`, each with its sun (module doc); the
    /// photos left out become notes.
    #[must_use]
    pub fn load(doc: &SiteDocument, view: &str) -> Self {
        Self::load_cached(doc, view, &mut PhotoCache::new())
    }

    /// [`OtherPhotos::load`] decoding only the photos `cache` does not hold yet (in parallel),
    /// and keeping them there.
    #[must_use]
    pub fn load_cached(doc: &SiteDocument, view: &str, cache: &mut PhotoCache) -> Self {
        let rendered_sun = sun_of(doc, view);
        let mut suns: Vec<(String, Vector3<f64>)> = Vec::new();
        // Which photos to read and under which sun (cheap: no decoding), in the site's order.
        let mut wanted: Vec<Result<(&str, usize), String>> = Vec::new();
        for p in doc.site.photos.iter().filter(|p| p.id != view) {
            let id = p.id.as_str();
            wanted.push(if p.exterior.is_none() {
                Err(left_out(id, "it is not solved"))
            } else {
                match (&rendered_sun, sun_of(doc, id)) {
                    (_, Err(e)) => Err(left_out(id, &format!("its sun: {e}"))),
                    (Err(e), _) => Err(left_out(id, &format!("the rendered photo's sun: {e}"))),
                    (Ok(Some(a)), Ok(Some(b))) if a.angle(&b).to_degrees() > SAME_SUN_DEG => {
                        sun_index(id, b, &mut suns).map(|k| (id, k))
                    }
                    _ => Ok((id, 0)),
                }
            });
        }
        let missing: Vec<&str> = wanted
            .iter()
            .filter_map(|w| w.as_ref().ok().map(|(id, _)| *id))
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
            match w.map(|(id, sun)| (id, sun, &cache[id])) {
                Ok((id, sun, Ok(photo))) => photos.push(OtherPhoto {
                    id: id.to_owned(),
                    photo: Arc::clone(photo),
                    sun,
                }),
                Ok((id, _, Err(e))) => notes.push(left_out(id, e)),
                Err(note) => notes.push(note),
            }
        }
        // A sun none of whose photos could be decoded is dropped, the others numbered again in
        // order: every sun is some loaded photo's.
        let mut renumbered = vec![0; suns.len() + 1];
        let mut kept = Vec::new();
        for (k, sun) in suns.into_iter().enumerate() {
            if photos.iter().any(|p| p.sun == k + 1) {
                kept.push(sun);
                renumbered[k + 1] = kept.len();
            }
        }
        for p in &mut photos {
            p.sun = renumbered[p.sun];
        }
        Self {
            photos,
            suns: kept,
            sun_weight: doc.site.lighting.sun_weight,
            notes,
        }
    }

    /// Per other sun (1, 2, …), the photo whose capture time gives it.
    pub fn sun_photos(&self) -> impl Iterator<Item = &str> {
        self.suns.iter().map(|(id, _)| id.as_str())
    }

    /// Per other sun, the lighting its photos are read in: `rendered` (the rendered photo's)
    /// with that sun (normal irradiance: the site's `sun_weight`); the photo reflectances read
    /// only its sun, ambient term and atmosphere.
    #[must_use]
    pub fn reading_lightings(&self, rendered: &Lighting) -> Vec<Lighting> {
        let weighted = self.sun_weight.iter().any(|&k| k != 0.0);
        self.suns
            .iter()
            .map(|(_, dir)| {
                let mut lighting = rendered.clone();
                lighting.daylight.sun = weighted.then_some(DistantLight {
                    dir_in_world: *dir,
                    normal_irradiance_rgb: self.sun_weight,
                });
                lighting
            })
            .collect()
    }

    /// Per other sun, the site's radiosity lighting at its photo's capture time
    /// ([`site_transfer_lighting`]: the sky follows that sun).
    ///
    /// # Errors
    /// As [`site_transfer_lighting`].
    pub fn sun_transfer_lightings(
        &self,
        doc: &SiteDocument,
        scene: &Scene,
    ) -> Result<Vec<TransferLighting>, SiteRenderError> {
        self.sun_photos()
            .map(|id| site_transfer_lighting(doc, scene, id).map(|(l, _)| l))
            .collect()
    }

    /// Both lightings of every other sun: [`OtherPhotos::sun_transfer_lightings`] for `doc`'s
    /// scene `scene`, [`OtherPhotos::reading_lightings`] from the rendered photo's `rendered`.
    ///
    /// # Errors
    /// As [`site_transfer_lighting`].
    pub fn sun_lights(
        &self,
        doc: &SiteDocument,
        scene: &Scene,
        rendered: &Lighting,
    ) -> Result<OtherSunLights, SiteRenderError> {
        Ok(OtherSunLights {
            transfer: self.sun_transfer_lightings(doc, scene)?,
            reading: self.reading_lightings(rendered),
        })
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

    /// The rendered photo `rendered` and these, each read in its sun's lighting: the rendered
    /// photo's, or that of `lightings` ([`OtherPhotos::reading_lightings`]).
    ///
    /// # Panics
    /// When `lightings` has not one lighting per other sun.
    #[must_use]
    pub fn views<'a>(
        &'a self,
        rendered: PhotoView<'a>,
        lightings: &'a [Lighting],
    ) -> PhotoViews<'a> {
        self.views_with(rendered, lightings, |k| &self.photos[k].photo.photo_linear)
    }

    /// As [`OtherPhotos::views`] with each photo's image given by `image` (its linear photo, or
    /// a spectral pass's image of it).
    ///
    /// # Panics
    /// When `lightings` has not one lighting per other sun.
    pub(super) fn views_with<'a>(
        &'a self,
        rendered: PhotoView<'a>,
        lightings: &'a [Lighting],
        image: impl Fn(usize) -> &'a Rgb32FImage,
    ) -> PhotoViews<'a> {
        assert_eq!(
            lightings.len(),
            self.suns.len(),
            "one lighting per other sun"
        );
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
                        lighting: match p.sun {
                            0 => rendered.lighting,
                            s => &lightings[s - 1],
                        },
                    },
                    sun: p.sun,
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

    use super::{OtherPhotos, PhotoCache, PhotoView, cached_photo};
    use crate::site::SiteDocument;
    use crate::site::radiosity_lighting::site_transfer_lighting;
    use crate::site::render::tests::{fixture, zurich};
    use crate::site::render::{prepare_view, site_sun_dir};

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
    #[allow(clippy::float_cmp)] // weights copied, not computed: equal bit for bit
    fn photos_taken_at_other_times_are_read_under_their_own_suns() {
        let dir = tempfile::tempdir().unwrap();
        let mut doc = two_solved(dir.path());
        let mut p3 = doc.site.photos[1].clone();
        p3.id = "p3".into();
        doc.site.photos.push(p3);
        doc.site.lighting.sun_manual = None;
        doc.site.location = Some(zurich());
        let job = prepare_view(&doc_at(&doc, ["10:44", "10:45", "10:45"]), "p1").unwrap();
        let rendered = PhotoView {
            camera: &job.camera,
            photo_linear: &job.photo_linear,
            lighting: &job.lighting,
        };
        // A minute later: the rendered photo's sun (within SAME_SUN_DEG).
        let same = doc_at(&doc, ["10:44", "10:45", "10:45"]);
        let others = OtherPhotos::load(&same, "p1");
        assert_eq!(others.len(), 2, "{:?}", others.notes);
        assert_eq!(others.sun_photos().count(), 0);
        let views = others.views(rendered, &[]);
        assert!(views.others.iter().all(|o| o.sun == 0));
        assert!(std::ptr::eq(views.others[0].view.lighting, &job.lighting));
        // An hour later: a sun of its own, which a photo a minute after it joins.
        let later = doc_at(&doc, ["10:44", "11:44", "11:45"]);
        let others = OtherPhotos::load(&later, "p1");
        assert_eq!(others.len(), 2, "{:?}", others.notes);
        assert_eq!(others.sun_photos().collect::<Vec<_>>(), ["p2"]);
        let lightings = others.reading_lightings(&job.lighting);
        let views = others.views(rendered, &lightings);
        assert_eq!(views.suns(), 2);
        assert_eq!(
            views.others.iter().map(|o| o.sun).collect::<Vec<_>>(),
            [1, 1]
        );
        let sun = lightings[0].daylight.sun.unwrap();
        let p2_sun = site_sun_dir(&later, "p2").unwrap();
        assert!((sun.dir_in_world - p2_sun).norm() < 1e-12);
        assert_eq!(sun.normal_irradiance_rgb, later.site.lighting.sun_weight);
        // The sun moves ≈ 15° an hour across the sky; here between 10 and 16 in August.
        let p1_sun = site_sun_dir(&later, "p1").unwrap();
        let angle_deg = p1_sun.angle(&p2_sun).to_degrees();
        assert!((10.0..16.0).contains(&angle_deg), "{angle_deg}");
        // Everything but the sun is the rendered photo's.
        assert_eq!(lightings[0].atmosphere, job.lighting.atmosphere);
        assert_eq!(
            lightings[0].daylight.ambient_radiance_rgb,
            job.lighting.daylight.ambient_radiance_rgb
        );
        // Its radiosity lighting is the site's at p2's time.
        let scene = &job.scene.scene;
        let transfer = others.sun_transfer_lightings(&later, scene).unwrap();
        assert_eq!(
            transfer,
            vec![site_transfer_lighting(&later, scene, "p2").unwrap().0]
        );
        // Three suns: p2 and p3 an hour apart.
        let mut three = doc_at(&doc, ["10:44", "11:44", "12:44"]);
        let others = OtherPhotos::load(&three, "p1");
        assert_eq!(others.sun_photos().collect::<Vec<_>>(), ["p2", "p3"]);
        // A sun whose photo cannot be read is dropped, the next one taking its number.
        three.site.photos[1].file = "missing.png".into();
        let others = OtherPhotos::load(&three, "p1");
        assert_eq!(others.sun_photos().collect::<Vec<_>>(), ["p3"]);
        let lightings = others.reading_lightings(&job.lighting);
        let views = others.views(rendered, &lightings);
        assert_eq!((views.suns(), views.others[0].sun), (2, 1));
        assert!(others.notes[0].starts_with("photo reflectance: photo p2 not read: "));
        three.site.photos[1].file = "p1.png".into();
        three.site.photos[2].file = "missing.png".into();
        let others = OtherPhotos::load(&three, "p1");
        assert_eq!(others.sun_photos().collect::<Vec<_>>(), ["p2"]);
        assert_eq!(
            others
                .views(rendered, &others.reading_lightings(&job.lighting))
                .suns(),
            2
        );
        // At night: left out, named.
        let night = doc_at(&doc, ["10:44", "11:44", "23:30"]);
        let others = OtherPhotos::load(&night, "p1");
        assert_eq!(others.len(), 1);
        assert!(
            others.notes[0].starts_with("photo reflectance: photo p3 not read: its sun is ")
                && others.notes[0].ends_with("° below the horizon"),
            "{:?}",
            others.notes
        );
        // No time at all: named.
        let mut untimed = later.clone();
        untimed.site.photos[1].taken_at = None;
        let others = OtherPhotos::load(&untimed, "p1");
        assert!(
            others.notes[0].starts_with("photo reflectance: photo p2 not read: its sun: "),
            "{:?}",
            others.notes
        );
    }

    /// `doc` with its three photos taken on 2024-08-21 at these local times (UTC+2).
    fn doc_at(doc: &SiteDocument, times: [&str; 3]) -> SiteDocument {
        let mut doc = doc.clone();
        for (p, t) in doc.site.photos.iter_mut().zip(times) {
            p.taken_at = Some(format!("2024-08-21T{t}:00+02:00"));
        }
        doc
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
