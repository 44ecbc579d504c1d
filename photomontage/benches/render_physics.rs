//! Cost of the renderer's physical models on one small scene (a 4 × 4 × 4 m box on
//! photographed ground under sun, ambient and 24 sky facets, 160 × 120 px, 4–16 adaptive rays):
//! the box diffuse (baseline), as glass, as GGX specular, as a water-wave mirror, lit by a
//! luminaire, and the diffuse scene in spectral mode (Durisch's 9 samples, Meyer's 4). The
//! interesting numbers are the ratios to the baseline.

use std::f64::consts::PI;
use std::hint::black_box;
use std::sync::atomic::AtomicBool;

use criterion::{Criterion, criterion_group, criterion_main};
use image::Rgb32FImage;
use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use photomontage::camera::{BrownConrady, Camera, Intrinsics, Pose};
use photomontage::colour::SampleSet;
use photomontage::luminaire::{IesFile, Luminaire};
use photomontage::render::{
    ArtificialLight, Daylight, DifferentialTracer, DistantLight, Lighting, LuminaireLight,
    RenderSettings, render_view, render_view_spectral,
};
use photomontage::scene::material::{Glass, Specular, WaterWaves};
use photomontage::scene::{Material, ObjectKind, Scene, SceneObject};
use photomontage::sky_dome::durisch_facets::durisch_dome;

const SIZE_PX: [u32; 2] = [160, 120];

fn camera() -> Camera {
    let eye = Point3::new(0.0, -15.0, 20.0);
    let f = (Point3::new(2.0, 0.0, 0.0) - eye).normalize();
    let r = f.cross(&Vector3::z()).normalize();
    let d = f.cross(&r);
    Camera {
        intrinsics: Intrinsics {
            distortion: BrownConrady::default(),
            ..Intrinsics::centred(125.0, SIZE_PX)
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                r, d, f,
            ])),
            camera_center_in_world: eye,
        },
    }
}

fn scene(box_material: Material) -> Scene {
    let mut s = Scene::new();
    let g = s
        .add_material(Material::diffuse("ground", [0.3; 3]))
        .expect("material");
    let ground = s
        .add_object(SceneObject {
            name: "ground".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .expect("object");
    let c = 1000.0;
    let quad = [[-c, -c, 0.0], [c, -c, 0.0], [c, c, 0.0], [-c, c, 0.0]].map(Point3::from);
    s.add_polygon(&quad, g, ground).expect("polygon");
    let m = s.add_material(box_material).expect("material");
    let o = s
        .add_object(SceneObject {
            name: "box".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .expect("object");
    let (a, h) = (2.0, 4.0);
    for f in [
        [[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]],
        [[-a, -a, 0.0], [a, -a, 0.0], [a, -a, h], [-a, -a, h]],
        [[a, -a, 0.0], [a, a, 0.0], [a, a, h], [a, -a, h]],
        [[a, a, 0.0], [-a, a, 0.0], [-a, a, h], [a, a, h]],
        [[-a, a, 0.0], [-a, -a, 0.0], [-a, -a, h], [-a, a, h]],
    ] {
        s.add_polygon(&f.map(Point3::from), m, o).expect("polygon");
    }
    s
}

fn lighting(with_luminaire: bool) -> Lighting {
    let dome = durisch_dome(4).expect("dome");
    let sun_dir = Vector3::new(-1.0, 0.0, 1.0).normalize();
    let mut lights = vec![];
    if with_luminaire {
        let ies = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 -1 1 7 1 1 2 0.2 0.2 0.1\n\
                   1.0 1.0 20\n0 30 60 90 120 150 180\n0\n1000 800 400 0 0 0 0\n";
        let web = IesFile::parse(ies.as_bytes())
            .and_then(|f| f.distribution())
            .expect("web");
        lights.push(ArtificialLight::from(LuminaireLight {
            luminaire: Luminaire::new(web, Point3::new(4.0, -4.0, 5.0)),
            rgb_per_cd: [1e-3; 3],
        }));
    }
    Lighting {
        daylight: Daylight {
            sun: Some(DistantLight {
                dir_in_world: sun_dir,
                normal_irradiance_rgb: [3.0, 2.85, 2.6],
            }),
            ambient_radiance_rgb: [0.02, 0.025, 0.03],
            sky: Daylight::uniform_sky_lights(&dome, [0.03, 0.04, 0.06]),
        },
        artificial_lights: lights,
        horizon_rgb: [0.3, 0.4, 0.6],
        ..Lighting::default()
    }
}

fn photo() -> Rgb32FImage {
    let g: [f64; 3] = [
        0.3 / PI * 3.0 * 0.707,
        0.3 / PI * 2.85 * 0.707,
        0.3 / PI * 2.6 * 0.707,
    ];
    #[allow(clippy::cast_possible_truncation)]
    Rgb32FImage::from_pixel(SIZE_PX[0], SIZE_PX[1], image::Rgb(g.map(|x| x as f32)))
}

fn bench(c: &mut Criterion) {
    let cam = camera();
    let img = photo();
    let settings = RenderSettings::default();
    let cancel = AtomicBool::new(false);
    let diffuse = Material::diffuse("box", [0.6, 0.5, 0.4]);
    let variants: Vec<(&str, Material, bool)> = vec![
        ("diffuse", diffuse.clone(), false),
        (
            "glass",
            Material {
                glass: Some(Glass {
                    ior: 1.52,
                    transmittance_rgb: [0.85, 0.88, 0.86],
                }),
                ..Material::diffuse("box", [0.0; 3])
            },
            false,
        ),
        (
            "ggx",
            Material {
                specular: Some(Specular {
                    roughness: 0.4,
                    f0: 0.04,
                }),
                ..diffuse.clone()
            },
            false,
        ),
        (
            "water_mirror",
            Material {
                mirror_rgb: Some([0.3; 3]),
                water: Some(WaterWaves {
                    scale_m: 2.0,
                    slope: 0.3,
                    octaves: 4,
                    seed: 7,
                }),
                ..Material::diffuse("box", [0.3; 3])
            },
            false,
        ),
        ("luminaire", diffuse.clone(), true),
    ];
    let mut group = c.benchmark_group("render_physics_160x120");
    group.sample_size(10);
    for (name, material, lum) in &variants {
        let s = scene(material.clone());
        let l = lighting(*lum);
        let tracer = DifferentialTracer::new(&s, &l, &cam, &img, 2).expect("tracer");
        group.bench_function(*name, |b| {
            b.iter(|| {
                black_box(render_view(&tracer, &settings, &|_| {}, &cancel).expect("render"))
            });
        });
    }
    let s = scene(diffuse);
    let l = lighting(false);
    let tracer = DifferentialTracer::new(&s, &l, &cam, &img, 2).expect("tracer");
    for (name, set) in [
        ("spectral_durisch9", SampleSet::Durisch9),
        ("spectral_meyer4", SampleSet::Meyer4),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                black_box(
                    render_view_spectral(&tracer, &settings, set, &|_| {}, &cancel)
                        .expect("render"),
                )
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
