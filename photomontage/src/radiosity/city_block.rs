//! The 50 000-element city block of the relight benches (issue 13's relight latency scene):
//! 16 buildings of 20 × 20 × 15 m (4 × 4, 40 m apart) on a 200 m ground, the ground meshed at
//! 8 m and the walls at 2 m (≈ 49 000 elements, 16 M links), lit by a sun, a CIE overcast sky and
//! one street lamp. Used by `benches/transfer.rs` (the core relight) and
//! `benches/relight_latency.rs` (the studio's path), so that both time the same scene.
//!
//! # Known limitations
//! A synthetic scene (boxes on a plane): no detail below the 2 m elements, no curved geometry.

use std::collections::BTreeMap;

use nalgebra::Point3;

use super::hierarchical::HierarchicalParams;
use super::{
    FormFactorParams, MeshParams, NamedLuminaire, PointSource, RelightStrategy, Sky, SolveParams,
    Solver, Sun, Sweep, TransferLighting, TransferParams,
};
use crate::scene::{ImportedModel, Material, ObjectKind, Scene, SceneError};
use crate::sky::{SkyModel, direction_from_elevation_azimuth};

type Tri = [Point3<f64>; 3];

/// Diffuse reflectance of the "render" buildings (even ones) and the "brick" ones (odd).
pub const RENDER_ALBEDO: f64 = 0.6;
/// Diffuse reflectance of the "brick" buildings.
pub const BRICK_ALBEDO: f64 = 0.35;

fn quad(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Vec<Tri> {
    let p = |v: [f64; 3]| Point3::from(v);
    vec![[p(a), p(b), p(c)], [p(a), p(c), p(d)]]
}

fn add(
    scene: &mut Scene,
    name: &str,
    triangles: Vec<Tri>,
    material: Material,
    kind: ObjectKind,
) -> Result<(), SceneError> {
    let n = triangles.len();
    let model = ImportedModel {
        triangles_in_world_m: triangles,
        triangle_materials: vec![0; n],
        materials: vec![material],
        warnings: Vec::new(),
    };
    scene.add_model(&model, name, kind).map(|_| ())
}

/// Walls and roof of a box (outward), no floor.
fn building(x: f64, y: f64, w: f64, h: f64) -> Vec<Tri> {
    let (x1, y1) = (x + w, y + w);
    let mut t = Vec::new();
    t.extend(quad([x, y, 0.], [x1, y, 0.], [x1, y, h], [x, y, h]));
    t.extend(quad([x1, y, 0.], [x1, y1, 0.], [x1, y1, h], [x1, y, h]));
    t.extend(quad([x1, y1, 0.], [x, y1, 0.], [x, y1, h], [x1, y1, h]));
    t.extend(quad([x, y1, 0.], [x, y, 0.], [x, y, h], [x, y1, h]));
    t.extend(quad([x, y, h], [x1, y, h], [x1, y1, h], [x, y1, h]));
    t
}

/// The block; the first `artificial` buildings are planned (artificial) objects, the rest and
/// the ground natural; the "render" material has diffuse reflectance `render_rgb`.
///
/// # Errors
/// Scene id overflow (not reachable for this size).
pub fn city_block(artificial: usize, render_rgb: [f64; 3]) -> Result<Scene, SceneError> {
    block(artificial, render_rgb, None)
}

/// [`city_block`] with building 0 planned and in its own material, "proposal" of reflectance
/// `proposal_rgb` (as a design imported from CAD brings its own materials): a colour change of
/// "proposal" touches the transfer with the planned building only.
///
/// # Errors
/// Scene id overflow (not reachable for this size).
pub fn city_block_with_proposal(
    render_rgb: [f64; 3],
    proposal_rgb: [f64; 3],
) -> Result<Scene, SceneError> {
    block(1, render_rgb, Some(proposal_rgb))
}

fn block(
    artificial: usize,
    render_rgb: [f64; 3],
    proposal_rgb: Option<[f64; 3]>,
) -> Result<Scene, SceneError> {
    let mut s = Scene::new();
    add(
        &mut s,
        "ground",
        quad(
            [-100., -100., 0.],
            [100., -100., 0.],
            [100., 100., 0.],
            [-100., 100., 0.],
        ),
        Material::diffuse("asphalt", [0.2; 3]),
        ObjectKind::Natural,
    )?;
    let mut k = 0;
    for i in 0..4 {
        for j in 0..4 {
            let (x, y) = (-70.0 + 40.0 * f64::from(i), -70.0 + 40.0 * f64::from(j));
            let material = match proposal_rgb {
                Some(rgb) if k == 0 => Material::diffuse("proposal", rgb),
                _ if k % 2 == 0 => Material::diffuse("render", render_rgb),
                _ => Material::diffuse("brick", [BRICK_ALBEDO; 3]),
            };
            let kind = if k < artificial {
                ObjectKind::Artificial
            } else {
                ObjectKind::Natural
            };
            add(
                &mut s,
                &format!("building{k}"),
                building(x, y, 20.0, 15.0),
                material,
                kind,
            )?;
            k += 1;
        }
    }
    Ok(s)
}

/// Longest patch edge of the block's transfer (the hierarchy's roots), metres.
pub const CITY_BLOCK_PATCH_EDGE_M: f64 = 8.0;

/// Transfer parameters of the block (8 m patches, 2 m elements, 8 m on the ground, 2 × 2
/// form-factor samples, hierarchical links).
#[must_use]
pub fn city_block_params(strategy: RelightStrategy, sweep: Sweep) -> TransferParams {
    city_block_params_with_roots(strategy, sweep, CITY_BLOCK_PATCH_EDGE_M)
}

/// [`city_block_params`] with patches (roots) of at most `patch_edge_m`.
#[must_use]
pub fn city_block_params_with_roots(
    strategy: RelightStrategy,
    sweep: Sweep,
    patch_edge_m: f64,
) -> TransferParams {
    let mut object_element_edge_m = BTreeMap::new();
    object_element_edge_m.insert("ground".to_owned(), 8.0);
    TransferParams {
        solve: SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: patch_edge_m,
                max_element_edge_m: 2.0,
                object_element_edge_m,
                ..MeshParams::default()
            },
            form_factors: FormFactorParams {
                samples_per_axis: 2,
                seed: 0,
                visibility: true,
            },
            solver: Solver::Hierarchical(HierarchicalParams::default()),
            ..SolveParams::default()
        },
        sky_tolerance: 0.1,
        strategy,
        sweep,
    }
}

/// The block's sun at `elevation` and `azimuth` (radians).
#[must_use]
pub fn city_block_sun(elevation: f64, azimuth: f64) -> Sun {
    Sun {
        dir_in_world: direction_from_elevation_azimuth(elevation, azimuth),
        normal_irradiance_rgb: [3.0, 2.9, 2.7],
    }
}

/// Sun (elevation 0.7, azimuth 2.6), CIE overcast sky, one 500 cd street lamp 6 m up.
#[must_use]
pub fn city_block_lighting() -> TransferLighting {
    TransferLighting {
        sun: Some(city_block_sun(0.7, 2.6)),
        sky: Some(Sky {
            model: SkyModel::CieOvercast,
            horizontal_irradiance_rgb: [0.4, 0.45, 0.5],
        }),
        luminaires: vec![NamedLuminaire {
            name: "luminaire:street".into(),
            source: PointSource {
                position_in_world_m: Point3::new(0.0, 0.0, 6.0),
                luminaire: None,
                intensity_rgb: [500.0; 3],
            },
            dimming: 1.0,
        }],
        emitters: false,
    }
}
