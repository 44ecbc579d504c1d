//! The photos the photo reflectances read ([`super::photo_reflectance`]), and what one element's
//! sample points give in each: the true colour a photo shows there (Durisch 1992 eq. 8, the
//! atmosphere's second inversion) and the part of E_nat that does not depend on the radiosity
//! solution (the sun through an exact shadow ray, and the ambient term), for the light that
//! photo was taken in.
//!
//! Every photo belongs to a *sun*: 0 is the rendered photo's, 1, 2, … those of the site's other
//! photos taken at other times ([`super::other_photos`]). The photos of one sun share its
//! lighting, so a point's fixed irradiance is traced once per sun.

use image::Rgb32FImage;
use nalgebra::{Point2, Point3, Vector3};

use crate::camera::Camera;
use crate::radiosity::Mesh;
use crate::render::Lighting;
use crate::render::differential::true_colour_rgb;
use crate::render::illumination::natural_irradiance_rgb;
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

/// The photo as the estimate reads it.
#[derive(Debug, Clone, Copy)]
pub struct PhotoView<'a> {
    /// The photo's solved camera.
    pub camera: &'a Camera,
    /// The photo, linear RGB, the camera's size.
    pub photo_linear: &'a Rgb32FImage,
    /// The lighting the photo was taken in (daylight, atmosphere): the view's for the rendered
    /// photo; for an other photo, the same with the sun of its capture time.
    pub lighting: &'a Lighting,
}

/// One of the site's other solved photos as the estimate reads it
/// ([`super::photo_reflectance::PhotoSamples::from_views`]).
#[derive(Debug, Clone, Copy)]
pub struct OtherView<'a> {
    /// The photo's id, for the notes.
    pub id: &'a str,
    /// Its camera, photo and lighting (its sun's).
    pub view: PhotoView<'a>,
    /// Its sun: 0 the rendered photo's, k > 0 the k-th other sun
    /// ([`super::other_photos::OtherPhotos::sun_photos`]); the solution it is read against.
    pub sun: usize,
}

/// The rendered photo and the site's other solved photos.
#[derive(Debug, Clone)]
pub struct PhotoViews<'a> {
    /// The photo being rendered: read first.
    pub rendered: PhotoView<'a>,
    /// The others, read in this order where the rendered photo does not see an element.
    pub others: Vec<OtherView<'a>>,
    /// What the loading of the others found (a photo not solved, unreadable).
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

    /// Suns the views were taken under: 1 (the rendered photo's) plus the other suns.
    #[must_use]
    pub fn suns(&self) -> usize {
        1 + self.others.iter().map(|o| o.sun).max().unwrap_or(0)
    }
}

/// What the photo gives one sample: its true colour and the part of E_nat that does not depend
/// on the solution (the sun through its shadow ray, and the ambient term), both under the
/// photo's own light.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub true_colour: Rgb,
    pub fixed_irradiance: Rgb,
}

/// True colours below this (linear, per channel) are left out of the exposure check.
pub(super) const MIN_RATIO_COLOUR: f64 = 1e-3;

/// What one element's sample points gave in every view.
#[derive(Default)]
pub(super) struct ElementRead {
    /// The rendered photo's samples (empty where fewer than [`MIN_SEEN_SAMPLES`]).
    pub rendered: Vec<Sample>,
    /// Per other view with enough seen samples (where the rendered photo has too few): its
    /// index in `others` and its samples.
    pub candidates: Vec<(usize, Vec<Sample>)>,
    /// Per point seen by the rendered photo and an other (both brighter than
    /// [`MIN_RATIO_COLOUR`]): the other's index, the rendered photo's sample and the other's.
    pub common: Vec<(usize, Sample, Sample)>,
}

/// The samples of element `e` of `mesh` in every view of `views`
/// ([`super::photo_reflectance::PhotoSamples::from_views`]).
pub(super) fn read_element(
    mesh: &Mesh,
    e: usize,
    natural: &SceneTracer,
    views: &PhotoViews<'_>,
) -> ElementRead {
    let node = mesh.element_node(e);
    let normal = node.normal_in_world;
    let step = 1.0 / SAMPLES_PER_AXIS as f64;
    let mut read = ElementRead::default();
    let mut other_samples: Vec<Vec<Sample>> = vec![Vec::new(); views.others.len()];
    let mut fixed: Vec<Option<Rgb>> = vec![None; views.suns()];
    for i in 0..SAMPLES_PER_AXIS {
        for j in 0..SAMPLES_PER_AXIS {
            let point = node.point_at((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
            // The sun's shadow ray, once per point and sun for every view that sees it.
            fixed.fill(None);
            let mut fixed_under = |sun: usize, lighting: &Lighting| {
                *fixed[sun]
                    .get_or_insert_with(|| fixed_irradiance(natural, lighting, &point, &normal))
            };
            let rendered =
                true_colour_seen(&views.rendered, natural, &point, &normal).map(|true_colour| {
                    Sample {
                        true_colour,
                        fixed_irradiance: fixed_under(0, views.rendered.lighting),
                    }
                });
            if let Some(sample) = rendered {
                read.rendered.push(sample);
            }
            for (k, other) in views.others.iter().enumerate() {
                let Some(true_colour) = true_colour_seen(&other.view, natural, &point, &normal)
                else {
                    continue;
                };
                let sample = Sample {
                    true_colour,
                    fixed_irradiance: fixed_under(other.sun, other.view.lighting),
                };
                if let Some(r) = rendered.filter(|r| {
                    (0..3).all(|c| {
                        r.true_colour[c] > MIN_RATIO_COLOUR && true_colour[c] > MIN_RATIO_COLOUR
                    })
                }) {
                    read.common.push((k, r, sample));
                }
                other_samples[k].push(sample);
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
/// projects inside the photo and is the first natural surface on the camera's ray
/// ([`super::photo_reflectance`]).
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

/// Whether the camera's ray to `point` meets no natural surface before it
/// ([`super::photo_reflectance`]).
fn seen(natural: &SceneTracer, centre: &Point3<f64>, point: &Point3<f64>, distance_m: f64) -> bool {
    let dir = (point - centre) / distance_m;
    let ray = natural.ray_from_world(centre, &dir, 0.0, f32::INFINITY);
    natural
        .closest_hit(&ray)
        .is_some_and(|h| f64::from(h.hit.t) >= distance_m - SEEN_TOLERANCE_M - 1e-4 * distance_m)
}
