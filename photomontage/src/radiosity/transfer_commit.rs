//! Applying a traced relight ([`Transfer::commit_relight`]): scalings, the sun step through the
//! axis responses, and the warm-started iteration of every group a change touches (the module
//! doc of `transfer.rs`).

use super::*;

/// A group a relight iterates: its index, its emitting materials' exitance per element (if it
/// has any), the ratio its gathered part is carried with, and whether the kept remainder goes
/// into the unshot part.
struct Pending {
    g: usize,
    emitted: Option<Vec<Rgb>>,
    carry: Rgb,
    pass_on: bool,
}

/// What one group's warm start reads (the doc in [`Transfer::commit_relight`]).
struct Warm<'a> {
    rho_new: &'a [Rgb],
    /// ρ before a material change (`None`: unchanged).
    rho_old: Option<&'a [Rgb]>,
    direct: &'a [Rgb],
    emitted: Option<&'a [Rgb]>,
    radiosity: &'a [Rgb],
    b0_old: &'a [Rgb],
    /// The kept remainder, where it is passed on.
    left: Option<&'a [Rgb]>,
    carry: Rgb,
}

impl Warm<'_> {
    /// Element `e`'s new initial exitance (as `initial_exitance_from`), warm start and unshot
    /// part: D = start − old (bit-equal values pass nothing on) plus the carried remainder.
    #[inline]
    fn at(&self, e: usize) -> (Rgb, Rgb, Rgb) {
        let (rho, direct) = (self.rho_new[e], self.direct[e]);
        let emitted = self.emitted.map_or([0.0; 3], |m| m[e]);
        let b0_new: Rgb = std::array::from_fn(|c| rho[c] * direct[c] + emitted[c]);
        let (b, b0_old) = (self.radiosity[e], self.b0_old[e]);
        let rho_old = self.rho_old.map_or(rho, |r| r[e]);
        let left = self.left.map_or([0.0; 3], |l| l[e]);
        let mut start = [0.0; 3];
        let mut unshot = [0.0; 3];
        for c in 0..3 {
            let gathered = b[c] - b0_old[c];
            let k = rho_ratio(rho[c], rho_old[c]);
            start[c] = b0_new[c] + k * self.carry[c] * gathered;
            let d = if start[c].to_bits() == b[c].to_bits() {
                0.0
            } else {
                start[c] - b[c]
            };
            unshot[c] = d + k * self.carry[c] * left[c];
        }
        (b0_new, start, unshot)
    }

    /// The new initial exitance and the warm start of every element, into `b0_new` and `start`.
    fn fill(&self, b0_new: &mut [Rgb], start: &mut [Rgb]) {
        b0_new
            .par_iter_mut()
            .zip(start.par_iter_mut())
            .enumerate()
            .for_each(|(e, (b0, s))| {
                let (b0_e, s_e, _) = self.at(e);
                (*b0, *s) = (b0_e, s_e);
            });
    }
}

/// Elements per chunk of the warm start written straight into the shooting's leaves.
const WARM_CHUNK: usize = 2048;

/// Every group's warm start in one pass over chunks of elements: the new initial exitance into
/// `b0_new` (one buffer per group) and the warm start and unshot part into the shooting's leaves
/// `b` and `u` (3 values per group and element, group-major within an element; [`Leaves::Filled`]).
fn fill_leaves(warm: &[Warm<'_>], b0_new: &mut [Vec<Rgb>], b: &mut [f64], u: &mut [f32]) {
    let stride = 3 * warm.len();
    let n = b.len() / stride.max(1);
    let mut parts: Vec<Vec<&mut [Rgb]>> = (0..n.div_ceil(WARM_CHUNK))
        .map(|_| Vec::with_capacity(warm.len()))
        .collect();
    for buffer in b0_new.iter_mut() {
        for (c, part) in buffer.chunks_mut(WARM_CHUNK).enumerate() {
            parts[c].push(part);
        }
    }
    b.par_chunks_mut(WARM_CHUNK * stride)
        .zip(u.par_chunks_mut(WARM_CHUNK * stride))
        .zip(parts)
        .enumerate()
        .for_each(|(c, ((b, u), mut b0_parts))| {
            for (i, (b, u)) in b
                .chunks_exact_mut(stride)
                .zip(u.chunks_exact_mut(stride))
                .enumerate()
            {
                let e = c * WARM_CHUNK + i;
                for (g, (w, b0)) in warm.iter().zip(b0_parts.iter_mut()).enumerate() {
                    let (b0_e, start, unshot) = w.at(e);
                    b0[i] = b0_e;
                    b[3 * g..3 * g + 3].copy_from_slice(&start);
                    #[allow(clippy::cast_possible_truncation)] // shot as `f32` (shooting.rs)
                    u[3 * g..3 * g + 3].copy_from_slice(&unshot.map(|v| v as f32));
                }
            }
        });
}

/// ρ′/ρ, the factor an element's gathered light (and kept remainder) is carried over with; 0
/// where ρ was 0 (nothing was gathered).
fn rho_ratio(new: f64, old: f64) -> f64 {
    if old > 0.0 { new / old } else { 0.0 }
}

impl Transfer {
    /// Applies a relight traced by [`Transfer::prepare_relight`] on this transfer (its solves).
    pub fn commit_relight(&mut self, prepared: PreparedRelight) {
        let PreparedRelight {
            lighting,
            reflectance,
            element_mesh,
            new_groups,
            warnings,
            mut actions,
            mut retraced,
            sun_counts,
        } = prepared;
        self.material_table = None;
        let material_changed = reflectance.is_some() || element_mesh.is_some();
        let linear = self.params.strategy == RelightStrategy::LinearResponses;
        // A sun step through the axis responses (sun_basis.rs): the sun group is done here and
        // kept by the loop below.
        let by_axes = (linear && self.params.sweep == Sweep::Shooting && !material_changed)
            .then(|| sun_basis::axes_source(&self.kinds, &new_groups))
            .flatten()
            .filter(|(g, _)| actions[*g] == Action::Retrace && retraced[*g].is_some());
        if by_axes.is_none() || sun_counts.is_none() {
            self.settle_sun_axes();
        }
        if material_changed {
            self.sun_basis = None;
        }
        if let (Some((g, source)), Some(counts)) = (by_axes, sun_counts.as_ref()) {
            // The group's composed remainder and initial exitance are written when something
            // other than a sun step reads them (`settle_sun_axes`).
            let direct = retraced[g].take().unwrap_or_default();
            let rows = self.relight_sun_by_axes(g, &source, counts);
            let group = &mut self.solution.groups[g];
            group.direct_irradiance_rgb = Arc::new(direct);
            group.convergence = rows;
            actions[g] = Action::Keep;
        }
        if let Some(mesh) = element_mesh {
            self.solution.mesh = Arc::new(mesh);
        }
        if let Some(rho) = reflectance {
            let mesh = Arc::make_mut(&mut self.solution.mesh);
            for (s, r) in mesh.surfaces.iter_mut().zip(rho) {
                s.reflectance_rgb = r;
            }
        }
        let old_rho: Option<Vec<Rgb>> = material_changed.then(|| {
            let new = self.topology.element_reflectances(&self.solution.mesh);
            std::mem::replace(&mut self.element_rho, new)
        });
        let new_rho = &self.element_rho;
        let mut solution_warnings: Vec<LightWarning> = self
            .solution
            .warnings
            .iter()
            .filter(|w| !matches!(w, LightWarning::SunBelowHorizon { .. }))
            .cloned()
            .collect();
        solution_warnings.extend(warnings);
        // Groups to iterate: index, new initial exitance, warm start, unshot part.
        let mut pending: Vec<Pending> = Vec::new();
        for (g, action) in actions.into_iter().enumerate() {
            let emission = self.groups[g].emission;
            let group = &mut self.solution.groups[g];
            let scale = match &action {
                Action::Scale(k) => Some(*k),
                _ => None,
            };
            if let Some(direct) = retraced[g].take() {
                group.direct_irradiance_rgb = Arc::new(direct);
            } else if let Some(k) = scale {
                for d in Arc::make_mut(&mut group.direct_irradiance_rgb) {
                    for c in 0..3 {
                        d[c] *= k[c];
                    }
                }
            }
            if action == Action::Keep && !material_changed {
                continue;
            }
            if let (Some(k), true, false) = (scale, linear, material_changed) {
                // The response is linear in the group's sources: scale it, exactly.
                for (b, b0) in Arc::make_mut(&mut group.radiosity_rgb)
                    .iter_mut()
                    .zip(&mut self.b0s[g])
                {
                    for c in 0..3 {
                        b[c] *= k[c];
                        b0[c] *= k[c];
                    }
                }
                for u in &mut self.unshot[g] {
                    for c in 0..3 {
                        u[c] *= k[c];
                    }
                }
                group.convergence.clear();
                continue;
            }
            let emitted = emission.then(|| self.topology.element_emissions(&self.solution.mesh));
            let carry = if linear {
                scale.unwrap_or([1.0; 3])
            } else {
                [1.0; 3]
            };
            // The warm start ([`Warm`], each element on its own, in parallel: the same values
            // on any number of threads) gives the shooting its unshot part: D = start − old
            // (bit-equal values pass nothing on), plus the group's kept remainder, carried over
            // as the gathered part is, once that carries more than the stop rule's residual of
            // the group's power. Until then it is only kept (scaled after the shooting), so a
            // step shoots what it changed and the solution stays within twice the stop rule of
            // its fixed point however long the series.
            let kept = &self.unshot[g];
            let areas = &self.topology.areas;
            let pass_on = !kept.is_empty() && {
                let (kept, all) =
                    rayon::join(|| power(kept, areas), || power(&group.radiosity_rgb, areas));
                kept > self.params.solve.stop.residual * all
            };
            // A dark group (sun down, sky off, light off: the new initial exitance, as
            // `Warm::at` computes it, is 0 everywhere): B = 0 exactly.
            let direct = &group.direct_irradiance_rgb;
            let lit = direct
                .par_iter()
                .zip(new_rho.par_iter())
                .enumerate()
                .any(|(e, (d, rho))| {
                    let m = emitted.as_deref().map_or([0.0; 3], |m| m[e]);
                    (0..3).any(|c| rho[c] * d[c] + m[c] != 0.0)
                });
            if !lit {
                let mut zeros = self.scratch.take_rgb(new_rho.len());
                zeros.fill([0.0; 3]);
                group.radiosity_rgb = Arc::new(zeros.clone());
                group.convergence.clear();
                let old = std::mem::replace(&mut self.b0s[g], zeros);
                self.scratch.give_rgb(old);
                self.unshot[g].clear();
                continue;
            }
            pending.push(Pending {
                g,
                emitted,
                carry,
                pass_on,
            });
        }
        let n = new_rho.len();
        // Per pending group, what its warm start reads, and buffers for its new initial
        // exitance.
        let warm: Vec<Warm<'_>> = pending
            .iter()
            .map(|p| Warm {
                rho_new: new_rho,
                rho_old: old_rho.as_deref(),
                direct: &self.solution.groups[p.g].direct_irradiance_rgb,
                emitted: p.emitted.as_deref(),
                radiosity: &self.solution.groups[p.g].radiosity_rgb,
                b0_old: &self.b0s[p.g],
                left: p.pass_on.then_some(self.unshot[p.g].as_slice()),
                carry: p.carry,
            })
            .collect();
        let mut b0_news: Vec<Vec<Rgb>> = warm.iter().map(|_| self.scratch.take_rgb(n)).collect();
        if self.params.sweep == Sweep::Shooting && !pending.is_empty() {
            // Shooting passes on D = start − old, which holds only if the old solution's
            // interreflected part scales with ρ. Where a channel's ρ was 0 and is not now, the
            // old solution kept nothing of the light that element gathers: those groups are
            // shot cold, from B₀′ with nothing old (the old solution of a dark scene, B = 0).
            let lit_from_zero = old_rho.as_ref().is_some_and(|old| {
                old.par_iter()
                    .zip(new_rho.par_iter())
                    .any(|(o, n)| (0..3).any(|c| o[c] == 0.0 && n[c] != 0.0))
            });
            let zeros: Vec<Rgb> = if lit_from_zero {
                vec![[0.0; 3]; n]
            } else {
                Vec::new()
            };
            let (shot, leaves): (Vec<ShotGroup<'_>>, Leaves) = if lit_from_zero {
                for (w, b0_new) in warm.iter().zip(&mut b0_news) {
                    let mut start = self.scratch.take_rgb(n);
                    w.fill(b0_new, &mut start);
                    self.scratch.give_rgb(start);
                }
                let shot = pending
                    .iter()
                    .zip(&b0_news)
                    .map(|(p, b0_new)| ShotGroup {
                        keep_unshot: true,
                        ..ShotGroup::against(
                            &self.solution.groups[p.g].name,
                            &zeros,
                            b0_new.clone(),
                        )
                    })
                    .collect();
                (shot, Leaves::InGroups)
            } else {
                // The warm start goes straight into the shooting's leaves, every group in one
                // pass; the groups' buffers receive the results.
                let shot = pending
                    .iter()
                    .map(|p| ShotGroup {
                        name: &self.solution.groups[p.g].name,
                        old: &[],
                        start: self.scratch.take_rgb(n),
                        unshot: Some(self.scratch.take_rgb(n)),
                        keep_unshot: true,
                    })
                    .collect();
                let (b, u) = self.scratch.leaves(n, 3 * warm.len());
                fill_leaves(&warm, &mut b0_news, b, u);
                (shot, Leaves::Filled)
            };
            let results = shoot(
                &self.topology,
                &self.source_rows,
                new_rho,
                shot,
                leaves,
                &self.params.solve.stop,
                &self.patch_links,
                &mut self.scratch,
            );
            drop(warm);
            for ((p, b0_new), shot) in pending.into_iter().zip(b0_news).zip(results) {
                let g = p.g;
                let group = &mut self.solution.groups[g];
                let old = std::mem::replace(&mut group.radiosity_rgb, Arc::new(shot.radiosity));
                group.convergence = shot.rows;
                // The old buffers go back to the scratch (where no clone of the solution
                // holds the radiosity).
                if let Ok(old) = Arc::try_unwrap(old) {
                    self.scratch.give_rgb(old);
                }
                let old = std::mem::replace(&mut self.b0s[g], b0_new);
                self.scratch.give_rgb(old);
                let remainder = shot.unshot.unwrap_or_default();
                if p.pass_on || lit_from_zero || self.unshot[g].len() != remainder.len() {
                    let old = std::mem::replace(&mut self.unshot[g], remainder);
                    self.scratch.give_rgb(old);
                } else {
                    // Kept, not passed on: scaled as the gathered part, plus this remainder.
                    let old_rho = old_rho.as_deref();
                    self.unshot[g]
                        .par_iter_mut()
                        .zip(remainder.par_iter())
                        .enumerate()
                        .for_each(|(e, (u, r))| {
                            let rho_old = old_rho.map_or(new_rho[e], |o| o[e]);
                            for c in 0..3 {
                                let k = rho_ratio(new_rho[e][c], rho_old[c]);
                                u[c] = k * p.carry[c] * u[c] + r[c];
                            }
                        });
                    self.scratch.give_rgb(remainder);
                }
            }
        } else {
            let starts: Vec<Vec<Rgb>> = warm
                .iter()
                .zip(&mut b0_news)
                .map(|(w, b0_new)| {
                    let mut start = self.scratch.take_rgb(n);
                    w.fill(b0_new, &mut start);
                    start
                })
                .collect();
            drop(warm);
            for ((Pending { g, .. }, b0_new), start) in pending.into_iter().zip(b0_news).zip(starts)
            {
                self.unshot[g].clear();
                let group = &mut self.solution.groups[g];
                let (radiosity, rows) = iterate(
                    &self.solution.mesh,
                    &self.rows,
                    &self.topology,
                    new_rho,
                    &b0_new,
                    &start,
                    &group.name,
                    &self.params.solve.stop,
                    self.params.sweep,
                );
                group.radiosity_rgb = Arc::new(radiosity);
                group.convergence = rows;
                let old = std::mem::replace(&mut self.b0s[g], b0_new);
                self.scratch.give_rgb(old);
                self.scratch.give_rgb(start);
            }
        }
        self.groups = new_groups;
        self.lighting = lighting;
        self.solution.warnings = solution_warnings;
        self.solution.locator = std::sync::OnceLock::new();
        // The kept ρ is derived state: in test builds, check it bit for bit against the mesh's
        // own lookup.
        debug_assert!(
            (0..self.element_rho.len()).all(|e| self.element_rho[e].map(f64::to_bits)
                == self
                    .solution
                    .mesh
                    .element_reflectance_rgb(e)
                    .map(f64::to_bits)),
            "the transfer's ρ per element follows its mesh"
        );
    }
}
