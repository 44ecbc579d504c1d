//! Known answer for the photo reflectances: a photo made from a radiosity solution of the site
//! fixture whose natural elements carry known reflectances ("true", unlike the library's), by
//! Durisch's model (L = ρ_d/π · E_nat, the renderer's E_nat of the radiosity mode), is read back
//! by [`PhotoSamples`] and the refitted solve.

#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;
use nalgebra::Point2;

use super::photo_reflectance::{
    EXPOSURE_TOLERANCE, MIN_COMMON_SAMPLES, OtherView, PhotoRefit, PhotoSamples, PhotoView,
    PhotoViews, REFIT_ROUNDS, sky_and_bounce_per_element,
};
use super::radiosity_lighting::site_transfer_lighting;
use super::render::prepare_view;
use super::render::tests::fixture;
use super::render_radiosity::{
    SKY_TOLERANCE, natural_part, refit_round_per_sun, site_solve_params,
};
use crate::bvh::BuildQuality;
use crate::camera::{Camera, Intrinsics};
use crate::radiosity::{
    LightGroup, Mesh, Rgb, Solution, solve_on_mesh, solve_on_mesh_refitting, sun_directions,
};
use crate::render::illumination::natural_irradiance_rgb;
use crate::scene::SceneTracer;
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// Per element, the recovered ρ_d against the true one: the photo's pixel centres and the
/// samples differ by under half a pixel (a sample across a shadow edge or an element edge reads
/// its neighbour; the median keeps most out), and the refitted solve's links were refined for
/// the library's values while the truth's were refined for its own (each within the BF
/// tolerance, ≈ 1 % of the interreflected light). 95 % of the seen elements lie within this.
const ELEMENT_REL_TOL: f64 = 0.01;
/// The median relative error over the seen elements.
const MEDIAN_REL_TOL: f64 = 0.002;

/// A deterministic "texture": the library's value times 0.7–1.3, per element, capped at 0.9.
fn true_reflectance(library: Rgb, e: usize) -> Rgb {
    #[allow(clippy::cast_precision_loss)]
    let k = 0.7 + 0.6 * ((e * 7919) % 101) as f64 / 100.0;
    library.map(|v| (v * k).min(0.9))
}

/// The fixture's natural scene solved with known reflectances, and what a photo of it needs.
struct Truth {
    job: super::render::ViewJob,
    scene: crate::scene::Scene,
    groups: Vec<crate::radiosity::LightGroup>,
    params: crate::radiosity::SolveParams,
    tracer: SceneTracer,
    rho_true: Vec<Rgb>,
    truth: Solution,
    e_rad: Vec<Rgb>,
    camera: Camera,
}

impl Truth {
    fn new(dir: &std::path::Path) -> Self {
        let doc = fixture(dir);
        let mut job = prepare_view(&doc, "p1").unwrap();
        // No atmosphere (tested with the renderer's eq. 8); a finer camera at the photo's pose.
        job.lighting.atmosphere = None;
        let camera = Camera {
            intrinsics: Intrinsics::centred(600.0, [640, 480]),
            pose: job.camera.pose,
        };
        let scene = natural_part(&job.scene.scene).unwrap();
        let (lighting, _) = site_transfer_lighting(&doc, &job.scene.scene, "p1").unwrap();
        let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath()).unwrap();
        let (groups, _) = lighting.light_groups(&dome, SKY_TOLERANCE).unwrap();
        let groups: Vec<_> = groups
            .into_iter()
            .filter(|g| !g.name.starts_with("luminaire"))
            .collect();
        assert!(
            groups.iter().any(|g| g.name == "sun"),
            "the fixture has a sun"
        );
        let (params, _) = site_solve_params(&doc, &job.scene.scene).unwrap();
        let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
        let cancel = AtomicBool::new(false);
        // The truth: every element at its own reflectance.
        let mut truth_mesh =
            Mesh::build_lit(&scene, &params.mesh, &sun_directions(&groups), &[&tracer]).unwrap();
        let rho_true: Vec<Rgb> = (0..truth_mesh.elements.len())
            .map(|e| true_reflectance(truth_mesh.element_reflectance_rgb(e), e))
            .collect();
        truth_mesh
            .set_element_reflectances(&rho_true.iter().copied().map(Some).collect::<Vec<_>>())
            .unwrap();
        let truth = solve_on_mesh(truth_mesh, &tracer, &groups, &params, &cancel, &|_| {}).unwrap();
        let e_rad = sky_and_bounce_per_element(&truth);
        Self {
            job,
            scene,
            groups,
            params,
            tracer,
            rho_true,
            truth,
            e_rad,
            camera,
        }
    }

    /// The mesh every solve starts from (the library's reflectances).
    fn mesh(&self) -> Mesh {
        Mesh::build_lit(
            &self.scene,
            &self.params.mesh,
            &sun_directions(&self.groups),
            &[&self.tracer],
        )
        .unwrap()
    }

    /// The photo `camera` takes: each pixel centre's natural hit, L = ρ_true/π · E_nat, times
    /// `exposure`.
    fn photo(&self, camera: &Camera, exposure: f64) -> Rgb32FImage {
        self.photo_under(
            camera,
            exposure,
            &self.job.lighting.daylight,
            &self.truth,
            &self.e_rad,
        )
    }

    /// The truth's mesh (its reflectances) solved under `groups`, and its E_rad per element.
    fn solved_under(&self, groups: &[LightGroup]) -> (Solution, Vec<Rgb>) {
        let solution = solve_on_mesh(
            (*self.truth.mesh).clone(),
            &self.tracer,
            groups,
            &self.params,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap();
        let e_rad = sky_and_bounce_per_element(&solution);
        (solution, e_rad)
    }

    /// [`Truth::photo`] under `daylight` (its sun by shadow rays) with E_rad from `truth`.
    fn photo_under(
        &self,
        camera: &Camera,
        exposure: f64,
        daylight: &crate::render::Daylight,
        truth: &Solution,
        e_rad: &[Rgb],
    ) -> Rgb32FImage {
        let tracer = &self.tracer;
        let (w, h) = (
            camera.intrinsics.image_size_px[0],
            camera.intrinsics.image_size_px[1],
        );
        Rgb32FImage::from_fn(w, h, |x, y| {
            let pixel = Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let dir = camera.ray_dir_in_world(pixel);
            let centre = camera.pose.camera_center_in_world;
            let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
            let Some(hit) = tracer.closest_hit(&ray) else {
                return image::Rgb([0.0; 3]);
            };
            let point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
            let [a, b, c] =
                self.scene.triangles()[hit.hit.triangle_id as usize].vertices_in_world_m;
            let normal = (b - a).cross(&(c - a)).normalize();
            let Some(sample) = truth.irradiance_at(&point, &normal) else {
                return image::Rgb([0.0; 3]);
            };
            let e = sample.element.unwrap();
            let origin = point + normal * crate::radiosity::shadow_refinement::SURFACE_OFFSET_M;
            let sun_visible = daylight.sun.as_ref().is_some_and(|s| {
                s.dir_in_world.dot(&normal) > 0.0
                    && !tracer.any_hit(&tracer.ray_from_world(
                        &origin,
                        &s.dir_in_world,
                        0.0,
                        f32::INFINITY,
                    ))
            });
            let fixed = natural_irradiance_rgb(daylight, &normal, sun_visible, |_| false);
            #[allow(clippy::cast_possible_truncation)]
            image::Rgb(std::array::from_fn(|k| {
                (exposure * self.rho_true[e][k] / std::f64::consts::PI * (fixed[k] + e_rad[e][k]))
                    as f32
            }))
        })
    }

    /// The refitted solve's reflectances of every round from `samples` (library values first).
    fn refit(&self, samples: &PhotoSamples) -> Vec<Vec<Option<Rgb>>> {
        self.refit_suns(samples, &[])
    }

    /// [`Truth::refit`] with photos taken under a second sun, lit by `other_groups`: one solve
    /// carries both suns' groups, as the render's ([`refit_round_per_sun`]).
    fn refit_suns(
        &self,
        samples: &PhotoSamples,
        other_groups: &[LightGroup],
    ) -> Vec<Vec<Option<Rgb>>> {
        let mut rounds: Vec<Vec<Option<Rgb>>> = Vec::new();
        let mut photo_refit = PhotoRefit::new(samples.clone());
        let groups: Vec<LightGroup> = self
            .groups
            .iter()
            .cloned()
            .chain(other_groups.iter().map(|g| LightGroup {
                refines_links: false,
                ..g.clone()
            }))
            .collect();
        let group_sun: Vec<usize> = (0..groups.len())
            .map(|g| usize::from(g >= self.groups.len()))
            .collect();
        let mut refit = |s: &Solution| {
            let rho = refit_round_per_sun(&mut photo_refit, s, &group_sun);
            rounds.push(rho.clone());
            Some(rho)
        };
        let solved = solve_on_mesh_refitting(
            self.mesh(),
            &self.tracer,
            &groups,
            &self.params,
            &AtomicBool::new(false),
            &|_| {},
            &mut refit,
            REFIT_ROUNDS,
        )
        .unwrap();
        assert_eq!(rounds.len(), REFIT_ROUNDS);
        assert_eq!(
            &solved.mesh.element_reflectance_overrides(),
            rounds.last().unwrap()
        );
        rounds
    }

    /// (elements valued, median, 95th percentile) of the largest relative error of a channel
    /// over the elements of `rho` that `keep` keeps.
    fn quantiles(&self, rho: &[Option<Rgb>], keep: impl Fn(usize) -> bool) -> (usize, f64, f64) {
        let mut errors: Vec<f64> = rho
            .iter()
            .enumerate()
            .filter(|(e, _)| keep(*e))
            .filter_map(|(e, r)| {
                r.map(|r| {
                    (0..3)
                        .map(|c| (r[c] / self.rho_true[e][c] - 1.0).abs())
                        .fold(0.0, f64::max)
                })
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let n = errors.len();
        (n, errors[n / 2], errors[n * 95 / 100])
    }
}

#[test]
fn reflectances_read_off_a_photo_made_with_known_ones_come_back() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Truth::new(dir.path());
    let photo = truth.photo(&truth.camera, 1.0);
    // Read back: library values first, then refitted.
    let view = PhotoView {
        camera: &truth.camera,
        photo_linear: &photo,
        lighting: &truth.job.lighting,
    };
    let samples = PhotoSamples::new(&truth.mesh(), &truth.tracer, &view);
    let rounds = truth.refit(&samples);
    let recovered = rounds.last().unwrap().clone();
    let quantiles = |rho: &[Option<Rgb>]| truth.quantiles(rho, |_| true);
    let (seen, median, p95) = quantiles(&recovered);
    let (_, first_median, first_p95) = quantiles(&rounds[0]);
    println!(
        "{seen} elements seen; relative error median {median:.4}, 95th percentile {p95:.4} \
         (from the library's solution alone: {first_median:.4}, {first_p95:.4})"
    );
    assert!(seen > 50, "the photo sees {seen} elements");
    assert!(median < MEDIAN_REL_TOL, "median {median}");
    assert!(p95 < ELEMENT_REL_TOL, "95th percentile {p95}");
    // The refit is what gets there: E_nat's interreflected part needs the photo's values.
    assert!(first_p95 > p95, "{first_p95} vs {p95}");
    // The library's values are far from the truth (the test can fail).
    let library = truth.mesh();
    let library_off = (0..library.elements.len())
        .filter(|&e| recovered[e].is_some())
        .filter(|&e| {
            let l = library.element_reflectance_rgb(e);
            (0..3).any(|c| (l[c] / truth.rho_true[e][c] - 1.0).abs() > 0.1)
        })
        .count();
    assert!(library_off > seen / 2, "{library_off} of {seen}");
}

/// A camera 10 m above the ground at (0.5, −8), looking straight down: it sees the ground the
/// first photo's camera (at y = −10, 1.5 m up, looking along +y) does not see below its frame,
/// and a strip both see.
fn camera_above() -> Camera {
    use nalgebra::{Matrix3, Point3, Rotation3};
    Camera {
        intrinsics: Intrinsics::centred(600.0, [640, 480]),
        pose: crate::camera::Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::new(
                1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0,
            )),
            camera_center_in_world: Point3::new(0.5, -8.0, 10.0),
        },
    }
}

/// The truth's photo `rendered_photo` with `above_photo` (taken by `above`) as the other photo,
/// both read with the truth's lighting; `notes` as the loading's.
fn with_photo_above<'a>(
    truth: &'a Truth,
    rendered_photo: &'a Rgb32FImage,
    above: &'a Camera,
    above_photo: &'a Rgb32FImage,
    notes: Vec<String>,
) -> PhotoViews<'a> {
    PhotoViews {
        rendered: PhotoView {
            camera: &truth.camera,
            photo_linear: rendered_photo,
            lighting: &truth.job.lighting,
        },
        others: vec![OtherView {
            id: "above",
            view: PhotoView {
                camera: above,
                photo_linear: above_photo,
                lighting: &truth.job.lighting,
            },
            sun: 0,
        }],
        notes,
    }
}

/// Recovered relative to true, per channel, as a ratio of exposures: within this of the true
/// ratio (the median over the points both photos see; the two photos' pixel centres fall on
/// different points of a shadow edge or an element edge, the median keeps those out).
const EXPOSURE_RATIO_TOL: f64 = 0.01;

#[test]
fn elements_the_rendered_photo_does_not_see_are_read_off_an_other_photo() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Truth::new(dir.path());
    let rendered_photo = truth.photo(&truth.camera, 1.0);
    let above = camera_above();
    let above_photo = truth.photo(&above, 1.0);
    let views = with_photo_above(&truth, &rendered_photo, &above, &above_photo, Vec::new());
    let rendered = views.rendered;
    let mesh = truth.mesh();
    let mut alone = PhotoSamples::new(&mesh, &truth.tracer, &rendered);
    let mut both = PhotoSamples::from_views(&mesh, &truth.tracer, &views);
    // Which photo each element is read from is decided against a solution.
    assert!(!both.other_views()[0].accepted);
    let (_, count) = both.reflectances(&[&truth.truth]);
    alone.reflectances(&[&truth.truth]);
    // Where the rendered photo sees an element, its samples are kept.
    for (e, s) in alone.sources().iter().enumerate() {
        if s.is_some() {
            assert_eq!(both.sources()[e], Some(0), "element {e}");
        }
    }
    let read = &both.other_views()[0];
    println!("{read:?}; notes {:?}", both.notes());
    assert!(read.accepted);
    let ratio = read.exposure_ratio.unwrap();
    assert!(
        ratio.iter().all(|r| (r - 1.0).abs() < EXPOSURE_RATIO_TOL),
        "{ratio:?}"
    );
    assert!(read.common_samples >= MIN_COMMON_SAMPLES);
    let from_above: Vec<bool> = both.sources().iter().map(|s| *s == Some(1)).collect();
    let n_above = from_above.iter().filter(|&&a| a).count();
    assert_eq!(read.elements, n_above);
    assert!(
        n_above > 30,
        "{n_above} elements read off the photo from above"
    );
    assert_eq!(both.seen_elements(), alone.seen_elements() + n_above);
    assert!(both.notes()[0].contains(&format!("photo above read on {n_above} elements")));

    // Those elements come back as the rendered photo's do.
    let rounds = truth.refit(&both);
    let recovered = rounds.last().unwrap();
    let (n, median, p95) = truth.quantiles(recovered, |e| from_above[e]);
    println!(
        "{n} elements from the photo above: relative error median {median:.4}, 95th percentile {p95:.4}"
    );
    assert_eq!(n, n_above);
    assert!(median < MEDIAN_REL_TOL, "median {median}");
    assert!(p95 < ELEMENT_REL_TOL, "95th percentile {p95}");
    assert_eq!(count.from_other_photos, n_above);
    assert_eq!(count.from_photo, both.seen_elements());
}

#[test]
fn an_other_photo_exposed_differently_is_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Truth::new(dir.path());
    let rendered_photo = truth.photo(&truth.camera, 1.0);
    let above = camera_above();
    let brighter = 1.2;
    let above_photo = truth.photo(&above, brighter);
    let views = with_photo_above(
        &truth,
        &rendered_photo,
        &above,
        &above_photo,
        vec!["photo reflectance: photo p3 not read: it is not solved".to_owned()],
    );
    let mut both = PhotoSamples::from_views(&truth.mesh(), &truth.tracer, &views);
    both.reflectances(&[&truth.truth]);
    let read = &both.other_views()[0];
    assert!(!read.accepted);
    assert_eq!(read.elements, 0);
    let ratio = read.exposure_ratio.unwrap();
    assert!(
        ratio
            .iter()
            .all(|r| (r / brighter - 1.0).abs() < EXPOSURE_RATIO_TOL),
        "{ratio:?}"
    );
    assert!(both.sources().iter().all(|s| *s != Some(1)));
    let notes = both.notes();
    assert_eq!(notes[0], views.notes[0]);
    assert!(
        notes[1].starts_with("photo reflectance: photo above not read: the reflectances it reads over the rendered photo's 1.2"),
        "{}",
        notes[1]
    );
    assert!(notes[1].contains("exposure or white balance differs"));
}

/// The fixture's light under an afternoon sun (225° / 30°; the truth's is 135° / 40°): the
/// renderer's lighting (no atmosphere, as the truth's) and the natural light groups.
fn afternoon_light(
    dir: &std::path::Path,
    truth: &Truth,
) -> (crate::render::Lighting, Vec<LightGroup>) {
    let mut doc = fixture(dir);
    doc.site.lighting.sun_manual = Some(crate::site::SunManual {
        azimuth_deg: 225.0,
        elevation_deg: 30.0,
    });
    let mut afternoon = prepare_view(&doc, "p1").unwrap().lighting;
    afternoon.atmosphere = None;
    let (lighting, _) = site_transfer_lighting(&doc, &truth.job.scene.scene, "p1").unwrap();
    let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath()).unwrap();
    let (groups, _) = lighting.light_groups(&dome, SKY_TOLERANCE).unwrap();
    let groups = groups
        .into_iter()
        .filter(|g| !g.name.starts_with("luminaire"))
        .collect();
    (afternoon, groups)
}

/// Groups carried on links refined for the others' light (`refines_links = false`, as the
/// render's solve carries another sun) leave those others' solutions bit for bit as they are
/// without them.
#[test]
fn groups_carried_on_the_links_leave_the_others_solutions_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Truth::new(dir.path());
    let (_, afternoon_groups) = afternoon_light(dir.path(), &truth);
    let solve = |groups: &[LightGroup]| {
        solve_on_mesh(
            truth.mesh(),
            &truth.tracer,
            groups,
            &truth.params,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap()
    };
    let alone = solve(&truth.groups);
    let carried_groups: Vec<LightGroup> = truth
        .groups
        .iter()
        .cloned()
        .chain(afternoon_groups.iter().map(|g| LightGroup {
            refines_links: false,
            ..g.clone()
        }))
        .collect();
    let carried = solve(&carried_groups);
    assert_eq!(
        carried.groups.len(),
        truth.groups.len() + afternoon_groups.len()
    );
    assert_eq!(carried.interactions, alone.interactions);
    let first = carried.groups_where(|g| g < truth.groups.len());
    for (a, b) in alone.groups.iter().zip(&first.groups) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.radiosity_rgb, b.radiosity_rgb, "{}", a.name);
        assert_eq!(
            a.direct_irradiance_rgb, b.direct_irradiance_rgb,
            "{}",
            a.name
        );
    }
    // Refined for all of them, the links differ (the test can fail).
    let refined = solve(&[truth.groups.clone(), afternoon_groups].concat());
    assert_ne!(refined.interactions, alone.interactions);
}

/// The photo from above taken under another sun (afternoon, 225° / 30°, where the truth's is
/// 135° / 40°): the elements only it sees come back as the rendered photo's do when it is read
/// against the solution for its own sun, and not when it is read as if taken under the
/// rendered photo's.
#[test]
fn an_other_photo_taken_under_another_sun_is_read_under_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Truth::new(dir.path());
    let (afternoon, afternoon_groups) = afternoon_light(dir.path(), &truth);
    let (afternoon_truth, afternoon_e_rad) = truth.solved_under(&afternoon_groups);
    let rendered_photo = truth.photo(&truth.camera, 1.0);
    let above = camera_above();
    let above_photo = truth.photo_under(
        &above,
        1.0,
        &afternoon.daylight,
        &afternoon_truth,
        &afternoon_e_rad,
    );
    // The suns really differ where the photo from above looks: the test can fail.
    let morning_sun = truth.job.lighting.daylight.sun.unwrap().dir_in_world;
    let afternoon_sun = afternoon.daylight.sun.unwrap().dir_in_world;
    assert!(morning_sun.angle(&afternoon_sun).to_degrees() > 60.0);

    let views = PhotoViews {
        rendered: PhotoView {
            camera: &truth.camera,
            photo_linear: &rendered_photo,
            lighting: &truth.job.lighting,
        },
        others: vec![OtherView {
            id: "above",
            view: PhotoView {
                camera: &above,
                photo_linear: &above_photo,
                lighting: &afternoon,
            },
            sun: 1,
        }],
        notes: Vec::new(),
    };
    assert_eq!(views.suns(), 2);
    let samples = PhotoSamples::from_views(&truth.mesh(), &truth.tracer, &views);
    // Against the true solutions the exposures agree (the same ρ_d under both suns).
    let mut probe = samples.clone();
    let (_, count) = probe.reflectances(&[&truth.truth, &afternoon_truth]);
    let read = &probe.other_views()[0];
    println!("{read:?}; notes {:?}", probe.notes());
    assert!(read.accepted);
    assert!(read.common_samples >= MIN_COMMON_SAMPLES);
    let ratio = read.exposure_ratio.unwrap();
    assert!(
        ratio.iter().all(|r| (r - 1.0).abs() < EXPOSURE_RATIO_TOL),
        "{ratio:?}"
    );
    assert!(probe.notes()[0].contains("read under the sun of its own capture time"));
    let from_above: Vec<bool> = probe.sources().iter().map(|s| *s == Some(1)).collect();
    let n_above = from_above.iter().filter(|&&a| a).count();
    assert!(
        n_above > 30,
        "{n_above} elements read off the photo from above"
    );
    assert_eq!(count.from_other_photos, n_above);

    // The refitted solve carrying both suns recovers them.
    let rounds = truth.refit_suns(&samples, &afternoon_groups);
    let recovered = rounds.last().unwrap();
    let (n, median, p95) = truth.quantiles(recovered, |e| from_above[e]);
    println!(
        "{n} elements from the afternoon photo: relative error median {median:.4}, 95th percentile {p95:.4}"
    );
    assert_eq!(n, n_above);
    assert!(median < MEDIAN_REL_TOL, "median {median}");
    assert!(p95 < ELEMENT_REL_TOL, "95th percentile {p95}");

    // Read as if taken under the rendered photo's sun, those elements come back wrong.
    let mut as_if_morning = views.clone();
    as_if_morning.others[0].view.lighting = &truth.job.lighting;
    as_if_morning.others[0].sun = 0;
    let mut wrong = PhotoSamples::from_views(&truth.mesh(), &truth.tracer, &as_if_morning);
    let (rho, _) = wrong.reflectances(&[&truth.truth]);
    let wrong_read = wrong.other_views()[0].clone();
    println!("as if under the rendered photo's sun: {wrong_read:?}");
    if wrong_read.accepted {
        let (_, wrong_median, _) = truth.quantiles(&rho, |e| from_above[e]);
        assert!(
            wrong_median > 10.0 * MEDIAN_REL_TOL,
            "median {wrong_median}"
        );
    } else {
        // Refused by the exposure check, which found other reflectances than the rendered
        // photo's at the points both see.
        let ratio = wrong_read.exposure_ratio.unwrap();
        assert!(
            ratio.iter().any(|r| (r - 1.0).abs() > EXPOSURE_TOLERANCE),
            "{ratio:?}"
        );
    }

    // The afternoon photo exposed 1.2 × brighter (or its clock wrong): refused, and the note
    // names the capture time among the causes.
    let brighter = truth.photo_under(
        &above,
        1.2,
        &afternoon.daylight,
        &afternoon_truth,
        &afternoon_e_rad,
    );
    let mut views = views.clone();
    views.others[0].view.photo_linear = &brighter;
    let mut refused = PhotoSamples::from_views(&truth.mesh(), &truth.tracer, &views);
    refused.reflectances(&[&truth.truth, &afternoon_truth]);
    assert!(!refused.other_views()[0].accepted);
    let note = &refused.notes()[0];
    assert!(
        note.starts_with("photo reflectance: photo above not read: the reflectances it reads over the rendered photo's 1.2")
            && note.ends_with("(exposure, white balance or capture time differs)"),
        "{note}"
    );
}
