//! The node topology of a radiosity mesh for iterative push–pull: each node's parent and area
//! fraction, each patch's subtree range and the element areas (used by the relights of
//! [`super::transfer`] and [`super::shooting`]).

use super::Rgb;
use super::mesh::Mesh;

/// Node topology for iterative push–pull (nodes are in pre-order per scene triangle).
#[derive(Debug, Clone)]
pub(super) struct Topology {
    /// Parent node, `u32::MAX` for a scene triangle's root.
    pub(super) parent: Vec<u32>,
    /// Area of a node over its parent's.
    pub(super) weight: Vec<f64>,
    /// Per patch, its subtree's node range.
    pub(super) patch_ranges: Vec<(usize, usize)>,
    /// Element areas, m².
    pub(super) areas: Vec<f64>,
    /// Per node, its element (leaves) — the mesh's `element` and `children`, kept compact so
    /// that sweeps over all nodes read 4 and 16 bytes per node, not a whole mesh node.
    pub(super) element: Vec<Option<u32>>,
    /// Per node, its children.
    pub(super) children: Vec<Option<[u32; 4]>>,
    /// Per patch, its elements' range: the mesh numbers elements depth first, so each patch's
    /// elements are contiguous and the patches' ranges follow one another in patch order.
    pub(super) patch_elements: Vec<(usize, usize)>,
    /// Per element, its mesh surface (the reflectance and emission it takes when no
    /// per-element value is set), so that a relight reads 4 bytes per element, not a mesh node.
    pub(super) element_surface: Vec<u32>,
}

impl Topology {
    pub(super) fn new(mesh: &Mesh) -> Self {
        let n = mesh.nodes.len();
        let mut parent = vec![u32::MAX; n];
        let mut weight = vec![1.0; n];
        for (p, node) in mesh.nodes.iter().enumerate() {
            if let Some(kids) = node.children {
                for k in kids {
                    #[allow(clippy::cast_possible_truncation)] // node ids are u32
                    {
                        parent[k as usize] = p as u32;
                    }
                    weight[k as usize] = mesh.nodes[k as usize].area_m2 / node.area_m2;
                }
            }
        }
        let mut last = (0..n).collect::<Vec<usize>>();
        for i in (0..n).rev() {
            if let Some(kids) = mesh.nodes[i].children {
                last[i] = kids.iter().map(|&k| last[k as usize]).max().unwrap_or(i);
            }
        }
        let patch_ranges: Vec<(usize, usize)> = mesh
            .patches
            .iter()
            .map(|&p| (p as usize, last[p as usize] + 1))
            .collect();
        let mut patch_elements: Vec<(usize, usize)> = Vec::with_capacity(mesh.patches.len());
        for &(lo, hi) in &patch_ranges {
            let at = patch_elements.last().map_or(0, |r| r.1);
            let count = (lo..hi)
                .filter(|&n| mesh.nodes[n].element.is_some())
                .count();
            patch_elements.push((at, at + count));
        }
        for (&(lo, hi), &(elo, _)) in patch_ranges.iter().zip(&patch_elements) {
            let mut e = elo;
            for n in lo..hi {
                if let Some(el) = mesh.nodes[n].element {
                    assert_eq!(el as usize, e, "mesh elements are numbered depth first");
                    e += 1;
                }
            }
        }
        assert_eq!(
            patch_elements.last().map_or(0, |r| r.1),
            mesh.elements.len(),
            "every element lies in a patch"
        );
        assert!(
            patch_ranges.windows(2).all(|w| w[0].1 <= w[1].0),
            "patches follow one another in node order"
        );
        let areas = (0..mesh.elements.len())
            .map(|e| mesh.element_node(e).area_m2)
            .collect();
        Self {
            parent,
            weight,
            patch_ranges,
            areas,
            element: mesh.nodes.iter().map(|node| node.element).collect(),
            children: mesh.nodes.iter().map(|node| node.children).collect(),
            patch_elements,
            element_surface: (0..mesh.elements.len())
                .map(|e| mesh.element_node(e).surface)
                .collect(),
        }
    }

    /// ρ_d per element of `mesh` (which has this topology's geometry): a per-element value
    /// where one is set ([`Mesh::set_element_reflectances`]), else its surface's — the same
    /// values as [`Mesh::element_reflectance_rgb`], without reading the mesh nodes.
    pub(super) fn element_reflectances(&self, mesh: &Mesh) -> Vec<Rgb> {
        let own = mesh.node_reflectance_rgb.as_deref();
        self.element_surface
            .iter()
            .zip(&mesh.elements)
            .map(|(&s, &n)| {
                own.and_then(|r| r[n as usize])
                    .unwrap_or(mesh.surfaces[s as usize].reflectance_rgb)
            })
            .collect()
    }

    /// Emitted exitance π·L_e per element of `mesh` (its surface's).
    pub(super) fn element_emissions(&self, mesh: &Mesh) -> Vec<Rgb> {
        self.element_surface
            .iter()
            .map(|&s| mesh.surfaces[s as usize].emission_rgb)
            .collect()
    }
}
