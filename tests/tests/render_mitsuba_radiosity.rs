//! The differential renderer in its radiosity lighting mode against Mitsuba 3 (issue 13
//! acceptance, "montage accuracy with the radiosity path on"): as `render_mitsuba.rs`, with the
//! sky and every bounce taken from radiosity solutions of the pair scene with and without the
//! box instead of the sky facets and the photo-bounce gathers.
//!
//! The interreflected light at a point is the renderer's final gather at the element vertices
//! (`radiosity::vertex_gather`). The radiosity mesh is the render scene's with the 1000 m ground cut into a fine square
//! around the box ([`NEAR_HALF_M`], elements of [`NEAR_ELEMENT_M`]) and a coarse ring
//! ([`FAR_ELEMENT_M`]), the same plane, so that the element budget goes where the box changes
//! the light. The images are box-filtered 4 × 4 as in `render_mitsuba.rs`.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use nalgebra::Point3;
use photomontage::peer_scene::{MAX_DEPTH, mitsuba_pair_scene};
use photomontage::radiosity::{DistantSource, LightGroup, MeshParams, SolveParams, solve};
use photomontage::render::differential::radiosity_light::RadiosityLight;
use photomontage::render::{DifferentialTracer, RenderSettings, render_view};
use photomontage::scene::{ObjectKind, Scene, SceneObject};
use photomontage_tests::mitsuba_pair::pair_errors;
use photomontage_tests::shared_file;
use photomontage_tests::street::downscale;
use serde_json::Value;

const SCALE: u32 = 4;
/// Half-size of the finely meshed ground square around the box, metres (the box's shadow at
/// 35° sun elevation reaches 17 m beyond its 9 m half-diagonal).
const NEAR_HALF_M: f64 = 40.0;
/// Element edge near the box and on it, metres.
const NEAR_ELEMENT_M: f64 = 1.0;
/// Element edge of the ground ring out to 500 m, metres.
const FAR_ELEMENT_M: f64 = 25.0;
/// Box pixels, mean relative error. The goal is the facet mode's figure or below
/// (`render_mitsuba.rs` at the same default settings: 2.5 %, 2.0 % without the irradiance
/// cache). Measured 2026-11-25: 0.85 % (signed −0.18 %) with the final gather at element
/// vertices; 4.9 % before it, when the box took its elements' own values (a hierarchical link
/// to a whole face triangle hands every element the same mean, so the shaded face was 10 % too
/// bright at its foot and 5 % too dark at its top).
const BOX_MEAN_REL_TOL: f64 = 0.012;
/// Shadow pixels: at or below the facet mode's 2.3 % at the same settings (2.0 % without the
/// cache). Measured 2026-11-25: 2.07 % (signed −0.9 %); 3.1 % before the vertex gathers.
const SHADOW_MEAN_REL_TOL: f64 = 0.023;

/// The render scene with the ground (object 0, the pair's only natural object) cut into the
/// near square and the far ring.
fn radiosity_scene(scene: &Scene, with_box: bool) -> Scene {
    let mut out = Scene::new();
    for m in scene.materials() {
        out.add_material(m.clone()).unwrap();
    }
    let ground_material = scene.triangles()[0].material;
    let g = 500.0;
    let n = NEAR_HALF_M;
    let near = out
        .add_object(SceneObject {
            name: "ground_near".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .unwrap();
    let far = out
        .add_object(SceneObject {
            name: "ground_far".into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
        .unwrap();
    let quad = |x0: f64, y0: f64, x1: f64, y1: f64| {
        [[x0, y0], [x1, y0], [x1, y1], [x0, y1]].map(|[x, y]| Point3::new(x, y, 0.0))
    };
    out.add_polygon(&quad(-n, -n, n, n), ground_material, near)
        .unwrap();
    for q in [
        quad(-g, -g, g, -n),
        quad(-g, n, g, g),
        quad(-g, -n, -n, n),
        quad(n, -n, g, n),
    ] {
        out.add_polygon(&q, ground_material, far).unwrap();
    }
    if with_box {
        let o = out.add_object(scene.objects()[1].clone()).unwrap();
        for t in scene
            .triangles()
            .iter()
            .filter(|t| scene.objects()[t.object.0 as usize].kind == ObjectKind::Artificial)
        {
            out.add_polygon(&t.vertices_in_world_m, t.material, o)
                .unwrap();
        }
    }
    out
}

#[test]
fn box_and_shadow_match_mitsuba_1024spp_in_radiosity_mode() {
    let (Some(json), Some(photo_path), Some(truth_path)) = (
        shared_file("bench/data/mitsuba/scene.json"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_without_box.exr"),
        shared_file("bench/data/mitsuba/llvm_ad_rgb_1024spp_with_box.exr"),
    ) else {
        return;
    };
    let spec: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let load = |p: &Path| photomontage::photo::load(p).unwrap().pixels;
    let photo = downscale(&load(&photo_path), SCALE);
    let truth = downscale(&load(&truth_path), SCALE);
    let (w, h) = (photo.width(), photo.height());
    let peer = mitsuba_pair_scene(&spec, [w, h]).unwrap();
    let (scene, camera, mut lighting) = (peer.scene, peer.camera, peer.lighting);

    let sun = lighting.daylight.sun.unwrap();
    let groups = vec![
        LightGroup::sun(sun.dir_in_world, sun.normal_irradiance_rgb),
        LightGroup::sky(
            lighting
                .daylight
                .sky
                .iter()
                .map(|f| DistantSource {
                    dir_in_world: f.dir_in_world,
                    normal_irradiance_rgb: f.normal_irradiance_rgb,
                })
                .collect(),
        ),
    ];
    let start = std::time::Instant::now();
    let solve_scene = |with_box: bool| {
        let mut sizes: std::collections::BTreeMap<String, f64> = [
            ("ground_near".to_owned(), NEAR_ELEMENT_M),
            ("ground_far".to_owned(), FAR_ELEMENT_M),
        ]
        .into_iter()
        .collect();
        if with_box {
            sizes.insert(scene.objects()[1].name.clone(), NEAR_ELEMENT_M);
        }
        let params = SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: FAR_ELEMENT_M,
                max_element_edge_m: FAR_ELEMENT_M,
                object_element_edge_m: sizes,
                ..MeshParams::default()
            },
            ..SolveParams::default()
        };
        solve(
            &radiosity_scene(&scene, with_box),
            &groups,
            &params,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap()
    };
    let (with, without) = (solve_scene(true), solve_scene(false));
    let precompute_s = start.elapsed().as_secs_f64();
    lighting.radiosity = Some(Arc::new(
        RadiosityLight::new(&with, &without, &RadiosityLight::traced_exactly).unwrap(),
    ));
    let tracer = DifferentialTracer::new(&scene, &lighting, &camera, &photo, MAX_DEPTH).unwrap();
    let start = std::time::Instant::now();
    let out = render_view(
        &tracer,
        &RenderSettings::default(),
        &|_| {},
        &AtomicBool::new(false),
    )
    .unwrap();
    let render_s = start.elapsed().as_secs_f64();

    let e = pair_errors(&out.rgba, &truth, &photo);
    println!(
        "mitsuba radiosity {w}x{h}: elements {} / {}, precompute {precompute_s:.2} s, render {render_s:.2} s; box pixels {} mean rel err {:.4}; shadow pixels {} mean rel err {:.4}; signed: box {:+.4}, shadow {:+.4}; RMSE {:.5}; changed pixels {}; rays/pixel {:.2}",
        with.mesh.elements.len(),
        without.mesh.elements.len(),
        e.box_pixels,
        e.box_mean_rel,
        e.shadow_pixels,
        e.shadow_mean_rel,
        e.box_bias,
        e.shadow_bias,
        e.rmse,
        out.changed_pixels,
        out.primary_rays as f64 / f64::from(w * h)
    );
    assert!(
        e.box_pixels > 1000 && e.shadow_pixels > 300,
        "masks: {} box, {} shadow",
        e.box_pixels,
        e.shadow_pixels
    );
    assert!(
        e.box_mean_rel <= BOX_MEAN_REL_TOL,
        "box mean relative error {}",
        e.box_mean_rel
    );
    assert!(
        e.shadow_mean_rel <= SHADOW_MEAN_REL_TOL,
        "shadow mean relative error {}",
        e.shadow_mean_rel
    );
}
