//! Tests of [`super::shadow_refinement`] through the mesh it refines.

use nalgebra::{Point3, Vector3};

use super::shadow_refinement::{SURFACE_OFFSET_M, crosses_shadow_edge};

use crate::bvh::BuildQuality;
use crate::radiosity::mesh::{Mesh, MeshParams, Refinement};
use crate::radiosity::test_scenes::{add, grey, quad};
use crate::scene::{Scene, SceneTracer};

/// A 2 m wall (x = 0 … 0.4, y = −5 … 5) on a 40 m ground; the sun low in the east, so the
/// wall's shadow is a strip x ∈ [−2, 0] on the ground.
fn wall_scene() -> (Scene, Vector3<f64>) {
    let p = Point3::new;
    let mut scene = Scene::new();
    add(
        &mut scene,
        "ground",
        quad(
            p(-20., -20., 0.),
            p(20., -20., 0.),
            p(20., 20., 0.),
            p(-20., 20., 0.),
        ),
        grey("g", 0.3),
    );
    // West face (x = 0, facing −x) and top (z = 2), enough to cast the shadow.
    let mut wall = quad(p(0., 5., 0.), p(0., -5., 0.), p(0., -5., 2.), p(0., 5., 2.));
    wall.extend(quad(
        p(0., -5., 2.),
        p(0.4, -5., 2.),
        p(0.4, 5., 2.),
        p(0., 5., 2.),
    ));
    wall.extend(quad(
        p(0.4, -5., 0.),
        p(0.4, 5., 0.),
        p(0.4, 5., 2.),
        p(0.4, -5., 2.),
    ));
    add(&mut scene, "wall", wall, grey("w", 0.5));
    // Sun in the east at 45°: the shadow reaches 2 m west of the wall's west face.
    let sun = Vector3::new(1.0, 0.0, 1.0).normalize();
    (scene, sun)
}

/// Shaded area of the refined mesh against the strip's (module test below).
const SHADED_AREA_REL_TOL: f64 = 0.05;

/// The ground is refined along the two edges of the wall's shadow and nowhere far from
/// them, down to the minimum edge; the shadow strip's area is resolved to that size.
#[test]
fn the_ground_is_refined_along_a_walls_shadow_edges_only() {
    let (scene, sun) = wall_scene();
    let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
    let dirs = [sun];
    let split = |v: &[Point3<f64>; 3], n: &Vector3<f64>| crosses_shadow_edge(&tracer, &dirs, v, n);
    let params = MeshParams {
        max_patch_edge_m: 8.0,
        max_element_edge_m: 4.0,
        ..MeshParams::default()
    };
    let min_edge_m = 0.5;
    let refinement = Refinement {
        min_element_edge_m: min_edge_m,
        split: &split,
    };
    let plain = Mesh::build(&scene, &params).unwrap();
    let refined = Mesh::build_refined(&scene, &params, Some(&refinement)).unwrap();
    assert!(refined.elements.len() > plain.elements.len());
    // The parameter route (what the solve and the transfer take) meshes the same.
    let lit = Mesh::build_lit(
        &scene,
        &MeshParams {
            shadow_edge_element_m: Some(min_edge_m),
            ..params.clone()
        },
        &dirs,
        &[],
    )
    .unwrap();
    assert_eq!(lit.nodes, refined.nodes);
    assert_eq!(lit.elements, refined.elements);
    let ground = 0;
    let mut small_near_edges = 0;
    for e in 0..refined.elements.len() {
        let node = refined.element_node(e);
        if refined.surfaces[node.surface as usize].object.0 != ground {
            continue;
        }
        let [a, b, c] = node.vertices_in_world_m;
        let edge = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let c = node.centroid_in_world_m();
        // Far from both shadow edges (x = −2 and x = 0, |y| ≤ 5): never refined.
        let far = c.y.abs() > 5.0 + 3.0 * edge || (c.x + 1.0).abs() > 1.0 + 3.0 * edge;
        if far {
            assert!(
                edge > min_edge_m,
                "element at {c:?} refined to {edge} far from the shadow"
            );
        }
        if edge <= min_edge_m {
            small_near_edges += 1;
        }
    }
    assert!(
        small_near_edges >= 40,
        "{small_near_edges} small ground elements"
    );
    // The refined mesh resolves the strip: the ground elements whose centroid is in the
    // shadow add up to its 2 m × 10 m plus the 0.4 m × 10 m under the wall, within
    // SHADED_AREA_REL_TOL (elements of the minimum edge along its 25 m outline).
    let shaded_area_of = |mesh: &Mesh| -> f64 {
        (0..mesh.elements.len())
            .map(|e| mesh.element_node(e))
            .filter(|n| mesh.surfaces[n.surface as usize].object.0 == ground)
            .filter(|n| {
                let p = n.centroid_in_world_m() + Vector3::z() * SURFACE_OFFSET_M;
                tracer.any_hit(&tracer.ray_from_world(&p, &sun, 1e-3, 1e7))
            })
            .map(|n| n.area_m2)
            .sum()
    };
    let (shaded_area, plain_area) = (shaded_area_of(&refined), shaded_area_of(&plain));
    assert!(
        (shaded_area - 24.0).abs() <= 24.0 * SHADED_AREA_REL_TOL,
        "shaded area {shaded_area} (unrefined {plain_area})"
    );
}
