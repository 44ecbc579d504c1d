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
//!   of its samples' ρ_d, clamped to [0, 1]; the others keep the library's value.
//!
//! E_nat's interreflected part depends on the surroundings' ρ_d, so the solve is refitted
//! ([`crate::radiosity::solve_on_mesh_refitting`]): solved with the library's values, then
//! [`REFIT_ROUNDS`] times with the photo's. The samples (rays, photo colours, sun) are taken
//! once; a round only reads the new solution.
//!
//! # Known limitations
//! Only the photo being rendered is read (not the site's other solved photos). What the model
//! lacks (a parked car, a tree in front of a wall) is read as the surface behind it; the median
//! over the samples keeps a small intrusion out. The element's sky and interreflected light is
//! its mean, not the value at the sample.

use image::Rgb32FImage;
use nalgebra::{Point2, Point3};
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
}

/// What [`PhotoSamples::reflectances`] did, for the render report.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhotoReflectanceCount {
    /// Elements that took ρ_d from the photo.
    pub from_photo: usize,
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

impl PhotoSamples {
    /// Samples the elements of `mesh` (the photographed state: natural objects only, traced by
    /// `natural`) in `view`.
    #[must_use]
    pub fn new(mesh: &Mesh, natural: &SceneTracer, view: &PhotoView<'_>) -> Self {
        let centre = view.camera.pose.camera_center_in_world;
        let (width, height) = view.photo_linear.dimensions();
        let daylight = &view.lighting.daylight;
        let step = 1.0 / SAMPLES_PER_AXIS as f64;
        let per_element = (0..mesh.elements.len())
            .into_par_iter()
            .map(|e| {
                let node = mesh.element_node(e);
                let normal = node.normal_in_world;
                let mut samples = Vec::new();
                for i in 0..SAMPLES_PER_AXIS {
                    for j in 0..SAMPLES_PER_AXIS {
                        let point = node.point_at((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
                        let to_camera = centre - point;
                        let distance_m = to_camera.norm();
                        if normal.dot(&to_camera) <= 0.0 || distance_m <= 0.0 {
                            continue;
                        }
                        let Some(pixel) = view.camera.project(&point) else {
                            continue;
                        };
                        let Some(rgb) = photo_pixel(view.photo_linear, pixel, width, height) else {
                            continue;
                        };
                        if !seen(natural, &centre, &point, distance_m) {
                            continue;
                        }
                        let origin =
                            point + normal * crate::radiosity::shadow_refinement::SURFACE_OFFSET_M;
                        let sun_visible = daylight.sun.as_ref().is_some_and(|s| {
                            s.dir_in_world.dot(&normal) > 0.0
                                && !natural.any_hit(&natural.ray_from_world(
                                    &origin,
                                    &s.dir_in_world,
                                    0.0,
                                    f32::INFINITY,
                                ))
                        });
                        samples.push(Sample {
                            true_colour: true_colour_rgb(view.lighting, rgb, distance_m),
                            fixed_irradiance: natural_irradiance_rgb(
                                daylight,
                                &normal,
                                sun_visible,
                                |_| false,
                            ),
                        });
                    }
                }
                if samples.len() < MIN_SEEN_SAMPLES {
                    samples.clear();
                }
                samples
            })
            .collect();
        Self { per_element }
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
