//! One entry point: mesh the scene, light each group directly, solve the interreflection with the
//! chosen solver, keep every group's solution apart (they add linearly).

use rayon::prelude::*;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use super::convergence::{ConvergenceRow, StopRule};
use super::form_factor::{FormFactorEngine, FormFactorParams};
use super::hierarchical::{HierarchicalParams, Hierarchy, Link};
use super::mesh::{Mesh, MeshParams};
use super::progressive::RowCache;
use super::sky_transfer::SkyRays;
use super::sky_transfer::SkyTransfer;
use super::sources::{self, DistantSource, GroundBelowHorizon, LightWarning, PointSource};
use super::twin::Twin;
use super::twin_factors::{FactorReuse, NaturalFactors};
use super::{RadiosityError, Rgb, direct, progressive};
use crate::bvh::BuildQuality;
use crate::scene::{Scene, SceneTracer};
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// The interreflection solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solver {
    /// Shoot the largest unshot power (Cohen et al. 1988), on the elements.
    Progressive,
    /// Hierarchical radiosity with BF refinement (Hanrahan et al. 1991).
    Hierarchical(HierarchicalParams),
    /// Gauss–Seidel on the full element matrix (small scenes, reference).
    Direct,
}

/// Everything a solve needs besides the scene and the lights.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveParams {
    /// Patch and element sizes.
    pub mesh: MeshParams,
    /// Form-factor (and direct-lighting) quadrature and seed.
    pub form_factors: FormFactorParams,
    /// The solver.
    pub solver: Solver,
    /// When to stop.
    pub stop: StopRule,
    /// Form factors the progressive solver may cache (f32 each).
    pub row_cache_entries: usize,
    /// Light from below the horizon where the ground is not modelled (`None`: nothing lights
    /// from below; the scene's own ground, if any, does).
    pub ground: Option<GroundBelowHorizon>,
}

impl Default for SolveParams {
    /// Default mesh and quadrature, hierarchical solver, the seed's stop rule, 32 M cached factors.
    fn default() -> Self {
        Self {
            mesh: MeshParams::default(),
            form_factors: FormFactorParams::default(),
            solver: Solver::Hierarchical(HierarchicalParams::default()),
            stop: StopRule::default(),
            row_cache_entries: 32 << 20,
            ground: None,
        }
    }
}

/// A light group: distant sources and/or the scene's emitting materials.
#[derive(Debug, Clone, PartialEq)]
pub struct LightGroup {
    /// Name (`sun`, `sky`, `emitters`, …).
    pub name: String,
    /// Distant sources.
    pub sources: Vec<DistantSource>,
    /// Point sources (luminaires).
    pub points: Vec<PointSource>,
    /// Whether the materials' emission belongs to this group.
    pub emission: bool,
    /// The sky these `sources` cluster, when known: the elements' direct light then comes from
    /// the sky transfer of this sky (module `sky_transfer`) instead of tracing the clusters,
    /// which still light the ground below the horizon and point queries.
    pub sky: Option<SkyLight>,
    /// Whether its light takes part in the hierarchical solver's link refinement (true as
    /// built); a group carried on links refined for other groups' light says false (another
    /// sun the site's photo reflectances read, `site::render_radiosity`).
    pub refines_links: bool,
}

/// A sky as a transfer relights it: its model, the sun it follows and its weight.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyLight {
    /// The luminance model.
    pub model: crate::sky::SkyModel,
    /// Unit vector towards the sun, world frame (z up).
    pub sun_dir_in_world: nalgebra::Vector3<f64>,
    /// Unobstructed horizontal irradiance, per channel.
    pub horizontal_irradiance_rgb: Rgb,
}

impl LightGroup {
    /// The sun: one distant source.
    #[must_use]
    pub fn sun(sun_dir_in_world: nalgebra::Vector3<f64>, normal_irradiance_rgb: Rgb) -> Self {
        Self {
            name: "sun".into(),
            sources: vec![DistantSource {
                dir_in_world: sun_dir_in_world,
                normal_irradiance_rgb,
            }],
            points: Vec::new(),
            emission: false,
            sky: None,
            refines_links: true,
        }
    }

    /// The sky as clustered dome sources ([`sources::sky_sources`]).
    #[must_use]
    pub fn sky(sources: Vec<DistantSource>) -> Self {
        Self {
            name: "sky".into(),
            sources,
            points: Vec::new(),
            emission: false,
            sky: None,
            refines_links: true,
        }
    }

    /// The emitting materials of the scene.
    #[must_use]
    pub fn emitters() -> Self {
        Self {
            name: "emitters".into(),
            sources: Vec::new(),
            points: Vec::new(),
            emission: true,
            sky: None,
            refines_links: true,
        }
    }

    /// One luminaire (or isotropic point light) named `name`.
    #[must_use]
    pub fn luminaire(name: &str, source: PointSource) -> Self {
        Self {
            name: name.to_owned(),
            sources: Vec::new(),
            points: vec![source],
            emission: false,
            sky: None,
            refines_links: true,
        }
    }
}

/// One group's solution, per element.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupSolution {
    /// The group's name.
    pub name: String,
    /// Direct irradiance (shadowed), per element. Shared, copied on write (`Arc::make_mut`):
    /// a cloned solution (the one [`crate::radiosity::Transfer::relight`] returns) copies no
    /// element until one of the two changes.
    pub direct_irradiance_rgb: Arc<Vec<Rgb>>,
    /// Radiosity (exitance, emission included), per element; shared as
    /// `direct_irradiance_rgb`.
    pub radiosity_rgb: Arc<Vec<Rgb>>,
    /// How the solve converged.
    pub convergence: Vec<ConvergenceRow>,
}

impl GroupSolution {
    /// Total irradiance (direct plus interreflected) per element, H = (B − π·L_e)/ρ per channel;
    /// where ρ = 0 the interreflected part is unknown and only the direct irradiance is given.
    #[must_use]
    pub fn irradiance_rgb(&self, mesh: &Mesh, include_emission: bool) -> Vec<Rgb> {
        (0..mesh.elements.len())
            .map(|e| self.irradiance_of(mesh, e, include_emission))
            .collect()
    }

    /// [`GroupSolution::irradiance_rgb`] of element `e` alone.
    #[must_use]
    pub fn irradiance_of(&self, mesh: &Mesh, e: usize, include_emission: bool) -> Rgb {
        let surface = &mesh.surfaces[mesh.element_node(e).surface as usize];
        let reflectance = mesh.element_reflectance_rgb(e);
        std::array::from_fn(|c| {
            let rho = reflectance[c];
            let emitted = if include_emission {
                surface.emission_rgb[c]
            } else {
                0.0
            };
            if rho > 0.0 {
                (self.radiosity_rgb[e][c] - emitted) / rho
            } else {
                self.direct_irradiance_rgb[e][c]
            }
        })
    }
}

/// The solution of all groups on one mesh.
#[derive(Debug, Clone)]
pub struct Solution {
    /// The mesh (shared with the [`super::Transfer`] that relit it, if any).
    pub mesh: Arc<Mesh>,
    /// Per-group solutions, in the order of the groups given.
    pub groups: Vec<GroupSolution>,
    /// Links (hierarchical), cached rows × elements (progressive), matrix entries (direct).
    pub interactions: u64,
    /// Convergence of the hierarchical refinement (empty for the other solvers).
    pub refinement: Vec<ConvergenceRow>,
    /// Lights that do not do what they seem to (a luminaire inside a wall, the sun down).
    pub warnings: Vec<LightWarning>,
    /// Element lookup and per-vertex irradiance for [`Solution::irradiance_at`], built on first use.
    pub(crate) locator: std::sync::OnceLock<super::element_lookup::ElementLocator>,
    /// The geometry part of the lookup, lent by the solution this one relit or built with the
    /// lookup ([`Solution::reuse_query_geometry`]).
    pub(crate) query_geometry: std::sync::OnceLock<Arc<super::element_lookup::LookupGeometry>>,
}

/// [`Solution::relative_difference`]: area-weighted, in luminance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadiosityDifference {
    /// Σ A·|L(B) − L(B_ref)| over Σ A·L(B_ref).
    pub l1_rel: f64,
    /// (mean − mean_ref) / mean_ref of the area-weighted mean brightness.
    pub mean_rel: f64,
}

impl Solution {
    /// Σ over groups of the radiosity, per element.
    #[must_use]
    pub fn total_radiosity_rgb(&self) -> Vec<Rgb> {
        let n = self.mesh.elements.len();
        let mut total = vec![[0.0; 3]; n];
        for g in &self.groups {
            for (t, b) in total.iter_mut().zip(g.radiosity_rgb.iter()) {
                for c in 0..3 {
                    t[c] += b[c];
                }
            }
        }
        total
    }

    /// How far this solution's total radiosity lies from `reference`'s on the same mesh, in
    /// luminance weighted by element area: the L1 difference over the reference's L1 norm, and
    /// the relative difference of the mean brightness. `None` when the meshes differ in size or
    /// the reference is dark.
    #[must_use]
    pub fn relative_difference(&self, reference: &Solution) -> Option<RadiosityDifference> {
        let (a, b) = (self.total_radiosity_rgb(), reference.total_radiosity_rgb());
        if a.len() != b.len() {
            return None;
        }
        let (mut diff, mut mean_a, mut mean_b) = (0.0, 0.0, 0.0);
        for (e, (x, y)) in a.iter().zip(&b).enumerate() {
            let w = reference.mesh.element_node(e).area_m2;
            let d: Rgb = std::array::from_fn(|c| (x[c] - y[c]).abs());
            diff += super::luminance(&d) * w;
            mean_a += super::luminance(x) * w;
            mean_b += super::luminance(y) * w;
        }
        (mean_b > 0.0).then(|| RadiosityDifference {
            l1_rel: diff / mean_b,
            mean_rel: (mean_a - mean_b) / mean_b,
        })
    }

    /// The same solution without the direct irradiance of the groups `exact` names: their
    /// direct term is taken out of both the direct irradiance and the radiosity
    /// (B − ρ·E_direct), so [`Solution::irradiance_at`] then gives every other group's light plus
    /// all interreflected light, theirs included. The differential renderer adds the named
    /// groups' direct light itself with exact shadow rays (the sun, the luminaires).
    #[must_use]
    pub fn without_direct_of(&self, exact: &(dyn Fn(&str) -> bool + Sync)) -> Self {
        self.without_direct_of_given(exact, None)
    }

    /// [`Solution::without_direct_of`] with ρ per element given (as a transfer keeps it: the
    /// values [`Mesh::element_reflectance_rgb`] gives, without reading a mesh node per element);
    /// `None`, or a slice of another length, reads the mesh.
    #[must_use]
    pub fn without_direct_of_given(
        &self,
        exact: &(dyn Fn(&str) -> bool + Sync),
        element_rho: Option<&[Rgb]>,
    ) -> Self {
        let mesh = &self.mesh;
        // ρ per element once for all the exact groups.
        let read;
        let rho: &[Rgb] = match element_rho {
            Some(r) if r.len() == mesh.elements.len() => r,
            _ if self.groups.iter().any(|g| exact(&g.name)) => {
                read = (0..mesh.elements.len())
                    .into_par_iter()
                    .map(|e| mesh.element_reflectance_rgb(e))
                    .collect::<Vec<Rgb>>();
                &read
            }
            _ => &[],
        };
        let groups = self
            .groups
            .iter()
            .map(|g| {
                if !exact(&g.name) {
                    return g.clone();
                }
                // Each element on its own: the same values on any number of threads.
                let radiosity_rgb: Vec<Rgb> = (0..mesh.elements.len())
                    .into_par_iter()
                    .map(|e| {
                        std::array::from_fn(|c| {
                            g.radiosity_rgb[e][c] - rho[e][c] * g.direct_irradiance_rgb[e][c]
                        })
                    })
                    .collect();
                GroupSolution {
                    name: g.name.clone(),
                    direct_irradiance_rgb: Arc::new(vec![[0.0; 3]; mesh.elements.len()]),
                    radiosity_rgb: Arc::new(radiosity_rgb),
                    convergence: g.convergence.clone(),
                }
            })
            .collect();
        Self {
            mesh: Arc::clone(&self.mesh),
            groups,
            interactions: self.interactions,
            refinement: self.refinement.clone(),
            warnings: self.warnings.clone(),
            locator: std::sync::OnceLock::new(),
            query_geometry: self.query_geometry.clone(),
        }
    }

    /// The solution of the groups whose indices `keep` keeps (in order), on the same mesh and
    /// links: a solve that carried several lightings as groups, read one lighting at a time.
    #[must_use]
    pub fn groups_where(&self, keep: impl Fn(usize) -> bool) -> Self {
        Self {
            mesh: Arc::clone(&self.mesh),
            groups: self
                .groups
                .iter()
                .enumerate()
                .filter(|(g, _)| keep(*g))
                .map(|(_, g)| g.clone())
                .collect(),
            interactions: self.interactions,
            refinement: self.refinement.clone(),
            warnings: self.warnings.clone(),
            locator: std::sync::OnceLock::new(),
            query_geometry: self.query_geometry.clone(),
        }
    }

    /// Every convergence row: the refinement's, then each group's.
    #[must_use]
    pub fn convergence(&self) -> Vec<ConvergenceRow> {
        let mut rows = self.refinement.clone();
        for g in &self.groups {
            rows.extend(g.convergence.iter().cloned());
        }
        rows
    }

    /// Whether every group met the stop rule before its pass limit.
    #[must_use]
    pub fn converged(&self, stop: &StopRule) -> bool {
        self.groups.iter().all(|g| {
            g.convergence
                .last()
                .is_none_or(|r| stop.met(r) || r.mean_brightness <= 0.0)
        })
    }
}

/// The directions toward the distant sources of the groups named `sun` ([`LightGroup::sun`]),
/// whose shadow edges [`Mesh::build_lit`] may refine.
#[must_use]
pub fn sun_directions(groups: &[LightGroup]) -> Vec<nalgebra::Vector3<f64>> {
    groups
        .iter()
        .filter(|g| g.name == "sun")
        .flat_map(|g| g.sources.iter().map(|s| s.dir_in_world))
        .collect()
}

/// Meshes `scene`, lights it by `groups` and solves (module doc). `on_pass` sees every pass.
///
/// # Errors
/// Meshing, tracing and parameter errors; [`RadiosityError::Cancelled`] when `cancel` rises.
pub fn solve(
    scene: &Scene,
    groups: &[LightGroup],
    params: &SolveParams,
    cancel: &AtomicBool,
    on_pass: &dyn Fn(&ConvergenceRow),
) -> Result<Solution, RadiosityError> {
    params.stop.validate()?;
    let mesh = Mesh::build_lit(scene, &params.mesh, &sun_directions(groups), &[])?;
    let tracer = SceneTracer::new(scene, BuildQuality::Medium)?;
    solve_on_mesh(mesh, &tracer, groups, params, cancel, on_pass)
}

/// [`solve`] on a mesh already built from the scene `tracer` traces.
///
/// # Errors
/// As [`solve`].
pub fn solve_on_mesh(
    mesh: Mesh,
    tracer: &SceneTracer,
    groups: &[LightGroup],
    params: &SolveParams,
    cancel: &AtomicBool,
    on_pass: &dyn Fn(&ConvergenceRow),
) -> Result<Solution, RadiosityError> {
    solve_on_mesh_refitting(
        mesh,
        tracer,
        groups,
        params,
        cancel,
        on_pass,
        &mut |_| None,
        0,
    )
}

/// Per-element reflectances from a solution ([`solve_on_mesh_refitting`]): `None` to stop,
/// else one entry per element (`None` where an element keeps its surface's ρ).
pub type Refit<'a> = dyn FnMut(&Solution) -> Option<Vec<Option<Rgb>>> + 'a;

/// [`solve_on_mesh`], then up to `rounds` times: `refit` reads the solution and returns
/// per-element reflectances ([`Mesh::set_element_reflectances`]), and every group is solved
/// again on the same links (the hierarchical solver's links are refined once, for the first
/// reflectances). The site's photo reflectances use it: ρ_d = π·L₀/E needs E, which depends on
/// the ρ_d of the surroundings (`site::photo_reflectance`).
///
/// # Errors
/// As [`solve`]; [`RadiosityError::InvalidParameter`] for `rounds` > 0 with a solver other than
/// the hierarchical one; [`RadiosityError::ElementReflectance`] for a refit value out of range.
#[allow(clippy::too_many_arguments)]
pub fn solve_on_mesh_refitting(
    mesh: Mesh,
    tracer: &SceneTracer,
    groups: &[LightGroup],
    params: &SolveParams,
    cancel: &AtomicBool,
    on_pass: &dyn Fn(&ConvergenceRow),
    refit: &mut Refit<'_>,
    rounds: usize,
) -> Result<Solution, RadiosityError> {
    solve_on_mesh_twinned(
        mesh, tracer, groups, params, cancel, on_pass, refit, rounds, None,
    )
    .map(|(solution, _)| solution)
}

/// [`solve_on_mesh_refitting`] keeping the sky rays it traced ([`SkyRays`], for a later solve
/// of the scene with planned objects added), and with `twin`, reading those of the natural
/// scene's solve for the elements it shares with it ([`super::twin`]: the same rays, traced
/// once). Without a twin the solution is [`solve_on_mesh_refitting`]'s, bit for bit.
///
/// # Errors
/// As [`solve_on_mesh_refitting`].
///
/// # Panics
/// When `twin` was made for another mesh (another element count).
#[allow(clippy::too_many_arguments)]
pub fn solve_on_mesh_twinned(
    mut mesh: Mesh,
    tracer: &SceneTracer,
    groups: &[LightGroup],
    params: &SolveParams,
    cancel: &AtomicBool,
    on_pass: &dyn Fn(&ConvergenceRow),
    refit: &mut Refit<'_>,
    rounds: usize,
    twin: Option<(&Twin, &SkyRays)>,
) -> Result<(Solution, Option<SkyRays>), RadiosityError> {
    if rounds > 0 && !matches!(params.solver, Solver::Hierarchical(_)) {
        return Err(RadiosityError::InvalidParameter {
            name: "refit rounds",
            value: rounds as f64,
            reason: "reflectances refitted from a solution need the hierarchical solver",
        });
    }
    if params.form_factors.visibility {
        super::covered::mark_covered(&mut mesh, tracer, &params.form_factors);
    }
    // The natural solve's form factors, read where they are the same (`super::twin_factors`).
    let reuse = twin.and_then(|(t, sky)| {
        let natural = sky.factors.as_deref()?;
        FactorReuse::new(natural, t, &mesh, params.form_factors)
    });
    let engine = FormFactorEngine::new(&mesh, tracer, params.form_factors)?
        .with_direct_streams(twin.map(|(t, _)| t.streams.as_slice()))
        .with_node_streams(reuse.as_ref().map(FactorReuse::streams));
    let n = mesh.elements.len();
    let ground = GroundTerm::new(&engine, params.ground.as_ref())?;
    let mut directs = Vec::with_capacity(groups.len());
    let mut b0s = Vec::with_capacity(groups.len());
    let mut warnings = Vec::new();
    let mut sky_rays: Option<SkyRays> = None;
    for (g, group) in groups.iter().enumerate() {
        warnings.extend(sources::check_point_sources(
            tracer,
            &group.name,
            &group.points,
            &mesh.object_names,
        ));
        let direct = if group.sky.is_some() && !group.sources.is_empty() && sky_rays.is_none() {
            // The first sky's transfer, traced here as `group_direct` would trace it, to be
            // kept (and, with a twin, from the twin's rays).
            sources::validate(&group.name, &group.sources)?;
            let samples = sources::DirectSamples::new(&engine, g as u64);
            let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath())?;
            let transfer =
                SkyTransfer::beside(&engine, &samples, &dome, twin.map(|(t, sky)| (t, sky, g)));
            let direct = group_direct(
                &engine,
                group,
                g as u64,
                ground.as_ref(),
                Some(&samples),
                Some(&transfer),
            )?;
            sky_rays = Some(SkyRays {
                group: g,
                transfer,
                factors: None,
            });
            direct
        } else {
            // A later sky reads the first sky's rays, as a transfer's relight does.
            let first_sky = sky_rays.as_ref().map(|s| &s.transfer);
            group_direct(&engine, group, g as u64, ground.as_ref(), None, first_sky)?
        };
        b0s.push(initial_exitance(&mesh, &direct, group.emission));
        directs.push(direct);
    }
    let mut refinement = Vec::new();
    let mut solved = Vec::with_capacity(groups.len());
    let interactions;
    let mut hierarchy = None;
    let mut computed = Vec::new();
    match params.solver {
        Solver::Progressive => {
            let mut cache = RowCache::new(n, params.row_cache_entries);
            for (group, b0) in groups.iter().zip(&b0s) {
                solved.push(progressive::solve(
                    &engine,
                    b0,
                    &group.name,
                    &params.stop,
                    &mut cache,
                    cancel,
                    on_pass,
                )?);
            }
            interactions = cache.rows_computed * n as u64;
        }
        Solver::Hierarchical(h) => {
            // The links are refined for the light of the groups that refine them (all, where
            // none says so).
            let refining = groups.iter().any(|g| g.refines_links);
            let mut b0_all = vec![[0.0; 3]; n];
            for (_, b0) in groups
                .iter()
                .zip(&b0s)
                .filter(|(g, _)| g.refines_links || !refining)
            {
                for (t, b) in b0_all.iter_mut().zip(b0) {
                    for c in 0..3 {
                        t[c] += b[c];
                    }
                }
            }
            let (built, links_computed) = Hierarchy::build_reusing(
                &engine,
                &h,
                &b0_all,
                &params.stop,
                cancel,
                on_pass,
                reuse.as_ref(),
            )?;
            computed = links_computed;
            for (group, b0) in groups.iter().zip(&b0s) {
                solved.push(built.solve(&mesh, b0, &group.name, &params.stop, cancel, on_pass)?);
            }
            interactions = built.links.len() as u64;
            refinement.clone_from(&built.refinement);
            hierarchy = Some(built);
        }
        Solver::Direct => {
            let matrix = direct::element_matrix(&engine, cancel)?;
            for (group, b0) in groups.iter().zip(&b0s) {
                solved.push(direct::solve(
                    &engine,
                    &matrix,
                    b0,
                    &group.name,
                    &params.stop,
                    cancel,
                )?);
            }
            interactions = matrix.len() as u64;
        }
    }
    // The direct terms move into the returned solution; only a refit's probes copy them.
    let assemble = |mesh: Mesh,
                    solved: Vec<(Vec<Rgb>, Vec<ConvergenceRow>)>,
                    directs: Vec<Vec<Rgb>>| Solution {
        mesh: Arc::new(mesh),
        groups: groups
            .iter()
            .zip(directs)
            .zip(solved)
            .map(
                |((group, direct), (radiosity, convergence))| GroupSolution {
                    name: group.name.clone(),
                    direct_irradiance_rgb: Arc::new(direct),
                    radiosity_rgb: Arc::new(radiosity),
                    convergence,
                },
            )
            .collect(),
        interactions,
        refinement: refinement.clone(),
        warnings: warnings.clone(),
        locator: std::sync::OnceLock::new(),
        query_geometry: std::sync::OnceLock::new(),
    };
    // A natural solve lends its form factors with its sky rays (a solve beside one does not;
    // one beside its identity twin, another colour of the same scene, does).
    let with_factors = |solution: Solution, sky_rays: Option<SkyRays>| {
        let sky_rays = sky_rays.map(|mut sky| {
            if hierarchy.is_some() && twin.is_none_or(|(t, _)| !t.plans_something()) {
                sky.factors = Some(Arc::new(NaturalFactors::new(
                    Arc::clone(&solution.mesh),
                    params.form_factors,
                    computed.iter().map(Link::triple),
                )));
            }
            sky
        });
        (solution, sky_rays)
    };
    let (mut mesh, mut solved) = (mesh, solved);
    for _ in 0..rounds {
        let probe = assemble(mesh, solved, directs.clone());
        let (Some(rho), Some(hierarchy)) = (refit(&probe), hierarchy.as_ref()) else {
            return Ok(with_factors(probe, sky_rays));
        };
        mesh = Arc::unwrap_or_clone(probe.mesh);
        mesh.set_element_reflectances(&rho)?;
        solved = Vec::with_capacity(groups.len());
        for (group, direct) in groups.iter().zip(&directs) {
            let b0 = initial_exitance(&mesh, direct, group.emission);
            solved.push(hierarchy.solve(&mesh, &b0, &group.name, &params.stop, cancel, on_pass)?);
        }
    }
    Ok(with_factors(assemble(mesh, solved, directs), sky_rays))
}

/// The ground below the horizon, ready to apply: its unit-radiance transfer per element.
#[derive(Debug, Clone)]
pub(crate) struct GroundTerm {
    pub(crate) ground: GroundBelowHorizon,
    /// The unit-radiance ground clusters ([`sources::ground_sources`]).
    pub(crate) sources: Vec<DistantSource>,
    /// Per element, irradiance from a unit-radiance ground below the horizon.
    pub(crate) transfer: Vec<f64>,
}

impl GroundTerm {
    /// Traces the ground transfer (once per mesh); `None` without a ground.
    pub(crate) fn new(
        engine: &FormFactorEngine<'_>,
        ground: Option<&GroundBelowHorizon>,
    ) -> Result<Option<Self>, RadiosityError> {
        let Some(ground) = ground else {
            return Ok(None);
        };
        ground.validate()?;
        let dome = crate::sky_dome::icosahedral::IcosahedralDome::new(
            &crate::sky_dome::icosahedral::IcosahedralParams {
                frequencies: GROUND_DOME_FREQUENCIES.to_vec(),
            },
        )?;
        let sources = sources::ground_sources(&dome, ground.cluster_tolerance)?;
        Ok(Some(Self {
            ground: *ground,
            transfer: sources::ground_transfer(engine, &sources),
            sources,
        }))
    }

    /// Adds the ground's light for a group of distant `sources` to `direct`.
    pub(crate) fn add(&self, sources: &[DistantSource], direct: &mut [Rgb]) {
        let l = self.ground.radiance_rgb(sources);
        if l.iter().all(|&v| v == 0.0) {
            return;
        }
        for (d, t) in direct.iter_mut().zip(&self.transfer) {
            for c in 0..3 {
                d[c] += l[c] * t;
            }
        }
    }
}

/// Dome of the ground's clusters: frequencies 4 × 2 (≈ 9° leaves; the ground is uniform, so the
/// leaf size only sets how finely the clusters can follow a receiver's horizon).
const GROUND_DOME_FREQUENCIES: [u32; 2] = [4, 2];

/// A group's direct irradiance per element: its distant sources (and the ground they light),
/// its point sources. `group_index` selects the random streams; `samples`, when given, are that
/// group's direct-light sample points drawn before (a transfer keeps them). A group that knows its
/// sky ([`LightGroup::sky`]) takes the elements' light from `sky_transfer` (a transfer keeps one),
/// else from one traced here from the same points.
pub(crate) fn group_direct(
    engine: &FormFactorEngine<'_>,
    group: &LightGroup,
    group_index: u64,
    ground: Option<&GroundTerm>,
    samples: Option<&sources::DirectSamples>,
    sky_transfer: Option<&SkyTransfer>,
) -> Result<Vec<Rgb>, RadiosityError> {
    sources::validate(&group.name, &group.sources)?;
    sources::validate_points(&group.name, &group.points)?;
    let mut direct = match (&group.sky, samples) {
        (Some(sky), _) if !group.sources.is_empty() => {
            let owned;
            let transfer = if let Some(t) = sky_transfer {
                t
            } else {
                let drawn;
                let samples = if let Some(s) = samples {
                    s
                } else {
                    drawn = sources::DirectSamples::new(engine, group_index);
                    &drawn
                };
                owned = SkyTransfer::new(
                    engine,
                    samples,
                    &IcosahedralDome::new(&IcosahedralParams::tonn_donath())?,
                );
                &owned
            };
            transfer.direct(
                &sky.model,
                &sky.sun_dir_in_world,
                sky.horizontal_irradiance_rgb,
            )?
        }
        (_, Some(samples)) => sources::direct_irradiance_at(engine, samples, &group.sources),
        (_, None) => sources::direct_irradiance(engine, &group.sources, group_index),
    };
    if let Some(ground) = ground {
        ground.add(&group.sources, &mut direct);
    }
    if !group.points.is_empty() {
        let from_points = sources::point_irradiance(engine, &group.points, group_index);
        for (d, p) in direct.iter_mut().zip(from_points) {
            for c in 0..3 {
                d[c] += p[c];
            }
        }
    }
    Ok(direct)
}

/// B₀ = ρ·E_direct (+ the emission when the group owns it), per element.
pub(crate) fn initial_exitance(mesh: &Mesh, direct: &[Rgb], emission: bool) -> Vec<Rgb> {
    let n = mesh.elements.len();
    let rho: Vec<Rgb> = (0..n).map(|e| mesh.element_reflectance_rgb(e)).collect();
    let emitted: Option<Vec<Rgb>> = emission.then(|| {
        (0..n)
            .map(|e| mesh.surfaces[mesh.element_node(e).surface as usize].emission_rgb)
            .collect()
    });
    initial_exitance_from(&rho, direct, emitted.as_deref())
}

/// B₀ = ρ·E_direct + emission, per element, from ρ per element and (when the group owns it)
/// the emission per element.
pub(crate) fn initial_exitance_from(
    rho: &[Rgb],
    direct: &[Rgb],
    emission: Option<&[Rgb]>,
) -> Vec<Rgb> {
    // Each element on its own: the same values on any number of threads.
    (0..rho.len())
        .into_par_iter()
        .map(|e| {
            let emitted = emission.map_or([0.0; 3], |m| m[e]);
            std::array::from_fn(|c| rho[e][c] * direct[e][c] + emitted[c])
        })
        .collect()
}
