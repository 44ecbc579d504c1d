//! Known-answer renders of the tracer's physics: glass panes (thin-slab Fresnel closed form),
//! the GGX sun highlight, water-wave normals, luminaires (inverse-square cosine law against the
//! web's tabulated candela) and the spectral mode (grey scene = RGB mode).

use super::*;
use crate::camera::{BrownConrady, Camera, Intrinsics, Pose};
use crate::colour::SampleSet;
use crate::luminaire::{IesFile, Luminaire};
use crate::scene::material::{Glass, Specular, WaterWaves};
use crate::scene::{Material, ObjectKind, Scene, SceneObject};
use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use std::f64::consts::PI;

const SIZE_PX: [u32; 2] = [64, 48];
/// f32 storage of f64 results (a few ulps) plus the ≤ 2 mrad spread of the view directions of
/// a 20 000 px lens around normal incidence, where the Fresnel and GGX terms are stationary
/// (second-order changes ≲ 1e-5).
const NARROW_VIEW_REL_TOL: f64 = 1e-4;
/// Spectral mode against RGB mode on a grey scene: the per-band photos are stored as f32
/// (relative 6e-8 per band) and the Appendix A round trip is exact to 1e-12; a few f32 ulps.
const SPECTRAL_RGB_REL_TOL: f64 = 1e-5;

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

/// Straight down onto `target` from `height_m` above it (tilted 1e-5 rad to keep the frame).
fn looking_down(target: Point3<f64>, height_m: f64, focal_px: f64) -> Camera {
    look_at(
        target + Vector3::new(0.0, 0.0, height_m),
        target + Vector3::new(0.0, 1e-5 * height_m, 0.0),
        focal_px,
    )
}

fn add_quad(scene: &mut Scene, half_m: f64, z_m: f64, material: Material, kind: ObjectKind) {
    let m = scene.add_material(material).unwrap();
    let o = scene
        .add_object(SceneObject {
            name: "o".into(),
            kind,
            image_attribute: None,
        })
        .unwrap();
    let c = half_m;
    let poly = [[-c, -c, z_m], [c, -c, z_m], [c, c, z_m], [-c, c, z_m]].map(Point3::from);
    scene.add_polygon(&poly, m, o).unwrap();
}

fn uniform_photo(rgb: [f64; 3]) -> Rgb32FImage {
    #[allow(clippy::cast_possible_truncation)]
    let p = image::Rgb(rgb.map(|x| x as f32));
    Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], p)
}

fn render(tracer: &DifferentialTracer<'_>, settings: &RenderSettings) -> RenderedImage {
    render_view(tracer, settings, &|_| {}, &AtomicBool::new(false)).unwrap()
}

fn assert_rel(got: f32, expected: f64, tol: f64, what: &str) {
    let got = f64::from(got);
    assert!(
        (got - expected).abs() <= tol * expected.abs().max(1e-3),
        "{what}: got {got}, expected {expected}"
    );
}

fn ambient(k_u: [f64; 3]) -> Lighting {
    Lighting {
        daylight: Daylight {
            ambient_radiance_rgb: k_u,
            ..Daylight::default()
        },
        ..Lighting::default()
    }
}

/// A glass pane 5 m above photographed ground, seen at normal incidence; ambient light only
/// (never occluded), so the ground behind the pane is unchanged and shows the photo.
fn pane_over_ground(tau: [f64; 3], horizon: [f64; 3], photo: [f64; 3]) -> RenderedImage {
    let mut scene = Scene::new();
    add_quad(
        &mut scene,
        1000.0,
        0.0,
        Material::diffuse("ground", [0.3; 3]),
        ObjectKind::Natural,
    );
    let window = Material {
        glass: Some(Glass {
            ior: 1.5,
            transmittance_rgb: tau,
        }),
        ..Material::diffuse("window", [0.0; 3])
    };
    add_quad(&mut scene, 50.0, 5.0, window, ObjectKind::Artificial);
    let lighting = Lighting {
        horizon_rgb: horizon,
        ..ambient([0.05, 0.06, 0.08])
    };
    let cam = looking_down(Point3::origin(), 10.0, 20_000.0);
    let photo = uniform_photo(photo);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    render(&tracer, &RenderSettings::default())
}

#[test]
fn a_pane_transmits_the_photo_by_the_thin_slab_closed_form_and_reflects_the_sky() {
    let tau = [0.9, 0.8, 0.5];
    let horizon = [0.4, 0.5, 0.7];
    let photo = [0.1, 0.12, 0.15];
    let out = pane_over_ground(tau, horizon, photo);
    // n = 1.5 at normal incidence: R = 0.04; slab T = τ(1−R)²/(1−τ²R²),
    // R_pane = R + τ²R(1−R)²/(1−τ²R²).
    for px in &out.rgba {
        for k in 0..3 {
            let denom = 1.0 - tau[k] * tau[k] * 0.0016;
            let t = tau[k] * 0.9216 / denom;
            let r = 0.04 + tau[k] * tau[k] * 0.04 * 0.9216 / denom;
            let expected = t * photo[k] + r * horizon[k];
            assert_rel(px[k], expected, NARROW_VIEW_REL_TOL, "pane");
        }
        assert_eq!(
            px[3].to_bits(),
            1.0_f32.to_bits(),
            "the pane covers the pixel"
        );
    }
    // A clear pane in front of a background as bright as the sky: R + T = 1.
    let grey = [0.3, 0.3, 0.3];
    let out = pane_over_ground([1.0; 3], grey, grey);
    for px in &out.rgba {
        for k in 0..3 {
            assert_rel(px[k], 0.3, NARROW_VIEW_REL_TOL, "clear pane");
        }
    }
}

#[test]
fn ggx_sun_highlight_at_the_mirror_direction_is_f0_over_4_pi_alpha2_times_e() {
    let e_sun = [3.0, 2.85, 2.6];
    let (roughness, f0) = (0.5_f64, 0.04);
    let mut scene = Scene::new();
    let glossy = Material {
        specular: Some(Specular { roughness, f0 }),
        ..Material::diffuse("glossy", [0.0; 3])
    };
    add_quad(&mut scene, 50.0, 0.0, glossy, ObjectKind::Artificial);
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: Vector3::z(),
                normal_irradiance_rgb: e_sun,
            }),
            ..Daylight::default()
        },
        ..Lighting::default()
    };
    let cam = looking_down(Point3::origin(), 10.0, 20_000.0);
    let photo = uniform_photo([0.5; 3]);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let out = render(&tracer, &RenderSettings::default());
    let alpha = roughness * roughness;
    for px in &out.rgba {
        for k in 0..3 {
            let expected = f0 / (4.0 * PI * alpha * alpha) * e_sun[k];
            assert_rel(px[k], expected, NARROW_VIEW_REL_TOL, "highlight");
        }
    }
}

fn sunlit_pool(water: Option<WaterWaves>) -> RenderedImage {
    let mut scene = Scene::new();
    let pool = Material {
        water,
        ..Material::diffuse("pool", [0.5; 3])
    };
    add_quad(&mut scene, 100.0, 0.0, pool, ObjectKind::Artificial);
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: Vector3::new(1.0, 0.0, 1.0).normalize(),
                normal_irradiance_rgb: [3.0; 3],
            }),
            ..Daylight::default()
        },
        ..Lighting::default()
    };
    let cam = look_at(Point3::new(0.0, -8.0, 10.0), Point3::origin(), 50.0);
    let photo = uniform_photo([0.5; 3]);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    render(&tracer, &RenderSettings::default())
}

#[test]
fn water_waves_shade_deterministically_and_vanish_at_zero_slope() {
    let waves = |slope| {
        Some(WaterWaves {
            scale_m: 2.0,
            slope,
            octaves: 4,
            seed: 9,
        })
    };
    let flat = sunlit_pool(None);
    let bits = |img: &RenderedImage| {
        img.rgba
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        bits(&sunlit_pool(waves(0.0))),
        bits(&flat),
        "slope 0 is flat"
    );
    // Flat: ρ/π · E cos 45° everywhere.
    for px in &flat.rgba {
        assert_rel(px[0], 0.5 / PI * 3.0 * 0.5_f64.sqrt(), 1e-6, "flat pool");
    }
    let a = sunlit_pool(waves(0.8));
    assert_eq!(bits(&a), bits(&sunlit_pool(waves(0.8))), "deterministic");
    let differing = a
        .rgba
        .iter()
        .zip(&flat.rgba)
        .filter(|(p, q)| (p[0] - q[0]).abs() > 1e-3)
        .count();
    assert!(differing > a.rgba.len() / 4, "waves shade: {differing}");
}

#[test]
fn a_luminaire_adds_its_tabulated_candela_by_the_inverse_square_cosine_law_case_d1() {
    // Hand-written LM-63-2002: type C, axial, 1000/800/400/0 cd at γ = 0/30/60/90°.
    let ies = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 -1 1 7 1 1 2 0.2 0.2 0.1\n\
               1.0 1.0 20\n0 30 60 90 120 150 180\n0\n1000 800 400 0 0 0 0\n";
    let web = IesFile::parse(ies.as_bytes())
        .unwrap()
        .distribution()
        .unwrap();
    let scale = [1e-4, 2e-4, 3e-4];
    let k_u = [0.05, 0.06, 0.08];
    let rho_ground = 0.3;
    let photo_rgb = k_u.map(|k| rho_ground * k);
    let mut scene = Scene::new();
    add_quad(
        &mut scene,
        1000.0,
        0.0,
        Material::diffuse("ground", [rho_ground; 3]),
        ObjectKind::Natural,
    );
    // A small artificial object far away (the tracer needs one; ambient light casts no shadow).
    let m = scene.add_material(Material::default()).unwrap();
    let o = scene
        .add_object(SceneObject {
            name: "kiosk".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let kiosk = [
        [500.0, 500.0, 0.0],
        [501.0, 500.0, 0.0],
        [501.0, 500.0, 2.0],
    ]
    .map(Point3::from);
    scene.add_polygon(&kiosk, m, o).unwrap();
    let lighting = Lighting {
        artificial_lights: vec![ArtificialLight::from(LuminaireLight {
            luminaire: Luminaire::new(web, Point3::new(0.0, 0.0, 5.0)),
            rgb_per_cd: scale,
        })],
        ..ambient(k_u)
    };
    let photo = uniform_photo(photo_rgb);
    // Below the luminaire (γ = 0, d = 5, cos 1) and at γ = 60° (d = 10, cos ½, 400 cd).
    for (target, e_lx) in [
        (Point3::origin(), 1000.0 / 25.0),
        (
            Point3::new(5.0 * 3f64.sqrt(), 0.0, 0.0),
            400.0 * 0.5 / 100.0,
        ),
    ] {
        let cam = looking_down(target, 20.0, 200_000.0);
        let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
        let out = render(&tracer, &RenderSettings::default());
        assert_eq!(out.changed_pixels, (SIZE_PX[0] * SIZE_PX[1]) as usize);
        // The four pixels at the image centre (≤ 0.15 mm from the target).
        for (x, y) in [(31, 23), (32, 23), (31, 24), (32, 24)] {
            let px = out.rgba[(y * SIZE_PX[0] + x) as usize];
            for k in 0..3 {
                // Second inversion: ρ = π·L₀/(π k_u); D1 adds ρ/π·E. Compare the change itself
                // (the photo's f32 value taken off in f64).
                let rho = photo_rgb[k] / k_u[k];
                let expected = rho / PI * scale[k] * e_lx;
                #[allow(clippy::cast_possible_truncation)]
                let photo_f32 = f64::from(photo_rgb[k] as f32);
                let delta = f64::from(px[k]) - photo_f32;
                assert!(
                    (delta - expected).abs() < NARROW_VIEW_REL_TOL * expected,
                    "luminaire D1: change {delta}, expected {expected}"
                );
            }
            assert_eq!(px[3].to_bits(), 0.0_f32.to_bits(), "ground, not covered");
        }
    }
}

/// The shadow scene of `tests.rs` in grey: ground ρ 0.3 photographed under a coloured sun and
/// ambient, a grey artificial box.
fn grey_box_scene() -> (Scene, Lighting, Camera, Rgb32FImage) {
    let mut scene = Scene::new();
    add_quad(
        &mut scene,
        1000.0,
        0.0,
        Material::diffuse("ground", [0.3; 3]),
        ObjectKind::Natural,
    );
    let m = scene
        .add_material(Material::diffuse("box", [0.6; 3]))
        .unwrap();
    let o = scene
        .add_object(SceneObject {
            name: "box".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let (a, h) = (2.0, 4.0);
    for f in [
        [[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]],
        [[-a, -a, 0.0], [a, -a, 0.0], [a, -a, h], [-a, -a, h]],
        [[a, -a, 0.0], [a, a, 0.0], [a, a, h], [a, -a, h]],
        [[a, a, 0.0], [-a, a, 0.0], [-a, a, h], [a, a, h]],
        [[-a, a, 0.0], [-a, -a, 0.0], [-a, -a, h], [-a, a, h]],
    ] {
        scene.add_polygon(&f.map(Point3::from), m, o).unwrap();
    }
    let sun_dir = Vector3::new(-1.0, 0.0, 1.0).normalize();
    let (e_sun, k_u) = ([3.0, 2.85, 2.6], [0.05, 0.06, 0.08]);
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: sun_dir,
                normal_irradiance_rgb: e_sun,
            }),
            ambient_radiance_rgb: k_u,
            sky: vec![],
        },
        horizon_rgb: [0.3, 0.4, 0.6],
        ..Lighting::default()
    };
    let ground = [0, 1, 2].map(|k| 0.3 / PI * (e_sun[k] * sun_dir.z + PI * k_u[k]));
    let cam = look_at(
        Point3::new(0.0, -15.0, 20.0),
        Point3::new(2.0, 0.0, 0.0),
        50.0,
    );
    (scene, lighting, cam, uniform_photo(ground))
}

#[test]
fn spectral_mode_renders_a_grey_scene_as_rgb_mode_and_keeps_untouched_pixels() {
    let (scene, lighting, cam, photo) = grey_box_scene();
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    // Fixed 8 rays per pixel: the adaptive stop must not depend on round-off.
    let settings = RenderSettings {
        min_rays_per_pixel: 8,
        max_rays_per_pixel: 8,
        ..RenderSettings::default()
    };
    let rgb = render(&tracer, &settings);
    let cancel = AtomicBool::new(false);
    let spectral =
        render_view_spectral(&tracer, &settings, SampleSet::Durisch9, &|_| {}, &cancel).unwrap();
    assert_eq!(spectral.changed_pixels, rgb.changed_pixels);
    assert_eq!(spectral.primary_rays, rgb.primary_rays);
    assert!(rgb.changed_pixels > 100 && rgb.changed_pixels < rgb.rgba.len());
    for (i, (s, r)) in spectral.rgba.iter().zip(&rgb.rgba).enumerate() {
        for k in 0..3 {
            assert_rel(
                s[k],
                f64::from(r[k]),
                SPECTRAL_RGB_REL_TOL,
                "spectral vs rgb",
            );
        }
        assert_eq!(s[3].to_bits(), r[3].to_bits(), "coverage");
        let p = photo.as_raw();
        let photo_bits = [p[3 * i], p[3 * i + 1], p[3 * i + 2]].map(f32::to_bits);
        if r[3] == 0.0 && [r[0], r[1], r[2]].map(f32::to_bits) == photo_bits {
            assert_eq!(
                [s[0], s[1], s[2]].map(f32::to_bits),
                photo_bits,
                "untouched pixel {i} is the photo bit for bit"
            );
        }
    }
    // Meyer's 4 samples: 2 passes; untouched pixels are still the photo bit for bit.
    let meyer =
        render_view_spectral(&tracer, &settings, SampleSet::Meyer4, &|_| {}, &cancel).unwrap();
    assert_eq!(meyer.changed_pixels, rgb.changed_pixels);
    let untouched = meyer
        .rgba
        .iter()
        .zip(photo.pixels())
        .filter(|(m, p)| [m[0], m[1], m[2]].map(f32::to_bits) == p.0.map(f32::to_bits))
        .count();
    assert!(untouched >= rgb.rgba.len() - rgb.changed_pixels);
}

#[test]
fn a_luminaire_lights_an_artificial_surface_case_c_and_aiming_turns_it_away() {
    let ies = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 -1 1 7 1 1 2 0.2 0.2 0.1\n\
               1.0 1.0 20\n0 30 60 90 120 150 180\n0\n1000 800 400 0 0 0 0\n";
    let web = IesFile::parse(ies.as_bytes())
        .unwrap()
        .distribution()
        .unwrap();
    let rho = [0.6, 0.5, 0.4];
    let scale = [1e-3, 1e-3, 2e-3];
    let mut scene = Scene::new();
    add_quad(
        &mut scene,
        50.0,
        0.0,
        Material::diffuse("plaza", rho),
        ObjectKind::Artificial,
    );
    let render_with = |luminaire: Luminaire| {
        let lighting = Lighting {
            artificial_lights: vec![ArtificialLight::from(LuminaireLight {
                luminaire,
                rgb_per_cd: scale,
            })],
            ..Lighting::default()
        };
        let cam = looking_down(Point3::origin(), 20.0, 200_000.0);
        let photo = uniform_photo([0.5; 3]);
        let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
        render(&tracer, &RenderSettings::default())
    };
    // 1000 cd straight down from 5 m: E = 40 lx × scale, L = ρ/π·E.
    let down = render_with(Luminaire::new(web.clone(), Point3::new(0.0, 0.0, 5.0)));
    let px = down.rgba[(24 * SIZE_PX[0] + 32) as usize];
    for k in 0..3 {
        assert_rel(
            px[k],
            rho[k] / PI * scale[k] * 40.0,
            NARROW_VIEW_REL_TOL,
            "case C",
        );
    }
    // Aimed at the sky (rotated 180° about x): the plaza is dark.
    let mut up = Luminaire::new(web, Point3::new(0.0, 0.0, 5.0));
    up.world_from_luminaire = Rotation3::from_axis_angle(&Vector3::x_axis(), PI);
    let dark = render_with(up);
    assert!(
        dark.rgba
            .iter()
            .all(|p| p[0].abs() < 1e-12 && p[2].abs() < 1e-12)
    );
}

#[test]
fn glossy_glass_and_spectral_renders_are_identical_for_one_and_two_threads() {
    let (mut scene, lighting, cam, photo) = grey_box_scene();
    // A glossy glass roof over the box's top face adds the glass and GGX code paths.
    let roof = Material {
        glass: Some(Glass {
            ior: 1.52,
            transmittance_rgb: [0.85, 0.88, 0.86],
        }),
        specular: Some(Specular {
            roughness: 0.3,
            f0: 0.04,
        }),
        ..Material::diffuse("roof", [0.0; 3])
    };
    add_quad(&mut scene, 3.0, 5.0, roof, ObjectKind::Artificial);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    let settings = RenderSettings {
        tile_size_px: 16,
        seed: 7,
        ..RenderSettings::default()
    };
    let run = |threads: usize, spectral: bool| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let cancel = AtomicBool::new(false);
        let img = pool.install(|| {
            if spectral {
                render_view_spectral(&tracer, &settings, SampleSet::Durisch9, &|_| {}, &cancel)
                    .unwrap()
            } else {
                render_view(&tracer, &settings, &|_| {}, &cancel).unwrap()
            }
        });
        img.rgba
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(1, false), run(2, false));
    assert_eq!(run(1, true), run(2, true));
}

/// Unpolarised Fresnel reflectance of one air–glass interface (index `n`) at incidence
/// cosine `cos_i`, written out from the Fresnel equations (independent of
/// `Glass::fresnel_reflectance`).
fn fresnel_unpolarised(n: f64, cos_i: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = ((cos_i - n * cos_t) / (cos_i + n * cos_t)).powi(2);
    let rp = ((n * cos_i - cos_t) / (n * cos_i + cos_t)).powi(2);
    0.5 * (rs + rp)
}

/// Photographed ground (value `photo`) under sun from 45° and ambient light; a 20 × 20 m roof
/// of `roof` material 50 m up casts its shadow 50 m to −x, where a camera 10 m up looks
/// straight down (the roof is behind it). Returns the shadow pixel values.
fn shadow_of_roof(roof: Material, photo: [f64; 3], k_s: [f64; 3], k_u: [f64; 3]) -> RenderedImage {
    let mut scene = Scene::new();
    add_quad(
        &mut scene,
        1000.0,
        0.0,
        Material::diffuse("ground", [0.3; 3]),
        ObjectKind::Natural,
    );
    add_quad(&mut scene, 10.0, 50.0, roof, ObjectKind::Artificial);
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: Vector3::new(1.0, 0.0, 1.0).normalize(),
                normal_irradiance_rgb: k_s,
            }),
            ambient_radiance_rgb: k_u,
            sky: Vec::new(),
        },
        ..Lighting::default()
    };
    let cam = looking_down(Point3::new(-50.0, 0.0, 0.0), 10.0, 20_000.0);
    let photo = uniform_photo(photo);
    let tracer = DifferentialTracer::new(&scene, &lighting, &cam, &photo, 2).unwrap();
    render(&tracer, &RenderSettings::default())
}

#[test]
fn a_glass_roof_takes_only_the_light_it_does_not_transmit_case_d3() {
    let photo = [0.2, 0.25, 0.3];
    let k_s = [3.0, 2.8, 2.5];
    let k_u = [0.1, 0.12, 0.16];
    let cos_sun = std::f64::consts::FRAC_1_SQRT_2;
    // Natural irradiance on the ground: π k_u + k_s cos θ; eq. 10 gives ρ/π = photo / E.
    let e_total = [0, 1, 2].map(|k| PI * k_u[k] + k_s[k] * cos_sun);
    let e_sun = k_s.map(|k| k * cos_sun);

    // Opaque roof: D3 removes all of the sun.
    let opaque = shadow_of_roof(Material::diffuse("roof", [0.5; 3]), photo, k_s, k_u);
    // Glass roof (n = 1.5, tinted): the sun crosses the pane at 45°.
    let tau = [0.9, 0.8, 0.6];
    let n = 1.5;
    let glass = Material {
        glass: Some(Glass {
            ior: n,
            transmittance_rgb: tau,
        }),
        ..Material::diffuse("glass roof", [0.0; 3])
    };
    let tinted = shadow_of_roof(glass, photo, k_s, k_u);
    // Thin slab at 45°: R from the Fresnel equations, τ_θ = τ^(1/cos θ_t),
    // T = τ_θ(1−R)²/(1−τ_θ²R²).
    let r = fresnel_unpolarised(n, cos_sun);
    let cos_t = (1.0 - 0.5 / (n * n)).sqrt();
    let t_pane = tau.map(|t| {
        let t_theta = t.powf(1.0 / cos_t);
        t_theta * (1.0 - r).powi(2) / (1.0 - t_theta * t_theta * r * r)
    });
    for (o, g) in opaque.rgba.iter().zip(&tinted.rgba) {
        for k in 0..3 {
            let lit_fraction_opaque = 1.0 - e_sun[k] / e_total[k];
            assert_rel(
                o[k],
                photo[k] * lit_fraction_opaque,
                NARROW_VIEW_REL_TOL,
                "opaque",
            );
            let lit_fraction_glass = 1.0 - (1.0 - t_pane[k]) * e_sun[k] / e_total[k];
            assert_rel(
                g[k],
                photo[k] * lit_fraction_glass,
                NARROW_VIEW_REL_TOL,
                "glass",
            );
        }
    }
    // A tinted shadow: the red channel (τ = 0.9) keeps relatively more light than blue.
    let px = tinted.rgba[0];
    assert!(f64::from(px[0]) / photo[0] > f64::from(px[2]) / photo[2]);
}
