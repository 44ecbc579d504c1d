//! Diffuse reflectances per element that differ from their surface's: ρ_d recovered from a
//! photo by the illumination model's second inversion (Durisch 1992 §3.3 eq. 10,
//! ρ_d = π·L₀/E; issue 13 item 2: "natural patches take ρ_d from the photo where a solved photo
//! sees them, else from the material library"). The site layer estimates the values
//! (`site::photo_reflectance`); this module stores them on the mesh, where every solver and
//! relight reads them through [`Mesh::reflectance_rgb`].
//!
//! An inner node (a patch or an intermediate node of the hierarchy) gets the area-weighted mean
//! of its children's reflectances, so that the hierarchical solver's BF test sees the light its
//! leaves will reflect; where all children agree the node takes their value exactly, so a mesh
//! whose elements all carry their surface's value solves bit for bit as one without.

use std::sync::Arc;

use super::mesh::Mesh;
use super::{RadiosityError, Rgb};

impl Mesh {
    /// Sets ρ_d per element (`None`: the surface's own); `rho` has one entry per element. All
    /// `None` clears every override.
    ///
    /// # Errors
    /// [`RadiosityError::ElementReflectance`] for a wrong length or a value that is not finite
    /// and in [0, 1], naming the element's object; on error the mesh is unchanged.
    pub fn set_element_reflectances(&mut self, rho: &[Option<Rgb>]) -> Result<(), RadiosityError> {
        if rho.len() != self.elements.len() {
            return Err(RadiosityError::ElementReflectance {
                element: rho.len(),
                object: String::new(),
                reason: format!(
                    "list has {} entries for {} elements",
                    rho.len(),
                    self.elements.len()
                ),
            });
        }
        for (e, r) in rho.iter().enumerate() {
            if let Some(r) = r
                && !r.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v))
            {
                return Err(RadiosityError::ElementReflectance {
                    element: e,
                    object: self.object_name(self.elements[e] as usize).to_owned(),
                    reason: format!("{r:?} must be finite and in [0, 1]"),
                });
            }
        }
        if rho.iter().all(Option::is_none) {
            self.node_reflectance_rgb = None;
            return Ok(());
        }
        let mut per_node: Vec<Option<Rgb>> = vec![None; self.nodes.len()];
        for (e, r) in rho.iter().enumerate() {
            per_node[self.elements[e] as usize] = *r;
        }
        // Children are numbered after their parents (the mesher pushes a node, then its
        // subtree), so a reverse sweep sees every child before its parent.
        for n in (0..self.nodes.len()).rev() {
            let Some(kids) = self.nodes[n].children else {
                continue;
            };
            if kids.iter().all(|&k| per_node[k as usize].is_none()) {
                continue;
            }
            let own = |k: u32| {
                per_node[k as usize].unwrap_or(
                    self.surfaces[self.nodes[k as usize].surface as usize].reflectance_rgb,
                )
            };
            let first = own(kids[0]);
            // Equal values are kept exactly (module doc), so the comparison is bitwise too.
            let same = |r: Rgb| (0..3).all(|c| r[c].to_bits() == first[c].to_bits());
            per_node[n] = Some(if kids.iter().all(|&k| same(own(k))) {
                first
            } else {
                let mut sum = [0.0; 3];
                let mut area = 0.0;
                for &k in &kids {
                    let (r, a) = (own(k), self.nodes[k as usize].area_m2);
                    for c in 0..3 {
                        sum[c] += r[c] * a;
                    }
                    area += a;
                }
                sum.map(|s| s / area)
            });
        }
        self.node_reflectance_rgb = Some(Arc::new(per_node));
        Ok(())
    }

    /// The per-element overrides as set (`None` where an element takes its surface's value).
    #[must_use]
    pub fn element_reflectance_overrides(&self) -> Vec<Option<Rgb>> {
        self.elements
            .iter()
            .map(|&n| {
                self.node_reflectance_rgb
                    .as_ref()
                    .and_then(|r| r[n as usize])
            })
            .collect()
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // values stored and read back: compared bit for bit
mod tests {
    use std::sync::atomic::AtomicBool;

    use nalgebra::{Point3, Vector3};

    use super::*;
    use crate::bvh::BuildQuality;
    use crate::radiosity::{
        DistantSource, LightGroup, MeshParams, Solution, SolveParams, solve_on_mesh, test_scenes,
    };
    use crate::scene::{Scene, SceneTracer};

    /// A 10 m ground square of reflectance `ground_rho` and a 3 m wall standing on it.
    pub(crate) fn yard(ground_rho: f64) -> Scene {
        let p = Point3::new;
        let mut scene = Scene::new();
        test_scenes::add(
            &mut scene,
            "ground",
            test_scenes::quad(
                p(-5., -5., 0.),
                p(5., -5., 0.),
                p(5., 5., 0.),
                p(-5., 5., 0.),
            ),
            test_scenes::grey("asphalt", ground_rho),
        );
        test_scenes::add(
            &mut scene,
            "wall",
            test_scenes::block(p(1.0, -4.0, 0.0), p(1.3, 4.0, 3.0)),
            test_scenes::grey("brick", 0.5),
        );
        scene
    }

    fn groups() -> Vec<LightGroup> {
        let sky = [(0.3, 0.5, 0.8), (-0.6, 0.2, 0.6), (0.1, -0.7, 0.5)]
            .map(|(x, y, z)| DistantSource {
                dir_in_world: Vector3::new(x, y, z).normalize(),
                normal_irradiance_rgb: [0.2, 0.25, 0.3],
            })
            .to_vec();
        vec![
            LightGroup::sun(Vector3::new(-0.5, 0.2, 0.7).normalize(), [2.0, 1.9, 1.7]),
            LightGroup::sky(sky),
        ]
    }

    fn params() -> SolveParams {
        SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: 4.0,
                max_element_edge_m: 1.0,
                ..MeshParams::default()
            },
            ..SolveParams::default()
        }
    }

    fn solve(scene: &Scene, mesh: Mesh) -> Solution {
        let tracer = SceneTracer::new(scene, BuildQuality::Medium).unwrap();
        let cancel = AtomicBool::new(false);
        solve_on_mesh(mesh, &tracer, &groups(), &params(), &cancel, &|_| {}).unwrap()
    }

    #[test]
    fn every_element_at_the_value_of_another_material_solves_as_that_material_bit_for_bit() {
        let reference_scene = yard(0.6);
        let reference = solve(
            &reference_scene,
            Mesh::build(&reference_scene, &params().mesh).unwrap(),
        );
        let base = yard(0.2);
        let mut mesh = Mesh::build(&base, &params().mesh).unwrap();
        let rho: Vec<Option<Rgb>> = (0..mesh.elements.len())
            .map(|e| (mesh.object_name(mesh.elements[e] as usize) == "ground").then_some([0.6; 3]))
            .collect();
        assert!(rho.iter().any(Option::is_some) && rho.iter().any(Option::is_none));
        mesh.set_element_reflectances(&rho).unwrap();
        assert_eq!(mesh.element_reflectance_overrides(), rho);
        let overridden = solve(&base, mesh);
        for (a, b) in overridden.groups.iter().zip(&reference.groups) {
            assert_eq!(a.radiosity_rgb, b.radiosity_rgb, "group {}", a.name);
        }
    }

    #[test]
    fn an_inner_node_takes_the_area_weighted_mean_of_its_children() {
        let scene = yard(0.2);
        let mut mesh = Mesh::build(&scene, &params().mesh).unwrap();
        let parent = (0..mesh.nodes.len())
            .find(|&n| {
                mesh.nodes[n]
                    .children
                    .is_some_and(|k| k.iter().all(|&c| mesh.nodes[c as usize].element.is_some()))
            })
            .unwrap();
        let kids = mesh.nodes[parent].children.unwrap();
        let surface = mesh.reflectance_rgb(kids[1] as usize);
        let mut rho = vec![None; mesh.elements.len()];
        let e0 = mesh.nodes[kids[0] as usize].element.unwrap() as usize;
        rho[e0] = Some([1.0, 0.0, 0.5]);
        mesh.set_element_reflectances(&rho).unwrap();
        let a: Vec<f64> = kids
            .iter()
            .map(|&k| mesh.nodes[k as usize].area_m2)
            .collect();
        let total: f64 = a.iter().sum();
        let expected: Rgb = std::array::from_fn(|c| {
            ([1.0, 0.0, 0.5][c] * a[0] + surface[c] * (total - a[0])) / total
        });
        let got = mesh.reflectance_rgb(parent);
        for c in 0..3 {
            assert!(
                (got[c] - expected[c]).abs() < 1e-12,
                "{got:?} vs {expected:?}"
            );
        }
        assert_eq!(mesh.element_reflectance_rgb(e0), [1.0, 0.0, 0.5]);
        // Clearing restores the surfaces' values.
        mesh.set_element_reflectances(&vec![None; mesh.elements.len()])
            .unwrap();
        assert_eq!(mesh.reflectance_rgb(parent), surface);
    }

    #[test]
    fn bad_values_are_refused_naming_the_object_and_leave_the_mesh_unchanged() {
        let scene = yard(0.2);
        let mut mesh = Mesh::build(&scene, &params().mesh).unwrap();
        let mut rho = vec![None; mesh.elements.len()];
        rho[0] = Some([0.5, 1.5, 0.5]);
        let err = mesh.set_element_reflectances(&rho).unwrap_err().to_string();
        let object = mesh.object_name(mesh.elements[0] as usize).to_owned();
        assert!(err.contains(&object) && err.contains("[0, 1]"), "{err}");
        rho[0] = Some([f64::NAN, 0.5, 0.5]);
        assert!(mesh.set_element_reflectances(&rho).is_err());
        assert!(mesh.set_element_reflectances(&rho[1..]).is_err());
        assert!(mesh.node_reflectance_rgb.is_none());
    }

    fn ground_at(mesh: &Mesh, value: Rgb) -> Vec<Option<Rgb>> {
        (0..mesh.elements.len())
            .map(|e| (mesh.object_name(mesh.elements[e] as usize) == "ground").then_some(value))
            .collect()
    }

    /// The refit's re-solve against a fresh solve of the scene with that material: the links
    /// were refined for the first reflectances (0.2), the fresh solve's for 0.6, each within the
    /// BF tolerance; the transfer's relight tolerances bound the difference
    /// (`transfer::RELIGHT_L1_REL_TOL`, `RELIGHT_MEAN_REL_TOL`).
    #[test]
    fn a_refit_round_solves_the_new_reflectances_on_the_first_links() {
        use crate::radiosity::solve_on_mesh_refitting;
        use crate::radiosity::transfer::{RELIGHT_L1_REL_TOL, RELIGHT_MEAN_REL_TOL};
        let base = yard(0.2);
        let tracer = SceneTracer::new(&base, BuildQuality::Medium).unwrap();
        let cancel = AtomicBool::new(false);
        let mut calls = 0;
        let refit = &mut |solution: &Solution| {
            calls += 1;
            (calls == 1).then(|| ground_at(&solution.mesh, [0.6; 3]))
        };
        let mesh = Mesh::build(&base, &params().mesh).unwrap();
        let refitted = solve_on_mesh_refitting(
            mesh,
            &tracer,
            &groups(),
            &params(),
            &cancel,
            &|_| {},
            refit,
            3,
        )
        .unwrap();
        assert_eq!(calls, 2, "the second call ends the rounds");
        let plain_scene = yard(0.6);
        let plain = solve(
            &plain_scene,
            Mesh::build(&plain_scene, &params().mesh).unwrap(),
        );
        let d = refitted.relative_difference(&plain).unwrap();
        assert!(d.l1_rel < RELIGHT_L1_REL_TOL, "L1 {}", d.l1_rel);
        assert!(
            d.mean_rel.abs() < RELIGHT_MEAN_REL_TOL,
            "mean {}",
            d.mean_rel
        );
        // The ground reflects more than at 0.2: the wall is brighter than the first solve's.
        let first = solve(&base, Mesh::build(&base, &params().mesh).unwrap());
        let wall_mean = |s: &Solution| -> f64 {
            let b = s.total_radiosity_rgb();
            (0..b.len())
                .filter(|&e| s.mesh.object_name(s.mesh.elements[e] as usize) == "wall")
                .map(|e| b[e][1])
                .sum()
        };
        assert!(wall_mean(&refitted) > 1.02 * wall_mean(&first));
        // Another solver is refused rather than silently not refitted.
        let progressive = SolveParams {
            solver: crate::radiosity::Solver::Progressive,
            ..params()
        };
        let err = solve_on_mesh_refitting(
            Mesh::build(&base, &params().mesh).unwrap(),
            &tracer,
            &groups(),
            &progressive,
            &cancel,
            &|_| {},
            &mut |_| None,
            1,
        )
        .unwrap_err();
        assert!(err.to_string().contains("hierarchical"), "{err}");
    }

    /// A transfer given per-element values equal to a material change gives that material
    /// change's solution bit for bit (same links, same warm start, same ρ per element).
    #[test]
    fn a_transfer_relights_per_element_values_as_the_same_material_change() {
        use crate::radiosity::transfer::{
            LightingChange, Sun, Transfer, TransferLighting, TransferParams,
        };
        let scene = yard(0.2);
        let lighting = TransferLighting {
            sun: Some(Sun {
                dir_in_world: Vector3::new(-0.5, 0.2, 0.7).normalize(),
                normal_irradiance_rgb: [2.0, 1.9, 1.7],
            }),
            sky: None,
            luminaires: Vec::new(),
            emitters: false,
        };
        let p = TransferParams {
            solve: params(),
            ..TransferParams::default()
        };
        let cancel = AtomicBool::new(false);
        let build = || Transfer::build(&scene, &lighting, &p, &cancel, &|_| {}).unwrap();
        let mut by_material = build();
        let material = by_material
            .relight(&LightingChange {
                material_reflectance: vec![("asphalt".into(), [0.6, 0.5, 0.4])],
                ..LightingChange::default()
            })
            .unwrap();
        let mut by_element = build();
        let rho = ground_at(&by_element.solution().mesh, [0.6, 0.5, 0.4]);
        by_element.set_element_reflectances(&rho).unwrap();
        for (a, b) in by_element.solution().groups.iter().zip(&material.groups) {
            assert_eq!(a.radiosity_rgb, b.radiosity_rgb, "group {}", a.name);
        }
        // A bad value changes nothing.
        let before = by_element.solution().total_radiosity_rgb();
        let mut bad = rho.clone();
        bad[0] = Some([2.0; 3]);
        assert!(by_element.set_element_reflectances(&bad).is_err());
        assert_eq!(by_element.solution().total_radiosity_rgb(), before);
    }
}
