//! The node topology of a radiosity mesh for iterative push–pull: each node's parent and area
//! fraction, each patch's subtree range and the element areas (used by the relights of
//! [`super::transfer`] and [`super::shooting`]).

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
    /// Per element, its mesh surface.
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
        let patch_ranges = mesh
            .patches
            .iter()
            .map(|&p| (p as usize, last[p as usize] + 1))
            .collect();
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
            element_surface: (0..mesh.elements.len())
                .map(|e| mesh.element_node(e).surface)
                .collect(),
        }
    }
}
