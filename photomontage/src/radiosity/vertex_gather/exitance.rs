//! The exitances a mesh's vertex gathers sum, with each vertex's sum kept once made.

use std::sync::{Arc, OnceLock};

use super::VertexGather;
use crate::radiosity::{RadiosityError, Rgb};

/// The vertex gathers of one mesh with the exitance per element they sum, each vertex's sum
/// kept once made: a render reads a vertex from every shading point of its elements, and the sum
/// runs over up to one element per gather ray. Made anew for every solution (a relight), so a
/// kept sum never belongs to other exitances; the gathers' rays are shared.
#[derive(Debug, Clone)]
pub struct GatheredExitance {
    gather: Arc<VertexGather>,
    radiosity_rgb: Vec<Rgb>,
    per_vertex: OnceLock<Box<[OnceLock<Rgb>]>>,
}

impl GatheredExitance {
    /// The gathers `gather` summing `radiosity_rgb`, the exitance per element of its mesh
    /// (every group's direct light in, as solved).
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] when `radiosity_rgb` has not one value per element.
    pub fn new(gather: Arc<VertexGather>, radiosity_rgb: Vec<Rgb>) -> Result<Self, RadiosityError> {
        if radiosity_rgb.len() != gather.mesh.elements.len() {
            #[allow(clippy::cast_precision_loss)]
            return Err(RadiosityError::InvalidParameter {
                name: "exitance values",
                value: radiosity_rgb.len() as f64,
                reason: "must be one per element of the gathers' mesh",
            });
        }
        Ok(Self {
            gather,
            radiosity_rgb,
            per_vertex: OnceLock::new(),
        })
    }

    /// The vertex gathers.
    #[must_use]
    pub fn gather(&self) -> &Arc<VertexGather> {
        &self.gather
    }

    /// Interreflected irradiance at the point of element `element` with barycentric weights
    /// `weights` (of its vertices).
    #[must_use]
    pub fn indirect_rgb(&self, element: usize, weights: [f64; 3]) -> Rgb {
        let g = &*self.gather;
        let per_vertex = self
            .per_vertex
            .get_or_init(|| (0..g.vertex_count()).map(|_| OnceLock::new()).collect());
        let mut out = [0.0; 3];
        for (k, &v) in g.element_vertices[element].iter().enumerate() {
            let v = v as usize;
            let e = per_vertex[v].get_or_init(|| g.vertex_indirect_rgb(v, &self.radiosity_rgb));
            for c in 0..3 {
                out[c] += weights[k] * e[c];
            }
        }
        out
    }
}
