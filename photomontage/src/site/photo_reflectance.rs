//! Diffuse reflectances of the photographed surfaces, read off the photo (issue 13 item 2:
//! "natural patches take ρ_d from the photo where a solved photo sees them, else from the
//! material library").
//!
//! The renderer's case D recovers ρ_d at every changed natural pixel by the two second
//! inversions of Durisch 1992: the atmosphere's (eq. 8, apparent colour → true colour L₀ at the
//! photo's distance) and the illumination model's (eq. 10, ρ_d = π·L₀ / E_nat). Here the same
//! inversions run on the radiosity mesh of the photographed state, so that the light the
//! surroundings reflect (onto the planned building, and between existing surfaces) is the light
//! the photo shows, not the library's guess:
//!
//! - Each natural element is sampled at [`SAMPLES_PER_AXIS`]² stratified points. A sample counts
//!   where it faces the camera, projects inside the photo and is the first natural surface on the
//!   camera's ray to it (within [`SEEN_TOLERANCE_M`] plus 10⁻⁴ of the distance).
//! - E_nat at a sample is the renderer's in the radiosity mode: the sun by an exact shadow ray
//!   against the natural geometry, the ambient term, and the element's sky and interreflected
//!   irradiance from the solution (the sun's direct term taken out, as
//!   [`RadiosityLight::traced_exactly`] names it).
//! - An element with at least [`MIN_SEEN_SAMPLES`] counted samples takes, per channel, the median
//!   of its samples' ρ_d, clamped to [0, 1].
//! - An element the rendered photo sees at fewer points takes its samples from the first of the
//!   site's other solved photos ([`super::other_photos`]) that sees it at enough
//!   ([`PhotoSamples::from_views`]). Each photo is read in the light it was taken in: its own
//!   sun's shadow rays, and E_rad from the solution for its sun (photos taken at another time
//!   are read against a solution lit by the sun of their capture time,
//!   [`super::render_radiosity`], [`refit_transfer`]). Such a photo is read only if its exposure
//!   agrees: at the sample points both photos see, the median ratio of the reflectance it reads
//!   to the rendered photo's is within [`EXPOSURE_TOLERANCE`] of 1 in every channel (a
//!   Lambertian surface has one ρ_d, whatever the light and the camera; under the same sun this
//!   is the ratio of their true colours). The other elements keep the library's value.
//!
//! E_nat's interreflected part depends on the surroundings' ρ_d, so the solve is refitted
//! ([`crate::radiosity::solve_on_mesh_refitting`]): solved with the library's values, then
//! [`REFIT_ROUNDS`] times with the photo's. The samples (rays, photo colours, sun) are taken
//! once; a round only reads the new solutions, and checks the exposures again against them.
//!
//! # Known limitations
//! An element seen by both the rendered photo and an other takes the rendered photo's samples
//! only. What the model lacks (a parked car, a tree in front of a wall) is read as the surface
//! behind it; the median over the samples keeps a small intrusion out. The element's sky and
//! interreflected light is its mean, not the value at the sample; the mesh follows the shadow
//! edges of the rendered photo's sun only, so under another sun an element across its shadow
//! edge has the mean of both sides (the sun itself is traced exactly at every sample).

use rayon::prelude::*;

use crate::radiosity::{
    LightingChange, Mesh, RadiosityError, Solution, Transfer, TransferLighting,
};
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::render::illumination::diffuse_reflectance_from_true_colour;
use crate::scene::SceneTracer;

use super::photo_views::{ElementRead, Sample, read_element};
pub use super::photo_views::{
    MIN_SEEN_SAMPLES, OtherView, PhotoView, PhotoViews, SAMPLES_PER_AXIS, SEEN_TOLERANCE_M,
};

type Rgb = [f64; 3];

/// Solves with the photo's reflectances after the first (the second moves ρ_d by well under 1 %
/// on the street site: docs/methodology.md).
pub const REFIT_ROUNDS: usize = 2;

/// The samples of every element of a photographed-state mesh (module doc).
#[derive(Debug, Clone)]
pub struct PhotoSamples {
    /// Per element, the rendered photo's seen samples (empty when fewer than
    /// [`MIN_SEEN_SAMPLES`]).
    rendered: Vec<Vec<Sample>>,
    /// Per element the rendered photo does not see, each other view that sees it at enough
    /// points, in order, with its samples.
    candidates: Vec<Vec<(usize, Vec<Sample>)>>,
    /// Per other view, the points it and the rendered photo both see: the element, the
    /// rendered photo's sample and its own.
    common: Vec<Vec<(usize, Sample, Sample)>>,
    /// Per other view, its sun ([`OtherView::sun`]).
    view_sun: Vec<usize>,
    /// Suns the views were taken under ([`PhotoViews::suns`]).
    suns: usize,
    /// Per element, the view its samples are from: 0 the rendered photo, k the k-th other (as
    /// of the last [`PhotoSamples::reflectances`]).
    source: Vec<Option<usize>>,
    /// What each other photo gave (as of the last [`PhotoSamples::reflectances`]).
    others: Vec<OtherViewRead>,
    /// What the loading of the other photos found.
    load_notes: Vec<String>,
}

/// What [`PhotoSamples::reflectances`] did, for the render report.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhotoReflectanceCount {
    /// Elements that took ρ_d from the photos (the rendered one and the others).
    pub from_photo: usize,
    /// Of those, the elements read on the site's other photos.
    pub from_other_photos: usize,
    /// Elements of the mesh.
    pub elements: usize,
    /// Of those from the photo, how many had a channel clamped to 1.
    pub clamped: usize,
    /// Mean over the elements from the photo of the largest relative change of a channel since
    /// the round before (the refit's convergence; 0 after the first round).
    pub mean_change_rel: f64,
}

/// The refit's rounds (module doc) for the render's solve and the studio's transfers alike: each
/// round reads ρ_d off the samples against the latest solutions and keeps the count to report,
/// with the change since the round before.
#[derive(Debug, Clone)]
pub struct PhotoRefit {
    samples: PhotoSamples,
    previous: Option<Vec<Option<Rgb>>>,
    count: Option<PhotoReflectanceCount>,
}

impl PhotoRefit {
    /// Rounds over `samples`.
    #[must_use]
    pub fn new(samples: PhotoSamples) -> Self {
        Self {
            samples,
            previous: None,
            count: None,
        }
    }

    /// ρ_d per element from `solutions`, one per sun ([`PhotoSamples::reflectances`]).
    ///
    /// # Panics
    /// When `solutions` has not one solution per sun of the samples.
    pub fn next_round(&mut self, solutions: &[&Solution]) -> Vec<Option<Rgb>> {
        let (rho, mut count) = self.samples.reflectances(solutions);
        if let Some(before) = &self.previous {
            count.mean_change_rel = mean_change_rel(before, &rho);
        }
        self.previous = Some(rho.clone());
        self.count = Some(count);
        rho
    }

    /// The last round's count; `None` before the first.
    #[must_use]
    pub fn count(&self) -> Option<PhotoReflectanceCount> {
        self.count
    }

    /// The samples' notes as of the last round ([`PhotoSamples::notes`]).
    #[must_use]
    pub fn notes(&self) -> Vec<String> {
        self.samples.notes()
    }

    /// Suns the samples were taken under ([`PhotoViews::suns`]).
    #[must_use]
    pub fn suns(&self) -> usize {
        self.samples.suns
    }
}

/// The lighting change that puts the sun and sky of `lighting` on a transfer.
fn sun_and_sky_of(lighting: &TransferLighting) -> LightingChange {
    LightingChange {
        sun: Some(lighting.sun),
        sky: Some(lighting.sky.clone()),
        ..LightingChange::default()
    }
}

/// `rounds` of `refit` on `transfer` (the photographed state, lit for the rendered photo): in
/// each, the transfer is relit to the sun and sky of every other sun of `other_suns` (the
/// transfer's links and sky rays, [`Transfer::relight`]) for that sun's solution, relit back,
/// and its elements set to the round's reflectances ([`Transfer::set_element_reflectances`]).
/// The studio's transfers and the fit's use it; the render's solve reads the other suns as
/// extra light groups of one solve ([`super::render_radiosity`]).
///
/// # Errors
/// A relight error; [`RadiosityError::InvalidParameter`] when `other_suns` does not give one
/// lighting per other sun of `refit`.
pub fn refit_transfer(
    transfer: &mut Transfer,
    refit: &mut PhotoRefit,
    other_suns: &[TransferLighting],
    rounds: usize,
) -> Result<(), RadiosityError> {
    if other_suns.len() + 1 != refit.suns() {
        return Err(RadiosityError::InvalidParameter {
            name: "other suns",
            value: other_suns.len() as f64,
            reason: "the photo reflectances need one lighting per other sun",
        });
    }
    let home = sun_and_sky_of(transfer.lighting());
    for _ in 0..rounds {
        let mut relit = Vec::with_capacity(other_suns.len());
        for lighting in other_suns {
            transfer.relight_in_place(&sun_and_sky_of(lighting))?;
            relit.push(transfer.solution().clone());
        }
        if !other_suns.is_empty() {
            transfer.relight_in_place(&home)?;
        }
        let solutions: Vec<&Solution> = std::iter::once(transfer.solution())
            .chain(relit.iter())
            .collect();
        let rho = refit.next_round(&solutions);
        transfer.set_element_reflectances(&rho)?;
    }
    Ok(())
}

/// The mean over elements valued in both of the largest relative change of a channel from
/// `before` to `after`; 0 when none is.
fn mean_change_rel(before: &[Option<Rgb>], after: &[Option<Rgb>]) -> f64 {
    let changes: Vec<f64> = before
        .iter()
        .zip(after)
        .filter_map(|(b, a)| {
            let (b, a) = ((*b)?, (*a)?);
            Some(
                (0..3)
                    .filter(|&c| b[c] > 0.0)
                    .map(|c| (a[c] / b[c] - 1.0).abs())
                    .fold(0.0, f64::max),
            )
        })
        .collect();
    if changes.is_empty() {
        0.0
    } else {
        changes.iter().sum::<f64>() / changes.len() as f64
    }
}

/// What one other photo gave ([`PhotoSamples::reflectances`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OtherViewRead {
    /// The photo's id.
    pub id: String,
    /// Its sun ([`OtherView::sun`]).
    pub sun: usize,
    /// Sample points both it and the rendered photo see.
    pub common_samples: usize,
    /// Per channel, the median over those points of the reflectance it reads over the rendered
    /// photo's (`None` with fewer than [`MIN_COMMON_SAMPLES`] points, or before the first
    /// round).
    pub exposure_ratio: Option<Rgb>,
    /// Whether its samples are used ([`EXPOSURE_TOLERANCE`]; none before the first round).
    pub accepted: bool,
    /// Elements that take their samples from it.
    pub elements: usize,
}

/// An other photo is read only when the reflectances it reads agree with the rendered photo's at
/// the points both see within this, per channel (median ratio): a photo exposed or
/// white-balanced differently would bring its own scale.
pub const EXPOSURE_TOLERANCE: f64 = 0.05;
/// The exposure check needs this many sample points seen by both photos; with fewer the other
/// photo is read unchecked (a note says so), as the daylight fit reads every photo with one set
/// of weights.
pub const MIN_COMMON_SAMPLES: usize = 100;

impl PhotoSamples {
    /// Samples the elements of `mesh` (the photographed state: natural objects only, traced by
    /// `natural`) in `view`.
    #[must_use]
    pub fn new(mesh: &Mesh, natural: &SceneTracer, view: &PhotoView<'_>) -> Self {
        Self::from_views(mesh, natural, &PhotoViews::single(*view))
    }

    /// Samples the elements of `mesh` in the rendered photo of `views`, and where it sees an
    /// element at fewer than [`MIN_SEEN_SAMPLES`] points, in every other photo that sees it at
    /// enough; which of those is read (the first whose exposure agrees with the rendered
    /// photo's, [`EXPOSURE_TOLERANCE`]) is decided by each [`PhotoSamples::reflectances`],
    /// which has the solutions the check needs.
    #[must_use]
    pub fn from_views(mesh: &Mesh, natural: &SceneTracer, views: &PhotoViews<'_>) -> Self {
        let reads: Vec<ElementRead> = (0..mesh.elements.len())
            .into_par_iter()
            .map(|e| read_element(mesh, e, natural, views))
            .collect();
        let mut common: Vec<Vec<(usize, Sample, Sample)>> = vec![Vec::new(); views.others.len()];
        let mut rendered = Vec::with_capacity(reads.len());
        let mut candidates = Vec::with_capacity(reads.len());
        for (e, r) in reads.into_iter().enumerate() {
            for (k, a, b) in r.common {
                common[k].push((e, a, b));
            }
            rendered.push(r.rendered);
            candidates.push(r.candidates);
        }
        let source = rendered
            .iter()
            .map(|s| (!s.is_empty()).then_some(0))
            .collect();
        let others = views
            .others
            .iter()
            .zip(&common)
            .map(|(o, c)| OtherViewRead {
                id: o.id.to_owned(),
                sun: o.sun,
                common_samples: c.len(),
                exposure_ratio: None,
                accepted: false,
                elements: 0,
            })
            .collect();
        Self {
            rendered,
            candidates,
            common,
            view_sun: views.others.iter().map(|o| o.sun).collect(),
            suns: views.suns(),
            source,
            others,
            load_notes: views.notes.clone(),
        }
    }

    /// Per element, the view its samples are from: `Some(0)` the rendered photo, `Some(k)` the
    /// k-th other photo, `None` where none sees it at enough points (or, before the first
    /// [`PhotoSamples::reflectances`], none but the rendered photo is read).
    #[must_use]
    pub fn sources(&self) -> &[Option<usize>] {
        &self.source
    }

    /// What each other photo gave (as of the last [`PhotoSamples::reflectances`]).
    #[must_use]
    pub fn other_views(&self) -> &[OtherViewRead] {
        &self.others
    }

    /// The notes for the report: what the loading of the other photos found, and per other
    /// photo what it gave or why it was not read (as of the last
    /// [`PhotoSamples::reflectances`]).
    #[must_use]
    pub fn notes(&self) -> Vec<String> {
        let mut notes = self.load_notes.clone();
        for o in &self.others {
            let ratio = o.exposure_ratio.map_or_else(
                || {
                    format!(
                        "exposure not checked: {} sample points seen by both, under {MIN_COMMON_SAMPLES}",
                        o.common_samples
                    )
                },
                |q| {
                    format!(
                        "the reflectances it reads over the rendered photo's {:.3}, {:.3}, {:.3} (median over {} points both see)",
                        q[0], q[1], q[2], o.common_samples
                    )
                },
            );
            let (sun, differs) = if o.sun > 0 {
                (
                    " (read under the sun of its own capture time)",
                    "exposure, white balance or capture time differs",
                )
            } else {
                ("", "exposure or white balance differs")
            };
            notes.push(if o.accepted {
                format!(
                    "photo reflectance: photo {} read on {} elements the rendered photo does not see{sun}; {ratio}",
                    o.id, o.elements
                )
            } else {
                format!(
                    "photo reflectance: photo {} not read: {ratio}, more than {:.0} % from 1 ({differs})",
                    o.id,
                    100.0 * EXPOSURE_TOLERANCE
                )
            });
        }
        notes
    }

    /// Elements with enough seen samples in the photos read (as of the last
    /// [`PhotoSamples::reflectances`]).
    #[must_use]
    pub fn seen_elements(&self) -> usize {
        self.source.iter().filter(|s| s.is_some()).count()
    }

    /// Checks every other photo's exposure against `e_rad` (per sun, per element) and decides
    /// which view each element's samples come from (module doc).
    fn decide(&mut self, e_rad: &[Vec<Rgb>]) {
        for (k, o) in self.others.iter_mut().enumerate() {
            let sun = self.view_sun[k];
            let ratios: Vec<Rgb> = self.common[k]
                .iter()
                .filter_map(|(e, r, s)| {
                    let q: [Option<f64>; 3] = std::array::from_fn(|c| {
                        let e_r = r.fixed_irradiance[c] + e_rad[0][*e][c];
                        let e_s = s.fixed_irradiance[c] + e_rad[sun][*e][c];
                        (e_r > 0.0 && e_s > 0.0)
                            .then(|| (s.true_colour[c] / e_s) / (r.true_colour[c] / e_r))
                    });
                    Some([q[0]?, q[1]?, q[2]?])
                })
                .collect();
            o.exposure_ratio = (ratios.len() >= MIN_COMMON_SAMPLES).then(|| {
                let mut column: Vec<f64> = Vec::with_capacity(ratios.len());
                std::array::from_fn(|c| {
                    column.clear();
                    column.extend(ratios.iter().map(|q| q[c]));
                    column.sort_by(f64::total_cmp);
                    column[column.len() / 2]
                })
            });
            o.accepted = o
                .exposure_ratio
                .is_none_or(|q| q.iter().all(|r| (r - 1.0).abs() <= EXPOSURE_TOLERANCE));
            o.elements = 0;
        }
        for (e, source) in self.source.iter_mut().enumerate() {
            *source = if self.rendered[e].is_empty() {
                self.candidates[e]
                    .iter()
                    .find(|(k, _)| self.others[*k].accepted)
                    .map(|(k, _)| {
                        self.others[*k].elements += 1;
                        k + 1
                    })
            } else {
                Some(0)
            };
        }
    }

    /// The samples element `e` is read from ([`PhotoSamples::sources`]) and their sun.
    fn samples_of(&self, e: usize) -> Option<(&[Sample], usize)> {
        match self.source[e]? {
            0 => Some((&self.rendered[e], 0)),
            k => self.candidates[e]
                .iter()
                .find(|(c, _)| *c == k - 1)
                .map(|(_, s)| (s.as_slice(), self.view_sun[k - 1])),
        }
    }

    /// ρ_d per element from `solutions` (the photographed state solved on the sampled mesh, one
    /// solution per sun: the rendered photo's first, [`PhotoViews::suns`]): the median over its
    /// samples of π·L₀ / (E_fixed + E_rad), E_rad the element's sky and interreflected
    /// irradiance under the samples' sun; `None` where no photo read sees the element or no
    /// light reaches it. Each call checks the other photos' exposures again
    /// ([`PhotoSamples::from_views`]).
    ///
    /// # Panics
    /// When `solutions` has not one solution per sun.
    pub fn reflectances(
        &mut self,
        solutions: &[&Solution],
    ) -> (Vec<Option<Rgb>>, PhotoReflectanceCount) {
        assert_eq!(
            solutions.len(),
            self.suns,
            "one solution per sun of the photos read"
        );
        let e_rad: Vec<Vec<Rgb>> = solutions
            .iter()
            .map(|s| sky_and_bounce_per_element(s))
            .collect();
        self.decide(&e_rad);
        let rho: Vec<Option<(Rgb, bool)>> = (0..self.rendered.len())
            .into_par_iter()
            .map(|e| {
                let (samples, sun) = self.samples_of(e)?;
                let e_rad = e_rad[sun][e];
                let values: Vec<Rgb> = samples
                    .iter()
                    .filter_map(|s| {
                        let e_nat: Rgb = std::array::from_fn(|c| s.fixed_irradiance[c] + e_rad[c]);
                        diffuse_reflectance_from_true_colour(s.true_colour, e_nat)
                    })
                    .collect();
                if values.len() < MIN_SEEN_SAMPLES {
                    return None;
                }
                // The median per channel: robust to the samples whose pixel shows another
                // surface (at a silhouette) or the other side of a shadow edge (module doc).
                let mut clamped = false;
                let mut column: Vec<f64> = Vec::with_capacity(values.len());
                let median = std::array::from_fn(|c| {
                    column.clear();
                    column.extend(values.iter().map(|v| v[c]));
                    column.sort_by(f64::total_cmp);
                    let m = column[column.len() / 2];
                    clamped |= m > 1.0;
                    m.clamp(0.0, 1.0)
                });
                Some((median, clamped))
            })
            .collect();
        let count = PhotoReflectanceCount {
            from_photo: rho.iter().filter(|r| r.is_some()).count(),
            from_other_photos: rho
                .iter()
                .zip(&self.source)
                .filter(|(r, s)| r.is_some() && s.is_some_and(|k| k > 0))
                .count(),
            elements: rho.len(),
            clamped: rho.iter().filter(|r| r.is_some_and(|(_, c)| c)).count(),
            mean_change_rel: 0.0,
        };
        (rho.into_iter().map(|r| r.map(|(v, _)| v)).collect(), count)
    }
}

/// The sky and interreflected irradiance per element of `solution`: every group's irradiance
/// with the direct light of the groups the renderer traces itself (the sun, the luminaires)
/// taken out, as case D's E_rad,without.
#[must_use]
pub fn sky_and_bounce_per_element(solution: &Solution) -> Vec<Rgb> {
    let rest = solution.without_direct_of(&RadiosityLight::traced_exactly);
    let mut sum = vec![[0.0; 3]; rest.mesh.elements.len()];
    for g in &rest.groups {
        for (s, v) in sum.iter_mut().zip(g.irradiance_rgb(&rest.mesh, false)) {
            for c in 0..3 {
                s[c] += v[c];
            }
        }
    }
    sum
}
