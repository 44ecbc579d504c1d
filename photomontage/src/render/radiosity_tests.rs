//! Known-answer tests of the radiosity lighting mode ([`differential::radiosity_light`]) on a
//! small synthetic site: a natural 60 × 60 m ground under a sun and a uniform sky (so the photo
//! is one colour, eq. 6 with the sky's horizontal irradiance), an artificial 4 × 4 × 4 m box, and
//! radiosity solutions of the site with and without the box.

use std::sync::Arc;

use super::differential::radiosity_light::RadiosityLight;
use super::*;
use crate::camera::{BrownConrady, Camera, Intrinsics, Pose};
use crate::radiosity::{DistantSource, LightGroup, MeshParams, Solution, SolveParams, solve};
use crate::scene::{Material, ObjectKind, Scene, SceneObject};
use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use std::f64::consts::PI;

const RHO_GROUND: [f64; 3] = [0.3, 0.25, 0.2];
const RHO_BOX: [f64; 3] = [0.6, 0.5, 0.4];
const E_SUN: [f64; 3] = [3.0, 2.85, 2.6];
const L_SKY: [f64; 3] = [0.25, 0.32, 0.45];
const BOX_HALF_M: f64 = 2.0;
const BOX_HEIGHT_M: f64 = 4.0;
const GROUND_HALF_M: f64 = 30.0;
const SIZE_PX: [u32; 2] = [64, 48];
/// The box top sees the sky only: no interreflection reaches it and its sky is the same
/// clustered sources, unoccluded; what is left is f32 storage and the sky's element quadrature.
const TOP_REL_TOL: f64 = 1e-3;
/// Inside the box's shadow a ray gives ρ_g/π·E_rad,with(x): the inversion recovers ρ_g exactly
/// from a photo that matches the "without" solution (sun + the same sky), so only rounding is
/// left (the change is added to the photo value, ~1e-8 relative); a wrong sign or a missing term would be ≥ 5 % off.
const SHADOW_REL_TOL: f64 = 1e-6;
/// Ground farther than this from the box changes by less than the change threshold: its view
/// factor to the box is below (4·4·cos)/(π·15²) ≈ 0.3 % of the hemisphere.
const FAR_FROM_BOX_M: f64 = 15.0;

fn sun_dir() -> Vector3<f64> {
    Vector3::new(-1.0, 0.0, 1.0).normalize()
}

fn sky_facets() -> Vec<DistantLight> {
    Daylight::uniform_sky_lights(
        &crate::sky_dome::durisch_facets::durisch_dome(8).unwrap(),
        L_SKY,
    )
}

/// Horizontal sky irradiance of the facets.
fn sky_horizontal() -> [f64; 3] {
    let mut e = [0.0; 3];
    for f in sky_facets() {
        for k in 0..3 {
            e[k] += f.normal_irradiance_rgb[k] * f.dir_in_world.z.max(0.0);
        }
    }
    e
}

fn quad(scene: &mut Scene, corners: [[f64; 3]; 4], rho: [f64; 3], kind: ObjectKind, name: &str) {
    let m = scene.add_material(Material::diffuse("m", rho)).unwrap();
    let o = scene
        .add_object(SceneObject {
            name: name.into(),
            kind,
            image_attribute: None,
        })
        .unwrap();
    let poly: Vec<Point3<f64>> = corners.iter().map(|c| Point3::from(*c)).collect();
    scene.add_polygon(&poly, m, o).unwrap();
}

fn site(with_box: bool) -> Scene {
    let mut s = Scene::new();
    let g = GROUND_HALF_M;
    quad(
        &mut s,
        [[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]],
        RHO_GROUND,
        ObjectKind::Natural,
        "ground",
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
            quad(&mut s, f, RHO_BOX, ObjectKind::Artificial, "box");
        }
    }
    s
}

fn groups() -> Vec<LightGroup> {
    vec![
        LightGroup::sun(sun_dir(), E_SUN),
        LightGroup::sky(
            sky_facets()
                .iter()
                .map(|f| DistantSource {
                    dir_in_world: f.dir_in_world,
                    normal_irradiance_rgb: f.normal_irradiance_rgb,
                })
                .collect(),
        ),
    ]
}

fn solved(with_box: bool) -> Solution {
    let params = SolveParams {
        mesh: MeshParams {
            max_patch_edge_m: 8.0,
            max_element_edge_m: 2.0,
            // The box's 1 m elements (only where the box is).
            object_element_edge_m: [("box".to_owned(), 1.0)]
                .into_iter()
                .filter(|_| with_box)
                .collect(),
            ..MeshParams::default()
        },
        ..SolveParams::default()
    };
    solve(
        &site(with_box),
        &groups(),
        &params,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap()
}

fn camera() -> Camera {
    let eye = Point3::new(0.0, -15.0, 20.0);
    let f = (Point3::new(2.0, 0.0, 0.0) - eye).normalize();
    let r = f.cross(&Vector3::z()).normalize();
    let d = f.cross(&r);
    Camera {
        intrinsics: Intrinsics {
            distortion: BrownConrady::default(),
            ..Intrinsics::centred(50.0, SIZE_PX)
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                r, d, f,
            ])),
            camera_center_in_world: eye,
        },
    }
}

/// The photographed ground: eq. 6 with the sun and the sky's horizontal irradiance.
fn ground_radiance() -> [f64; 3] {
    let (cos, sky) = (sun_dir().z, sky_horizontal());
    [0, 1, 2].map(|k| RHO_GROUND[k] / PI * (E_SUN[k] * cos + sky[k]))
}

struct Fixture {
    scene: Scene,
    lighting: Lighting,
    camera: Camera,
    photo: Rgb32FImage,
}

fn fixture() -> Fixture {
    let (with, without) = (solved(true), solved(false));
    let lighting = Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: sun_dir(),
                normal_irradiance_rgb: E_SUN,
            }),
            ambient_radiance_rgb: [0.0; 3],
            sky: sky_facets(),
        },
        radiosity: Some(Arc::new(
            RadiosityLight::new(&with, &without, &RadiosityLight::traced_exactly).unwrap(),
        )),
        ..Lighting::default()
    };
    #[allow(clippy::cast_possible_truncation)]
    let photo = Rgb32FImage::from_pixel(
        SIZE_PX[0],
        SIZE_PX[1],
        image::Rgb(ground_radiance().map(|x| x as f32)),
    );
    Fixture {
        scene: site(true),
        lighting,
        camera: camera(),
        photo,
    }
}

fn render_on(tracer: &DifferentialTracer<'_>, threads: usize) -> RenderedImage {
    let settings = RenderSettings {
        min_rays_per_pixel: 4,
        max_rays_per_pixel: 16,
        seed: 7,
        tile_size_px: 16,
        ..RenderSettings::default()
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| render_view(tracer, &settings, &|_| {}, &AtomicBool::new(false)).unwrap())
}

/// Ground points (z = 0) of a pixel's four corners, `None` where a corner misses the ground.
fn footprint(cam: &Camera, x: u32, y: u32) -> Option<Vec<Point3<f64>>> {
    let c = cam.pose.camera_center_in_world;
    [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)]
        .iter()
        .map(|(dx, dy)| {
            let d =
                cam.ray_dir_in_world(nalgebra::Point2::new(f64::from(x) + dx, f64::from(y) + dy));
            let p = c + d * (-c.z / d.z);
            (d.z < 0.0 && p.x.abs() < GROUND_HALF_M && p.y.abs() < GROUND_HALF_M).then_some(p)
        })
        .collect()
}

fn bits(img: &RenderedImage) -> Vec<u32> {
    img.rgba.iter().flat_map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn radiosity_mode_known_answers_untouched_pixels_and_threads() {
    let fx = fixture();
    let tracer =
        DifferentialTracer::new(&fx.scene, &fx.lighting, &fx.camera, &fx.photo, 2).unwrap();
    let one = render_on(&tracer, 1);
    let two = render_on(&tracer, 2);
    assert_eq!(bits(&one), bits(&two), "1 and 2 threads differ");

    // Case C on the box top: sun + sky, nothing else reaches it.
    let top = fx
        .camera
        .project(&Point3::new(0.0, 0.0, BOX_HEIGHT_M))
        .unwrap();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i = (top.y.round() as u32 * SIZE_PX[0] + top.x.round() as u32) as usize;
    let sky = sky_horizontal();
    for k in 0..3 {
        let expected = RHO_BOX[k] / PI * (E_SUN[k] * sun_dir().z + sky[k]);
        let got = f64::from(one.rgba[i][k]);
        assert!(
            (got - expected).abs() <= TOP_REL_TOL * expected,
            "box top channel {k}: {got} vs {expected}"
        );
    }

    let photo_bits = fx.photo.get_pixel(0, 0).0.map(f32::to_bits);
    let radiosity = fx.lighting.radiosity.as_ref().unwrap();
    let a = BOX_HALF_M;
    let shadow_x = BOX_HEIGHT_M * (-sun_dir().x / sun_dir().z);
    let (mut far, mut shadow) = (0, 0);
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let Some(fp) = footprint(&fx.camera, x, y) else {
                continue;
            };
            let p = one.rgba[(y * SIZE_PX[0] + x) as usize];
            let (min_x, max_x) = fp.iter().fold((f64::MAX, f64::MIN), |(lo, hi), q| {
                (lo.min(q.x), hi.max(q.x))
            });
            let (min_y, max_y) = fp.iter().fold((f64::MAX, f64::MIN), |(lo, hi), q| {
                (lo.min(q.y), hi.max(q.y))
            });
            // Distance from the footprint to the box's footprint square.
            let gap_x = (min_x - a).max(-a - max_x).max(0.0);
            let gap_y = (min_y - a).max(-a - max_y).max(0.0);
            if gap_x.hypot(gap_y) > FAR_FROM_BOX_M && p[3] <= 0.0 {
                far += 1;
                assert_eq!(
                    [p[0], p[1], p[2]].map(f32::to_bits),
                    photo_bits,
                    "far pixel ({x}, {y})"
                );
            }
        }
    }
    assert!(far > 200, "{far} far pixels");

    // Case D inside the box's shadow, ray by ray: the photo's ρ_g (eq. 10 with the sun and
    // the "without" solution) times what the "with" solution says the shadowed ground receives.
    let c = fx.camera.pose.camera_center_in_world;
    for i in 0..20 {
        for j in 0..20 {
            let q = Point3::new(
                a + 0.05 + (shadow_x - 0.1) * f64::from(i) / 19.0,
                -a + 0.05 + (2.0 * a - 0.1) * f64::from(j) / 19.0,
                0.0,
            );
            let to = q - c;
            let sample = tracer.trace_primary(&to.normalize(), ground_radiance());
            let Some(hit) = sample.first_hit else {
                panic!("the shadow point {q} is in view");
            };
            if (hit.distance_m - to.norm()).abs() > 1e-3 {
                continue; // hidden by the box
            }
            shadow += 1;
            assert!(sample.changed);
            let e = radiosity.with_at(&q, &Vector3::z()).unwrap();
            for k in 0..3 {
                let expected = RHO_GROUND[k] / PI * e[k];
                let got = sample.radiance_rgb[k];
                assert!(
                    (got - expected).abs() <= SHADOW_REL_TOL * expected,
                    "shadow point {q} channel {k}: {got} vs {expected}"
                );
            }
            // The sky the box blocks is more than the light it reflects there.
            assert!(e[1] < sky[1], "{q}: {e:?}");
        }
    }
    assert!(shadow > 200, "{shadow} shadow points in view");
}

/// The instant preview's records ([`preview`]) are the renderer's own samples: each equals
/// `trace_primary` through its block's middle pixel, bit for bit, and a replay under the same
/// light returns them. Replayed under a sun twice as strong (no ray traced), the box top is
/// eq. 6 with the doubled sun.
#[test]
#[allow(clippy::float_cmp)] // the same function of the same inputs: compared bit for bit
fn preview_records_are_the_renderers_samples_and_replay_a_stronger_sun() {
    const STRIDE_PX: u32 = 2;
    let fx = fixture();
    let tracer =
        DifferentialTracer::new(&fx.scene, &fx.lighting, &fx.camera, &fx.photo, 2).unwrap();
    let records =
        preview::PreviewRecords::record(&tracer, STRIDE_PX, &AtomicBool::new(false)).unwrap();
    let cols = SIZE_PX[0] / STRIDE_PX;
    assert_eq!(
        records.samples().len(),
        (cols * SIZE_PX[1] / STRIDE_PX) as usize
    );
    let c = fx.camera.pose.camera_center_in_world;
    let mut top = Vec::new();
    for (i, s) in records.samples().iter().enumerate() {
        #[allow(clippy::cast_possible_truncation)]
        let i = i as u32;
        // The middle pixel of a 2-pixel block is its first.
        let (x, y) = (i % cols * STRIDE_PX, i / cols * STRIDE_PX);
        let dir = fx
            .camera
            .ray_dir_in_world(nalgebra::Point2::new(f64::from(x), f64::from(y)));
        let photo_rgb = fx.photo.get_pixel(x, y).0.map(f64::from);
        let traced = tracer.trace_primary(&dir, photo_rgb);
        assert_eq!(traced.radiance_rgb, s.radiance_rgb, "sample ({x}, {y})");
        assert_eq!(traced.changed, s.changed);
        if let Some(hit) = s.first_hit.filter(|_| s.hit_artificial) {
            let p = c + dir * hit.distance_m;
            if (p.z - BOX_HEIGHT_M).abs() < 1e-4 {
                top.push(i as usize);
            }
        }
    }
    assert!(top.len() >= 4, "{} box-top samples", top.len());
    let same = records.replay(&fx.scene, &fx.lighting, &fx.camera).unwrap();
    for (s, p) in records.samples().iter().zip(&same.rgba) {
        #[allow(clippy::cast_possible_truncation)]
        let recorded = s.radiance_rgb.map(|v| v as f32);
        assert_eq!([p[0], p[1], p[2]], recorded);
    }

    // At full resolution: a pixel whose block did not change is the photo's own value; a
    // sample's own pixel is its value (the change factor times the photo there).
    let (mut unchanged, mut own) = (0, 0);
    for y in 0..SIZE_PX[1] {
        for x in 0..SIZE_PX[0] {
            let i = ((y / STRIDE_PX) * cols + x / STRIDE_PX) as usize;
            let v = same.linear_at(x, y, &fx.photo);
            if !same.changed[i] {
                unchanged += 1;
                assert_eq!(v, fx.photo.get_pixel(x, y).0);
            } else if x % STRIDE_PX == 0 && y % STRIDE_PX == 0 {
                own += 1;
                let p = same.rgba[i];
                for k in 0..3 {
                    assert!((v[k] - p[k]).abs() <= 1e-6 * p[k].abs(), "({x}, {y})");
                }
            }
        }
    }
    assert!(unchanged > 1000 && own > 50, "{unchanged} {own}");

    let mut stronger = fx.lighting.clone();
    if let Some(sun) = stronger.daylight.sun.as_mut() {
        sun.normal_irradiance_rgb = E_SUN.map(|e| 2.0 * e);
    }
    let replayed = records.replay(&fx.scene, &stronger, &fx.camera).unwrap();
    let sky = sky_horizontal();
    for i in top {
        for k in 0..3 {
            let expected = RHO_BOX[k] / PI * (2.0 * E_SUN[k] * sun_dir().z + sky[k]);
            let got = f64::from(replayed.rgba[i][k]);
            assert!(
                (got - expected).abs() <= TOP_REL_TOL * expected,
                "box top sample {i} channel {k}: {got} vs {expected}"
            );
        }
        assert_eq!(replayed.rgba[i][3], 1.0);
    }
}

/// The preview's stride keeps it under the sample budget with the smallest stride, and a
/// block's sample goes through its middle pixel (the last, smaller block's own middle).
#[test]
fn preview_stride_and_sample_pixels() {
    assert_eq!(preview::stride_for([1280, 960], 200_000), 3);
    assert_eq!(preview::stride_for([1280, 960], 1_228_800), 1);
    assert_eq!(preview::stride_for([64, 48], 0), 64);
    for (photo, budget) in [([1280_u32, 960_u32], 200_000_u64), ([6000, 4000], 150_000)] {
        let s = preview::stride_for(photo, budget);
        let n = |s: u32| u64::from(photo[0].div_ceil(s)) * u64::from(photo[1].div_ceil(s));
        assert!(
            n(s) <= budget && (s == 1 || n(s - 1) > budget),
            "{photo:?}: {s}"
        );
    }
}
