//! Precomputed transfer and relighting (Tonn & Donath, seed 000: "the geometry-dependent part of
//! the radiosity solution is calculated once … the lighting situation [sun position, sky type,
//! artificial lights, materials] can then be changed interactively").
//!
//! [`Transfer::build`] does everything that depends on the geometry once: the mesh, the BVH, the
//! hierarchical links with their form factors (Hanrahan, Salzman & Aupperle 1991, refined for the
//! lighting it was built with), the ground-below-horizon transfer, and one solution per light
//! group (sun, sky, each luminaire, the emitting materials). [`Transfer::relight`] then applies a
//! [`LightingChange`] without computing a single form factor:
//!
//! - **Scalings** (the sun's normal irradiance with its direction unchanged, the sky's weights
//!   with its type unchanged, a luminaire's dimming): the group's response is linear in its
//!   sources, so with [`RelightStrategy::LinearResponses`] its direct irradiance and radiosity
//!   are multiplied by the ratio, per channel, exactly and in O(elements).
//! - **A sun move** re-traces only the sun's shadow rays (the same sample points and random
//!   streams as [`super::solve`], so the direct term is the re-solve's bit for bit; the points
//!   of the sun and sky groups are drawn once at build and kept) and then
//!   iterates the sun group on the stored links; a sky whose luminance follows the sun (CIE
//!   general skies, Perez) changes as well.
//! - **A sky change** (type, or one that follows the sun) traces nothing: the build keeps each
//!   element's visibility of every dome facet (≈ 9°, module `sky_transfer`), so the sky's direct
//!   light is a sum over facets per element; the dome is re-clustered (under a millisecond) for
//!   the ground below the horizon and for point queries.
//! - **A material's reflectance** changes ρ on its elements; every group is iterated again.
//!
//! Iterations start warm: B_start = B₀′ + (ρ′/ρ)·(B − B₀) per element, i.e. the previous
//! interreflected part carried over (scaled by the ratio of the group's sources under
//! `LinearResponses`), and run Gauss–Seidel sweeps (patch by patch, sequential), Jacobi sweeps
//! (parallel) or ΔB shooting (only the difference from the old solution is passed on, through
//! the links by source, with what the group's last shooting left unshot; the default) on the
//! stored links ([`Sweep`]) until the stop rule holds, its mean-change test measured from the
//! warm start. [`RelightStrategy::WarmGaussSeidel`] is
//! the first way: every change, scalings included, re-iterates the groups it touches from
//! their previous solution. All are measured in docs/benchmarks.md.
//!
//! Links are stored as compressed rows per receiver node with `f32` factors (the factors'
//! Monte Carlo error is ~1e-2, their rounding 6e-8); sweeps visit receivers in a fixed order,
//! so relit solutions are bit-identical on any number of threads.
//!
//! # Known limitations
//! The links keep the refinement made for the build's lighting: a sun moved far from where it
//! was is solved on links refined for the old shadows (BF refinement is not redone; a full
//! [`super::solve`] would refine differently, within the BF tolerance). Emission and geometry
//! cannot change (a new scene needs a new transfer). The sky's visibility is resolved per
//! facet, not per cluster of the current sky (module `sky_transfer`).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use super::convergence::ConvergenceRow;
use super::form_factor::FormFactorEngine;
use super::hierarchical::{Hierarchy, Link};
use super::mesh::Mesh;
use super::shooting::{Leaves, ShootScratch, ShotGroup, shoot};
use super::sky_transfer::{SkyRays, SkyTransfer};
use super::solve::{
    GroundTerm, group_direct, initial_exitance, initial_exitance_from, sun_directions,
};
use super::source_rows::SourceRows;
use super::sources::{self, DirectSamples, LightWarning};
use super::sun_rays::{SunCounts, sun_counts as sun_counts_of};
pub use super::sweeps::Sweep;
use super::sweeps::{LinkRows, iterate};
use super::topology::Topology;
use super::transfer_lighting::check_rgb;
pub use super::transfer_lighting::{LightingChange, NamedLuminaire, Sky, Sun, TransferLighting};
use super::twin::{Twin, twin_elements};
use super::twin_factors::{FactorReuse, NaturalFactors};
use super::{GroupSolution, LightGroup, RadiosityError, Rgb, Solution, SolveParams, Solver};
use crate::bvh::BuildQuality;
use crate::scene::{Scene, SceneTracer};
use crate::sky::SkyModel;
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// How close a relit solution is to a fresh solve of the new lighting
/// ([`Solution::relative_difference`]), as the transfer's tests check it: the relight keeps the
/// links refined for the build's lighting, a fresh solve refines for the new lighting, each
/// within the BF tolerance 0.002 × mean; the interreflected part differs by ≈ 1 %, the total
/// (direct identical) by less, so 2 % bounds the area-weighted L1 difference.
pub const RELIGHT_L1_REL_TOL: f64 = 0.02;
/// The mean brightness of a relit solution against a fresh solve: within the stop rule's 1 %.
pub const RELIGHT_MEAN_REL_TOL: f64 = 0.01;

/// How a relight re-solves (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RelightStrategy {
    /// Every touched group is iterated from its previous solution.
    WarmGaussSeidel,
    /// Scalings are exact multiplications; only re-traced groups and material changes iterate.
    LinearResponses,
}

/// Transfer tunables.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferParams {
    /// Mesh, form factors, stop rule, ground; the solver must be hierarchical.
    pub solve: SolveParams,
    /// Clustering tolerance of the sky dome ([`sources::sky_sources`]).
    pub sky_tolerance: f64,
    /// How relights re-solve.
    pub strategy: RelightStrategy,
    /// The sweep of relight iterations.
    pub sweep: Sweep,
}

impl Default for TransferParams {
    /// Default solve parameters (hierarchical), sky tolerance 0.1, linear responses with ΔB
    /// shooting (the fastest pair measured in docs/benchmarks.md).
    fn default() -> Self {
        Self {
            solve: SolveParams::default(),
            sky_tolerance: 0.1,
            strategy: RelightStrategy::LinearResponses,
            sweep: Sweep::Shooting,
        }
    }
}

/// Which light a group stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GroupKind {
    Sun,
    Sky,
    Luminaire(usize),
    Emitters,
}

/// What a change does to one group.
#[derive(Debug, Clone, PartialEq)]
enum Action {
    Keep,
    Scale(Rgb),
    Retrace,
}

/// The geometry-dependent part of a radiosity solution, and the current lighting on it.
#[derive(Debug, Clone)]
pub struct Transfer {
    tracer: SceneTracer,
    params: TransferParams,
    rows: LinkRows,
    /// The same links by source, for [`Sweep::Shooting`].
    source_rows: SourceRows,
    /// Per patch, the links a shot of it reads ([`SourceRows::patch_links`]).
    patch_links: Vec<u64>,
    /// The shooting's buffers, kept between relights.
    scratch: ShootScratch,
    topology: Topology,
    /// ρ_d per element of the solution's mesh, kept current by every relight that changes it.
    element_rho: Vec<Rgb>,
    ground: Option<GroundTerm>,
    /// Material index per mesh surface, and the material names.
    surface_material: Vec<usize>,
    material_names: Vec<String>,
    lighting: TransferLighting,
    kinds: Vec<GroupKind>,
    /// The current light groups (sources as traced).
    groups: Vec<LightGroup>,
    /// Per group, the initial exitance of the current solution.
    b0s: Vec<Vec<Rgb>>,
    /// Per group, what its ΔB shootings left unshot and was not passed on yet (empty: nothing,
    /// after a build, a sweep or a table read): a shooting passes it on once it carries more
    /// than the stop rule's residual, so a long series of relights (a sun drag) does not drift
    /// from the fixed point.
    unshot: Vec<Vec<Rgb>>,
    /// Per group whose distant sources a relight re-traces (sun, sky), its direct-light sample
    /// points, drawn once.
    direct_samples: Vec<Option<Arc<DirectSamples>>>,
    /// The sky's visibility per element and dome facet: a sky change is a sum, not a trace.
    /// The sky group's transfer (group 1), lent to a twin build ([`super::twin`]).
    sky_rays: SkyRays,
    solution: Solution,
    /// The table of the material being edited ([`Transfer::relight_material`]); any other
    /// change drops it.
    material_table: Option<material_table::TableState>,
    /// The twins of this transfer's elements in the natural transfer it was built beside
    /// ([`super::twin`]): a relight reads the natural sun counts through them.
    twin: Option<Arc<Twin>>,
    /// The sun group's axis responses ([`sun_basis`]), built at the first sun step that uses
    /// them; a reflectance change drops them.
    sun_basis: Option<sun_basis::SunBasis>,
}

/// What a relight traced ([`Transfer::prepare_relight`]), before [`Transfer::commit_relight`]
/// applies it; nothing of the transfer has changed yet.
#[derive(Debug)]
pub struct PreparedRelight {
    lighting: TransferLighting,
    reflectance: Option<Vec<Rgb>>,
    element_mesh: Option<Mesh>,
    new_groups: Vec<LightGroup>,
    warnings: Vec<LightWarning>,
    actions: Vec<Action>,
    retraced: Vec<Option<Vec<Rgb>>>,
    sun_counts: Option<SunCounts>,
}

impl PreparedRelight {
    /// The sun's visible-ray counts this relight traced, if it moved the sun (for the transfer
    /// built beside this one, [`super::sun_rays`]).
    #[must_use]
    pub fn sun_counts(&self) -> Option<&SunCounts> {
        self.sun_counts.as_ref()
    }
}

/// Elements per chunk of [`power`]'s parallel sum.
const POWER_CHUNK: usize = 4096;

/// Σ A_e·Y(|v_e|), the power the shooting weighs: fixed chunks of [`POWER_CHUNK`] elements
/// summed in parallel (each in element order), then the chunk sums in chunk order, so the same
/// on any number of threads. It runs on every relight of every group.
fn power(v: &[Rgb], areas: &[f64]) -> f64 {
    let chunks: Vec<f64> = v
        .par_chunks(POWER_CHUNK)
        .zip(areas.par_chunks(POWER_CHUNK))
        .map(|(v, areas)| {
            v.iter()
                .zip(areas)
                .map(|(v, a)| a * super::luminance(&v.map(f64::abs)))
                .sum()
        })
        .collect();
    chunks.iter().sum()
}

#[path = "transfer_build.rs"]
mod build;
#[path = "transfer_commit.rs"]
mod commit;
#[path = "material_table.rs"]
mod material_table;
#[path = "sun_basis.rs"]
mod sun_basis;
pub use material_table::{
    MaterialTableReport, NODE_STOP_FACTOR, TABLE_NODES, chebyshev_coefficients, chebyshev_value,
    table_nodes,
};

fn sky_needs_sun(model: &SkyModel) -> bool {
    matches!(model, SkyModel::CieGeneral(_) | SkyModel::Perez(_))
}

/// The ratio new/old per channel, `None` when an old channel is 0 and the new is not.
fn ratio(new: Rgb, old: Rgb) -> Option<Rgb> {
    let mut k = [0.0; 3];
    for c in 0..3 {
        if old[c] > 0.0 {
            k[c] = new[c] / old[c];
        } else if new[c] != 0.0 {
            return None;
        }
    }
    Some(k)
}

impl Transfer {
    /// The same transfer relighting with another strategy and sweep.
    #[must_use]
    pub fn with_strategy(mut self, strategy: RelightStrategy, sweep: Sweep) -> Self {
        self.params.strategy = strategy;
        self.params.sweep = sweep;
        self
    }

    /// The current solution.
    #[must_use]
    pub fn solution(&self) -> &Solution {
        &self.solution
    }

    /// The current lighting.
    #[must_use]
    pub fn lighting(&self) -> &TransferLighting {
        &self.lighting
    }

    /// The current light groups, in solution order (as [`super::solve`] would take them).
    #[must_use]
    pub fn light_groups(&self) -> &[LightGroup] {
        &self.groups
    }

    /// ρ_d per element of the current solution's mesh (the values
    /// [`Mesh::element_reflectance_rgb`] gives, kept by every relight).
    #[must_use]
    pub fn element_reflectances(&self) -> &[Rgb] {
        &self.element_rho
    }

    /// How many elements have a twin in the natural transfer this one was built beside
    /// ([`super::twin`]); `None` when it has no twins.
    #[must_use]
    pub fn twins(&self) -> Option<usize> {
        self.twin.as_deref().map(Twin::twins)
    }

    /// The tracer of the scene.
    #[must_use]
    pub fn tracer(&self) -> &SceneTracer {
        &self.tracer
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &TransferParams {
        &self.params
    }

    /// The ground-below-horizon term, if any.
    pub(crate) fn ground(&self) -> Option<&GroundTerm> {
        self.ground.as_ref()
    }

    /// The lighting after `change`, checked, and the new reflectance per surface (if any
    /// material changes).
    fn apply_to_lighting(
        &self,
        change: &LightingChange,
    ) -> Result<(TransferLighting, Option<Vec<Rgb>>), RadiosityError> {
        let mut lighting = self.lighting.clone();
        if let Some(sun) = &change.sun {
            lighting.sun = *sun;
        }
        if let Some(sky) = &change.sky {
            lighting.sky.clone_from(sky);
        }
        for (name, dimming) in &change.luminaire_dimming {
            let l = lighting
                .luminaires
                .iter_mut()
                .find(|l| l.name == *name)
                .ok_or_else(|| RadiosityError::InvalidSource {
                    group: name.clone(),
                    reason: "no luminaire of that name in the transfer".into(),
                })?;
            l.dimming = *dimming;
        }
        let reflectance = if change.material_reflectance.is_empty() {
            None
        } else {
            let mut rho: Vec<Rgb> = self
                .solution
                .mesh
                .surfaces
                .iter()
                .map(|s| s.reflectance_rgb)
                .collect();
            for (name, value) in &change.material_reflectance {
                check_rgb(name, "reflectance", *value, 1.0)?;
                let Some(m) = self.material_names.iter().position(|n| n == name) else {
                    return Err(RadiosityError::UnknownMaterial {
                        material: name.clone(),
                    });
                };
                for (r, &sm) in rho.iter_mut().zip(&self.surface_material) {
                    if sm == m {
                        *r = *value;
                    }
                }
            }
            Some(rho)
        };
        Ok((lighting, reflectance))
    }

    /// What `lighting` does to each group, relative to the current lighting.
    fn actions(&self, lighting: &TransferLighting) -> Vec<Action> {
        let sun_moved =
            lighting.sun.map(|s| s.dir_in_world) != self.lighting.sun.map(|s| s.dir_in_world);
        self.kinds
            .iter()
            .map(|kind| match kind {
                GroupKind::Sun => match (&lighting.sun, &self.lighting.sun) {
                    (a, b) if a == b => Action::Keep,
                    (Some(a), Some(b)) if !sun_moved && a.dir_in_world.z > 0.0 => {
                        ratio(a.normal_irradiance_rgb, b.normal_irradiance_rgb)
                            .map_or(Action::Retrace, Action::Scale)
                    }
                    _ => Action::Retrace,
                },
                GroupKind::Sky => match (&lighting.sky, &self.lighting.sky) {
                    (Some(a), Some(b))
                        if a.model == b.model && !(sun_moved && sky_needs_sun(&a.model)) =>
                    {
                        if a == b {
                            Action::Keep
                        } else {
                            ratio(a.horizontal_irradiance_rgb, b.horizontal_irradiance_rgb)
                                .map_or(Action::Retrace, Action::Scale)
                        }
                    }
                    (None, None) => Action::Keep,
                    _ => Action::Retrace,
                },
                GroupKind::Luminaire(i) => {
                    let (a, b) = (
                        lighting.luminaires[*i].dimming,
                        self.lighting.luminaires[*i].dimming,
                    );
                    if a.to_bits() == b.to_bits() {
                        Action::Keep
                    } else {
                        ratio([a; 3], [b; 3]).map_or(Action::Retrace, Action::Scale)
                    }
                }
                GroupKind::Emitters => Action::Keep,
            })
            .collect()
    }

    /// Relights the transfer (module doc) and returns the new solution; on error nothing
    /// changes. The returned solution shares its per-element values with the transfer's own
    /// (copied on write): while the caller keeps it, the next relight copies the groups it
    /// changes; dropped before, nothing is copied.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidSource`] for a bad or unknown light,
    /// [`RadiosityError::UnknownMaterial`] for a material the scene does not have.
    pub fn relight(&mut self, change: &LightingChange) -> Result<Solution, RadiosityError> {
        self.relight_in_place(change)?;
        Ok(self.solution.clone())
    }

    /// [`Self::relight`] without the solution it returns (read it with [`Self::solution`]): the
    /// studio's live preview, which reads the transfer's own.
    ///
    /// # Errors
    /// As [`Self::relight`]; on error nothing changes.
    pub fn relight_in_place(&mut self, change: &LightingChange) -> Result<(), RadiosityError> {
        self.relight_with(change, None)
    }

    /// Sets ρ_d per element (`None`: the surface's own; [`Mesh::set_element_reflectances`], the
    /// site's photo reflectances) and iterates every group again on the stored links, as a
    /// material change does; the lighting stays.
    ///
    /// # Errors
    /// [`RadiosityError::ElementReflectance`] for a wrong length or a value out of [0, 1]; on
    /// error nothing changes.
    pub fn set_element_reflectances(&mut self, rho: &[Option<Rgb>]) -> Result<(), RadiosityError> {
        self.relight_with(&LightingChange::default(), Some(rho))
    }

    fn relight_with(
        &mut self,
        change: &LightingChange,
        element_rho: Option<&[Option<Rgb>]>,
    ) -> Result<(), RadiosityError> {
        let prepared = self.prepare_with(change, element_rho, None)?;
        self.commit_relight(prepared);
        Ok(())
    }

    /// The traced part of [`Transfer::relight`] (rays only, never a form factor); with
    /// `natural_sun`, the natural transfer's sun counts for the same sun, read through this
    /// transfer's twins where it was built beside that transfer ([`super::sun_rays`]).
    ///
    /// # Errors
    /// As [`Transfer::relight`]; nothing changes.
    pub fn prepare_relight(
        &self,
        change: &LightingChange,
        natural_sun: Option<&SunCounts>,
    ) -> Result<PreparedRelight, RadiosityError> {
        self.prepare_with(change, None, natural_sun)
    }

    fn prepare_with(
        &self,
        change: &LightingChange,
        element_rho: Option<&[Option<Rgb>]>,
        natural_sun: Option<&SunCounts>,
    ) -> Result<PreparedRelight, RadiosityError> {
        let (lighting, reflectance) = self.apply_to_lighting(change)?;
        let element_mesh = match element_rho {
            Some(rho) => {
                let mut mesh = (*self.solution.mesh).clone();
                mesh.set_element_reflectances(rho)?;
                Some(mesh)
            }
            None => None,
        };
        let actions = self.actions(&lighting);
        // A kept sky (a sun step under a sky that does not follow the sun) is not clustered
        // again: its sources are the same.
        let kept_sky = (self.kinds.get(1) == Some(&GroupKind::Sky)
            && actions.get(1) == Some(&Action::Keep))
        .then(|| &self.groups[1]);
        let (new_groups, warnings) = lighting.light_groups_keeping_sky(
            self.sky_rays.transfer.dome(),
            self.params.sky_tolerance,
            kept_sky,
        )?;
        // Re-trace what needs it (only the changed groups' rays; never a form factor).
        let mut retraced: Vec<Option<Vec<Rgb>>> = vec![None; actions.len()];
        let mut sun_counts = None;
        {
            let engine = FormFactorEngine::new(
                &self.solution.mesh,
                &self.tracer,
                self.params.solve.form_factors,
            )?;
            for (g, action) in actions.iter().enumerate() {
                if *action != Action::Retrace {
                    continue;
                }
                let group = &new_groups[g];
                let samples = self.direct_samples.get(g).and_then(Option::as_deref);
                // The sun alone (one distant source, at every sample point): counted, so that
                // the transfer built beside this one can read the counts (`sun_rays`).
                if let (GroupKind::Sun, [source], None, true, Some(samples)) = (
                    self.kinds[g],
                    group.sources.as_slice(),
                    &group.sky,
                    group.points.is_empty(),
                    samples,
                ) {
                    sources::validate(&group.name, &group.sources)?;
                    let twin = self.twin.as_deref().zip(natural_sun);
                    let (counts, mut direct) = sun_counts_of(&engine, samples, source, twin);
                    if let Some(ground) = self.ground.as_ref() {
                        ground.add(&group.sources, &mut direct);
                    }
                    retraced[g] = Some(direct);
                    sun_counts = Some(counts);
                    continue;
                }
                retraced[g] = Some(group_direct(
                    &engine,
                    group,
                    g as u64,
                    self.ground.as_ref(),
                    samples,
                    Some(&self.sky_rays.transfer),
                )?);
            }
        }
        Ok(PreparedRelight {
            lighting,
            reflectance,
            element_mesh,
            new_groups,
            warnings,
            actions,
            retraced,
            sun_counts,
        })
    }

    /// Links whose source node lies on scene object `object` (tests of the shooting relight).
    #[cfg(test)]
    pub(super) fn links_from_object(&self, object: &str) -> u64 {
        let mesh = &self.solution.mesh;
        (0..mesh.nodes.len())
            .filter(|&n| mesh.object_name(n) == object)
            .map(|n| self.source_rows.row_len(n))
            .sum()
    }
}
