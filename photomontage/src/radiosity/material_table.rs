//! One material's reflectance as an interactive parameter: the transfer's solution tabulated in
//! it ([`Transfer::relight_material`]).
//!
//! A colour designer drags one material's colour while the sun, the sky, the lamps and every
//! other material stay put. Per channel c the radiosity of every element is then a function of
//! that material's ρ_c alone (the channels do not mix): with R(s) the reflectances with
//! ρ_c = s on the material's elements, B(s) = (I − R(s)·F)⁻¹·B₀(s), a rational function of s
//! whose poles lie where the spectral radius of R(s)·F reaches 1, i.e. beyond s = 1 (at s = 1
//! itself only for a closed enclosure of that one material). On [0, 1] it is analytic, so its
//! Chebyshev interpolant converges geometrically (Trefethen, *Approximation Theory and
//! Approximation Practice*, SIAM 2013, ch. 8: error O(r⁻ⁿ) for a function analytic inside the
//! Bernstein ellipse of parameter r).
//!
//! The table is [`TABLE_NODES`] relights of the transfer to the Chebyshev points of the first
//! kind s_j = (1 + cos(π(j + ½)/N))/2, with the stop rule tightened by [`NODE_STOP_FACTOR`]; the
//! coefficients per element, channel and light group come from the discrete cosine transform of
//! the node values. A later change of the same material to any ρ ∈ [0, 1]³ is then, per element
//! and channel, one Clenshaw sum (no link is read). How well the table holds is measured, not
//! assumed: the table is refused, and the change relit exactly, when the last two
//! coefficients carry more than the stop rule's residual of any group's area-weighted
//! luminance ([`MaterialTableReport::tail`]); the relight checks that bound, and the tests
//! compare the table with exact relights between the nodes.
//!
//! Any other change (sun, sky, a lamp, another material, the per-element reflectances) drops the
//! table, and the next change of a material builds one again.
//!
//! # Known limitations
//! The node values carry the solves' own error (the tightened residual), which the interpolant
//! passes on times its Lebesgue constant (≈ 2.2 for 8 nodes). A solution read from the table is
//! within that of the exact fixed point, not at it; a following exact relight starts from it as
//! from any solution. Building the table costs about [`TABLE_NODES`] material relights at the
//! tightened stop rule, once per material edited.

use std::sync::Arc;

use rayon::prelude::*;

use super::{LightingChange, Transfer, initial_exitance_from};
use crate::radiosity::{RadiosityError, Rgb, StopRule, luminance};

/// Chebyshev points per table (the interpolant's degree + 1).
pub const TABLE_NODES: usize = 8;
/// The node solves' stop rule: the transfer's residual and mean change times this.
pub const NODE_STOP_FACTOR: f64 = 0.1;

/// A material's table: Chebyshev coefficients per light group, element, coefficient and channel.
#[derive(Debug, Clone)]
pub(super) struct MaterialTable {
    /// The material's index among the transfer's materials.
    material: usize,
    /// Per group, `coeffs[(e·N + k)·3 + c]` (the first halved, as Clenshaw's sum takes it).
    coeffs: Vec<Vec<f32>>,
}

/// What the transfer keeps about the material being edited.
#[derive(Debug, Clone)]
pub(super) enum TableState {
    /// A table of this material.
    Table(MaterialTable),
    /// A table of this material was refused (its tail over the bound): its changes relight
    /// exactly until something else changes.
    Refused(usize),
}

/// What [`Transfer::relight_material`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialTableReport {
    /// A table was built for this change (`TABLE_NODES` node relights).
    pub built: bool,
    /// The change was read from a table (`false`: relit exactly, the table refused).
    pub from_table: bool,
    /// The largest share of a group's area-weighted luminance in the table's last two
    /// coefficients, when this change built a table.
    pub tail: Option<f64>,
}

/// The Chebyshev points of the first kind, mapped to [0, 1].
#[must_use]
pub fn table_nodes() -> [f64; TABLE_NODES] {
    #[allow(clippy::cast_precision_loss)]
    std::array::from_fn(|j| {
        0.5 * (1.0 + (std::f64::consts::PI * (j as f64 + 0.5) / TABLE_NODES as f64).cos())
    })
}

/// Chebyshev coefficients of the values `f[j]` at [`table_nodes`] (the first halved).
#[must_use]
pub fn chebyshev_coefficients(f: &[f64; TABLE_NODES]) -> [f64; TABLE_NODES] {
    #[allow(clippy::cast_precision_loss)]
    let n = TABLE_NODES as f64;
    let mut c: [f64; TABLE_NODES] = std::array::from_fn(|k| {
        #[allow(clippy::cast_precision_loss)]
        let sum: f64 = f
            .iter()
            .enumerate()
            .map(|(j, v)| v * (std::f64::consts::PI * k as f64 * (j as f64 + 0.5) / n).cos())
            .sum();
        2.0 * sum / n
    });
    c[0] *= 0.5;
    c
}

/// Clenshaw's sum Σ c_k·T_k(2s − 1) of coefficients from [`chebyshev_coefficients`].
#[must_use]
pub fn chebyshev_value(c: &[f64], s: f64) -> f64 {
    let x = 2.0 * s - 1.0;
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        let b = ck + 2.0 * x * b1 - b2;
        b2 = b1;
        b1 = b;
    }
    c.first().copied().unwrap_or(0.0) + x * b1 - b2
}

/// [`chebyshev_value`] over one element's `f32` coefficients of one channel (stride 3).
fn clenshaw_f32(c: &[f32], channel: usize, x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for k in (1..TABLE_NODES).rev() {
        let b = f64::from(c[k * 3 + channel]) + 2.0 * x * b1 - b2;
        b2 = b1;
        b1 = b;
    }
    f64::from(c[channel]) + x * b1 - b2
}

impl Transfer {
    /// Changes material `name`'s diffuse reflectance to `value` (each channel in [0, 1]) and
    /// nothing else, through the material's table (module doc): built by this call when the
    /// transfer has none for `name`, read when it has. The result is [`Transfer::relight`]'s
    /// within the table's error; a refused table relights exactly.
    ///
    /// # Errors
    /// [`RadiosityError::UnknownMaterial`], [`RadiosityError::InvalidSource`] for a value out of
    /// range; on error nothing changes.
    pub fn relight_material(
        &mut self,
        name: &str,
        value: Rgb,
    ) -> Result<MaterialTableReport, RadiosityError> {
        let change = LightingChange {
            material_reflectance: vec![(name.to_owned(), value)],
            ..LightingChange::default()
        };
        // Checks the name and the value before anything changes.
        self.apply_to_lighting(&change)?;
        let m = self
            .material_names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| RadiosityError::UnknownMaterial {
                material: name.to_owned(),
            })?;
        match self.material_table.take() {
            Some(TableState::Table(table)) if table.material == m => {
                self.read_table(&table, value);
                self.material_table = Some(TableState::Table(table));
                return Ok(MaterialTableReport {
                    built: false,
                    from_table: true,
                    tail: None,
                });
            }
            Some(TableState::Refused(r)) if r == m => {
                self.relight_in_place(&change)?;
                self.material_table = Some(TableState::Refused(m));
                return Ok(MaterialTableReport {
                    built: false,
                    from_table: false,
                    tail: None,
                });
            }
            _ => {}
        }
        let (table, tail) = self.build_table(m, name)?;
        if tail <= self.params.solve.stop.residual {
            self.read_table(&table, value);
            self.material_table = Some(TableState::Table(table));
            Ok(MaterialTableReport {
                built: true,
                from_table: true,
                tail: Some(tail),
            })
        } else {
            self.relight_in_place(&change)?;
            self.material_table = Some(TableState::Refused(m));
            Ok(MaterialTableReport {
                built: true,
                from_table: false,
                tail: Some(tail),
            })
        }
    }

    /// Relights to every node of the table of material `m` and returns the table with its tail.
    fn build_table(
        &mut self,
        m: usize,
        name: &str,
    ) -> Result<(MaterialTable, f64), RadiosityError> {
        let stop = self.params.solve.stop;
        self.params.solve.stop = StopRule {
            mean_change: stop.mean_change * NODE_STOP_FACTOR,
            residual: stop.residual * NODE_STOP_FACTOR,
            ..stop
        };
        let nodes = table_nodes();
        let elements = self.element_rho.len();
        let groups = self.solution.groups.len();
        // Per node, per group, the radiosity of every element.
        let mut values: Vec<Vec<Vec<Rgb>>> = Vec::with_capacity(TABLE_NODES);
        // Ascending s (the points come descending): each node relight is a small step.
        let mut failed = None;
        for &s in nodes.iter().rev() {
            let change = LightingChange {
                material_reflectance: vec![(name.to_owned(), [s; 3])],
                ..LightingChange::default()
            };
            if let Err(e) = self.relight_in_place(&change) {
                failed = Some(e);
                break;
            }
            values.push(
                self.solution
                    .groups
                    .iter()
                    .map(|g| g.radiosity_rgb.to_vec())
                    .collect(),
            );
        }
        self.params.solve.stop = stop;
        if let Some(e) = failed {
            return Err(e);
        }
        values.reverse();
        let areas = &self.topology.areas;
        let mut coeffs = Vec::with_capacity(groups);
        let mut tail: f64 = 0.0;
        for g in 0..groups {
            let per_element: Vec<([f32; TABLE_NODES * 3], f64, f64)> = (0..elements)
                .into_par_iter()
                .map(|e| {
                    let mut out = [0.0_f32; TABLE_NODES * 3];
                    let (mut head, mut last) = ([0.0; 3], [0.0; 3]);
                    for c in 0..3 {
                        let f: [f64; TABLE_NODES] = std::array::from_fn(|j| values[j][g][e][c]);
                        let k = chebyshev_coefficients(&f);
                        for (i, v) in k.iter().enumerate() {
                            #[allow(clippy::cast_possible_truncation)]
                            {
                                out[i * 3 + c] = *v as f32;
                            }
                        }
                        head[c] = k[0].abs();
                        last[c] = k[TABLE_NODES - 1].abs() + k[TABLE_NODES - 2].abs();
                    }
                    (
                        out,
                        areas[e] * luminance(&head),
                        areas[e] * luminance(&last),
                    )
                })
                .collect();
            let (head, last) = per_element
                .iter()
                .fold((0.0, 0.0), |(h, l), (_, a, b)| (h + a, l + b));
            if head > 0.0 {
                tail = tail.max(last / head);
            }
            coeffs.push(per_element.into_iter().flat_map(|(c, _, _)| c).collect());
        }
        Ok((
            MaterialTable {
                material: m,
                coeffs,
            },
            tail,
        ))
    }

    /// Sets the material of `table` to `value` and every group's radiosity to the table's.
    fn read_table(&mut self, table: &MaterialTable, value: Rgb) {
        let m = table.material;
        let mesh = std::sync::Arc::make_mut(&mut self.solution.mesh);
        for (s, &sm) in mesh.surfaces.iter_mut().zip(&self.surface_material) {
            if sm == m {
                s.reflectance_rgb = value;
            }
        }
        self.element_rho = self.topology.element_reflectances(&self.solution.mesh);
        let x = value.map(|v| 2.0 * v - 1.0);
        for (g, coeffs) in table.coeffs.iter().enumerate() {
            let emitted = self.groups[g]
                .emission
                .then(|| self.topology.element_emissions(&self.solution.mesh));
            let group = &mut self.solution.groups[g];
            self.b0s[g] = initial_exitance_from(
                &self.element_rho,
                &group.direct_irradiance_rgb,
                emitted.as_deref(),
            );
            Arc::make_mut(&mut group.radiosity_rgb)
                .par_iter_mut()
                .zip(coeffs.par_chunks_exact(TABLE_NODES * 3))
                .for_each(|(b, c)| {
                    *b = std::array::from_fn(|ch| clenshaw_f32(c, ch, x[ch]));
                });
            group.convergence.clear();
            // The table's values carry the node solves' error, not a kept remainder.
            self.unshot[g].clear();
        }
        // The axis responses hold for the old reflectances.
        self.sun_basis = None;
        self.solution.locator = std::sync::OnceLock::new();
    }
}
