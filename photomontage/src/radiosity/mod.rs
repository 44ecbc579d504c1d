//! Diffuse radiosity on the scene: meshing, form factors with visibility, progressive and
//! hierarchical solvers, and light groups for the sun, the sky and emitting materials.
//!
//! Sources: Goral et al. 1984 (the radiosity equation B = E + ρ F B, as quoted by Tonn & Donath,
//! seed 000 eq. 1); Cohen & Wallace 1993 (seed 002), ch. 4 (form factors: Lambert's contour
//! integral for a point to a polygon, ray-cast visibility after Wallace, Elmquist & Haines 1989),
//! ch. 5 (Jacobi, Gauss–Seidel and Southwell / progressive refinement, Cohen et al. 1988) and
//! ch. 7 (hierarchical radiosity, Hanrahan, Salzman & Aupperle 1991, with BF refinement); Tonn &
//! Donath (seed 000, "Generation of patches": one global patch size plus per-object sizes, sky as
//! hierarchical dome sources, geometry computed once and lighting applied per group); Üncü &
//! Kayakuş (seed 004): iterate until the mean brightness changes by less than 1 % between passes.
//!
//! Layering: this module sits between `scene`/`bvh` and `render`; it imports the scene, the BVH
//! (through [`crate::scene::SceneTracer`]), the sky models and domes, and nothing above.
//!
//! Units: radiosity B is exitance (W/m² or the site's linear units per m²), B = π·L for a
//! Lambertian surface; irradiance E is in the same units; a group's initial exitance is
//! B₀ = ρ·E_direct + π·L_emitted.
//!
//! Pipeline: [`mesh::Mesh::build`] cuts scene triangles into patches (the hierarchy roots) and
//! elements (its leaves); [`sources`] computes each light group's direct irradiance per element
//! with shadow rays; [`progressive`] or [`hierarchical`] solves the interreflection; each group
//! keeps its own solution, so groups add linearly (`Solution::total_radiosity_rgb`).
//! [`transfer::Transfer`] keeps the geometry-dependent part (mesh, links, ground transfer) and
//! relights it (sun, sky, dimming, reflectance) without recomputing form factors;
//! [`query`] interpolates irradiance at any surface point, with a final gather where the mesh
//! is coarse; [`vertex_gather`] gathers the interreflected light at element vertices for the
//! renderer's radiosity mode (hit lists traced once, re-summed for any exitances).
//!
//! # Known limitations
//! Surfaces are one-sided (front = counter-clockwise normal) and Lambertian: specular, glass and
//! water materials are treated by their diffuse reflectance only. Elements are midpoint 1→4
//! splits to the element size, split further only where a sun shadow edge crosses them
//! ([`shadow_refinement`], when asked for); there is no discontinuity meshing, and otherwise the
//! adaptivity is the hierarchical solver's (links at coarser levels where the transfer is small).
//! The renderer uses the solution only in its opt-in radiosity lighting mode
//! (`render::differential::radiosity_light`). The solver is RGB; a spectral render solves it once
//! per spectral pass of three samples (`site::spectral_radiosity`). Luminaires are point
//! sources. [`transfer`] relights on the links refined for the lighting it was built with.

pub mod city_block;
pub mod convergence;
pub mod convergence_plot;
pub mod corner_refinement;
pub mod covered;
pub mod direct;
mod element_grid;
mod element_lookup;
pub mod element_reflectance;
pub mod form_factor;
#[cfg(target_arch = "x86_64")]
mod gather_avx2;
pub mod hierarchical;
pub mod mesh;
pub mod mesh_grading;
pub mod mesh_sizing;
pub mod progressive;
pub mod query;
pub mod shadow_refinement;
mod shooting;
mod sky_transfer;
mod solve;
mod source_rows;
pub mod sources;
pub mod sun_rays;
mod surface_point;
mod sweeps;
mod topology;
pub mod transfer;
pub mod transfer_lighting;
pub mod twin;
mod twin_factors;
pub mod vertex_gather;

#[cfg(test)]
mod corner_refinement_tests;
#[cfg(test)]
mod form_factor_tests;
#[cfg(test)]
mod material_table_tests;
#[cfg(test)]
mod peer_tests;
#[cfg(test)]
mod radiance_tests;
#[cfg(test)]
mod relight_drift_tests;
#[cfg(test)]
mod shadow_refinement_tests;
#[cfg(test)]
mod solver_tests;
#[cfg(test)]
pub(crate) mod test_scenes;
#[cfg(test)]
mod transfer_tests;
#[cfg(test)]
mod twin_factors_tests;
#[cfg(test)]
mod twin_tests;

pub use convergence::{ConvergenceRow, StopRule};
pub use form_factor::FormFactorParams;
pub use mesh::{Mesh, MeshParams, MeshWarning, Refinement};
pub use query::{IrradianceSample, PointOnElement, QueryParams, QueryPoint, parse_query_points};
pub use sky_transfer::SkyRays;
pub use solve::{
    GroupSolution, LightGroup, RadiosityDifference, Refit, SkyLight, Solution, SolveParams, Solver,
    solve, solve_on_mesh, solve_on_mesh_refitting, solve_on_mesh_twinned, sun_directions,
};
pub use sources::{DistantSource, GroundBelowHorizon, LightWarning, PointSource};
pub use transfer::{
    LightingChange, MaterialTableReport, NamedLuminaire, PreparedRelight, RELIGHT_L1_REL_TOL,
    RELIGHT_MEAN_REL_TOL, RelightStrategy, Sky, Sun, Sweep, Transfer, TransferLighting,
    TransferParams,
};
pub use vertex_gather::{GatheredExitance, VertexGather};

/// RGB triple (linear).
pub type Rgb = [f64; 3];

/// Rec. 709 luminance weights, the "brightness" of the stop rule (ITU-R BT.709 item 3.2).
pub const LUMINANCE_WEIGHTS: Rgb = [0.2126, 0.7152, 0.0722];

/// Luminance of a linear RGB triple.
#[must_use]
pub fn luminance(rgb: &Rgb) -> f64 {
    rgb[0] * LUMINANCE_WEIGHTS[0] + rgb[1] * LUMINANCE_WEIGHTS[1] + rgb[2] * LUMINANCE_WEIGHTS[2]
}

/// Errors of the radiosity module.
#[derive(Debug, thiserror::Error)]
pub enum RadiosityError {
    /// Nothing to solve on.
    #[error("the scene has no patches to solve radiosity on{reason}")]
    NoPatches {
        /// Why (e.g. every triangle degenerate), with a leading separator, or empty.
        reason: String,
    },
    /// A tunable outside its range.
    #[error("radiosity parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// The accepted range.
        reason: &'static str,
    },
    /// A per-object size names an object the scene does not have.
    #[error("element size given for object `{object}`, which is not in the scene")]
    UnknownObject {
        /// The name given.
        object: String,
    },
    /// The mesh would exceed the element budget.
    #[error("meshing gives more than {limit} elements (object `{object}`); raise the element size")]
    TooManyElements {
        /// The budget.
        limit: usize,
        /// The object being meshed when the budget ran out.
        object: String,
    },
    /// A row of a points file is unusable.
    #[error("points file line {line}: {message}")]
    PointsRow {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A lighting change names a material the scene does not have.
    #[error("material `{material}` is not in the scene")]
    UnknownMaterial {
        /// The name given.
        material: String,
    },
    /// A per-element reflectance ([`Mesh::set_element_reflectances`]) that is unusable.
    #[error("element {element} (object `{object}`): reflectance {reason}")]
    ElementReflectance {
        /// Element index.
        element: usize,
        /// Its object's name.
        object: String,
        /// What is wrong.
        reason: String,
    },
    /// A light source with a non-finite or negative value.
    #[error("light group `{group}`: {reason}")]
    InvalidSource {
        /// Group name.
        group: String,
        /// What is wrong.
        reason: String,
    },
    /// The scene could not be prepared for ray casting.
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// The sky dome failed.
    #[error(transparent)]
    Dome(#[from] crate::sky_dome::DomeError),
    /// The caller's cancel flag was raised.
    #[error("the radiosity solve was cancelled")]
    Cancelled,
    /// Writing an output failed.
    #[error("writing {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
}

pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), RadiosityError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(RadiosityError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        })
    }
}
