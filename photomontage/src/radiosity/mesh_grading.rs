//! Mesh grading: coarser patches and elements far from where the mesh is looked at.
//!
//! Importance-driven radiosity (Smits, Arvo & Salesin 1992, "An importance-driven radiosity
//! algorithm", SIGGRAPH '92) refines a mesh where a view needs it and leaves it coarse
//! elsewhere; Tonn & Donath (seed 000) give the mesh "a single global size and different local
//! geometric sizes". This module is the geometric form of both: the places a montage looks at
//! (the cameras' centres and the planned objects' box, [`Grading::focus_in_world_m`]) keep the
//! global size, and beyond the distance at which an element of the global edge E subtends the
//! angle θ seen from the nearest of them, every size of the mesh (patch, element, an object's
//! own, the refinement floor) grows in proportion to the distance:
//!
//! g = max(1, d · tan θ / E),
//!
//! d the distance from the node's bounding box to the nearest focus box. An element far out
//! then subtends about θ from the nearest focus, as one of edge E does at d = E / tan θ. Near the
//! focus (d ≤ E / tan θ) the mesh is the ungraded one, node for node.
//!
//! # Known limitations
//! Distance is a proxy for importance: a large bright surface far from every camera (a sunlit
//! hillside facing the planned building) is meshed as coarsely as a dark one. Its light still
//! reaches the focus through the form factors of its coarse elements, which are exact for their
//! average radiosity; only the variation within an element is lost.

use nalgebra::Point3;

use super::{RadiosityError, check_positive};

/// How sizes grow away from the focus (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Grading {
    /// The boxes (minimum and maximum corner, world metres) the mesh keeps its sizes around: a
    /// camera centre is a box of zero size.
    pub focus_in_world_m: Vec<[Point3<f64>; 2]>,
    /// tan θ: beyond the focus an element subtends at most about θ seen from the nearest focus.
    pub tan_angle: f64,
}

impl Grading {
    /// A grading around `focus_in_world_m` (boxes as [`Grading::focus_in_world_m`]); `None` when
    /// there is no focus.
    #[must_use]
    pub fn around(focus_in_world_m: Vec<[Point3<f64>; 2]>, tan_angle: f64) -> Option<Self> {
        (!focus_in_world_m.is_empty()).then_some(Self {
            focus_in_world_m,
            tan_angle,
        })
    }

    /// Checks the angle and the focus boxes.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] for a non-positive angle, no focus, or a focus box
    /// with a non-finite or inverted corner.
    pub fn validate(&self) -> Result<(), RadiosityError> {
        check_positive("grading.tan_angle", self.tan_angle)?;
        #[allow(clippy::cast_precision_loss)]
        let count = self.focus_in_world_m.len() as f64;
        if count == 0.0 {
            return Err(RadiosityError::InvalidParameter {
                name: "grading.focus_in_world_m",
                value: count,
                reason: "needs at least one focus box",
            });
        }
        for [lo, hi] in &self.focus_in_world_m {
            if let Some(&value) = lo.iter().chain(hi.iter()).find(|c| !c.is_finite()) {
                return Err(RadiosityError::InvalidParameter {
                    name: "grading.focus_in_world_m",
                    value,
                    reason: "a focus box corner must be finite",
                });
            }
            if let Some((a, _)) = lo.iter().zip(hi.iter()).find(|(a, b)| a > b) {
                return Err(RadiosityError::InvalidParameter {
                    name: "grading.focus_in_world_m",
                    value: *a,
                    reason: "a focus box's minimum corner must not pass its maximum",
                });
            }
        }
        Ok(())
    }

    /// The factor g ≥ 1 by which sizes grow at the triangle `v` (module doc), for the global
    /// element edge `edge_m`.
    #[must_use]
    pub fn factor(&self, v: &[Point3<f64>; 3], edge_m: f64) -> f64 {
        let lo = v[0].inf(&v[1]).inf(&v[2]);
        let hi = v[0].sup(&v[1]).sup(&v[2]);
        let d = self
            .focus_in_world_m
            .iter()
            .map(|[f_lo, f_hi]| box_distance_m(&lo, &hi, f_lo, f_hi))
            .fold(f64::INFINITY, f64::min);
        (d * self.tan_angle / edge_m).max(1.0)
    }
}

/// Distance between two axis-aligned boxes, metres (0 where they overlap).
fn box_distance_m(
    a_lo: &Point3<f64>,
    a_hi: &Point3<f64>,
    b_lo: &Point3<f64>,
    b_hi: &Point3<f64>,
) -> f64 {
    (0..3)
        .map(|k| {
            let gap = (b_lo[k] - a_hi[k]).max(a_lo[k] - b_hi[k]).max(0.0);
            gap * gap
        })
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::mesh::{Mesh, MeshParams, longest_edge_m};
    use crate::radiosity::test_scenes;

    /// Near the focus the graded mesh is the ungraded one node for node; far out its elements
    /// are as coarse as the grading allows and no coarser, and there are far fewer of them.
    #[test]
    fn a_graded_mesh_keeps_the_focus_and_coarsens_with_distance() {
        let scene = test_scenes::kilometre_site();
        let ungraded = MeshParams {
            max_patch_edge_m: 32.0,
            max_element_edge_m: 8.0,
            ..MeshParams::default()
        };
        let focus = [Point3::new(-10.0, -10.0, 0.0), Point3::new(10.0, 10.0, 8.0)];
        let tan = 0.1;
        let graded = MeshParams {
            grading: Grading::around(vec![focus, [Point3::new(0.0, -40.0, 1.6); 2]], tan),
            ..ungraded.clone()
        };
        let flat = Mesh::build(&scene, &ungraded).unwrap();
        let mesh = Mesh::build(&scene, &graded).unwrap();
        let grading = graded.grading.as_ref().unwrap();
        let node = |m: &Mesh, e: u32| m.nodes[e as usize].vertices_in_world_m;
        // Every element of the ungraded mesh within E / tan θ = 80 m of the focus is an
        // element of the graded one, with the same vertices bit for bit.
        let near: Vec<[Point3<f64>; 3]> = flat
            .elements
            .iter()
            .map(|&e| node(&flat, e))
            .filter(|v| (grading.factor(v, 8.0) - 1.0).abs() < f64::EPSILON)
            .collect();
        let graded_elements: Vec<[Point3<f64>; 3]> =
            mesh.elements.iter().map(|&e| node(&mesh, e)).collect();
        assert!(near.len() > 100, "{}", near.len());
        for v in &near {
            assert!(graded_elements.contains(v), "{v:?} lost near the focus");
        }
        // Every element is within its graded size, and its parent was not (no element is
        // split further than the grading asks): the ground's nodes halve a 1414 m edge.
        let mut parent_of = vec![None; mesh.nodes.len()];
        for (id, n) in mesh.nodes.iter().enumerate() {
            for c in n.children.into_iter().flatten() {
                parent_of[c as usize] = Some(id);
            }
        }
        for (&e, v) in mesh.elements.iter().zip(&graded_elements) {
            let g = grading.factor(v, 8.0);
            let edge = longest_edge_m(v);
            assert!(edge <= 8.0 * g * (1.0 + 1e-9), "{edge} m at g = {g}");
            if let Some(parent) = parent_of[e as usize].map(|p| &mesh.nodes[p]) {
                let gp = grading.factor(&parent.vertices_in_world_m, 8.0);
                assert!(
                    longest_edge_m(&parent.vertices_in_world_m) > 8.0 * gp,
                    "over-split"
                );
            }
        }
        // Patches tile every scene triangle: each element has exactly one patch above it (or
        // is one), and the areas add up.
        let mut patches_above = vec![0_u32; mesh.nodes.len()];
        let mut stack: Vec<u32> = mesh.patches.clone();
        while let Some(n) = stack.pop() {
            patches_above[n as usize] += 1;
            stack.extend(mesh.nodes[n as usize].children.into_iter().flatten());
        }
        assert!(
            mesh.elements
                .iter()
                .all(|&e| patches_above[e as usize] == 1)
        );
        let area = |m: &Mesh, ids: &[u32]| ids.iter().map(|&i| m.nodes[i as usize].area_m2).sum();
        let total: f64 = area(&mesh, &mesh.elements);
        let patches: f64 = area(&mesh, &mesh.patches);
        assert!(
            (total - patches).abs() < 1e-9 * total,
            "{total} vs {patches}"
        );
        assert!((total - flat.total_area_m2()).abs() < 1e-9 * total);
        // The far ground: 8 m elements over a 1 km square would be 131 072 triangles.
        assert!(flat.elements.len() > 130_000, "{}", flat.elements.len());
        assert!(mesh.elements.len() < 20_000, "{}", mesh.elements.len());
    }

    /// A graded mesh past the element budget is refused, as an ungraded one, without building
    /// the ungraded mesh first.
    #[test]
    fn a_graded_mesh_past_the_budget_is_refused() {
        let scene = test_scenes::kilometre_site();
        let params = MeshParams {
            max_patch_edge_m: 4.0,
            max_element_edge_m: 0.05,
            max_elements: 5_000,
            grading: Grading::around(vec![[Point3::new(0.0, 0.0, 0.0); 2]], 0.01),
            ..MeshParams::default()
        };
        let err = Mesh::build(&scene, &params).unwrap_err();
        assert!(
            matches!(
                err,
                crate::radiosity::RadiosityError::TooManyElements { .. }
            ),
            "{err}"
        );
        let bad = MeshParams {
            grading: Grading::around(vec![[Point3::new(0.0, 0.0, 0.0); 2]], -1.0),
            ..MeshParams::default()
        };
        assert!(
            Mesh::build(&scene, &bad)
                .unwrap_err()
                .to_string()
                .contains("tan_angle")
        );
    }

    #[test]
    fn the_factor_is_one_near_the_focus_and_grows_with_distance() {
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let grading = Grading::around(
            vec![
                [p(0.0, 0.0, 0.0), p(10.0, 10.0, 10.0)],
                [p(100.0, 0.0, 0.0); 2],
            ],
            0.1,
        )
        .unwrap();
        grading.validate().unwrap();
        // A triangle touching the first box: distance 0.
        let near = [p(10.0, 5.0, 0.0), p(20.0, 5.0, 0.0), p(15.0, 8.0, 0.0)];
        assert!((grading.factor(&near, 2.0) - 1.0).abs() < f64::EPSILON);
        // 30 m beyond the box in x and 40 m below it: d = 50 m, g = 50·0.1/2 = 2.5.
        let far = [
            p(40.0, 5.0, -40.0),
            p(45.0, 5.0, -40.0),
            p(42.0, 6.0, -45.0),
        ];
        assert!((grading.factor(&far, 2.0) - 2.5).abs() < 1e-12);
        // The nearest focus counts: this one is 70 m from the box, 10 m from the camera at
        // x = 100: g = 10·0.1/0.5 = 2.
        let by_camera = [p(80.0, 0.0, 0.0), p(90.0, 0.0, 0.0), p(85.0, -1.0, 0.0)];
        assert!((grading.factor(&by_camera, 0.5) - 2.0).abs() < 1e-12);
        // Inside the distance E / tan θ = 20 m: ungraded.
        let inside = [p(25.0, 0.0, 0.0), p(26.0, 0.0, 0.0), p(25.0, 1.0, 0.0)];
        assert!((grading.factor(&inside, 2.0) - 1.0).abs() < f64::EPSILON);
    }

    #[test]
    fn bad_gradings_are_named() {
        let p = Point3::new(0.0, 0.0, 0.0);
        assert!(Grading::around(Vec::new(), 0.1).is_none());
        let zero = Grading::around(vec![[p; 2]], 0.0).unwrap();
        assert!(
            zero.validate()
                .unwrap_err()
                .to_string()
                .contains("tan_angle")
        );
        let inverted = Grading::around(vec![[Point3::new(1.0, 0.0, 0.0), p]], 0.1).unwrap();
        let err = inverted.validate().unwrap_err().to_string();
        assert!(err.contains("focus"), "{err}");
        let nan = Grading::around(vec![[p, Point3::new(f64::NAN, 0.0, 0.0)]], 0.1).unwrap();
        assert!(nan.validate().is_err());
    }
}
