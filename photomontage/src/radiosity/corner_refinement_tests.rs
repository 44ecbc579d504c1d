//! Corner refinement against a closed form: a (nearly) black ground x ∈ [−2, 6] m in front of
//! (and behind) a uniformly emitting wall in the plane x = 0 facing +x. The ground's irradiance
//! at a distance x from the wall foot is B_wall × F(x), with F the
//! form factor from a horizontal differential area to a vertical rectangle of half-width a and
//! height H centred in front of it (integrated in closed form over the wall's height and width):
//! F(x) = (1/π)·[atan(a/x) − x/√(x²+H²)·atan(a/√(x²+H²))], ½ at the foot.
#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};

use super::hierarchical::HierarchicalParams;
use super::mesh::{Mesh, MeshParams, longest_edge_m};
use super::{LightGroup, SolveParams, Solver, solve, test_scenes};
use crate::scene::Scene;

const HALF_WIDTH_M: f64 = 3.0;
const HEIGHT_M: f64 = 2.0;
const WALL_RADIANCE_W_M2_SR: f64 = 100.0;
/// Nearly black but reflecting, so that its irradiance is read off the solution.
const GROUND_RHO: f64 = 1e-3;
const ELEMENT_M: f64 = 0.5;
const CORNER_M: f64 = ELEMENT_M / 16.0;
/// Interpolated irradiance within this of the closed form 5–20 cm from the foot, refined (the
/// hierarchical links' own error near a contact, see the module doc of `corner_refinement`).
const REFINED_REL_TOL: f64 = 0.06;
/// The uniform mesh misses the closed form by at least this there.
const UNIFORM_MIN_REL: f64 = 0.25;

fn form_factor(x: f64) -> f64 {
    let s = x.hypot(HEIGHT_M);
    ((HALF_WIDTH_M / x).atan() - x / s * (HALF_WIDTH_M / s).atan()) / std::f64::consts::PI
}

/// Longest edge of the element under the ground point `x` m in front of the wall foot.
fn element_edge_at(mesh: &Mesh, x: f64) -> f64 {
    let probe = Point3::new(x, 0.1, 0.0);
    let e = (0..mesh.elements.len())
        .find(|&e| {
            let n = mesh.element_node(e);
            n.normal_in_world.z > 0.5 && inside(&n.vertices_in_world_m, &probe)
        })
        .unwrap();
    longest_edge_m(&mesh.element_node(e).vertices_in_world_m)
}

/// Whether `p` lies in the triangle `v` in plan.
fn inside(v: &[Point3<f64>; 3], p: &Point3<f64>) -> bool {
    let side =
        |a: &Point3<f64>, b: &Point3<f64>| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    let s = [side(&v[0], &v[1]), side(&v[1], &v[2]), side(&v[2], &v[0])];
    s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0)
}

#[test]
fn the_closed_form_is_one_half_at_the_foot_and_falls_off() {
    assert!((form_factor(1e-9) - 0.5).abs() < 1e-6);
    assert!(form_factor(0.1) > form_factor(0.5));
}

fn mesh_params(corner_element_m: Option<f64>) -> MeshParams {
    MeshParams {
        max_patch_edge_m: 2.0,
        max_element_edge_m: ELEMENT_M,
        corner_element_m,
        ..MeshParams::default()
    }
}

/// Ground elements at the wall foot are split down to the corner size in front of the wall
/// and not behind it (the wall's back); far from it the mesh keeps the element size; the wall's
/// elements are split at its foot and not at its top.
#[test]
fn elements_are_split_at_the_wall_foot_in_front_only() {
    let plain = Mesh::build(&emitter_scene(), &mesh_params(None)).unwrap();
    let refined = Mesh::build(&emitter_scene(), &mesh_params(Some(CORNER_M))).unwrap();
    let uniform = element_edge_at(&plain, 0.02);
    assert!(uniform > 0.3 && uniform <= ELEMENT_M, "{uniform}");
    let at_foot = element_edge_at(&refined, 0.02);
    assert!(
        at_foot <= CORNER_M + 1e-9,
        "in front of the foot: {at_foot} m"
    );
    assert!((element_edge_at(&refined, -0.02) - element_edge_at(&plain, -0.02)).abs() < 1e-12);
    assert!((element_edge_at(&refined, 4.5) - element_edge_at(&plain, 4.5)).abs() < 1e-12);
    let wall_edges = |mesh: &Mesh, z: std::ops::Range<f64>| -> f64 {
        (0..mesh.elements.len())
            .map(|e| mesh.element_node(e))
            .filter(|n| n.normal_in_world.x > 0.5)
            .filter(|n| z.contains(&n.centroid_in_world_m().z))
            .map(|n| longest_edge_m(&n.vertices_in_world_m))
            .fold(f64::INFINITY, f64::min)
    };
    assert!(wall_edges(&refined, 0.0..0.05) <= CORNER_M + 1e-9);
    assert!((wall_edges(&refined, 1.5..2.0) - wall_edges(&plain, 1.5..2.0)).abs() < 1e-12);
    assert!(refined.elements.len() > plain.elements.len());
}

/// The wall as a uniform emitter (ρ 0, L_e = 100 W/m²/sr, so B_wall = 100π exactly) on the
/// nearly black ground: the ground's irradiance is B_wall × F(x).
fn emitter_scene() -> Scene {
    let p = Point3::new;
    let mut scene = Scene::new();
    let (a, h) = (HALF_WIDTH_M, HEIGHT_M);
    test_scenes::add(
        &mut scene,
        "ground",
        test_scenes::quad(
            p(-2.0, -a, 0.0),
            p(6.0, -a, 0.0),
            p(6.0, a, 0.0),
            p(-2.0, a, 0.0),
        ),
        test_scenes::grey("dark", GROUND_RHO),
    );
    let mut lamp = test_scenes::grey("lamp", 0.0);
    lamp.emission_rgb_w_m2_sr = Some([WALL_RADIANCE_W_M2_SR; 3]);
    test_scenes::add(
        &mut scene,
        "wall",
        test_scenes::quad(p(0.0, -a, 0.0), p(0.0, a, 0.0), p(0.0, a, h), p(0.0, -a, h)),
        lamp,
    );
    scene
}

/// The ground's irradiance that the solution gives at points 5–20 cm in front of the wall foot
/// (interpolated on its elements, as `photomontage irradiance` reads it) against the closed
/// form: the uniform 0.5 m elements average the fall-off away (−37 % at 5 cm); the corner
/// elements follow it. The BF tolerance is scaled by the ground's albedo against a usual 0.2
/// (BF refinement weighs the light a link carries, and this ground reflects almost none), so
/// that the links are refined as over a real ground.
#[test]
fn refined_corners_follow_the_closed_form_at_the_wall_foot() {
    let b_wall = std::f64::consts::PI * WALL_RADIANCE_W_M2_SR;
    let up = Vector3::z();
    let worst = |corner_element_m: Option<f64>| -> f64 {
        let params = SolveParams {
            mesh: mesh_params(corner_element_m),
            solver: Solver::Hierarchical(HierarchicalParams {
                bf_tolerance: HierarchicalParams::default().bf_tolerance * GROUND_RHO / 0.2,
                ..HierarchicalParams::default()
            }),
            ..SolveParams::default()
        };
        let groups = [LightGroup::emitters()];
        let s = solve(
            &emitter_scene(),
            &groups,
            &params,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap();
        [0.05, 0.1, 0.2]
            .iter()
            .map(|&x| {
                let sample = s.irradiance_at(&Point3::new(x, 0.1, 0.0), &up).unwrap();
                let expect = b_wall * form_factor(x);
                let rel = sample.total_rgb[1] / expect - 1.0;
                println!(
                    "corner {corner_element_m:?}, x {x:.2} m: {:.2} against {expect:.2} ({:+.2} %)",
                    sample.total_rgb[1],
                    100.0 * rel
                );
                rel.abs()
            })
            .fold(0.0, f64::max)
    };
    let plain = worst(None);
    let refined = worst(Some(CORNER_M));
    assert!(
        refined <= REFINED_REL_TOL,
        "refined: {:.2} %",
        100.0 * refined
    );
    assert!(plain >= UNIFORM_MIN_REL, "uniform: {:.2} %", 100.0 * plain);
}
