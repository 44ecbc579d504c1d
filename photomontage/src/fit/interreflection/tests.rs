//! Known answer of the interreflection term: a site whose photo our renderer made (eq. 6 per
//! pixel, Durisch §6.2 case C, direct light only) and whose sample pixels then received
//! `ρ_d/π·E_r`, E_r gathered from that same photo by the renderer's gather (repeated until the
//! photo and its gather agree), so the extended eq. 9 holds at every sample with chosen k_s, k_u,
//! k_h: the site fit must give them back. The ground and the façades are of two materials with
//! known ρ_d, fitted jointly (vertical and horizontal samples separate k_h from k_u).

use image::{Rgb, Rgb32FImage};
use nalgebra::Point2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::fit::natural_scene::natural_scene;
use crate::fit::site::tests::{HORIZON, K_H, K_S, K_U, RHO, SIZE_PX, base_site};
use crate::fit::site::{SiteFitOptions, fit_site};
use crate::scene::SceneTracer;
use crate::site::render::site_material_library;
use crate::site::{Sample, SamplePurpose};

/// Albedo of the façades (the box and the wall).
const RHO_FACADE: [f64; 3] = [0.62, 0.56, 0.45];
/// Sky dome of the render and the fit: m_h = 4 (64 facets) keeps the full-frame render quick;
/// render and fit use the same facets, so the answer does not depend on it.
const SKY_M_H: u32 = 4;
/// Gather dome of E_r, the same in the photo's making and in the fit.
const BOUNCE_M_H: u32 = 4;
/// The colours are exact but stored as f32 (6e-8) and the fit locates each sample by an f32 ray
/// hit (sub-millimetre shifts move E_s, E_h by ≲ 1e-5); the gather in the fit sees the sample
/// pixels it changed after the last making pass (≲ 1e-6). 1e-3 is the brief's bound.
const RECOVERED_REL: f64 = 1e-3;
/// Without E_r the same photo must give visibly wrong weights (the term matters here): some
/// weight off by more than 2 %.
const WITHOUT_MIN_REL: f64 = 0.02;

/// A sample of the test: pixel, located point, normal facing the camera, albedo.
type Picked = ([u32; 2], Point3<f64>, Vector3<f64>, [f64; 3]);

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn worst_rel(r: &crate::fit::site::SiteFitReport) -> f64 {
    let (s, u, h) = (
        r.sun_weight.unwrap(),
        r.ambient_weight.unwrap(),
        r.sky_weight.unwrap(),
    );
    (0..3)
        .map(|k| {
            rel(s[k], K_S[k])
                .max(rel(u[k], K_U[k]))
                .max(rel(h[k], K_H[k]))
        })
        .fold(0.0, f64::max)
}

#[test]
fn weights_of_a_photo_with_interreflection_are_recovered() {
    use crate::render::DifferentialTracer;
    use crate::scene::{ObjectKind, Scene, SceneObject};
    use crate::site::render::{SiteLightingOptions, site_lighting};
    let dir = tempfile::tempdir().unwrap();
    let mut site = base_site();
    site.fit_settings.interreflection = true;
    for poly in &mut site.polygons {
        if poly.id != "ground" {
            poly.material = "plaster".into();
        }
    }
    std::fs::write(
        dir.path().join("materials.toml"),
        format!(
            "[[material]]\nname = \"stone\"\ndiffuse_rgb = {RHO:?}\n\n[[material]]\n\
             name = \"plaster\"\ndiffuse_rgb = {RHO_FACADE:?}\n"
        ),
    )
    .unwrap();
    site.lighting.sun_weight = K_S;
    site.lighting.ambient_weight = K_U;
    site.lighting.sky_weight = K_H;
    site.lighting.atmosphere.extinction_per_m = [0.0; 3];
    site.lighting.atmosphere.horizon_colour = HORIZON;
    let doc = SiteDocument {
        path: dir.path().join("site.toml"),
        site: site.clone(),
    };
    let library = site_material_library(&doc).unwrap();
    let natural = natural_scene(&site, library.as_ref()).unwrap().scene;
    // The photo, direct light only: the same triangles as artificial objects (case C).
    let mut scene = Scene::new();
    let object = scene
        .add_object(SceneObject {
            name: "rendered".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    for m in natural.materials() {
        scene.add_material(m.clone()).unwrap();
    }
    for t in natural.triangles() {
        scene
            .add_polygon(&t.vertices_in_world_m, t.material, object)
            .unwrap();
    }
    let direct_options = SiteLightingOptions {
        sky_dome_m_h: SKY_M_H,
        photo_bounce_m_h: None,
        photo_bounce_nested_m_h: None,
    };
    let (lighting, _) = site_lighting(&doc, "P1", &direct_options).unwrap();
    let camera = stored_camera(&site, "P1").unwrap();
    let blank = Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], Rgb(HORIZON.map(|c| c as f32)));
    let tracer = DifferentialTracer::new(&scene, &lighting, &camera, &blank, 1).unwrap();
    let rows: Vec<Vec<[f64; 3]>> = (0..SIZE_PX[1])
        .into_par_iter()
        .map(|y| {
            (0..SIZE_PX[0])
                .map(|x| {
                    let d = camera.ray_dir_in_world(Point2::new(f64::from(x), f64::from(y)));
                    tracer.trace_primary(&d, HORIZON).radiance_rgb
                })
                .collect()
        })
        .collect();
    let direct = Rgb32FImage::from_fn(SIZE_PX[0], SIZE_PX[1], |x, y| {
        Rgb(rows[y as usize][x as usize].map(|v| v as f32))
    });
    // Samples: ground around the box (sun and shadow), the box's south and west faces, the wall.
    let natural_tracer = SceneTracer::new(&natural, crate::bvh::BuildQuality::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let mut picked: Vec<Picked> = Vec::new();
    while picked.len() < 28 {
        let (p, rho) = match picked.len() % 4 {
            0 => (
                Point3::new(
                    rng.random_range(0.0..16.0),
                    rng.random_range(1.0..18.0),
                    0.0,
                ),
                RHO,
            ),
            1 => (
                Point3::new(rng.random_range(8.3..11.7), 8.0, rng.random_range(0.3..3.7)),
                RHO_FACADE,
            ),
            2 => (
                Point3::new(8.0, rng.random_range(8.3..11.7), rng.random_range(0.3..3.7)),
                RHO_FACADE,
            ),
            _ => (
                Point3::new(
                    rng.random_range(-29.0..-13.0),
                    20.0,
                    rng.random_range(0.3..7.5),
                ),
                RHO_FACADE,
            ),
        };
        let Some(px) = camera.project(&p) else {
            continue;
        };
        let c = [px.x.round() as u32, px.y.round() as u32];
        if c[0] >= SIZE_PX[0] || c[1] >= SIZE_PX[1] || picked.iter().any(|q| q.0 == c) {
            continue;
        }
        // The point the fit will locate: the f32 hit of the ray through the pixel centre.
        let centre = camera.pose.camera_center_in_world;
        let dir = camera.ray_dir_in_world(Point2::new(f64::from(c[0]), f64::from(c[1])));
        let ray = natural_tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
        let hit = natural_tracer.closest_hit(&ray).unwrap();
        let point = natural_tracer.hit_point_in_world_m(&ray, hit.hit.t);
        let g = hit.hit.normal_geometric;
        let mut normal =
            Vector3::new(f64::from(g[0]), f64::from(g[1]), f64::from(g[2])).normalize();
        if normal.dot(&dir) > 0.0 {
            normal = -normal;
        }
        picked.push((c, point, normal, rho));
    }
    // Add ρ/π·E_r at the sample pixels, E_r gathered from the photo itself, until they agree.
    let probe = scene_with_probe(&natural).unwrap();
    let bounce_options = SiteLightingOptions {
        photo_bounce_m_h: Some(BOUNCE_M_H),
        ..direct_options
    };
    let (bounce_lighting, _) = site_lighting(&doc, "P1", &bounce_options).unwrap();
    let mut photo = direct.clone();
    let mut largest_e_r = 0.0_f64;
    for _ in 0..4 {
        let t = DifferentialTracer::new(&probe, &bounce_lighting, &camera, &photo, 1).unwrap();
        let mut next = direct.clone();
        for (c, point, normal, rho) in &picked {
            let e = t.natural_interreflection_irradiance(point, normal);
            largest_e_r = largest_e_r.max(e[0]);
            let d = direct.get_pixel(c[0], c[1]).0;
            let v = [0, 1, 2].map(|k| f64::from(d[k]) + rho[k] / std::f64::consts::PI * e[k]);
            next.put_pixel(c[0], c[1], Rgb(v.map(|x| x as f32)));
        }
        photo = next;
    }
    assert!(
        largest_e_r > 0.1,
        "the scene has interreflection: {largest_e_r}"
    );
    for (i, (c, _, _, rho)) in picked.iter().enumerate() {
        site.samples.push(Sample {
            id: format!("r{i}"),
            photo: "P1".into(),
            material: if *rho == RHO { "stone" } else { "plaster" }.into(),
            purpose: SamplePurpose::Daylight,
            point: None,
            x_px: Some(f64::from(c[0])),
            y_px: Some(f64::from(c[1])),
            window_px: 1,
            enabled: true,
        });
    }
    image::DynamicImage::ImageRgb32F(photo)
        .save(dir.path().join("p1.exr"))
        .unwrap();
    // The fit starts from zero weights: the surfaces the photo does not show are black in its
    // first pass.
    site.lighting.sun_weight = [0.0; 3];
    site.lighting.ambient_weight = [0.0; 3];
    site.lighting.sky_weight = [0.0; 3];
    let path = dir.path().join("site.toml");
    site.save(&path).unwrap();
    let doc = SiteDocument::load(&path).unwrap();
    let options = SiteFitOptions {
        sky_m_h: SKY_M_H,
        interreflection_m_h: BOUNCE_M_H,
        ..SiteFitOptions::default()
    };
    let report = fit_site(&doc, &options, None).unwrap();
    assert!(
        report.residuals.iter().all(|r| !r.flagged) && !report.weights_relative,
        "{:?}",
        report.warnings
    );
    assert!(
        worst_rel(&report) < RECOVERED_REL,
        "k_s {:?} k_u {:?} k_h {:?}",
        report.sun_weight,
        report.ambient_weight,
        report.sky_weight
    );
    assert!(
        report
            .samples
            .iter()
            .all(|s| s.interreflection_rgb.is_some())
    );
    // The same photo fitted by eq. 9 without E_r.
    let mut plain = doc.clone();
    plain.site.fit_settings.interreflection = false;
    let report = fit_site(&plain, &options, None).unwrap();
    assert!(worst_rel(&report) > WITHOUT_MIN_REL, "{report:?}");
    drop(dir);
}
