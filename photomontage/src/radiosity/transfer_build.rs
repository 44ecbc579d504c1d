//! Building a [`Transfer`]: the mesh, the links with their form factors, the sky's and the sun's
//! rays and every light group's first solution (the module doc of `transfer.rs`).

use super::*;

impl Transfer {
    /// Precomputes the transfer of `scene` and solves `lighting` on it (module doc). The
    /// initial solution is [`crate::radiosity::solve`]'s for the same groups and parameters.
    ///
    /// # Errors
    /// Meshing, tracing and parameter errors (the solver must be hierarchical),
    /// [`RadiosityError::Cancelled`].
    pub fn build(
        scene: &Scene,
        lighting: &TransferLighting,
        params: &TransferParams,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
    ) -> Result<Self, RadiosityError> {
        Self::build_shadowed_by(scene, &[], lighting, params, cancel, on_pass)
    }

    /// [`Transfer::build`] with the mesh refined along the sun shadow edges that each of
    /// `occluders` casts instead of `scene`'s own ([`Mesh::build_lit`], when
    /// [`crate::radiosity::MeshParams::shadow_edge_element_m`] is set): a site's two transfers are both
    /// meshed along the shadows of the scene with and without the planned objects, so that
    /// their natural surfaces are meshed alike and each resolves its own shadows.
    ///
    /// # Errors
    /// As [`Transfer::build`].
    pub fn build_shadowed_by(
        scene: &Scene,
        occluders: &[&SceneTracer],
        lighting: &TransferLighting,
        params: &TransferParams,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
    ) -> Result<Self, RadiosityError> {
        Self::build_beside(scene, occluders, lighting, params, cancel, on_pass, None)
    }

    /// [`Transfer::build_shadowed_by`] for a scene that is `natural`'s scene plus the planned
    /// objects `artificial` ([`crate::radiosity::twin`]): the elements it shares with `natural`'s mesh
    /// draw their direct-light points from their twins' streams and read the twins' sky rays
    /// (tracing only the planned objects' own). The twin is not used when the two tracers'
    /// local frames differ or there is nothing planned.
    ///
    /// # Errors
    /// As [`Transfer::build`].
    pub fn build_beside(
        scene: &Scene,
        occluders: &[&SceneTracer],
        lighting: &TransferLighting,
        params: &TransferParams,
        cancel: &AtomicBool,
        on_pass: &dyn Fn(&ConvergenceRow),
        natural: Option<(&Transfer, &Scene)>,
    ) -> Result<Self, RadiosityError> {
        params.solve.stop.validate()?;
        let Solver::Hierarchical(h) = params.solve.solver else {
            return Err(RadiosityError::InvalidParameter {
                name: "solver",
                value: f64::NAN,
                reason: "a transfer needs the hierarchical solver (its links are what is stored)",
            });
        };
        let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath())?;
        let (groups, mut warnings) = lighting.light_groups(&dome, params.sky_tolerance)?;
        // As `solve`: refined along the shadow edges of the sun it is built with.
        let mut mesh = Mesh::build_lit(
            scene,
            &params.solve.mesh,
            &sun_directions(&groups),
            occluders,
        )?;
        let tracer = SceneTracer::new(scene, BuildQuality::Medium)?;
        // As `solve_on_mesh`: element parts covered by a solid standing on them do not emit.
        if params.solve.form_factors.visibility {
            crate::radiosity::covered::mark_covered(&mut mesh, &tracer, &params.solve.form_factors);
        }
        // The planned objects alone, in this tracer's frame, and each element's twin.
        let twin = match natural {
            Some((t, artificial)) => Twin::new(
                twin_elements(&t.solution.mesh, &mesh),
                t.solution.mesh.elements.len(),
                &t.tracer,
                &tracer,
                artificial,
                &mesh,
            )?
            .map(|twin| (twin, t)),
            None => None,
        };
        // The natural transfer's form factors, read where they are the same
        // (`crate::radiosity::twin_factors`).
        let reuse = twin.as_ref().and_then(|(t, natural)| {
            let factors = natural.sky_rays.factors.as_deref()?;
            FactorReuse::new(factors, t, &mesh, params.solve.form_factors)
        });
        let engine = FormFactorEngine::new(&mesh, &tracer, params.solve.form_factors)?
            .with_direct_streams(twin.as_ref().map(|(t, _)| t.streams.as_slice()))
            .with_node_streams(reuse.as_ref().map(FactorReuse::streams));
        let ground = GroundTerm::new(&engine, params.solve.ground.as_ref())?;
        let n = mesh.elements.len();
        let mut directs = Vec::with_capacity(groups.len());
        let mut b0s = Vec::with_capacity(groups.len());
        // Groups 0 and 1 are the sun and the sky (`kinds` below).
        let direct_samples: Vec<Option<Arc<DirectSamples>>> = (0..groups.len())
            .map(|g| (g < 2).then(|| Arc::new(DirectSamples::new(&engine, g as u64))))
            .collect();
        // Group 1's sample points (the sky's) are where the sky transfer looks from.
        let sky_transfer = SkyTransfer::beside(
            &engine,
            direct_samples[1]
                .as_deref()
                .unwrap_or_else(|| unreachable!("the sky group has sample points")),
            &dome,
            twin.as_ref().map(|(t, natural)| (t, &natural.sky_rays, 1)),
        );
        for (g, group) in groups.iter().enumerate() {
            warnings.extend(sources::check_point_sources(
                &tracer,
                &group.name,
                &group.points,
                &mesh.object_names,
            ));
            let direct = group_direct(
                &engine,
                group,
                g as u64,
                ground.as_ref(),
                direct_samples[g].as_deref(),
                Some(&sky_transfer),
            )?;
            b0s.push(initial_exitance(&mesh, &direct, group.emission));
            directs.push(direct);
        }
        let mut b0_all = vec![[0.0; 3]; n];
        for b0 in &b0s {
            for (t, b) in b0_all.iter_mut().zip(b0) {
                for c in 0..3 {
                    t[c] += b[c];
                }
            }
        }
        let (hierarchy, computed) = Hierarchy::build_reusing(
            &engine,
            &h,
            &b0_all,
            &params.solve.stop,
            cancel,
            on_pass,
            reuse.as_ref(),
        )?;
        let mut solved = Vec::with_capacity(groups.len());
        for ((group, b0), direct) in groups.iter().zip(&b0s).zip(directs) {
            let (radiosity, convergence) =
                hierarchy.solve(&mesh, b0, &group.name, &params.solve.stop, cancel, on_pass)?;
            solved.push(GroupSolution {
                name: group.name.clone(),
                direct_irradiance_rgb: Arc::new(direct),
                radiosity_rgb: Arc::new(radiosity),
                convergence,
            });
        }
        let mut kinds = vec![GroupKind::Sun, GroupKind::Sky];
        kinds.extend((0..lighting.luminaires.len()).map(GroupKind::Luminaire));
        if lighting.emitters {
            kinds.push(GroupKind::Emitters);
        }
        let material_names: Vec<String> =
            scene.materials().iter().map(|m| m.name.clone()).collect();
        let surface_material = mesh
            .surfaces
            .iter()
            .map(|s| scene.triangles()[s.scene_triangle].material.0 as usize)
            .collect();
        let rows = LinkRows::new(mesh.nodes.len(), &hierarchy);
        let source_rows = SourceRows::new(mesh.nodes.len(), &hierarchy.links);
        let topology = Topology::new(&mesh);
        let patch_links = source_rows.patch_links(&topology.patch_ranges);
        let element_rho = topology.element_reflectances(&mesh);
        let mesh = Arc::new(mesh);
        // A natural transfer lends its form factors to one built beside it.
        let factors = twin.is_none().then(|| {
            Arc::new(NaturalFactors::new(
                Arc::clone(&mesh),
                params.solve.form_factors,
                computed.iter().map(Link::triple),
            ))
        });
        Ok(Self {
            tracer,
            params: params.clone(),
            rows,
            source_rows,
            patch_links,
            scratch: ShootScratch::default(),
            topology,
            element_rho,
            ground,
            surface_material,
            material_names,
            lighting: lighting.clone(),
            kinds,
            groups,
            unshot: vec![Vec::new(); b0s.len()],
            b0s,
            direct_samples,
            sky_rays: SkyRays {
                group: 1,
                transfer: sky_transfer,
                factors,
            },
            solution: Solution {
                mesh,
                groups: solved,
                interactions: hierarchy.links.len() as u64,
                refinement: hierarchy.refinement,
                warnings,
                locator: std::sync::OnceLock::new(),
                query_geometry: std::sync::OnceLock::new(),
            },
            material_table: None,
            twin: twin.map(|(t, _)| Arc::new(t)),
            sun_basis: None,
        })
    }
}
