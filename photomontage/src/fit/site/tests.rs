//! The site glue on a synthetic site written to disk: a solved camera, polygons from control
//! points, a linear EXR photo whose sample windows hold the colours of eq. 2 and eq. 6 for chosen
//! τₐ, L∞, k_s, k_u, k_h (E's from our own illumination code: the model; the truth values are
//! chosen), a material library with the material's ρ_d.

use super::*;
use crate::fit::daylight::{irradiance_components, normalised_sky_facets};
use crate::fit::natural_scene::natural_scene;
use crate::scene::Material;
use crate::scene::{ObjectKind, Scene, SceneObject};
use crate::site::render::site_sun_dir;
use crate::site::stored_camera;
use crate::site::{
    ControlPoint, Exterior, HorizonSample, Interior, Photo, Polygon, Sample, SunShadowPair,
};
use crate::sky_dome::durisch_facets::durisch_dome;
use image::{Rgb, Rgb32FImage};
use nalgebra::Point2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Issue 5's acceptance goal: every fitted parameter within 2 % of the truth.
const ACCEPTANCE_REL: f64 = 0.02;
/// Exact samples stored as f32 in the EXR (relative rounding 6e-8), but the atmosphere samples
/// are not exactly of one true colour as eq. 7 assumes: the nearest (150 m) sees slightly less
/// sky past the box and the wall (eq. 7 residuals ≈ 3e-5 on colours ≈ 0.5), which moves τₐ by
/// ≈ 1e-4 and the weights through eq. 8 by as much; 1e-3 bounds that.
const SYNTHETIC_SITE_REL: f64 = 1e-3;

/// The radiosity mode's fit builds its solution with its first pass's weights and relights it,
/// the truth is built with the true ones: the links are refined for the lighting of the build,
/// which did not move the weights beyond the other synthetic tests' bound.
const RADIOSITY_SITE_REL: f64 = SYNTHETIC_SITE_REL;

const TAU_1KM: [f64; 3] = [0.80, 0.74, 0.62];
pub(crate) const HORIZON: [f64; 3] = [0.60, 0.68, 0.84];
pub(crate) const K_S: [f64; 3] = [3.1, 2.9, 2.5];
pub(crate) const K_U: [f64; 3] = [0.04, 0.045, 0.06];
pub(crate) const K_H: [f64; 3] = [0.6, 0.7, 0.95];
pub(crate) const RHO: [f64; 3] = [0.42, 0.38, 0.30];
pub(crate) const SIZE_PX: [u32; 2] = [400, 300];
const FOCAL_PX: f64 = 400.0;

fn camera_centre() -> Point3<f64> {
    Point3::new(0.0, -10.0, 1.6)
}

/// Ground to 4 km north, a wall facing south at y = 20, a 4 m box at (8–12, 8–12).
fn geometry() -> Vec<(&'static str, Vec<[f64; 3]>)> {
    vec![
        (
            "ground",
            vec![
                [-3000.0, -50.0, 0.0],
                [3000.0, -50.0, 0.0],
                [3000.0, 4000.0, 0.0],
                [-3000.0, 4000.0, 0.0],
            ],
        ),
        (
            "wall",
            vec![
                [-30.0, 20.0, 0.0],
                [-30.0, 20.0, 8.0],
                [-12.0, 20.0, 8.0],
                [-12.0, 20.0, 0.0],
            ],
        ),
        (
            "box_s",
            vec![
                [8.0, 8.0, 0.0],
                [12.0, 8.0, 0.0],
                [12.0, 8.0, 4.0],
                [8.0, 8.0, 4.0],
            ],
        ),
        (
            "box_e",
            vec![
                [12.0, 8.0, 0.0],
                [12.0, 12.0, 0.0],
                [12.0, 12.0, 4.0],
                [12.0, 8.0, 4.0],
            ],
        ),
        (
            "box_n",
            vec![
                [12.0, 12.0, 0.0],
                [8.0, 12.0, 0.0],
                [8.0, 12.0, 4.0],
                [12.0, 12.0, 4.0],
            ],
        ),
        (
            "box_w",
            vec![
                [8.0, 12.0, 0.0],
                [8.0, 8.0, 0.0],
                [8.0, 8.0, 4.0],
                [8.0, 12.0, 4.0],
            ],
        ),
        (
            "box_t",
            vec![
                [8.0, 8.0, 4.0],
                [12.0, 8.0, 4.0],
                [12.0, 12.0, 4.0],
                [8.0, 12.0, 4.0],
            ],
        ),
    ]
}

pub(crate) fn base_site() -> Site {
    let mut site = Site {
        location: Some(crate::site::render::tests::zurich()),
        ..Site::default()
    };
    site.lighting.time = Some("2024-06-21T10:30:00+02:00".into());
    site.lighting.sky_model = crate::site::SkyModelName::CieGeneral(12);
    site.lighting.material_library = Some("materials.toml".into());
    // The photos hold eq. 9's colours without interreflection (the rest of the image is the
    // horizon colour, not a rendering of the surroundings): eq. 9 as in the paper.
    site.fit_settings.interreflection = false;
    site.photos.push(Photo {
        id: "P1".into(),
        file: "p1.exr".into(),
        taken_at: Some("2024-06-21T10:30:00+02:00".into()),
        profile: None,
        interior: Some(Interior {
            focal_px: FOCAL_PX,
            principal_point_px: None,
            distortion: crate::camera::BrownConrady::default(),
            image_size_px: Some(SIZE_PX),
        }),
        self_calibration: crate::site::SelfCalibrationFlags::default(),
        // Looking north: camera x → east, y (down) → −Z, z (forward) → north.
        exterior: Some(Exterior {
            camera_center: camera_centre().into(),
            rotation_world_from_camera: [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            rms_px: 0.0,
            sigma_center_m: [0.0; 3],
            solved_by: "resection".into(),
        }),
    });
    for (name, verts) in geometry() {
        let mut ids = Vec::new();
        for (i, v) in verts.iter().enumerate() {
            let id = format!("{name}{i}");
            site.control_points.push(ControlPoint {
                id: id.clone(),
                xyz: *v,
                sigma_m: [0.01; 3],
                crs: None,
                enabled: true,
            });
            ids.push(id);
        }
        site.polygons.push(Polygon {
            id: name.into(),
            vertices: ids,
            material: "stone".into(),
            image: Some("P1".into()),
        });
    }
    site.horizon_samples.push(HorizonSample {
        id: "sky".into(),
        photo: "P1".into(),
        origin_px: [10, 5],
        size_px: [40, 20],
        enabled: true,
    });
    site
}

struct Synthetic {
    dir: tempfile::TempDir,
    doc: SiteDocument,
    corrupted: Vec<String>,
}

/// Writes the site, the material library and the photo; `corrupt_every` paints every n-th
/// daylight sample's window ×1.6 (a mis-click on a poster or a window).
fn synthetic_site(seed: u64, corrupt_every: Option<usize>) -> Synthetic {
    synthetic_site_lit(seed, corrupt_every, false, false)
}

/// [`synthetic_site`]; with `radiosity`, the site is in the radiosity mode with the fit's
/// interreflection on, and every true colour adds the interreflected irradiance of a radiosity
/// solution of the natural scene built here with the true weights (the renderer's solve
/// parameters and light groups, read as the renderer reads it at a natural point: vertex
/// gathers).
///
/// With `whole_photo` (radiosity mode), every pixel showing a natural surface that faces the
/// camera holds Durisch's model of that solution too (ρ_d/π · E_nat, E_nat the sun by a shadow
/// ray, the ambient term and the element's sky and interreflected irradiance, through the
/// atmosphere), so that the fit can read the surfaces' reflectances off the photo
/// (`[render] photo_reflectance`); without it the rest of the image is the horizon colour and
/// the fit reads the library's.
fn synthetic_site_lit(
    seed: u64,
    corrupt_every: Option<usize>,
    radiosity: bool,
    whole_photo: bool,
) -> Synthetic {
    let dir = tempfile::tempdir().unwrap();
    let mut site = base_site();
    if radiosity {
        site.render.radiosity = true;
        site.render.photo_reflectance = whole_photo;
        site.fit_settings.interreflection = true;
    }
    std::fs::write(
        dir.path().join("materials.toml"),
        format!("[[material]]\nname = \"stone\"\ndiffuse_rgb = {RHO:?}\n"),
    )
    .unwrap();
    let doc0 = SiteDocument {
        path: dir.path().join("site.toml"),
        site: site.clone(),
    };
    // With the material library, as the fit builds it (the radiosity truth reflects with ρ_d).
    let library = crate::site::render::site_material_library(&doc0).unwrap();
    let scene = natural_scene(&site, library.as_ref()).unwrap().scene;
    let tracer = SceneTracer::new(&scene, crate::bvh::BuildQuality::default()).unwrap();
    let sun = site_sun_dir(&doc0, "P1").unwrap();
    let sky = normalised_sky_facets(
        &durisch_dome(SiteFitOptions::default().sky_m_h).unwrap(),
        &crate::site::render::site_sky_model(&doc0, "P1", &sun).unwrap(),
        &sun,
    )
    .unwrap();
    let truth = radiosity.then(|| {
        let mut doc = doc0.clone();
        doc.site.lighting.sun_weight = K_S;
        doc.site.lighting.ambient_weight = K_U;
        doc.site.lighting.sky_weight = K_H;
        let (lighting, _) =
            crate::site::radiosity_lighting::site_transfer_lighting(&doc, &scene, "P1").unwrap();
        let (solve, _) = crate::site::render_radiosity::site_solve_params(&doc, &scene).unwrap();
        let params = crate::radiosity::TransferParams {
            solve,
            sky_tolerance: crate::site::render_radiosity::SKY_TOLERANCE,
            ..crate::radiosity::TransferParams::default()
        };
        let transfer = crate::radiosity::Transfer::build(
            &scene,
            &lighting,
            &params,
            &std::sync::atomic::AtomicBool::new(false),
            &|_| {},
        )
        .unwrap();
        let solution = transfer.solution().clone();
        let gather = crate::radiosity::VertexGather::new(
            std::sync::Arc::clone(&solution.mesh),
            crate::radiosity::vertex_gather::DEFAULT_RAYS_PER_AXIS,
        )
        .unwrap();
        let gathered = crate::radiosity::GatheredExitance::new(
            std::sync::Arc::new(gather),
            solution.total_radiosity_rgb(),
        )
        .unwrap();
        (transfer, solution, gathered)
    });
    // The interreflected irradiance as the renderer reads it at a natural point.
    let e_r = |p: &Point3<f64>, n: &Vector3<f64>| -> [f64; 3] {
        truth
            .as_ref()
            .map_or([0.0; 3], |(transfer, solution, gathered)| {
                solution.irradiance_gathered_at(p, n, gathered).map_or_else(
                    || {
                        let query = crate::radiosity::QueryParams {
                            gather_rays:
                                crate::fit::radiosity_interreflection::FALLBACK_GATHER_RAYS,
                            ..crate::radiosity::QueryParams::default()
                        };
                        transfer.irradiance_at(p, n, &query).unwrap().indirect_rgb
                    },
                    |s| s.indirect_rgb,
                )
            })
    };
    let camera = stored_camera(&site, "P1").unwrap();
    let mut img = Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], Rgb(HORIZON.map(|c| c as f32)));
    if let Some((_, solution, _)) = truth.as_ref().filter(|_| whole_photo) {
        paint_whole_photo(&mut img, &doc0, &scene, &tracer, solution);
    }
    let mut taken: Vec<[i64; 2]> = Vec::new();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut paint = |p: Point3<f64>, n: Vector3<f64>, factor: f64, img: &mut Rgb32FImage| -> bool {
        let Some(px) = camera.project(&p) else {
            return false;
        };
        let c = [px.x.round() as i64, px.y.round() as i64];
        if c[0] < 2
            || c[1] < 30
            || c[0] > i64::from(SIZE_PX[0]) - 3
            || c[1] > i64::from(SIZE_PX[1]) - 3
        {
            return false;
        }
        if taken
            .iter()
            .any(|t| (t[0] - c[0]).abs() < 4 && (t[1] - c[1]).abs() < 4)
        {
            return false;
        }
        // Visible from the camera?
        let dir = p - camera_centre();
        let ray = tracer.ray_from_world(&camera_centre(), &dir, 0.0, f32::INFINITY);
        let Some(hit) = tracer.closest_hit(&ray) else {
            return false;
        };
        if (f64::from(hit.hit.t) - dir.norm()).abs() > 0.01_f64.max(1e-3 * dir.norm()) {
            return false;
        }
        taken.push(c);
        let e = irradiance_components(&tracer, &p, &n, Some(&sun), &sky);
        let reflected = e_r(&p, &n);
        let d = dir.norm();
        let colour = [0, 1, 2].map(|k| {
            let l0 = RHO[k] / std::f64::consts::PI
                * (K_S[k] * e.sun + K_U[k] * e.ambient + K_H[k] * e.sky + reflected[k]);
            crate::atmosphere::schachter::apparent_radiance(l0, HORIZON[k], TAU_1KM[k], d, 1000.0)
                * factor
        });
        for y in c[1] - 1..=c[1] + 1 {
            for x in c[0] - 1..=c[0] + 1 {
                img.put_pixel(x as u32, y as u32, Rgb(colour.map(|v| v as f32)));
            }
        }
        true
    };
    // Atmosphere: open ground in sun, 150 m … 3.5 km, spread in azimuth between the wall
    // (azimuths −45° … −22°) and the box (20° … 34°).
    for (i, (dist, az_deg)) in [
        (150.0, -18.0),
        (400.0, -10.0),
        (800.0, -3.0),
        (1300.0, 4.0),
        (2000.0, 10.0),
        (3500.0, 16.0),
    ]
    .iter()
    .enumerate()
    {
        let az = f64::to_radians(*az_deg);
        let p = Point3::new(dist * az.sin(), -10.0 + dist * az.cos(), 0.0);
        assert!(
            paint(p, Vector3::z(), 1.0, &mut img),
            "atmosphere sample {i} not placed"
        );
        site.samples.push(Sample {
            id: format!("a{i}"),
            photo: "P1".into(),
            material: "stone".into(),
            purpose: SamplePurpose::Atmosphere,
            point: Some(p.into()),
            x_px: None,
            y_px: None,
            window_px: 3,
            enabled: true,
        });
    }
    // Daylight: ground near the box (sun and shadow), box faces, the wall.
    let mut corrupted = Vec::new();
    let mut count = 0;
    while count < 20 {
        // The wall's polygon faces away from the camera (its mesh has no element on the side
        // the photo sees), so its E_r would be a final gather, whose noise (≈ 0.5 % at 4096
        // rays, at a point the fit locates a few µm away) moves the weakly separated ambient
        // and sky weights by ~3 %: the radiosity variant samples the ground and the box.
        let kinds = if radiosity { 3 } else { 4 };
        let (p, n) = match rng.random_range(0..kinds) {
            0 => (
                Point3::new(
                    rng.random_range(0.0..16.0),
                    rng.random_range(1.0..18.0),
                    0.0,
                ),
                Vector3::z(),
            ),
            1 => (
                Point3::new(rng.random_range(8.3..11.7), 8.0, rng.random_range(0.3..3.7)),
                -Vector3::y(),
            ),
            2 => (
                Point3::new(8.0, rng.random_range(8.3..11.7), rng.random_range(0.3..3.7)),
                -Vector3::x(),
            ),
            _ => (
                Point3::new(
                    rng.random_range(-29.0..-13.0),
                    20.0,
                    rng.random_range(0.3..7.5),
                ),
                -Vector3::y(),
            ),
        };
        let id = format!("d{count}");
        let corrupt = corrupt_every.is_some_and(|m| count % m == m - 1);
        if !paint(p, n, if corrupt { 1.6 } else { 1.0 }, &mut img) {
            continue;
        }
        if corrupt {
            corrupted.push(id.clone());
        }
        site.samples.push(Sample {
            id,
            photo: "P1".into(),
            material: "stone".into(),
            purpose: SamplePurpose::Daylight,
            point: Some(p.into()),
            x_px: None,
            y_px: None,
            window_px: 3,
            enabled: true,
        });
        count += 1;
    }
    image::DynamicImage::ImageRgb32F(img)
        .save(dir.path().join("p1.exr"))
        .unwrap();
    let path = dir.path().join("site.toml");
    site.save(&path).unwrap();
    let doc = SiteDocument::load(&path).unwrap();
    Synthetic {
        dir,
        doc,
        corrupted,
    }
}

/// Paints every pixel of `img` whose ray first meets a natural surface facing the camera with
/// Durisch's model of `solution` (the true weights; [`synthetic_site_lit`]).
fn paint_whole_photo(
    img: &mut Rgb32FImage,
    doc0: &SiteDocument,
    scene: &crate::scene::Scene,
    tracer: &SceneTracer,
    solution: &crate::radiosity::Solution,
) {
    let mut doc = doc0.clone();
    doc.site.lighting.sun_weight = K_S;
    doc.site.lighting.ambient_weight = K_U;
    doc.site.lighting.sky_weight = K_H;
    let (lighting, _) = crate::site::render::site_lighting(
        &doc,
        "P1",
        &crate::site::render::SiteLightingOptions::default(),
    )
    .unwrap();
    let daylight = &lighting.daylight;
    let e_rad = crate::site::photo_reflectance::sky_and_bounce_per_element(solution);
    let camera = stored_camera(&doc.site, "P1").unwrap();
    let centre = camera_centre();
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let pixel = nalgebra::Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let dir = camera.ray_dir_in_world(pixel);
            let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
            let Some(hit) = tracer.closest_hit(&ray) else {
                continue;
            };
            let point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
            let [a, b, c] = scene.triangles()[hit.hit.triangle_id as usize].vertices_in_world_m;
            let normal = (b - a).cross(&(c - a)).normalize();
            if normal.dot(&(centre - point)) <= 0.0 {
                continue;
            }
            let Some(e) = solution
                .irradiance_at(&point, &normal)
                .and_then(|s| s.element)
            else {
                continue;
            };
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
            let fixed = crate::render::illumination::natural_irradiance_rgb(
                daylight,
                &normal,
                sun_visible,
                |_| false,
            );
            let rho = solution.mesh.element_reflectance_rgb(e);
            let d = (point - centre).norm();
            let colour = [0, 1, 2].map(|k| {
                let l0 = rho[k] / std::f64::consts::PI * (fixed[k] + e_rad[e][k]);
                crate::atmosphere::schachter::apparent_radiance(
                    l0, HORIZON[k], TAU_1KM[k], d, 1000.0,
                ) as f32
            });
            img.put_pixel(x, y, Rgb(colour));
        }
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn assert_recovered(r: &SiteFitReport, tol: f64) {
    let (t, s, u, h) = (
        r.transmittance.unwrap(),
        r.sun_weight.unwrap(),
        r.ambient_weight.unwrap(),
        r.sky_weight.unwrap(),
    );
    for k in 0..3 {
        assert!(rel(t[k], TAU_1KM[k]) < tol, "τ {t:?}");
        assert!(
            rel(r.horizon_colour[k], HORIZON[k]) < tol,
            "L∞ {:?}",
            r.horizon_colour
        );
        assert!(rel(s[k], K_S[k]) < tol, "k_s {s:?}");
        assert!(rel(u[k], K_U[k]) < tol, "k_u {u:?}");
        assert!(rel(h[k], K_H[k]) < tol, "k_h {h:?}");
    }
}

#[test]
fn recovers_the_chosen_lighting_from_the_photo_and_writes_it_back() {
    let mut syn = synthetic_site(21, None);
    let report = fit_site(&syn.doc, &SiteFitOptions::default(), None).unwrap();
    assert!(!report.weights_relative);
    assert!(report.residuals.iter().all(|r| !r.flagged));
    assert_recovered(&report, SYNTHETIC_SITE_REL);
    assert_eq!(report.samples.len(), 26);
    // Write back atomically and read again: the renderer's [lighting] now holds the fit.
    apply_fit(&mut syn.doc.site, &report, "2026-11-21T10:00:00Z");
    syn.doc.save().unwrap();
    let back = SiteDocument::load(&syn.doc.path).unwrap();
    // The site file keeps floats bit-exact.
    let bits = |v: [f64; 3]| v.map(f64::to_bits);
    assert_eq!(
        bits(back.site.lighting.sun_weight),
        bits(report.sun_weight.unwrap())
    );
    assert_eq!(
        bits(back.site.lighting.sky_weight),
        bits(report.sky_weight.unwrap())
    );
    let ext = back.site.lighting.atmosphere.extinction_per_m;
    for k in 0..3 {
        assert!(rel((-ext[k] * 1000.0).exp(), TAU_1KM[k]) < SYNTHETIC_SITE_REL);
    }
    let record = back.site.fit.unwrap();
    assert_eq!(record.fitted_at, "2026-11-21T10:00:00Z");
    assert!(record.sun_weight_sigma.is_some() && record.transmittance.is_some());
    drop(syn.dir);
}

/// Fits `doc` (radiosity mode): no sample flagged, E_r reported for all 20 daylight samples,
/// and the weights recovered within [`RADIOSITY_SITE_REL`].
fn assert_radiosity_fit_recovers(doc: &SiteDocument) {
    let report = fit_site(doc, &SiteFitOptions::default(), None).unwrap();
    assert!(
        report.residuals.iter().all(|r| !r.flagged),
        "{:?}",
        report.warnings
    );
    let e_r: Vec<[f64; 3]> = report
        .samples
        .iter()
        .filter_map(|r| r.interreflection_rgb)
        .collect();
    assert_eq!(e_r.len(), 20, "E_r reported for every daylight sample");
    assert!(e_r.iter().any(|e| e[1] > 0.0), "{e_r:?}");
    assert_recovered(&report, RADIOSITY_SITE_REL);
}

/// The radiosity mode: the photo's colours hold the interreflected light of a radiosity
/// solution built with the true weights; the fit takes E_r from its own solution (built with
/// its first pass's weights and relit to each later pass's) and recovers the weights. Without
/// E_r (interreflection off) the same photo gives weights off by more than the tolerance.
#[test]
fn weights_are_recovered_with_the_radiosity_interreflection() {
    let s = synthetic_site_lit(7, None, true, false);
    assert_radiosity_fit_recovers(&s.doc);
    let mut off = s.doc.clone();
    off.site.fit_settings.interreflection = false;
    let biased = fit_site(&off, &SiteFitOptions::default(), None).unwrap();
    let (s_off, h_off) = (biased.sun_weight.unwrap(), biased.sky_weight.unwrap());
    assert!(
        (0..3).any(|k| rel(h_off[k], K_H[k]) > 3.0 * RADIOSITY_SITE_REL
            || rel(s_off[k], K_S[k]) > 3.0 * RADIOSITY_SITE_REL),
        "the photo's interreflection is large enough to matter: k_s {s_off:?}, k_h {h_off:?}"
    );
}

/// The radiosity mode with the surroundings' reflectances read off the photo (`[render]
/// photo_reflectance`, the renderer's default): the whole photo holds Durisch's model of a
/// solution with the true weights, the fit reads the surfaces' ρ_d off it under each pass's
/// weights and refits its transfer to them, and recovers the weights as with the library's.
#[test]
fn weights_are_recovered_with_the_reflectances_read_off_the_photo() {
    let s = synthetic_site_lit(7, None, true, true);
    assert!(s.doc.site.render.photo_reflectance);
    assert_radiosity_fit_recovers(&s.doc);
}

#[test]
fn ten_percent_corrupted_samples_are_flagged_by_name() {
    let syn = synthetic_site(22, Some(10));
    assert_eq!(syn.corrupted.len(), 2);
    let report = fit_site(&syn.doc, &SiteFitOptions::default(), None).unwrap();
    let flagged: Vec<&str> = report
        .residuals
        .iter()
        .filter(|r| r.flagged)
        .map(|r| r.sample.as_str())
        .collect();
    assert_eq!(
        flagged,
        syn.corrupted.iter().map(String::as_str).collect::<Vec<_>>()
    );
    assert_recovered(&report, ACCEPTANCE_REL);
}

#[test]
fn bad_samples_are_named() {
    let syn = synthetic_site(23, None);
    let mut doc = syn.doc.clone();
    // A pixel in the sky: not on any polygon.
    doc.site.samples.push(Sample {
        id: "in_the_sky".into(),
        photo: "P1".into(),
        material: "stone".into(),
        purpose: SamplePurpose::Daylight,
        point: None,
        x_px: Some(200.0),
        y_px: Some(20.0),
        window_px: 3,
        enabled: true,
    });
    let report = fit_site(&doc, &SiteFitOptions::default(), None).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("`in_the_sky`") && w.contains("not on any polygon")),
        "{:?}",
        report.warnings
    );
    // A clip level just below the brightest sample: that sample's window is all clipped.
    let brightest = report
        .samples
        .iter()
        .max_by(|a, b| a.apparent_rgb[2].total_cmp(&b.apparent_rgb[2]))
        .unwrap();
    let clipped = SiteFitOptions {
        colour: ColourReadOptions {
            linear_saturation: Some((brightest.apparent_rgb[2] as f32) * 0.999_99),
            ..ColourReadOptions::default()
        },
        ..SiteFitOptions::default()
    };
    let r = fit_site(&doc, &clipped, None).unwrap();
    let name = format!("sample `{}` not used", brightest.id);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.contains(&name) && w.contains("9 saturated")),
        "{:?}",
        r.warnings
    );
    // A daylight sample on the wall, with the wall's material changed to one the library does
    // not have: two materials, one without ρ_d.
    let mut mixed = syn.doc.clone();
    let wall_sample = mixed
        .site
        .samples
        .iter()
        .find(|s| {
            s.purpose == SamplePurpose::Daylight
                && s.point.is_some_and(|p| (p[1] - 20.0).abs() < 1e-9)
        })
        .unwrap()
        .id
        .clone();
    mixed.site.polygons[1].material = "render".into();
    for s in &mut mixed.site.samples {
        if s.id == wall_sample {
            s.material = "render".into();
        }
    }
    let err = fit_site(&mixed, &SiteFitOptions::default(), None).unwrap_err();
    assert!(
        matches!(err, SiteFitError::NoReflectance { .. })
            && err.to_string().contains(&format!("`{wall_sample}`"))
            && err.to_string().contains("`render`"),
        "{err}"
    );
    // Atmosphere samples at one distance.
    let mut same = syn.doc.clone();
    same.site
        .samples
        .retain(|s| s.purpose == SamplePurpose::Daylight || s.id == "a2");
    let err = fit_site(&same, &SiteFitOptions::default(), None).unwrap_err();
    assert!(
        err.to_string().contains("`a2`") && err.to_string().contains("distinct distances"),
        "{err}"
    );
    // Too few daylight samples.
    let mut few = syn.doc.clone();
    few.site
        .samples
        .retain(|s| s.purpose == SamplePurpose::Atmosphere || s.id == "d0" || s.id == "d1");
    let err = fit_site(&few, &SiteFitOptions::default(), None).unwrap_err();
    assert!(
        err.to_string().contains("`d0`, `d1`") && err.to_string().contains("at least 3"),
        "{err}"
    );
}

#[test]
fn sun_pair_cross_check_flags_a_wrong_clock() {
    let syn = synthetic_site(24, None);
    let mut doc = syn.doc.clone();
    // The box's top corner and the point its shadow falls on, from the true sun.
    let sun = site_sun_dir(&doc, "P1").unwrap();
    let top = Point3::new(8.0, 8.0, 4.0);
    let shadow = top - sun * (4.0 / sun.z);
    doc.site.control_points.push(ControlPoint {
        id: "tip_shadow".into(),
        xyz: shadow.into(),
        sigma_m: [0.01; 3],
        crs: None,
        enabled: true,
    });
    doc.site.sun_shadow_pairs.push(SunShadowPair {
        id: "box".into(),
        object_point: "box_s3".into(),
        shadow_point: "tip_shadow".into(),
        photo: "P1".into(),
    });
    let report = fit_site(&doc, &SiteFitOptions::default(), None).unwrap();
    assert_eq!(report.sun_checks.len(), 1);
    assert!(report.sun_checks[0].check.angle_deg < 1e-6);
    // The camera clock was an hour fast.
    doc.site.photos[0].taken_at = Some("2024-06-21T11:30:00+02:00".into());
    let report = fit_site(&doc, &SiteFitOptions::default(), None).unwrap();
    assert_eq!(report.sun_checks[0].check.clock_offset_s, Some(-3600));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("sun check `box`") && w.contains("fast"))
    );
}

/// The sample colours rendered by our renderer (`crate::render`, case C of Durisch §6.2, eq. 6
/// and eq. 2) with the site's lighting built by `crate::site::render::site_lighting` from chosen
/// weights: the fit must give those weights back, which also checks that the fit's units are the
/// renderer's (sun normal irradiance, ambient radiance, horizontal sky irradiance).
#[test]
fn weights_rendered_by_the_renderer_are_recovered() {
    use crate::render::DifferentialTracer;
    use crate::site::render::{SiteLightingOptions, site_lighting};
    let dir = tempfile::tempdir().unwrap();
    let mut site = base_site();
    std::fs::write(
        dir.path().join("materials.toml"),
        format!("[[material]]\nname = \"stone\"\ndiffuse_rgb = {RHO:?}\n"),
    )
    .unwrap();
    site.lighting.sun_weight = K_S;
    site.lighting.ambient_weight = K_U;
    site.lighting.sky_weight = K_H;
    site.lighting.atmosphere.extinction_per_m = TAU_1KM.map(|t| -t.ln() / 1000.0);
    site.lighting.atmosphere.horizon_colour = HORIZON;
    let doc = SiteDocument {
        path: dir.path().join("site.toml"),
        site: site.clone(),
    };
    // No photo bounce: the rendered surfaces are lit by sun, sky and ambient only, as eq. 9.
    let options = SiteLightingOptions {
        sky_dome_m_h: SiteFitOptions::default().sky_m_h,
        photo_bounce_m_h: None,
        photo_bounce_nested_m_h: None,
    };
    let (lighting, _) = site_lighting(&doc, "P1", &options).unwrap();
    // The same polygons as artificial objects, so the renderer shades them (case C).
    let natural = natural_scene(&site, None).unwrap().scene;
    let mut scene = Scene::new();
    let object = scene
        .add_object(SceneObject {
            name: "rendered".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let stone = scene.add_material(Material::diffuse("stone", RHO)).unwrap();
    for t in natural.triangles() {
        scene
            .add_polygon(&t.vertices_in_world_m, stone, object)
            .unwrap();
    }
    let camera = stored_camera(&site, "P1").unwrap();
    let blank = Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], Rgb(HORIZON.map(|c| c as f32)));
    let tracer = DifferentialTracer::new(&scene, &lighting, &camera, &blank, 1).unwrap();
    let mut img = blank.clone();
    let mut pixels: Vec<([u32; 2], SamplePurpose)> = Vec::new();
    // Atmosphere: open ground just below the horizon row (149.5): rows 150–155 are 1.3 km …
    // 116 m away, at azimuths between the wall and the box.
    for (i, x) in [80_u32, 130, 180, 230, 280, 320].iter().enumerate() {
        pixels.push(([*x, 150 + i as u32], SamplePurpose::Atmosphere));
    }
    // Daylight: pixels of random points near the box and on the wall.
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    while pixels.len() < 6 + 24 {
        let p = match rng.random_range(0..4) {
            0 => Point3::new(
                rng.random_range(0.0..16.0),
                rng.random_range(1.0..18.0),
                0.0,
            ),
            1 => Point3::new(rng.random_range(8.3..11.7), 8.0, rng.random_range(0.3..3.7)),
            2 => Point3::new(8.0, rng.random_range(8.3..11.7), rng.random_range(0.3..3.7)),
            _ => Point3::new(
                rng.random_range(-29.0..-13.0),
                20.0,
                rng.random_range(0.3..7.5),
            ),
        };
        let Some(px) = camera.project(&p) else {
            continue;
        };
        let c = [px.x.round() as u32, px.y.round() as u32];
        if c[0] >= SIZE_PX[0] || c[1] >= SIZE_PX[1] || pixels.iter().any(|(q, _)| *q == c) {
            continue;
        }
        pixels.push((c, SamplePurpose::Daylight));
    }
    for (i, (c, purpose)) in pixels.iter().enumerate() {
        let dir = camera.ray_dir_in_world(Point2::new(f64::from(c[0]), f64::from(c[1])));
        let sample = tracer.trace_primary(&dir, HORIZON);
        assert!(sample.hit_artificial, "sample {i} at {c:?} sees no surface");
        img.put_pixel(c[0], c[1], Rgb(sample.radiance_rgb.map(|v| v as f32)));
        site.samples.push(Sample {
            id: format!("r{i}"),
            photo: "P1".into(),
            material: "stone".into(),
            purpose: *purpose,
            point: None,
            x_px: Some(f64::from(c[0])),
            y_px: Some(f64::from(c[1])),
            window_px: 1,
            enabled: true,
        });
    }
    image::DynamicImage::ImageRgb32F(img)
        .save(dir.path().join("p1.exr"))
        .unwrap();
    // The fit starts from the site's defaults, not from the truth.
    site.lighting = crate::site::Lighting {
        time: site.lighting.time.clone(),
        sky_model: site.lighting.sky_model,
        material_library: site.lighting.material_library.clone(),
        ..crate::site::Lighting::default()
    };
    let path = dir.path().join("site.toml");
    site.save(&path).unwrap();
    let doc = SiteDocument::load(&path).unwrap();
    let report = fit_site(&doc, &SiteFitOptions::default(), None).unwrap();
    assert!(
        report.residuals.iter().all(|r| !r.flagged),
        "{:?}",
        report.warnings
    );
    assert_recovered(&report, SYNTHETIC_SITE_REL);
}

#[test]
fn an_observer_that_cancels_stops_the_fit() {
    struct Stop;
    impl FitObserver for Stop {
        fn on_iteration(&self, _event: &crate::fit::FitIteration) {}
        fn cancelled(&self) -> bool {
            true
        }
    }
    let syn = synthetic_site(24, None);
    let r = fit_site(&syn.doc, &SiteFitOptions::default(), Some(Arc::new(Stop)));
    assert!(matches!(r, Err(SiteFitError::Cancelled)), "{r:?}");
    // Without the observer the same site fits (the cancel is what stopped it).
    assert!(fit_site(&syn.doc, &SiteFitOptions::default(), None).is_ok());
}
