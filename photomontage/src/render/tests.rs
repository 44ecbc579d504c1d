//! Known-answer tests of the differential renderer on a small synthetic site: a natural ground
//! plane photographed under sun + ambient light (so the photo is one uniform colour, eq. 6), and
//! an artificial 4 × 4 × 4 m box.

use super::*;
use crate::camera::{BrownConrady, Camera, Intrinsics, Pose};
use crate::scene::{Material, ObjectKind, Scene, SceneObject};
use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use std::f64::consts::PI;
use std::sync::Mutex;

/// Values are computed in f64 and stored as f32: a relative error of a few f32 ulps.
const F32_REL_TOL: f64 = 1e-6;

const RHO_GROUND: [f64; 3] = [0.3, 0.25, 0.2];
const RHO_BOX: [f64; 3] = [0.6, 0.5, 0.4];
const E_SUN: [f64; 3] = [3.0, 2.85, 2.6];
const K_U: [f64; 3] = [0.05, 0.06, 0.08];
const BOX_HALF_M: f64 = 2.0;
const BOX_HEIGHT_M: f64 = 4.0;
const SIZE_PX: [u32; 2] = [64, 48];

fn sun_dir() -> Vector3<f64> {
    // Elevation 45°, in the −x direction from the scene: the shadow falls on x ∈ [2, 6].
    Vector3::new(-1.0, 0.0, 1.0).normalize()
}

fn look_at(eye: Point3<f64>, target: Point3<f64>, focal_px: f64) -> Camera {
    let f = (target - eye).normalize();
    let r = f.cross(&Vector3::z()).normalize();
    let d = f.cross(&r);
    Camera {
        intrinsics: Intrinsics {
            distortion: BrownConrady::default(),
            ..Intrinsics::centred(focal_px, SIZE_PX)
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                r, d, f,
            ])),
            camera_center_in_world: eye,
        },
    }
}

fn camera() -> Camera {
    look_at(
        Point3::new(0.0, -15.0, 20.0),
        Point3::new(2.0, 0.0, 0.0),
        50.0,
    )
}

fn quad(scene: &mut Scene, corners: [[f64; 3]; 4], rho: [f64; 3], kind: ObjectKind) {
    let m = scene.add_material(Material::diffuse("m", rho)).unwrap();
    let o = scene
        .add_object(SceneObject {
            name: "o".into(),
            kind,
            image_attribute: None,
        })
        .unwrap();
    let poly: Vec<Point3<f64>> = corners.iter().map(|c| Point3::from(*c)).collect();
    scene.add_polygon(&poly, m, o).unwrap();
}

fn site(with_box: bool) -> Scene {
    let mut s = Scene::new();
    let g = 1000.0;
    quad(
        &mut s,
        [[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]],
        RHO_GROUND,
        ObjectKind::Natural,
    );
    if with_box {
        let (a, h) = (BOX_HALF_M, BOX_HEIGHT_M);
        let faces = [
            [[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]],
            [[-a, -a, 0.0], [a, -a, 0.0], [a, -a, h], [-a, -a, h]],
            [[a, -a, 0.0], [a, a, 0.0], [a, a, h], [a, -a, h]],
            [[a, a, 0.0], [-a, a, 0.0], [-a, a, h], [a, a, h]],
            [[-a, a, 0.0], [-a, -a, 0.0], [-a, -a, h], [-a, a, h]],
        ];
        for f in faces {
            quad(&mut s, f, RHO_BOX, ObjectKind::Artificial);
        }
    }
    s
}

fn sun_and_ambient() -> Lighting {
    Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: sun_dir(),
                normal_irradiance_rgb: E_SUN,
            }),
            ambient_radiance_rgb: K_U,
            sky: vec![],
        },
        ..Lighting::default()
    }
}

/// Eq. 6 for the sunlit ground: the uniform colour of the photo.
fn ground_radiance() -> [f64; 3] {
    let cos = sun_dir().z;
    [0, 1, 2].map(|k| RHO_GROUND[k] / PI * (E_SUN[k] * cos + PI * K_U[k]))
}

fn uniform_photo(rgb: [f64; 3]) -> Rgb32FImage {
    #[allow(clippy::cast_possible_truncation)]
    let p = image::Rgb(rgb.map(|x| x as f32));
    Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], p)
}

fn render(tracer: &DifferentialTracer<'_>, settings: &RenderSettings) -> RenderedImage {
    render_view(tracer, settings, &|_| {}, &AtomicBool::new(false)).unwrap()
}

/// Ground points (z = 0) of a pixel's four corners.
fn footprint_on_ground(cam: &Camera, x: u32, y: u32) -> Vec<Point3<f64>> {
    let c = cam.pose.camera_center_in_world;
    [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)]
        .iter()
        .map(|(dx, dy)| {
            let d = cam.ray_dir_in_world(Point2::new(f64::from(x) + dx, f64::from(y) + dy));
            assert!(
                d.z < 0.0,
                "every ray of the test view must reach the ground"
            );
            c + d * (-c.z / d.z)
        })
        .collect()
}

fn assert_close(got: f32, expected: f64, what: &str) {
    let got = f64::from(got);
    assert!(
        (got - expected).abs() <= F32_REL_TOL * expected.abs().max(1e-3),
        "{what}: {got} vs {expected}"
    );
}

#[test]
fn unaffected_pixels_are_bit_identical_and_the_shadow_is_exactly_the_sun_share() {
    let scene = site(true);
    let lighting = sun_and_ambient();
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let out = render(&tracer, &RenderSettings::default());

    // Image-space bounds of the box (its 8 corners projected), 1 px margin.
    let (a, h) = (BOX_HALF_M, BOX_HEIGHT_M);
    let mut box_rect = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for &x in &[-a, a] {
        for &y in &[-a, a] {
            for &z in &[0.0, h] {
                let p = cam.project(&Point3::new(x, y, z)).unwrap();
                box_rect = [
                    box_rect[0].min(p.x - 1.0),
                    box_rect[1].min(p.y - 1.0),
                    box_rect[2].max(p.x + 1.0),
                    box_rect[3].max(p.y + 1.0),
                ];
            }
        }
    }
    // On the ground: the box's base and its sun shadow (x from −2 to 2 + 4·cot 45° = 6).
    let margin = 0.05;
    let shadow_x = BOX_HEIGHT_M * (-sun_dir().x / sun_dir().z);
    let affected = [-a - margin, -a - margin, a + shadow_x + margin, a + margin];

    let shadow_expected: Vec<f64> = (0..3)
        .map(|k| ground_radiance()[k] * PI * K_U[k] / (E_SUN[k] * sun_dir().z + PI * K_U[k]))
        .collect();
    let (mut unaffected, mut in_shadow) = (0, 0);
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let px = out.rgba[(y * SIZE_PX[0] + x) as usize];
            let photo_px = photo.get_pixel(x, y).0;
            let fp = footprint_on_ground(&cam, x, y);
            let (fx, fy) = (f64::from(x), f64::from(y));
            let off_box_in_image = fx + 0.5 < box_rect[0]
                || fx - 0.5 > box_rect[2]
                || fy + 0.5 < box_rect[1]
                || fy - 0.5 > box_rect[3];
            let min_x = fp.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
            let max_x = fp.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
            let min_y = fp.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
            let max_y = fp.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
            let off_region = max_x < affected[0]
                || min_x > affected[2]
                || max_y < affected[1]
                || min_y > affected[3];
            if off_box_in_image && off_region {
                unaffected += 1;
                for k in 0..3 {
                    assert_eq!(px[k].to_bits(), photo_px[k].to_bits(), "pixel {x},{y}");
                }
                assert_eq!(px[3].to_bits(), 0.0_f32.to_bits());
            }
            // Wholly inside the visible shadow (x ∈ (2, 6)) and clear of the box in the image.
            let inside_shadow = min_x > a + margin
                && max_x < a + shadow_x - margin
                && min_y > -a + margin
                && max_y < a - margin;
            if inside_shadow && off_box_in_image {
                in_shadow += 1;
                for k in 0..3 {
                    assert_close(px[k], shadow_expected[k], &format!("shadow pixel {x},{y}"));
                }
                assert_eq!(px[3].to_bits(), 0.0_f32.to_bits());
            }
        }
    }
    assert!(
        unaffected > 1000,
        "only {unaffected} unaffected pixels checked"
    );
    assert!(in_shadow > 10, "only {in_shadow} shadow pixels checked");
    assert!(out.changed_pixels < (SIZE_PX[0] * SIZE_PX[1]) as usize - unaffected + 1);

    // The box top, seen at pixel centre of its projection: ρ/π·(E_sun cos θ + π k_u), alpha 1.
    let top = cam.project(&Point3::new(0.0, 0.0, h)).unwrap();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (tx, ty) = (top.x.round() as u32, top.y.round() as u32);
    let px = out.rgba[(ty * SIZE_PX[0] + tx) as usize];
    for k in 0..3 {
        let expected = RHO_BOX[k] / PI * (E_SUN[k] * sun_dir().z + PI * K_U[k]);
        assert_close(px[k], expected, "box top");
    }
    assert_eq!(px[3].to_bits(), 1.0_f32.to_bits());
}

/// A view straight down on an artificial quad filling the image (no natural geometry).
fn quad_only(rho: [f64; 3], lighting: &Lighting, photo_value: f64) -> RenderedImage {
    let mut scene = Scene::new();
    quad(
        &mut scene,
        [
            [-50.0, -50.0, 0.0],
            [50.0, -50.0, 0.0],
            [50.0, 50.0, 0.0],
            [-50.0, 50.0, 0.0],
        ],
        rho,
        ObjectKind::Artificial,
    );
    let cam = look_at(
        Point3::new(0.0, 0.0, 10.0),
        Point3::new(0.0, 0.001, 0.0),
        50.0,
    );
    let photo = uniform_photo([photo_value; 3]);
    let tracer = DifferentialTracer::new(&scene, lighting, &cam, &photo, 2).unwrap();
    render(&tracer, &RenderSettings::default())
}

#[test]
fn sunlit_artificial_quad_is_rho_over_pi_e_cos() {
    let theta = 0.7_f64;
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: Vector3::new(theta.sin(), 0.0, theta.cos()),
                normal_irradiance_rgb: E_SUN,
            }),
            ..Daylight::default()
        },
        ..Lighting::default()
    };
    let out = quad_only(RHO_BOX, &lighting, 0.9);
    for px in &out.rgba {
        for k in 0..3 {
            assert_close(px[k], RHO_BOX[k] / PI * E_SUN[k] * theta.cos(), "sun quad");
        }
        assert_eq!(px[3].to_bits(), 1.0_f32.to_bits());
    }
    // Uniform radiance: zero variance, so the adaptive sampler stops at 4 rays per pixel.
    assert_eq!(out.primary_rays, 4 * u64::from(SIZE_PX[0] * SIZE_PX[1]));
}

#[test]
fn ambient_only_is_rho_k_u() {
    let lighting = Lighting {
        daylight: Daylight {
            ambient_radiance_rgb: K_U,
            ..Daylight::default()
        },
        ..Lighting::default()
    };
    let out = quad_only(RHO_BOX, &lighting, 0.9);
    for px in &out.rgba {
        for k in 0..3 {
            assert_close(px[k], RHO_BOX[k] * K_U[k], "ambient quad");
        }
    }
}

#[test]
fn a_mirror_reflects_the_horizon_colour_case_b() {
    let mut scene = Scene::new();
    let m = scene
        .add_material(Material {
            mirror_rgb: Some([0.8, 0.7, 0.6]),
            ..Material::diffuse("mirror", [0.0; 3])
        })
        .unwrap();
    let o = scene
        .add_object(SceneObject {
            name: "pool".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let c = 50.0;
    let poly = [[-c, -c, 0.0], [c, -c, 0.0], [c, c, 0.0], [-c, c, 0.0]].map(Point3::from);
    scene.add_polygon(&poly, m, o).unwrap();
    let lighting = Lighting {
        horizon_rgb: [0.5, 0.6, 0.9],
        ..sun_and_ambient()
    };
    let cam = look_at(
        Point3::new(0.0, 0.0, 10.0),
        Point3::new(0.0, 0.001, 0.0),
        50.0,
    );
    let photo = uniform_photo([0.1; 3]);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 1).unwrap();
    let out = render(&tracer, &RenderSettings::default());
    for px in &out.rgba {
        for k in 0..3 {
            assert_close(px[k], [0.8, 0.7, 0.6][k] * [0.5, 0.6, 0.9][k], "mirror");
        }
    }
}

#[test]
fn tile_progress_carries_the_final_pixels_of_its_rect() {
    let scene = site(true);
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let lighting = sun_and_ambient();
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 1).unwrap();
    let settings = RenderSettings {
        tile_size_px: 16,
        ..RenderSettings::default()
    };
    let tiles = Mutex::new(Vec::new());
    let img = render_view(
        &tracer,
        &settings,
        &|t| tiles.lock().unwrap().push(t),
        &AtomicBool::new(false),
    )
    .unwrap();
    let tiles = tiles.into_inner().unwrap();
    let w = img.size_px[0];
    let mut covered = 0;
    for t in &tiles {
        let [tw, th] = t.size_px;
        assert_eq!(t.rgb_linear.len(), (tw * th) as usize);
        for y in 0..th {
            for x in 0..tw {
                let full = img.rgba[((t.origin_px[1] + y) * w + t.origin_px[0] + x) as usize];
                let tile = t.rgb_linear[(y * tw + x) as usize];
                assert_eq!(
                    tile.map(f32::to_bits),
                    [full[0], full[1], full[2]].map(f32::to_bits)
                );
                covered += 1;
            }
        }
    }
    assert_eq!(covered, img.rgba.len(), "the tiles cover the image once");
    assert!(img.changed_pixels > 0, "the box changes some pixels");
}

#[test]
fn one_and_two_threads_give_identical_images_and_every_tile_is_reported() {
    let scene = site(true);
    let dome = crate::sky_dome::durisch_facets::durisch_dome(4).unwrap();
    let mut lighting = sun_and_ambient();
    lighting.daylight.sky = Daylight::uniform_sky_lights(&dome, [0.02, 0.03, 0.05]);
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let settings = RenderSettings {
        tile_size_px: 16,
        seed: 42,
        ..RenderSettings::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let tiles = Mutex::new(Vec::new());
        let img = pool
            .install(|| {
                render_view(
                    &tracer,
                    &settings,
                    &|t| tiles.lock().unwrap().push(t.tile_index),
                    &AtomicBool::new(false),
                )
            })
            .unwrap();
        let mut tiles = tiles.into_inner().unwrap();
        tiles.sort_unstable();
        (img, tiles)
    };
    let (one, tiles_one) = run(1);
    let (two, tiles_two) = run(2);
    let bits = |img: &RenderedImage| {
        img.rgba
            .iter()
            .flat_map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&one), bits(&two));
    assert_eq!(
        tiles_one,
        (0..12).collect::<Vec<_>>(),
        "4 × 3 tiles of 16 px"
    );
    assert_eq!(tiles_one, tiles_two);
    // Edge pixels of the box get more than the minimum of 4 rays.
    assert!(one.primary_rays > 4 * u64::from(SIZE_PX[0] * SIZE_PX[1]));
    // A different seed moves the samples.
    let other = render(
        &tracer,
        &RenderSettings {
            seed: 43,
            ..settings
        },
    );
    assert_ne!(bits(&one), bits(&other));
}

#[test]
fn cancel_and_bad_settings_are_errors() {
    let scene = site(true);
    let lighting = sun_and_ambient();
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let cancelled = render_view(
        &tracer,
        &RenderSettings::default(),
        &|_| {},
        &AtomicBool::new(true),
    );
    assert!(matches!(cancelled, Err(RenderError::Cancelled)));
    let bad = RenderSettings {
        min_rays_per_pixel: 6,
        ..RenderSettings::default()
    };
    assert!(matches!(
        render_view(&tracer, &bad, &|_| {}, &AtomicBool::new(false)),
        Err(RenderError::InvalidSetting { .. })
    ));
    let small = Rgb32FImage::new(8, 8);
    let t2 = DifferentialTracer::new(&scene, &lighting, &cam, &small, 2).unwrap();
    assert!(matches!(
        render_view(
            &t2,
            &RenderSettings::default(),
            &|_| {},
            &AtomicBool::new(false)
        ),
        Err(RenderError::SizeMismatch { .. })
    ));
    assert!(matches!(
        DifferentialTracer::new(&site(false), &lighting, &cam, &photo, 2),
        Err(DifferentialError::NoArtificialObject)
    ));
}

#[test]
fn exr_and_png_round_trip() {
    let img = RenderedImage {
        size_px: [3, 2],
        rgba: (0..6_u8)
            .map(|i| [f32::from(i) * 0.1, 0.5, 0.25, f32::from(i % 2)])
            .collect(),
        changed_pixels: 0,
        primary_rays: 0,
    };
    let dir = tempfile::tempdir().unwrap();
    let exr_path = dir.path().join("out.exr");
    img.write_exr(&exr_path).unwrap();
    let back = image::open(&exr_path).unwrap().into_rgba32f();
    for (p, q) in back.pixels().zip(&img.rgba) {
        assert_eq!(p.0.map(f32::to_bits), q.map(f32::to_bits));
    }
    let png_path = dir.path().join("out.png");
    img.write_png(&png_path, &ToneMap::clamp()).unwrap();
    let png = image::open(&png_path).unwrap().into_rgb8();
    // 0.5 linear → sRGB 0.7354 → 188 of 255.
    assert_eq!(png.get_pixel(0, 0).0[1], 188);
}

/// The photographed ground lights a new wall (Durisch §6.2 case D for a secondary ray, gathered
/// once): a vertical Lambertian wall on an unbounded ground of radiance `L_g` receives
/// `π·L_g/2` from it (the cosine integral over the quarter sphere below the horizon in front of
/// the wall), so with ambient light `k_u` only, `L_wall = ρ_w·k_u + ρ_w·L_g/2` where the photo
/// gives `L_g = ρ_g·k_u`.
#[test]
fn photographed_ground_lights_the_wall_by_its_photo_radiance() {
    /// Durisch facets of m_h = 8 sum the cosine lobe cut by the wall's plane with the
    /// centre-point rule: the midpoint rule over 8 polar bands errs by ~(Δθ)²/24 ≈ 0.1 %, and
    /// the cut through the 32 azimuth sectors adds a comparable amount; 0.5 % covers both and
    /// the ground's 1 km edge, while a missing bounce would be 10–13 % off.
    const GATHER_REL_TOL: f64 = 5e-3;
    let mut scene = site(false);
    quad(
        &mut scene,
        [
            [0.0, -2.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 2.0, 4.0],
            [0.0, -2.0, 4.0],
        ],
        RHO_BOX,
        ObjectKind::Artificial,
    );
    let lighting = Lighting {
        daylight: Daylight {
            ambient_radiance_rgb: K_U,
            ..Daylight::default()
        },
        photo_bounce_dome: Some(crate::sky_dome::durisch_facets::durisch_dome(8).unwrap()),
        ..Lighting::default()
    };
    let cam = look_at(
        Point3::new(-12.0, 0.0, 3.0),
        Point3::new(0.0, 0.0, 2.0),
        50.0,
    );
    let photo = uniform_photo([0, 1, 2].map(|k| RHO_GROUND[k] * K_U[k]));
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 1).unwrap();
    let out = render(&tracer, &RenderSettings::default());
    let p = cam.project(&Point3::new(0.0, 0.0, 2.0)).unwrap();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (x, y) = (p.x.round() as u32, p.y.round() as u32);
    let px = out.rgba[(y * SIZE_PX[0] + x) as usize];
    assert_eq!(px[3].to_bits(), 1.0_f32.to_bits());
    for k in 0..3 {
        let expected = RHO_BOX[k] * K_U[k] * (1.0 + RHO_GROUND[k] / 2.0);
        let got = f64::from(px[k]);
        assert!(
            (got - expected).abs() <= GATHER_REL_TOL * expected,
            "channel {k}: {got} vs {expected}"
        );
    }
}

#[test]
fn output_layers_give_depth_object_and_the_exact_shadow_change() {
    let scene = site(true);
    let lighting = sun_and_ambient();
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let settings = RenderSettings::default();
    let all = LayerSet::parse("depth,object_id,shadow_change").unwrap();
    let (out, layers) =
        render_view_with_layers(&tracer, &settings, all, &|_| {}, &AtomicBool::new(false)).unwrap();
    // The layers do not change the image.
    assert_eq!(out, render(&tracer, &settings));
    let depth = layers.depth_m.unwrap();
    let ids = layers.object_id.unwrap();
    let change = layers.shadow_change_rgb.unwrap();

    let a = BOX_HALF_M;
    let shadow_x = BOX_HEIGHT_M * (-sun_dir().x / sun_dir().z);
    let margin = 0.05;
    let c = cam.pose.camera_center_in_world;
    let (mut ground, mut shadow) = (0, 0);
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let i = (y * SIZE_PX[0] + x) as usize;
            let fp = footprint_on_ground(&cam, x, y);
            let min_x = fp.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
            let max_x = fp.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
            let min_y = fp.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
            let max_y = fp.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
            let far_from_box = max_x < -a - 5.0 || min_y > a + 5.0;
            if far_from_box {
                // Ground (object 0): the first ray's distance lies between the pixel corners'.
                ground += 1;
                assert_eq!(ids[i].to_bits(), 0.0_f32.to_bits());
                let d: Vec<f64> = fp.iter().map(|p| (p - c).norm()).collect();
                let (lo, hi) = (
                    d.iter().copied().fold(f64::INFINITY, f64::min),
                    d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                );
                let got = f64::from(depth[i]);
                assert!(got >= lo * (1.0 - F32_REL_TOL) && got <= hi * (1.0 + F32_REL_TOL));
                assert_eq!(change[i].map(f32::to_bits), [0; 3]);
            }
            let inside_shadow = min_x > a + margin
                && max_x < a + shadow_x - margin
                && min_y > -a + margin
                && max_y < a - margin
                && out.rgba[i][3] <= 0.0;
            if inside_shadow {
                // D3: the sun's share of the photo is removed, exactly.
                shadow += 1;
                for k in 0..3 {
                    let e = E_SUN[k] * sun_dir().z;
                    let expected = -ground_radiance()[k] * e / (e + PI * K_U[k]);
                    assert_close(change[i][k], expected, "shadow change");
                }
            }
        }
    }
    assert!(
        ground > 500 && shadow > 10,
        "{ground} ground, {shadow} shadow"
    );
    // The box top (object 1, the first artificial quad) at its projected centre.
    let top = cam.project(&Point3::new(0.0, 0.0, BOX_HEIGHT_M)).unwrap();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i = (top.y.round() as u32 * SIZE_PX[0] + top.x.round() as u32) as usize;
    assert_eq!(ids[i].to_bits(), 1.0_f32.to_bits());
}

/// The irradiance cache ([`irradiance_cache`]) on the box scene with the photo bounce (main and
/// nested dome): the image is the same bits on 1 and 2 threads (per-tile records), the same
/// pixels change as without the cache, and every pixel is within `CACHE_REL_TOL` of the render
/// that gathers at every ray sample (the known answer the cache approximates).
#[test]
fn irradiance_cache_is_thread_independent_and_close_to_gathering_every_sample() {
    /// This image is coarse (64 × 48 px, a pixel ≈ 0.5 m on the ground), so a record reaches
    /// at least a·R_min = 0.4 px ≈ 0.2 m and up to ~10 px ≈ 5 m of open ground. In the box's
    /// shadow the pixel holds only ambient light plus the bounce, so the bounce is up to ~40 %
    /// of it, and Ward's estimate at a = 0.2 bounds the interpolated irradiance's error at
    /// ~a·(its change over R), i.e. up to ~20 % of that share: ≤ 10 % of the worst pixel.
    /// A cache returning another kind's or a far point's gather would be off by the whole share.
    const CACHE_REL_TOL: f64 = 0.10;
    /// The mean over the channel values the cache alters: most sit close to a record, where
    /// the error goes to zero; 1.5 % is a sixth of the worst bound.
    const CACHE_MEAN_REL_TOL: f64 = 0.015;
    let scene = site(true);
    let lighting = Lighting {
        photo_bounce_dome: Some(crate::sky_dome::durisch_facets::durisch_dome(4).unwrap()),
        photo_bounce_nested_dome: Some(crate::sky_dome::durisch_facets::durisch_dome(2).unwrap()),
        ..sun_and_ambient()
    };
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let mut tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let settings = RenderSettings {
        tile_size_px: 16,
        min_rays_per_pixel: 4,
        max_rays_per_pixel: 4,
        seed: 3,
        ..RenderSettings::default()
    };
    let run = |tracer: &DifferentialTracer<'_>, threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(tracer, &settings))
    };
    let bits = |img: &RenderedImage| {
        img.rgba
            .iter()
            .flat_map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    let cached_one = run(&tracer, 1);
    let cached_two = run(&tracer, 2);
    assert_eq!(bits(&cached_one), bits(&cached_two));
    tracer.set_irradiance_cache(None);
    let exact = run(&tracer, 2);
    assert_eq!(cached_one.changed_pixels, exact.changed_pixels);
    assert!(exact.changed_pixels > 100, "{}", exact.changed_pixels);
    let (mut worst, mut sum, mut n) = (0.0_f64, 0.0, 0);
    for (c, e) in cached_one.rgba.iter().zip(&exact.rgba) {
        assert_eq!(c[3].to_bits(), e[3].to_bits(), "coverage");
        if c.map(f32::to_bits) == e.map(f32::to_bits) {
            continue;
        }
        for k in 0..3 {
            let rel = (f64::from(c[k]) - f64::from(e[k])).abs() / f64::from(e[k]).max(1e-6);
            worst = worst.max(rel);
            sum += rel;
            n += 1;
        }
    }
    assert!(n > 0, "the cache changed nothing: it did not interpolate");
    let mean = sum / f64::from(n);
    println!("cache vs exact: worst {worst}, mean {mean} over {n} channel values");
    assert!(worst <= CACHE_REL_TOL, "worst {worst}, mean {mean}");
    assert!(mean <= CACHE_MEAN_REL_TOL, "worst {worst}, mean {mean}");
}

/// Render farms (issue 18): every band of the view, rendered alone, holds exactly the
/// whole-image render's pixels and layers; parts written from the bands merge into files
/// byte-identical to the whole render's EXR and PNG.
#[test]
fn bands_rendered_alone_merge_into_the_whole_render_byte_for_byte() {
    use crate::render::partial::{PART_FORMAT, PartInfo, merge_parts, write_part};
    let scene = site(true);
    let dome = crate::sky_dome::durisch_facets::durisch_dome(4).unwrap();
    let mut lighting = sun_and_ambient();
    lighting.daylight.sky = Daylight::uniform_sky_lights(&dome, [0.02, 0.03, 0.05]);
    let cam = camera();
    let photo = uniform_photo(ground_radiance());
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    // 4-px tiles: 12 tile rows, so 7 bands are uneven (1 or 2 rows each).
    let settings = RenderSettings {
        tile_size_px: 4,
        seed: 5,
        ..RenderSettings::default()
    };
    let all = LayerSet::parse("depth,object_id,shadow_change").unwrap();
    let cancel = AtomicBool::new(false);
    let (whole, whole_layers) =
        render_view_with_layers(&tracer, &settings, all, &|_| {}, &cancel).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let tm = crate::colour::ToneMap::clamp();
    let whole_exr = dir.path().join("whole.exr");
    let whole_png = dir.path().join("whole.png");
    output::write_output(&whole_exr, &whole, &whole_layers, &tm).unwrap();
    output::write_output(&whole_png, &whole, &OutputLayers::default(), &tm).unwrap();
    for count in [1, 4, 7] {
        let mut paths = Vec::new();
        for index in 1..=count {
            let band = Band::new(index, count).unwrap();
            let (img, layers) =
                render_band_with_layers(&tracer, &settings, all, band, &|_| {}, &cancel).unwrap();
            let rows = band.pixel_rows(SIZE_PX[1], 4).unwrap();
            let info = PartInfo {
                format: PART_FORMAT.into(),
                tile: band.to_string(),
                full_size_px: SIZE_PX,
                rows_px: [rows.start, rows.end],
                identity: std::collections::BTreeMap::new(),
                exposure: 1.0,
                object_names: None,
                changed_pixels: img.changed_pixels,
                primary_rays: img.primary_rays,
                view_json: None,
            };
            let path = dir.path().join(format!("part-{index}-of-{count}.exr"));
            write_part(&path, &img, &layers, &info).unwrap();
            paths.push(path);
        }
        let merged = merge_parts(&paths).unwrap();
        assert_eq!(merged.image, whole, "{count} bands");
        assert_eq!(merged.layers.object_id, whole_layers.object_id);
        let exr = dir.path().join(format!("merged-{count}.exr"));
        let png = dir.path().join(format!("merged-{count}.png"));
        output::write_output(&exr, &merged.image, &merged.layers, &tm).unwrap();
        output::write_output(&png, &merged.image, &OutputLayers::default(), &tm).unwrap();
        assert_eq!(
            std::fs::read(&exr).unwrap(),
            std::fs::read(&whole_exr).unwrap()
        );
        assert_eq!(
            std::fs::read(&png).unwrap(),
            std::fs::read(&whole_png).unwrap()
        );
    }
    // The spectral renderer cuts the same bands.
    let whole_spectral = render_view_spectral(
        &tracer,
        &settings,
        crate::colour::SampleSet::Durisch9,
        &|_| {},
        &cancel,
    )
    .unwrap();
    let band = Band::new(2, 3).unwrap();
    let part = render_band_spectral(
        &tracer,
        &settings,
        crate::colour::SampleSet::Durisch9,
        band,
        &|_| {},
        &cancel,
    )
    .unwrap();
    let rows = band.pixel_rows(SIZE_PX[1], 4).unwrap();
    let w = SIZE_PX[0] as usize;
    assert_eq!(
        part.rgba,
        whole_spectral.rgba[rows.start as usize * w..rows.end as usize * w]
    );
    // More bands than tile rows: a clear error, no render.
    let err = render_band_with_layers(
        &tracer,
        &settings,
        all,
        Band::new(1, 13).unwrap(),
        &|_| {},
        &cancel,
    )
    .unwrap_err();
    assert!(err.to_string().contains("at most 12"), "{err}");
}
