//! Element sizes fitted to a scene: an object whose area would need more than
//! [`OBJECT_ELEMENT_BUDGET`] elements at the requested element edge gets a local size of its own
//! (Tonn & Donath's per-object sizes, seed 000, chosen for the user), so that a site with a 1 km
//! ground meshes at 1 m on its buildings instead of refusing with "more than 200 000 elements".
//! Sizes the user gave for an object are kept. `photomontage radiosity`, `irradiance` and
//! `elevation --irradiance` and the studio's irradiance elevation use it; the renderer's
//! radiosity mode sizes the whole site by its own budget instead (`site::render_radiosity`).
//!
//! The element count of an object at edge e is the mesher's own: a triangle whose longest edge is
//! L is split 1→4 at its edge midpoints until its edges are at most e, into 4^⌈log₂(L/e)⌉
//! elements. The object's own edge is the smallest of e·1.05^k that keeps its count within the
//! budget.

use super::mesh::MeshParams;
use crate::scene::Scene;

/// Most elements one object gets at the requested element edge before its own edge is raised.
pub const OBJECT_ELEMENT_BUDGET: f64 = 50_000.0;

/// Step between the element edges tried, as a factor.
const EDGE_STEP: f64 = 1.05;

/// The elements of triangles with longest edges `longest_m` at element edge `edge_m` (module
/// doc).
fn elements(longest_m: &[f64], edge_m: f64) -> f64 {
    longest_m
        .iter()
        .map(|&l| {
            let splits = (l / edge_m).log2().ceil().max(0.0);
            4.0_f64.powf(splits)
        })
        .sum()
}

impl MeshParams {
    /// These parameters with an element edge of its own for every object of `scene` that would
    /// pass [`OBJECT_ELEMENT_BUDGET`] (module doc), and a note per object so sized naming the
    /// size and how to set another.
    #[must_use]
    pub fn sized_for(&self, scene: &Scene) -> (Self, Vec<String>) {
        let mut longest_m: Vec<Vec<f64>> = vec![Vec::new(); scene.objects().len()];
        for t in scene.triangles() {
            let [a, b, c] = t.vertices_in_world_m;
            let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
            if let Some(list) = longest_m.get_mut(t.object.0 as usize)
                && longest.is_finite()
            {
                list.push(longest);
            }
        }
        let mut out = self.clone();
        let mut notes = Vec::new();
        for (object, longest) in scene.objects().iter().zip(longest_m) {
            if self.object_element_edge_m.contains_key(&object.name) {
                continue;
            }
            let edge_m = self.max_element_edge_m;
            let count = elements(&longest, edge_m);
            if edge_m <= 0.0 || edge_m.is_nan() || count <= OBJECT_ELEMENT_BUDGET {
                continue;
            }
            let mut own_m = edge_m;
            while elements(&longest, own_m) > OBJECT_ELEMENT_BUDGET {
                own_m *= EDGE_STEP;
            }
            // Rounded up to the centimetre, so that the note gives the size used.
            let own_m = (own_m * 100.0).ceil() / 100.0;
            notes.push(format!(
                "object `{}`: element edge {own_m:.2} m instead of {edge_m} m ({:.0} elements \
                 instead of {count:.0}; --object-element-edge {}=M sets another)",
                object.name,
                elements(&longest, own_m),
                object.name
            ));
            out.object_element_edge_m.insert(object.name.clone(), own_m);
            // Patches as many elements across as the global sizes make them.
            let ratio = (self.max_patch_edge_m / edge_m).max(1.0);
            out.object_patch_edge_m
                .insert(object.name.clone(), own_m * ratio);
        }
        (out, notes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::mesh::Mesh;
    use crate::radiosity::test_scenes;
    use nalgebra::Point3;

    /// The 1 km ground of a site at 1 m would be 4 million elements and the mesh is refused; the
    /// sized parameters give it its own edge, keep the house at 1 m, and mesh within budget.
    #[test]
    fn a_large_ground_gets_its_own_edge_and_the_mesh_fits() {
        let scene = test_scenes::kilometre_site();
        let params = MeshParams::default();
        assert!(
            Mesh::build(&scene, &params).is_err(),
            "the 1 m mesh is refused"
        );
        let (sized, notes) = params.sized_for(&scene);
        let ground_m = sized.object_element_edge_m["ground"];
        // The ground's two triangles have a 1414 m hypotenuse: 7 splits (2 · 4⁷ = 32 768
        // elements) need an edge of 1414/2⁷ = 11.05 m; 8 would be 131 072. The first step of
        // 1.05 past 11.05 m: 1.05^50 = 11.47.
        assert!((11.05..11.7).contains(&ground_m), "{ground_m}");
        assert!(!sized.object_element_edge_m.contains_key("house"));
        // Its patches stay 4 elements across, as the global 4 m / 1 m.
        assert!((sized.object_patch_edge_m["ground"] - 4.0 * ground_m).abs() < 1e-9);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("`ground`") && notes[0].contains("32768 elements"),
            "{notes:?}"
        );
        let mesh = Mesh::build(&scene, &sized).expect("fits the budget");
        let ground_elements = (0..mesh.elements.len())
            .filter(|&e| mesh.object_name(mesh.elements[e] as usize) == "ground")
            .count();
        #[allow(clippy::cast_precision_loss)]
        let count = ground_elements as f64;
        assert!(count <= OBJECT_ELEMENT_BUDGET, "{ground_elements}");
        assert_eq!(ground_elements, 32_768);
        let ground_patches = mesh
            .patches
            .iter()
            .filter(|&&p| mesh.object_name(p as usize) == "ground")
            .count();
        assert_eq!(
            ground_patches,
            2 * 4_usize.pow(5),
            "patches 4 elements across"
        );
        // A size the user gave is kept, whatever the budget says.
        let mut own = MeshParams::default();
        own.object_element_edge_m.insert("ground".into(), 40.0);
        let (kept, notes) = own.sized_for(&scene);
        assert!((kept.object_element_edge_m["ground"] - 40.0).abs() < f64::EPSILON);
        assert!(notes.is_empty());
        // A small scene is left as it is.
        let mut small = Scene::new();
        test_scenes::add(
            &mut small,
            "house",
            test_scenes::block(Point3::new(0.0, 0.0, 0.0), Point3::new(5.0, 5.0, 5.0)),
            test_scenes::grey("white", 0.6),
        );
        assert_eq!(params.sized_for(&small), (params.clone(), Vec::new()));
    }
}
