//! Known answer for the photo reflectances: a photo made from a radiosity solution of the site
//! fixture whose natural elements carry known reflectances ("true", unlike the library's), by
//! Durisch's model (L = ρ_d/π · E_nat, the renderer's E_nat of the radiosity mode), is read back
//! by [`PhotoSamples`] and the refitted solve.

#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;
use nalgebra::Point2;

use super::photo_reflectance::{PhotoSamples, PhotoView, REFIT_ROUNDS, sky_and_bounce_per_element};
use super::radiosity_lighting::site_transfer_lighting;
use super::render::prepare_view;
use super::render::tests::fixture;
use super::render_radiosity::{SKY_TOLERANCE, natural_part, site_solve_params};
use crate::bvh::BuildQuality;
use crate::camera::{Camera, Intrinsics};
use crate::radiosity::{
    Mesh, Rgb, Solution, solve_on_mesh, solve_on_mesh_refitting, sun_directions,
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

#[test]
fn reflectances_read_off_a_photo_made_with_known_ones_come_back() {
    let dir = tempfile::tempdir().unwrap();
    let doc = fixture(dir.path());
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
    let mesh =
        || Mesh::build_lit(&scene, &params.mesh, &sun_directions(&groups), &[&tracer]).unwrap();

    // The truth: every element at its own reflectance.
    let mut truth_mesh = mesh();
    let rho_true: Vec<Rgb> = (0..truth_mesh.elements.len())
        .map(|e| true_reflectance(truth_mesh.element_reflectance_rgb(e), e))
        .collect();
    truth_mesh
        .set_element_reflectances(&rho_true.iter().copied().map(Some).collect::<Vec<_>>())
        .unwrap();
    let truth = solve_on_mesh(truth_mesh, &tracer, &groups, &params, &cancel, &|_| {}).unwrap();
    let e_rad = sky_and_bounce_per_element(&truth);

    // The photo: each pixel centre's natural hit, L = ρ_true/π · E_nat.
    let daylight = &job.lighting.daylight;
    let photo = Rgb32FImage::from_fn(640, 480, |x, y| {
        let pixel = Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
        let dir = camera.ray_dir_in_world(pixel);
        let centre = camera.pose.camera_center_in_world;
        let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
        let Some(hit) = tracer.closest_hit(&ray) else {
            return image::Rgb([0.0; 3]);
        };
        let point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
        let [a, b, c] = scene.triangles()[hit.hit.triangle_id as usize].vertices_in_world_m;
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
            (rho_true[e][k] / std::f64::consts::PI * (fixed[k] + e_rad[e][k])) as f32
        }))
    });

    // Read back: library values first, then refitted.
    let view = PhotoView {
        camera: &camera,
        photo_linear: &photo,
        lighting: &job.lighting,
    };
    let start_mesh = mesh();
    let samples = PhotoSamples::new(&start_mesh, &tracer, &view);
    let mut rounds: Vec<Vec<Option<Rgb>>> = Vec::new();
    let mut refit = |s: &Solution| {
        let (rho, _) = samples.reflectances(s);
        rounds.push(rho.clone());
        Some(rho)
    };
    let solved = solve_on_mesh_refitting(
        start_mesh,
        &tracer,
        &groups,
        &params,
        &cancel,
        &|_| {},
        &mut refit,
        REFIT_ROUNDS,
    )
    .unwrap();
    assert_eq!(rounds.len(), REFIT_ROUNDS);
    let recovered = rounds.last().unwrap().clone();
    assert_eq!(solved.mesh.element_reflectance_overrides(), recovered);
    let quantiles = |rho: &[Option<Rgb>]| {
        let mut errors: Vec<f64> = rho
            .iter()
            .enumerate()
            .filter_map(|(e, r)| {
                r.map(|r| {
                    (0..3)
                        .map(|c| (r[c] / rho_true[e][c] - 1.0).abs())
                        .fold(0.0, f64::max)
                })
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let n = errors.len();
        (n, errors[n / 2], errors[n * 95 / 100])
    };
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
    let library = mesh();
    let library_off = (0..library.elements.len())
        .filter(|&e| recovered[e].is_some())
        .filter(|&e| {
            let l = library.element_reflectance_rgb(e);
            (0..3).any(|c| (l[c] / rho_true[e][c] - 1.0).abs() > 0.1)
        })
        .count();
    assert!(library_off > seen / 2, "{library_off} of {seen}");
}
