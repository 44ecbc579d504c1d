//! The radiosity solve options a user sets for a site (the CLI's `--patch-edge-m`,
//! `--element-edge-m`, `--object-element-edge`, `--samples`, `--seed`, `--bf-tolerance`,
//! `--sky-tolerance`, `--mean-change`, `--residual` of `radiosity`, `irradiance` and
//! `elevation`, and the studio's irradiance elevation), with one set of defaults and one
//! mapping onto the solver's [`SolveParams`] and [`TransferParams`], so that the CLI and the
//! studio solve with the same parameters for the same options.
//!
//! # Known limitations
//! Only the options above are exposed; the rest of [`SolveParams`] (row cache, form-factor
//! tolerance and link budget of the hierarchical solver, the pass limit) keeps the solver's
//! defaults.

use std::collections::BTreeMap;

use crate::radiosity::hierarchical::HierarchicalParams;
use crate::radiosity::{
    FormFactorParams, GroundBelowHorizon, MeshParams, RelightStrategy, SolveParams, Solver,
    StopRule, Sweep, TransferParams,
};

/// The user-facing radiosity solve options.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveOptions {
    /// Longest patch edge, metres (the global size).
    pub patch_edge_m: f64,
    /// Longest element edge, metres, unless the object has its own.
    pub element_edge_m: f64,
    /// Element edge of single objects (object name → metres).
    pub object_element_edge_m: BTreeMap<String, f64>,
    /// Form-factor samples per axis (n² per pair).
    pub samples_per_axis: u32,
    /// Seed of the form factors and shadow rays.
    pub seed: u64,
    /// Hierarchical BF tolerance (fraction of the mean brightness).
    pub bf_tolerance: f64,
    /// Sky clustering tolerance of the icosahedral dome.
    pub sky_tolerance: f64,
    /// Stop when the mean brightness changes by less than this between passes …
    pub mean_change: f64,
    /// … and the relative residual is below this.
    pub residual: f64,
    /// Split elements at concave corners down to this edge, metres
    /// ([`crate::radiosity::corner_refinement`]); `None`: no corner refinement.
    pub corner_element_m: Option<f64>,
}

impl Default for SolveOptions {
    /// 4 m patches, 1 m elements, 4 × 4 form-factor samples, seed 0, the hierarchical
    /// solver's BF tolerance, sky tolerance 0.1, the seed's stop rule, no corner refinement.
    fn default() -> Self {
        Self {
            patch_edge_m: 4.0,
            element_edge_m: 1.0,
            object_element_edge_m: BTreeMap::new(),
            samples_per_axis: 4,
            seed: 0,
            bf_tolerance: HierarchicalParams::default().bf_tolerance,
            sky_tolerance: 0.1,
            mean_change: StopRule::default().mean_change,
            residual: StopRule::default().residual,
            corner_element_m: None,
        }
    }
}

impl SolveOptions {
    /// The stop rule.
    #[must_use]
    pub fn stop(&self) -> StopRule {
        StopRule {
            mean_change: self.mean_change,
            residual: self.residual,
            ..StopRule::default()
        }
    }

    /// The hierarchical solver with these options' BF tolerance.
    #[must_use]
    pub fn hierarchical(&self) -> Solver {
        Solver::Hierarchical(HierarchicalParams {
            bf_tolerance: self.bf_tolerance,
            ..HierarchicalParams::default()
        })
    }

    /// Solve parameters with `solver` and the ground below the horizon.
    #[must_use]
    pub fn solve_params(&self, solver: Solver, ground: Option<GroundBelowHorizon>) -> SolveParams {
        SolveParams {
            mesh: MeshParams {
                max_patch_edge_m: self.patch_edge_m,
                max_element_edge_m: self.element_edge_m,
                object_element_edge_m: self.object_element_edge_m.clone(),
                corner_element_m: self.corner_element_m,
                ..MeshParams::default()
            },
            form_factors: FormFactorParams {
                samples_per_axis: self.samples_per_axis,
                seed: self.seed,
                visibility: true,
            },
            solver,
            stop: self.stop(),
            ground,
            ..SolveParams::default()
        }
    }

    /// The transfer parameters of the unfolded elevation's irradiance view (`photomontage
    /// elevation --irradiance` and the studio's): the hierarchical solver, linear responses,
    /// Gauss–Seidel sweeps; the ground is set by `site_elevation` from the site.
    #[must_use]
    pub fn elevation_transfer_params(&self) -> TransferParams {
        TransferParams {
            solve: self.solve_params(self.hierarchical(), None),
            sky_tolerance: self.sky_tolerance,
            strategy: RelightStrategy::LinearResponses,
            sweep: Sweep::GaussSeidel,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::float_cmp)] // values are copied, never computed
    fn every_option_reaches_the_transfer_parameters() {
        let options = SolveOptions {
            patch_edge_m: 3.0,
            element_edge_m: 0.5,
            object_element_edge_m: BTreeMap::from([("model:box".to_owned(), 0.25)]),
            samples_per_axis: 6,
            seed: 9,
            bf_tolerance: 0.004,
            sky_tolerance: 0.2,
            mean_change: 0.02,
            residual: 1e-4,
            corner_element_m: Some(0.125),
        };
        let t = options.elevation_transfer_params();
        let s = &t.solve;
        assert_eq!(
            (s.mesh.max_patch_edge_m, s.mesh.max_element_edge_m),
            (3.0, 0.5)
        );
        assert_eq!(s.mesh.object_element_edge_m["model:box"], 0.25);
        assert_eq!(s.mesh.corner_element_m, Some(0.125));
        assert_eq!(
            (s.form_factors.samples_per_axis, s.form_factors.seed),
            (6, 9)
        );
        match s.solver {
            Solver::Hierarchical(h) => assert_eq!(h.bf_tolerance, 0.004),
            _ => panic!("hierarchical expected"),
        }
        assert_eq!((s.stop.mean_change, s.stop.residual), (0.02, 1e-4));
        assert_eq!(t.sky_tolerance, 0.2);
        assert_eq!(
            (t.strategy, t.sweep),
            (RelightStrategy::LinearResponses, Sweep::GaussSeidel)
        );
    }
}
