//! The Mitsuba pair in the renderer's radiosity lighting mode (issue 13, "montage accuracy with
//! the radiosity path on" and the `render_bench` speed target): radiosity solutions of the pair
//! with and without the box, lit by the pair's sun and its sky facets as two light groups, which
//! the differential renderer reads instead of the sky facets and the photo-bounce gathers
//! ([`RadiosityLight`]). The accuracy test (`tests/tests/render_mitsuba_radiosity.rs`) and
//! `render_bench --lighting radiosity` both build their lighting here, so they measure the same
//! thing.
//!
//! The radiosity mesh is the render scene's with the 1000 m ground cut into a fine square around
//! the box ([`NEAR_HALF_M`], elements of [`NEAR_ELEMENT_M`]) and a coarse ring
//! ([`FAR_ELEMENT_M`]), the same plane, so that the element budget goes where the box changes
//! the light; the box has [`NEAR_ELEMENT_M`] elements.
//!
//! # Known limitations
//! The ground ring's 25 m elements are far coarser than a pixel there: the renderer's vertex
//! gathers, not the elements, carry the interreflected light at a changed point
//! (docs/methodology.md).

use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;

use nalgebra::Point3;

use super::{PeerScene, PeerSceneError};
use crate::radiosity::{
    DistantSource, LightGroup, MeshParams, RadiosityError, Solution, SolveParams, solve,
};
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::scene::{ObjectKind, Scene, SceneObject, SceneTriangle};

/// Half-size of the finely meshed ground square around the box, metres (the box's shadow at
/// 35° sun elevation reaches 17 m beyond its 9 m half-diagonal).
pub const NEAR_HALF_M: f64 = 40.0;
/// Element edge near the box and on it, metres.
pub const NEAR_ELEMENT_M: f64 = 1.0;
/// Element edge of the ground ring out to the ground's edge, metres.
pub const FAR_ELEMENT_M: f64 = 25.0;

/// The pair's radiosity solutions.
#[derive(Debug, Clone)]
pub struct PairRadiosity {
    /// With the box.
    pub with_box: Solution,
    /// Without the box (the photographed state).
    pub without_box: Solution,
}

impl PairRadiosity {
    /// What the renderer reads: both solutions, the sun's direct light out, with vertex gathers
    /// of their own (filled as the render reaches them; a fresh light fills them again).
    ///
    /// # Errors
    /// As [`RadiosityLight::new`].
    pub fn light(&self) -> Result<RadiosityLight, RadiosityError> {
        RadiosityLight::new(
            &self.with_box,
            &self.without_box,
            &RadiosityLight::traced_exactly,
        )
    }

    /// Elements of the solutions with and without the box.
    #[must_use]
    pub fn elements(&self) -> [usize; 2] {
        [
            self.with_box.mesh.elements.len(),
            self.without_box.mesh.elements.len(),
        ]
    }
}

/// The render scene with the ground (the pair's natural object) cut into the near square and the
/// far ring, and with the box when `with_box`.
fn radiosity_scene(peer: &PeerScene, with_box: bool) -> Result<Scene, PeerSceneError> {
    let scene = &peer.scene;
    let natural =
        |t: &&SceneTriangle| scene.objects()[t.object.0 as usize].kind == ObjectKind::Natural;
    let ground = scene
        .triangles()
        .iter()
        .find(natural)
        .ok_or(PeerSceneError::Degenerate { what: "ground" })?;
    // The ground's square half-size (its corners are at ±g in x and y).
    let g = scene
        .triangles()
        .iter()
        .filter(natural)
        .flat_map(|t| {
            t.vertices_in_world_m
                .iter()
                .flat_map(|p| [p.x.abs(), p.y.abs()])
        })
        .fold(0.0_f64, f64::max);
    if g <= NEAR_HALF_M {
        return Err(PeerSceneError::Degenerate {
            what: "ground (smaller than the finely meshed square)",
        });
    }
    let mut out = Scene::new();
    for m in scene.materials() {
        out.add_material(m.clone())?;
    }
    let object = |out: &mut Scene, name: &str| {
        out.add_object(SceneObject {
            name: name.into(),
            kind: ObjectKind::Natural,
            image_attribute: None,
        })
    };
    let near = object(&mut out, "ground_near")?;
    let far = object(&mut out, "ground_far")?;
    let quad = |x0: f64, y0: f64, x1: f64, y1: f64| {
        [[x0, y0], [x1, y0], [x1, y1], [x0, y1]].map(|[x, y]| Point3::new(x, y, 0.0))
    };
    let n = NEAR_HALF_M;
    out.add_polygon(&quad(-n, -n, n, n), ground.material, near)?;
    for q in [
        quad(-g, -g, g, -n),
        quad(-g, n, g, g),
        quad(-g, -n, -n, n),
        quad(n, -n, g, n),
    ] {
        out.add_polygon(&q, ground.material, far)?;
    }
    if with_box {
        for (index, o) in scene.objects().iter().enumerate() {
            if o.kind != ObjectKind::Artificial {
                continue;
            }
            let id = out.add_object(o.clone())?;
            for t in scene
                .triangles()
                .iter()
                .filter(|t| t.object.0 as usize == index)
            {
                out.add_polygon(&t.vertices_in_world_m, t.material, id)?;
            }
        }
    }
    Ok(out)
}

/// Solves the pair with and without the box under its sun and sky facets (module doc).
///
/// # Errors
/// [`PeerSceneError::Field`] when the pair has no sun, [`PeerSceneError::Degenerate`] for a
/// ground smaller than the fine square, scene and radiosity errors.
pub fn mitsuba_pair_radiosity(peer: &PeerScene) -> Result<PairRadiosity, PeerSceneError> {
    let daylight = &peer.lighting.daylight;
    let sun = daylight.sun.ok_or(PeerSceneError::Field {
        field: "sun".into(),
        expected: "present",
    })?;
    let groups = vec![
        LightGroup::sun(sun.dir_in_world, sun.normal_irradiance_rgb),
        LightGroup::sky(
            daylight
                .sky
                .iter()
                .map(|f| DistantSource {
                    dir_in_world: f.dir_in_world,
                    normal_irradiance_rgb: f.normal_irradiance_rgb,
                })
                .collect(),
        ),
    ];
    let solve_scene = |with_box: bool| -> Result<_, PeerSceneError> {
        let mut sizes: BTreeMap<String, f64> = [
            ("ground_near".to_owned(), NEAR_ELEMENT_M),
            ("ground_far".to_owned(), FAR_ELEMENT_M),
        ]
        .into_iter()
        .collect();
        let scene = radiosity_scene(peer, with_box)?;
        for o in scene.objects() {
            if o.kind == ObjectKind::Artificial {
                sizes.insert(o.name.clone(), NEAR_ELEMENT_M);
            }
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
        Ok(solve(
            &scene,
            &groups,
            &params,
            &AtomicBool::new(false),
            &|_| {},
        )?)
    };
    Ok(PairRadiosity {
        with_box: solve_scene(true)?,
        without_box: solve_scene(false)?,
    })
}
