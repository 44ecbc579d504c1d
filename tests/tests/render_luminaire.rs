//! A real luminaire in the differential renderer (issue 4, "luminaires as artificial lights",
//! Durisch 1992 §6.2 case D1): the bollard of `data/real/ies/bollard.ies` (BALLABS test 14397,
//! type C, axially symmetric) lights photographed ground; the rendered change at ground points
//! below it must be `ρ_d/π · I(γ) cos γ / d²` with `I(γ)` the file's tabulated candela and ρ_d
//! from the second inversion of the photo.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
use photomontage::camera::{BrownConrady, Camera, Intrinsics, Pose};
use photomontage::luminaire::{Luminaire, PhotometricFile};
use photomontage::render::{
    ArtificialLight, Daylight, DifferentialTracer, Lighting, LuminaireLight, RenderSettings,
    render_view,
};
use photomontage::scene::{Material, ObjectKind, Scene, SceneObject};
use photomontage_tests::shared_file;

const SIZE_PX: [u32; 2] = [16, 16];
/// The four centre pixels lie within 0.1 mm of the target (focal 200 000 px at 20 m); there the
/// bilinear web changes by ≲ 25 cd/° × 0.005° ≈ 0.1 cd of ≥ 400 cd, plus f32 storage: 5e-4.
const CENTRE_REL_TOL: f64 = 5e-4;

fn looking_down(target: Point3<f64>) -> Camera {
    let eye = target + Vector3::new(0.0, 0.0, 20.0);
    let f = (target + Vector3::new(0.0, 2e-4, 0.0) - eye).normalize();
    let r = f.cross(&Vector3::z()).normalize();
    let d = f.cross(&r);
    Camera {
        intrinsics: Intrinsics {
            distortion: BrownConrady::default(),
            ..Intrinsics::centred(200_000.0, SIZE_PX)
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                r, d, f,
            ])),
            camera_center_in_world: eye,
        },
    }
}

#[test]
fn bollard_lights_the_photographed_ground_by_its_tabulated_candela() {
    let Some(path) = shared_file("data/real/ies/bollard.ies") else {
        return;
    };
    let web = PhotometricFile::read(&path)
        .unwrap()
        .distribution()
        .unwrap();
    let height_m = 1.0;
    let k_u = [0.05, 0.06, 0.08];
    let rho_ground = 0.3;
    let photo_rgb = k_u.map(|k| rho_ground * k);
    let scale = [2e-4, 2e-4, 1.5e-4];
    let mut scene = Scene::new();
    let ground = scene
        .add_material(Material::diffuse("ground", [rho_ground; 3]))
        .unwrap();
    let natural = scene
        .add_object(SceneObject {
            name: "ground".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .unwrap();
    let g = 500.0;
    let quad = [[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]].map(Point3::from);
    scene.add_polygon(&quad, ground, natural).unwrap();
    // The planned object: a small sign far off (the tracer needs an artificial object; ambient
    // light casts no shadow).
    let m = scene.add_material(Material::default()).unwrap();
    let sign = scene
        .add_object(SceneObject {
            name: "sign".into(),
            kind: ObjectKind::Artificial,
            image_attribute: None,
        })
        .unwrap();
    let tri = [
        [300.0, 300.0, 0.0],
        [301.0, 300.0, 0.0],
        [301.0, 300.0, 2.0],
    ]
    .map(Point3::from);
    scene.add_polygon(&tri, m, sign).unwrap();
    let luminaire = Luminaire::new(web.clone(), Point3::new(0.0, 0.0, height_m));
    let lighting = Lighting {
        daylight: Daylight {
            ambient_radiance_rgb: k_u,
            ..Daylight::default()
        },
        artificial_lights: vec![ArtificialLight::from(LuminaireLight {
            luminaire,
            rgb_per_cd: scale,
        })],
        ..Lighting::default()
    };
    let photo = image::Rgb32FImage::from_pixel(
        SIZE_PX[0],
        SIZE_PX[1],
        image::Rgb(photo_rgb.map(|x| x as f32)),
    );
    // The file tabulates 703 cd at γ = 45° and 487 cd at γ = 60°.
    for (gamma_deg, candela) in [(45.0_f64, 703.0), (60.0, 487.0)] {
        let gamma = gamma_deg.to_radians();
        let target = Point3::new(height_m * gamma.tan(), 0.0, 0.0);
        let d2 = height_m * height_m / (gamma.cos() * gamma.cos());
        let e_lx = candela * gamma.cos() / d2;
        let camera = looking_down(target);
        let tracer = DifferentialTracer::new(&scene, &lighting, &camera, &photo, 2).unwrap();
        let out = render_view(
            &tracer,
            &RenderSettings::default(),
            &|_| {},
            &AtomicBool::new(false),
        )
        .unwrap();
        let mut worst: f64 = 0.0;
        for (x, y) in [(7, 7), (8, 7), (7, 8), (8, 8)] {
            let px = out.rgba[(y * SIZE_PX[0] + x) as usize];
            for k in 0..3 {
                // Second inversion under ambient light only: ρ_d = π L₀ / (π k_u).
                let rho = photo_rgb[k] / k_u[k];
                let delta_expected = rho / PI * scale[k] * e_lx;
                let delta = f64::from(px[k]) - photo_rgb[k];
                let rel = (delta - delta_expected).abs() / delta_expected;
                worst = worst.max(rel);
                assert!(
                    rel < CENTRE_REL_TOL,
                    "γ {gamma_deg}°: change {delta}, expected {delta_expected}"
                );
            }
        }
        println!(
            "bollard.ies γ = {gamma_deg}°: E = {e_lx:.3} lx, worst relative error {worst:.2e}"
        );
    }
}
