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
//!   site's other solved photos taken under the same sun ([`super::other_photos`]) that sees it at
//!   enough ([`PhotoSamples::from_views`]), read with the rendered view's lighting. Such a photo
//!   is read only if its exposure agrees: at the sample points both photos see, the median ratio
//!   of its true colours to the rendered photo's is within [`EXPOSURE_TOLERANCE`] of 1 in every
//!   channel (a Lambertian surface shows one radiance to every camera). The other elements keep
//!   the library's value.
//!
//! E_nat's interreflected part depends on the surroundings' ρ_d, so the solve is refitted
//! ([`crate::radiosity::solve_on_mesh_refitting`]): solved with the library's values, then
//! [`REFIT_ROUNDS`] times with the photo's. The samples (rays, photo colours, sun) are taken
//! once; a round only reads the new solution.
//!
//! # Known limitations
//! Photos taken under another sun are not read ([`super::other_photos`]). An element seen by
//! both the rendered photo and an other takes the rendered photo's samples only. What the model
//! lacks (a parked car, a tree in front of a wall) is read as the surface behind it; the median
//! over the samples keeps a small intrusion out. The element's sky and interreflected light is
//! its mean, not the value at the sample.

use image::Rgb32FImage;
use nalgebra::{Point2, Point3, Vector3};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::radiosity::{Mesh, Solution};
use crate::render::Lighting;
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::render::differential::true_colour_rgb;
use crate::render::illumination::{diffuse_reflectance_from_true_colour, natural_irradiance_rgb};
use crate::scene::SceneTracer;

type Rgb = [f64; 3];

/// Sample points per element along each axis of the unit square (Shirley's warp onto the
/// triangle).
pub const SAMPLES_PER_AXIS: usize = 3;
/// An element takes its ρ_d from the photo when at least this many of its samples are seen:
/// more than half, so that an element mostly hidden or out of frame keeps the library's.
pub const MIN_SEEN_SAMPLES: usize = 5;
/// A sample is seen when the camera's ray to it first meets the natural geometry no nearer than
/// this (plus 10⁻⁴ of the distance: the `f32` hit) before it, metres.
pub const SEEN_TOLERANCE_M: f64 = 0.02;
/// Solves with the photo's reflectances after the first (the second moves ρ_d by well under 1 %
/// on the street site: docs/methodology.md).
pub const REFIT_ROUNDS: usize = 2;

/// What the photo gives one sample: its true colour and the part of E_nat that does not depend
/// on the solution (the sun through its shadow ray, and the ambient term).
#[derive(Debug, Clone, Copy)]
struct Sample {
    true_colour: Rgb,
    fixed_irradiance: Rgb,
}

/// The photo as the estimate reads it.
#[derive(Debug, Clone, Copy)]
pub struct PhotoView<'a> {
    /// The photo's solved camera.
    pub camera: &'a Camera,
    /// The photo, linear RGB, the camera's size.
    pub photo_linear: &'a Rgb32FImage,
    /// The view's lighting (daylight, atmosphere).
    pub lighting: &'a Lighting,
}

/// The samples of every element of a photographed-state mesh (module doc).
#[derive(Debug, Clone)]
pub struct PhotoSamples {
    /// Per element, its seen samples (empty when fewer than [`MIN_SEEN_SAMPLES`]).
    per_element: Vec<Vec<Sample>>,
    /// Per element, the view its samples are from: 0 the rendered photo, k the k-th other.
    source: Vec<Option<usize>>,
    /// What each other photo gave.
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
/// round reads ρ_d off the samples against the latest solution and keeps the count to report,
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

    /// ρ_d per element from `solution` ([`PhotoSamples::reflectances`]).
    pub fn next_round(&mut self, solution: &Solution) -> Vec<Option<Rgb>> {
        let (rho, mut count) = self.samples.reflectances(solution);
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

/// One of the site's other solved photos as the estimate reads it ([`PhotoSamples::from_views`]).
#[derive(Debug, Clone, Copy)]
pub struct OtherView<'a> {
    /// The photo's id, for the notes.
    pub id: &'a str,
    /// Its camera and photo; the lighting is the rendered view's (the photo was taken under the
    /// same sun, [`super::other_photos`]).
    pub view: PhotoView<'a>,
}

/// The rendered photo and the site's other solved photos taken under the same light.
#[derive(Debug, Clone)]
pub struct PhotoViews<'a> {
    /// The photo being rendered: read first.
    pub rendered: PhotoView<'a>,
    /// The others, read in this order where the rendered photo does not see an element.
    pub others: Vec<OtherView<'a>>,
    /// What the loading of the others found (a photo not solved, under another sun, unreadable).
    pub notes: Vec<String>,
}

impl<'a> PhotoViews<'a> {
    /// The rendered photo alone.
    #[must_use]
    pub fn single(rendered: PhotoView<'a>) -> Self {
        Self {
            rendered,
            others: Vec::new(),
            notes: Vec::new(),
        }
    }
}

/// What one other photo gave ([`PhotoSamples::from_views`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OtherViewRead {
    /// The photo's id.
    pub id: String,
    /// Sample points both it and the rendered photo see.
    pub common_samples: usize,
    /// Per channel, the median over those points of its true colour over the rendered photo's
    /// (`None` with fewer than [`MIN_COMMON_SAMPLES`]).
    pub exposure_ratio: Option<Rgb>,
    /// Whether its samples are used ([`EXPOSURE_TOLERANCE`]).
    pub accepted: bool,
    /// Elements that take their samples from it.
    pub elements: usize,
}

/// An other photo is read only when its true colours agree with the rendered photo's at the
/// points both see within this, per channel (median ratio): the model reads ρ_d = π·L₀ / E_nat
/// with one lighting, so a photo exposed or white-balanced differently would bring its own scale.
pub const EXPOSURE_TOLERANCE: f64 = 0.05;
/// The exposure check needs this many sample points seen by both photos; with fewer the other
/// photo is read unchecked (a note says so), as the daylight fit reads every photo with one set
/// of weights.
pub const MIN_COMMON_SAMPLES: usize = 100;
/// True colours below this (linear, per channel) are left out of the exposure ratios.
const MIN_RATIO_COLOUR: f64 = 1e-3;

/// What one element's sample points gave in every view.
#[derive(Default)]
struct ElementRead {
    /// The rendered photo's samples.
    rendered: Vec<Sample>,
    /// Per other view with enough seen samples (where the rendered photo has too few): its
    /// index in `others` and its samples.
    candidates: Vec<(usize, Vec<Sample>)>,
    /// Per point seen by the rendered photo and an other: the other's index and the ratio of
    /// their true colours.
    ratios: Vec<(usize, Rgb)>,
}

impl PhotoSamples {
    /// Samples the elements of `mesh` (the photographed state: natural objects only, traced by
    /// `natural`) in `view`.
    #[must_use]
    pub fn new(mesh: &Mesh, natural: &SceneTracer, view: &PhotoView<'_>) -> Self {
        Self::from_views(mesh, natural, &PhotoViews::single(*view))
    }

    /// Samples the elements of `mesh` in the rendered photo of `views`, and where it sees an
    /// element at fewer than [`MIN_SEEN_SAMPLES`] points, in the first other photo (in order)
    /// that sees it at enough, if that photo's exposure agrees with the rendered one's
    /// ([`EXPOSURE_TOLERANCE`]) at the points both see.
    #[must_use]
    pub fn from_views(mesh: &Mesh, natural: &SceneTracer, views: &PhotoViews<'_>) -> Self {
        let lighting = views.rendered.lighting;
        let reads: Vec<ElementRead> = (0..mesh.elements.len())
            .into_par_iter()
            .map(|e| read_element(mesh, e, natural, lighting, views))
            .collect();
        let mut others: Vec<OtherViewRead> = views
            .others
            .iter()
            .enumerate()
            .map(|(k, other)| {
                let ratios: Vec<Rgb> = reads
                    .iter()
                    .flat_map(|r| r.ratios.iter().filter(|(v, _)| *v == k).map(|(_, q)| *q))
                    .collect();
                let exposure_ratio = (ratios.len() >= MIN_COMMON_SAMPLES).then(|| {
                    let mut column: Vec<f64> = Vec::with_capacity(ratios.len());
                    std::array::from_fn(|c| {
                        column.clear();
                        column.extend(ratios.iter().map(|q| q[c]));
                        column.sort_by(f64::total_cmp);
                        column[column.len() / 2]
                    })
                });
                OtherViewRead {
                    id: other.id.to_owned(),
                    common_samples: ratios.len(),
                    exposure_ratio,
                    accepted: exposure_ratio
                        .is_none_or(|q| q.iter().all(|r| (r - 1.0).abs() <= EXPOSURE_TOLERANCE)),
                    elements: 0,
                }
            })
            .collect();
        let mut source = Vec::with_capacity(reads.len());
        let per_element = reads
            .into_iter()
            .map(|r| {
                if !r.rendered.is_empty() {
                    source.push(Some(0));
                    return r.rendered;
                }
                match r.candidates.into_iter().find(|(k, _)| others[*k].accepted) {
                    Some((k, samples)) => {
                        others[k].elements += 1;
                        source.push(Some(k + 1));
                        samples
                    }
                    None => {
                        source.push(None);
                        Vec::new()
                    }
                }
            })
            .collect();
        Self {
            per_element,
            source,
            others,
            load_notes: views.notes.clone(),
        }
    }

    /// Per element, the view its samples are from: `Some(0)` the rendered photo, `Some(k)` the
    /// k-th other photo, `None` where none sees it at enough points.
    #[must_use]
    pub fn sources(&self) -> &[Option<usize>] {
        &self.source
    }

    /// What each other photo gave.
    #[must_use]
    pub fn other_views(&self) -> &[OtherViewRead] {
        &self.others
    }

    /// The notes for the report: what the loading of the other photos found, and per other
    /// photo what it gave or why it was not read.
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
                        "its true colours over the rendered photo's {:.3}, {:.3}, {:.3} (median over {} points both see)",
                        q[0], q[1], q[2], o.common_samples
                    )
                },
            );
            notes.push(if o.accepted {
                format!(
                    "photo reflectance: photo {} read on {} elements the rendered photo does not see; {ratio}",
                    o.id, o.elements
                )
            } else {
                format!(
                    "photo reflectance: photo {} not read: {ratio}, more than {:.0} % from 1 (exposure or white balance differs)",
                    o.id,
                    100.0 * EXPOSURE_TOLERANCE
                )
            });
        }
        notes
    }

    /// Elements with enough seen samples.
    #[must_use]
    pub fn seen_elements(&self) -> usize {
        self.per_element.iter().filter(|s| !s.is_empty()).count()
    }

    /// ρ_d per element of `solution` (the photographed state solved on the sampled mesh): the
    /// median over its samples of π·L₀ / (E_fixed + E_rad), E_rad the element's sky and
    /// interreflected irradiance; `None` where the photo does not see the element or no light
    /// reaches it.
    #[must_use]
    pub fn reflectances(&self, solution: &Solution) -> (Vec<Option<Rgb>>, PhotoReflectanceCount) {
        let sky_and_bounce = sky_and_bounce_per_element(solution);
        let rho: Vec<Option<(Rgb, bool)>> = (0..self.per_element.len())
            .into_par_iter()
            .map(|e| {
                let samples = &self.per_element[e];
                if samples.is_empty() {
                    return None;
                }
                let e_rad = sky_and_bounce[e];
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

/// The samples of element `e` of `mesh` in every view of `views` (module doc,
/// [`PhotoSamples::from_views`]).
fn read_element(
    mesh: &Mesh,
    e: usize,
    natural: &SceneTracer,
    lighting: &Lighting,
    views: &PhotoViews<'_>,
) -> ElementRead {
    let node = mesh.element_node(e);
    let normal = node.normal_in_world;
    let step = 1.0 / SAMPLES_PER_AXIS as f64;
    let mut read = ElementRead::default();
    let mut other_samples: Vec<Vec<Sample>> = vec![Vec::new(); views.others.len()];
    for i in 0..SAMPLES_PER_AXIS {
        for j in 0..SAMPLES_PER_AXIS {
            let point = node.point_at((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
            // The sun's shadow ray, once per point for every view that sees it.
            let mut fixed: Option<Rgb> = None;
            let mut fixed_irradiance = || {
                *fixed.get_or_insert_with(|| fixed_irradiance(natural, lighting, &point, &normal))
            };
            let rendered = true_colour_seen(&views.rendered, natural, &point, &normal);
            if let Some(true_colour) = rendered {
                read.rendered.push(Sample {
                    true_colour,
                    fixed_irradiance: fixed_irradiance(),
                });
            }
            for (k, other) in views.others.iter().enumerate() {
                let Some(true_colour) = true_colour_seen(&other.view, natural, &point, &normal)
                else {
                    continue;
                };
                if let Some(t0) = rendered.filter(|t0| {
                    (0..3).all(|c| t0[c] > MIN_RATIO_COLOUR && true_colour[c] > MIN_RATIO_COLOUR)
                }) {
                    read.ratios
                        .push((k, std::array::from_fn(|c| true_colour[c] / t0[c])));
                }
                other_samples[k].push(Sample {
                    true_colour,
                    fixed_irradiance: fixed_irradiance(),
                });
            }
        }
    }
    if read.rendered.len() < MIN_SEEN_SAMPLES {
        read.rendered.clear();
        read.candidates = other_samples
            .into_iter()
            .enumerate()
            .filter(|(_, s)| s.len() >= MIN_SEEN_SAMPLES)
            .collect();
    }
    read
}

/// The true colour `view`'s photo shows at `point` (normal `normal`) where it faces the camera,
/// projects inside the photo and is the first natural surface on the camera's ray (module doc).
fn true_colour_seen(
    view: &PhotoView<'_>,
    natural: &SceneTracer,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
) -> Option<Rgb> {
    let centre = view.camera.pose.camera_center_in_world;
    let to_camera = centre - point;
    let distance_m = to_camera.norm();
    if normal.dot(&to_camera) <= 0.0 || distance_m <= 0.0 {
        return None;
    }
    let pixel = view.camera.project(point)?;
    let (width, height) = view.photo_linear.dimensions();
    let rgb = photo_pixel(view.photo_linear, pixel, width, height)?;
    if !seen(natural, &centre, point, distance_m) {
        return None;
    }
    Some(true_colour_rgb(view.lighting, rgb, distance_m))
}

/// The part of E_nat at `point` that does not depend on the solution: the sun through its
/// shadow ray against the natural geometry, and the ambient term.
fn fixed_irradiance(
    natural: &SceneTracer,
    lighting: &Lighting,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
) -> Rgb {
    let daylight = &lighting.daylight;
    let origin = point + normal * crate::radiosity::shadow_refinement::SURFACE_OFFSET_M;
    let sun_visible = daylight.sun.as_ref().is_some_and(|s| {
        s.dir_in_world.dot(normal) > 0.0
            && !natural.any_hit(&natural.ray_from_world(
                &origin,
                &s.dir_in_world,
                0.0,
                f32::INFINITY,
            ))
    });
    natural_irradiance_rgb(daylight, normal, sun_visible, |_| false)
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

/// The photo's linear colour at continuous pixel position `pixel` (pixel (x, y) covers
/// [x, x+1) × [y, y+1), as the renderer's primary rays); `None` outside the photo.
fn photo_pixel(photo: &Rgb32FImage, pixel: Point2<f64>, width: u32, height: u32) -> Option<Rgb> {
    let (x, y) = (pixel.x.floor(), pixel.y.floor());
    if !(x >= 0.0 && y >= 0.0 && x < f64::from(width) && y < f64::from(height)) {
        return None;
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let p = photo.get_pixel(x as u32, y as u32).0;
    Some(p.map(f64::from))
}

/// Whether the camera's ray to `point` meets no natural surface before it (module doc).
fn seen(natural: &SceneTracer, centre: &Point3<f64>, point: &Point3<f64>, distance_m: f64) -> bool {
    let dir = (point - centre) / distance_m;
    let ray = natural.ray_from_world(centre, &dir, 0.0, f32::INFINITY);
    natural
        .closest_hit(&ray)
        .is_some_and(|h| f64::from(h.hit.t) >= distance_m - SEEN_TOLERANCE_M - 1e-4 * distance_m)
}
