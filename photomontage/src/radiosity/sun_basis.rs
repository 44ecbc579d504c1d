//! The sun group as three axis responses: a sun step reads the stored links only for what its
//! shadows changed.
//!
//! Hold the sun's visibility fixed: v_e, the fraction of element e's sample rays towards the sun
//! that escape the scene ([`super::super::sun_rays`]; 0 for an element facing away). The sun's
//! direct irradiance E_n·v_e·(n_e·s), plus the unmodelled ground's (a/π)·E_n·s_z·t_e for a sun
//! above the horizon ([`crate::radiosity::sources::GroundBelowHorizon`]), is then linear in the
//! sun's direction s: the sum over the axes c ∈ {x, y, z} of s_c·E_n·(v_e·n_{e,c} + [c = z]·
//! (a/π)·t_e). Radiosity is linear in the initial exitance, channel by channel, so the sun
//! group's solution is
//!
//! B = E_n ⊙ Σ_c s_c·G_c,
//!
//! G_c being the solution for a unit normal irradiance along axis c with the visibility v. This is
//! the seed's light-group superposition (Tonn & Donath, `000_…`: a lighting change as a linear
//! combination of precomputed responses) applied to the sun's direction vector. A sun step keeps
//! the G_c and changes them only where v changed: on the elements a moving shadow edge crosses,
//! and on those that turn towards or away from the sun (on the city block of the studio's bench,
//! 150–190 of 49 152 elements per 1° step). There D_c = ρ·Δv·n_c is added to G_c and to what G_c
//! has left unshot. As a group's kept remainder ([`Transfer::unshot`]), the remainder is only kept
//! until it carries more than the stop rule's residual of G_c's power; then the three axes are
//! shot together on the stored links ([`super::super::shooting`]) to the stop rule. A step that
//! keeps its remainder reads no link: the direct light is exact at once, the interreflection is
//! within the stop rule's residual of its fixed point, as after any shooting.
//!
//! The basis is built at the first sun step that can use it, by shooting the three axes from
//! nothing, and holds for the transfer's reflectances: a material or per-element reflectance
//! change drops it (the next sun step builds it again). It is used with the default relight
//! (linear responses, ΔB shooting) and a sun above the horizon; every other case relights the sun
//! group as before. Each element is composed on its own and the shootings are
//! thread-count independent, so the result is the same on any number of threads.

use std::sync::Arc;

use rayon::prelude::*;

use super::{GroupKind, Transfer, initial_exitance_from, power};
use crate::radiosity::convergence::ConvergenceRow;
use crate::radiosity::shooting::{Leaves, ShotGroup, shoot};
use crate::radiosity::sources::DistantSource;
use crate::radiosity::sun_rays::SunCounts;
use crate::radiosity::{LightGroup, Rgb, luminance};

/// The axes' names in the convergence rows.
const AXES: [&str; 3] = ["x", "y", "z"];

/// The sun group's axis responses (module doc) for the transfer's current reflectances.
#[derive(Debug, Clone)]
pub(super) struct SunBasis {
    /// Per element, how many of its sun rays escaped when the basis was last updated.
    escaped: Vec<u8>,
    /// Per axis x, y, z: G_c per element.
    radiosity: [Vec<Rgb>; 3],
    /// Per axis: what its shootings left unshot and its steps added, kept.
    unshot: [Vec<Rgb>; 3],
    /// Per axis, the power (area-weighted luminance of |v|) of `radiosity` and of `unshot`:
    /// summed afresh when the axis is built or shot, and updated element by element by a step's
    /// visibility change (the same order on any number of threads), so that a step reads the
    /// three axes only where their counts changed.
    powers: [[f64; 2]; 3],
    /// The sun group and source of the last step when its composed remainder
    /// ([`Transfer::unshot`]) and initial exitance ([`Transfer::b0s`]) are not yet written: only
    /// a relight other than a sun step through the basis reads them
    /// ([`Transfer::settle_sun_axes`]), so a drag of sun steps never composes them.
    pending: Option<(usize, DistantSource)>,
}

/// The sun group's index and its one source, when a relight can go through the basis: the sun
/// group's only source is distant and above the horizon, with no sky and no point sources (then
/// the relight counted its rays).
pub(super) fn axes_source(
    kinds: &[GroupKind],
    groups: &[LightGroup],
) -> Option<(usize, DistantSource)> {
    let g = kinds.iter().position(|k| *k == GroupKind::Sun)?;
    let group = groups.get(g)?;
    match (
        group.sources.as_slice(),
        &group.sky,
        group.points.is_empty(),
    ) {
        ([source], None, true) if source.dir_in_world.z > 0.0 => Some((g, *source)),
        _ => None,
    }
}

impl Transfer {
    /// Forgets the sun's axis responses: the next sun step shoots them from nothing, a cold
    /// shooting (the reference of a drift measurement).
    pub fn drop_sun_axes(&mut self) {
        self.settle_sun_axes();
        self.sun_basis = None;
    }

    /// Writes the sun group's composed remainder and initial exitance of the last step through
    /// the basis where they are still pending ([`SunBasis::pending`]), for the transfer's
    /// current reflectances and the group's direct light: before anything else relights.
    pub(super) fn settle_sun_axes(&mut self) {
        let Some((g, source)) = self.sun_basis.as_mut().and_then(|b| b.pending.take()) else {
            return;
        };
        if let Some(basis) = &self.sun_basis {
            compose(&basis.unshot, &source, &mut self.unshot[g]);
        }
        let emitted = self.groups[g]
            .emission
            .then(|| self.topology.element_emissions(&self.solution.mesh));
        self.b0s[g] = initial_exitance_from(
            &self.element_rho,
            &self.solution.groups[g].direct_irradiance_rgb,
            emitted.as_deref(),
        );
    }

    /// Relights sun group `g` to `source` with its ray `counts` through the basis (module doc),
    /// building the basis first when there is none: the group's radiosity and kept remainder
    /// ([`Transfer::unshot`]) are set; returns the axes' convergence rows (none when the step
    /// kept every axis's remainder).
    pub(super) fn relight_sun_by_axes(
        &mut self,
        g: usize,
        source: &DistantSource,
        counts: &SunCounts,
    ) -> Vec<ConvergenceRow> {
        let n_el = self.element_rho.len();
        let name = self.solution.groups[g].name.clone();
        // Rays per element (every element has as many sample points).
        #[allow(clippy::cast_precision_loss)]
        let rays = self.direct_samples[g]
            .as_deref()
            .unwrap_or_else(|| unreachable!("counted sun rays have their sample points"))
            .per_element() as f64;
        let basis = self
            .sun_basis
            .take()
            .filter(|b| b.escaped.len() == n_el && counts.escaped.len() == n_el);
        // Which axes are shot: all of a new basis; of a kept one, those whose remainder now
        // carries more than the residual of their power.
        let (mut basis, shot_axes): (SunBasis, Vec<usize>) = match basis {
            Some(mut b) => {
                self.add_visibility_change(&mut b, counts, rays);
                let residual = self.params.solve.stop.residual;
                let over: Vec<usize> = (0..3)
                    .filter(|&c| b.powers[c][1] > residual * b.powers[c][0])
                    .collect();
                (b, over)
            }
            None => (self.cold_basis(counts, rays), vec![0, 1, 2]),
        };
        let mut rows = Vec::new();
        if !shot_axes.is_empty() {
            let axes: Vec<ShotGroup<'_>> = shot_axes
                .iter()
                .map(|&c| ShotGroup {
                    name: AXES[c],
                    old: &[],
                    start: std::mem::take(&mut basis.radiosity[c]),
                    unshot: Some(std::mem::take(&mut basis.unshot[c])),
                    keep_unshot: true,
                })
                .collect();
            let shots = shoot(
                &self.topology,
                &self.source_rows,
                &self.element_rho,
                axes,
                Leaves::InGroups,
                &self.params.solve.stop,
                &self.patch_links,
                &mut self.scratch,
            );
            for (&c, shot) in shot_axes.iter().zip(shots) {
                basis.radiosity[c] = shot.radiosity;
                basis.unshot[c] = shot.unshot.unwrap_or_else(|| vec![[0.0; 3]; n_el]);
                basis.powers[c] = shot.powers;
                rows.extend(shot.rows.into_iter().map(|mut r| {
                    r.group = format!("{name} ({} axis)", AXES[c]);
                    r
                }));
            }
        }
        compose(
            &basis.radiosity,
            source,
            Arc::make_mut(&mut self.solution.groups[g].radiosity_rgb),
        );
        basis.pending = Some((g, *source));
        self.sun_basis = Some(basis);
        rows
    }

    /// The initial exitance of axis c per element for the visibility `counts` (module doc).
    fn axis_exitance(&self, counts: &SunCounts, rays: f64) -> [Vec<Rgb>; 3] {
        let mesh = &self.solution.mesh;
        let ground: Option<(Rgb, &[f64])> = self.ground.as_ref().map(|gt| {
            let a = gt.ground.albedo_rgb;
            (a.map(|v| v / std::f64::consts::PI), gt.transfer.as_slice())
        });
        std::array::from_fn(|c| {
            (0..counts.escaped.len())
                .into_par_iter()
                .map(|e| {
                    let n = mesh.element_node(e).normal_in_world;
                    let v = f64::from(counts.escaped[e]) / rays;
                    let rho = self.element_rho[e];
                    std::array::from_fn(|k| {
                        let ground_k = match ground {
                            Some((l, t)) if c == 2 => l[k] * t[e],
                            _ => 0.0,
                        };
                        rho[k] * (v * n[c] + ground_k)
                    })
                })
                .collect()
        })
    }

    /// The basis for `counts`, nothing shot yet: G_c = B₀_c, all of it unshot.
    fn cold_basis(&self, counts: &SunCounts, rays: f64) -> SunBasis {
        let b0 = self.axis_exitance(counts, rays);
        let areas = &self.topology.areas;
        let powers = std::array::from_fn(|c| {
            let p = power(&b0[c], areas);
            [p, p]
        });
        SunBasis {
            escaped: counts.escaped.clone(),
            unshot: b0.clone(),
            radiosity: b0,
            powers,
            pending: None,
        }
    }

    /// Adds D_c = ρ·Δv·n_c of the elements whose count changed to G_c and to its unshot part.
    fn add_visibility_change(&self, basis: &mut SunBasis, counts: &SunCounts, rays: f64) {
        let mesh = &self.solution.mesh;
        for (e, (old, &new)) in basis.escaped.iter_mut().zip(&counts.escaped).enumerate() {
            if *old == new {
                continue;
            }
            let dv = (f64::from(new) - f64::from(*old)) / rays;
            *old = new;
            let n = mesh.element_node(e).normal_in_world;
            let rho = self.element_rho[e];
            let area = self.topology.areas[e];
            let weighted = |v: &Rgb| area * luminance(&v.map(f64::abs));
            for c in 0..3 {
                let (r, u) = (&mut basis.radiosity[c][e], &mut basis.unshot[c][e]);
                let before = [weighted(r), weighted(u)];
                for k in 0..3 {
                    let d = rho[k] * dv * n[c];
                    r[k] += d;
                    u[k] += d;
                }
                basis.powers[c][0] += weighted(r) - before[0];
                basis.powers[c][1] += weighted(u) - before[1];
            }
        }
    }
}

/// `out` = E_n ⊙ Σ_c s_c·v_c per element, each on its own (the same on any number of threads),
/// in `out`'s own buffer.
fn compose(axes: &[Vec<Rgb>; 3], source: &DistantSource, out: &mut Vec<Rgb>) {
    let s = source.dir_in_world;
    let en = source.normal_irradiance_rgb;
    out.resize(axes[0].len(), [0.0; 3]);
    out.par_iter_mut().enumerate().for_each(|(e, o)| {
        *o = std::array::from_fn(|k| {
            en[k] * (s.x * axes[0][e][k] + s.y * axes[1][e][k] + s.z * axes[2][e][k])
        });
    });
}

#[cfg(test)]
#[path = "sun_basis_tests.rs"]
mod tests;
