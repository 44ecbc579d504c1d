//! The real OBJ of the Embree peer benchmark (`bench/data/embree/city_10k.obj`, written by
//! `gen_data.py`): triangle count and bounding box as recorded in its `manifest.json`, and two
//! rays with closed-form answers.

use nalgebra::{Point3, Vector3};
use photomontage::bvh::BuildQuality;
use photomontage::scene::{ImportOptions, ObjectKind, Scene, SceneTracer, obj::load_obj};
use photomontage_tests::shared_file;

/// The OBJ prints float32 vertices with 9 significant digits, so they are exact; the manifest's
/// bounding box is the same float32 values. 1e-9 m only absorbs the f64 printing.
const BBOX_TOL_M: f64 = 1e-9;

/// The icosphere (subdivision 4, radius 12 m) is inscribed in its sphere; its faces lie at most
/// r·(1 − cos(edge angle)) ≈ 12·(1 − cos 4°) ≈ 0.03 m inside it. 0.05 m covers that.
const ICOSPHERE_SAGITTA_M: f64 = 0.05;

#[test]
fn city_10k_matches_its_manifest_and_traces() {
    let (Some(obj), Some(manifest)) = (
        shared_file("bench/data/embree/city_10k.obj"),
        shared_file("bench/data/embree/manifest.json"),
    ) else {
        return;
    };
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(manifest).unwrap()).unwrap();
    let city = &manifest["scenes"]["city_10k"];
    let model = load_obj(&obj, &ImportOptions::default()).unwrap();
    assert_eq!(
        model.triangles_in_world_m.len() as u64,
        city["triangles"].as_u64().unwrap()
    );
    assert!(model.warnings.iter().all(|w| matches!(
        w,
        photomontage::scene::ImportWarning::FacesWithoutMaterial { .. }
    )));

    let mut scene = Scene::new();
    scene
        .add_model(&model, "city_10k", ObjectKind::Natural)
        .unwrap();
    let [lo, hi] = scene.bounding_box_in_world_m().unwrap();
    for k in 0..3 {
        assert!((lo[k] - city["mesh_bbox"][0][k].as_f64().unwrap()).abs() < BBOX_TOL_M);
        assert!((hi[k] - city["mesh_bbox"][1][k].as_f64().unwrap()).abs() < BBOX_TOL_M);
    }

    let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
    let down = Vector3::new(0.0, 0.0, -1.0);
    // Free ground between the boxes (box 0 is centred at (−70, −70), at most 6 m half-width).
    let ground =
        tracer.ray_from_world(&Point3::new(-80.0, -80.0, 200.0), &down, 0.0, f32::INFINITY);
    let h = tracer.closest_hit(&ground).unwrap();
    assert!((f64::from(h.hit.t) - 200.0).abs() < 1e-4);
    assert!(
        (h.hit.normal_geometric[2] - 1.0).abs() < 1e-6,
        "ground faces up"
    );
    // The big icosphere, centre (0, 0, 70), radius 12, hit off its top vertex (no edge ties).
    let (x, y) = (0.3, 0.2);
    let sphere_z = 70.0 + (144.0f64 - x * x - y * y).sqrt();
    let sphere = tracer.ray_from_world(&Point3::new(x, y, 200.0), &down, 0.0, f32::INFINITY);
    let t = f64::from(tracer.closest_hit(&sphere).unwrap().hit.t);
    let expected = 200.0 - sphere_z;
    assert!(
        t >= expected - 1e-4 && t < expected + ICOSPHERE_SAGITTA_M,
        "{t} vs {expected}"
    );
}
