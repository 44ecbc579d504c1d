//! Interactive relighting of a site's radiosity mode (issue 17: "the montage preview updates
//! within a frame for the radiosity part"; Tonn & Donath, seed 000: "the geometry-dependent part
//! of the radiosity solution is calculated once … the lighting situation [sun position, sky type,
//! artificial lights, materials] can then be changed interactively").
//!
//! [`SiteTransfers`] keeps the two precomputed transfers ([`Transfer`]) the renderer's radiosity
//! mode reads ([`super::render_radiosity`]: the site with and without its artificial objects),
//! built with the same light groups and solve parameters as [`super::render_radiosity`]'s
//! solves, so that the first solution is theirs. [`SiteTransfers::update`] then takes the site as
//! it is now and either:
//!
//! - finds nothing changed for the radiosity (the solutions are kept);
//! - expresses the change as a [`LightingChange`] ([`lighting_change`]: a new sun, a new sky, a
//!   luminaire's dimming, a material's diffuse reflectance) and relights both transfers
//!   (never a form factor): the rays first ([`Transfer::prepare_relight`]: the natural
//!   transfer's, then the other's, which reads the natural sun counts through its twins,
//!   [`crate::radiosity::sun_rays`]), then both solves side by side
//!   ([`Transfer::commit_relight`]), which is [`Transfer::relight`] of each, bit for bit; a change of one
//!   material's reflectance and nothing else, the colour designer's edit, goes through
//!   [`Transfer::relight_material`]: its first edit tabulates the solution in that material's
//!   reflectance, and the edits after it read the table (no link is read);
//! - or, when the geometry, the solve parameters or anything a relight cannot express changed (a
//!   model moved, a luminaire added, moved or re-aimed, an emitting material), builds both
//!   transfers again.
//!
//! The geometry is compared through a fingerprint of the scene's triangles, objects and the
//! solve parameters ([`scene_fingerprint`]).
//!
//! # Known limitations
//! A relit solution keeps the links refined for the lighting the transfers were built with
//! ([`crate::radiosity::transfer`]): it equals a fresh solve within the transfer's tolerance, not
//! bit for bit. Both transfers are kept in memory (links of both scenes).

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use super::SiteDocument;
use super::other_photos::other_photos_for;
use super::photo_reflectance::{
    PhotoRefit, PhotoSamples, PhotoView, PhotoViews, REFIT_ROUNDS, refit_transfer,
};
use super::radiosity_lighting::site_transfer_lighting;
use super::render_error::SiteRenderError;
use super::render_radiosity::{
    RadiosityReport, artificial_part, natural_part, same_elements, site_solve_params,
};
use crate::bvh::BuildQuality;
use crate::radiosity::twin::twin_elements;
use crate::radiosity::{
    LightingChange, PreparedRelight, RadiosityError, Solution, Transfer, TransferLighting,
    TransferParams,
};
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::scene::{Scene, SceneTracer};

/// Two luminaire outputs are the same source dimmed when their channel ratios agree within this
/// relative difference (ratios of the same `f64` products differ by rounding only).
pub const DIMMING_RATIO_REL_TOL: f64 = 1e-9;

type Rgb = [f64; 3];

/// What [`SiteTransfers::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransferUpdate {
    /// Both transfers were (re)built: first use, or a change a relight cannot express.
    Built,
    /// The change was applied with [`Transfer::relight`].
    Relit,
    /// Nothing the radiosity depends on changed.
    Unchanged,
}

/// The outcome of an update: what was done and how long it took.
#[derive(Debug, Clone, PartialEq)]
pub struct RelightReport {
    /// Built, relit or unchanged.
    pub update: TransferUpdate,
    /// Wall time of the update (build or relight of both transfers), seconds.
    pub seconds: f64,
    /// After a build, its report (element counts, the photos' reflectances, notes); `None`
    /// after a relight.
    pub build: Option<RadiosityReport>,
}

/// The diffuse reflectance and emission of each material of `scene`, by name (what a relight
/// can change, and what it cannot).
#[must_use]
pub fn material_state(scene: &Scene) -> Vec<(String, Rgb, Option<Rgb>)> {
    scene
        .materials()
        .iter()
        .map(|m| {
            (
                m.name.clone(),
                m.diffuse_reflectance_rgb(),
                m.emission_rgb_w_m2_sr,
            )
        })
        .collect()
}

/// A fingerprint of what a transfer's links depend on: the triangles (vertex bits, object and
/// material index), the objects' names and kinds, and the transfer parameters.
#[must_use]
pub fn scene_fingerprint(scene: &Scene, params: &TransferParams) -> u64 {
    let mut h = DefaultHasher::new();
    for t in scene.triangles() {
        for v in &t.vertices_in_world_m {
            for c in v.iter() {
                c.to_bits().hash(&mut h);
            }
        }
        t.object.0.hash(&mut h);
        t.material.0.hash(&mut h);
    }
    for o in scene.objects() {
        o.name.hash(&mut h);
        format!("{:?}", o.kind).hash(&mut h);
    }
    // The parameters hold floats; their debug text is exact (shortest round-trip form).
    format!("{params:?}").hash(&mut h);
    h.finish()
}

/// The dimming that turns `built` (full output) into `now` (`now`'s own dimming applied), when
/// `now` is `built` dimmed: same position and photometry, every channel in the same ratio.
fn dimming_between(
    built: &crate::radiosity::NamedLuminaire,
    now: &crate::radiosity::NamedLuminaire,
) -> Option<f64> {
    let (a, b) = (&built.source, &now.source);
    if built.name != now.name
        || a.position_in_world_m != b.position_in_world_m
        || a.luminaire != b.luminaire
    {
        return None;
    }
    let mut ratio: Option<f64> = None;
    for c in 0..3 {
        let (full, wanted) = (a.intensity_rgb[c], b.intensity_rgb[c] * now.dimming);
        if full == 0.0 {
            if wanted != 0.0 {
                return None;
            }
            continue;
        }
        let k = wanted / full;
        match ratio {
            None => ratio = Some(k),
            Some(r) if (r - k).abs() <= DIMMING_RATIO_REL_TOL * r.abs().max(k.abs()) => {}
            Some(_) => return None,
        }
    }
    Some(ratio.unwrap_or(0.0))
}

/// The [`LightingChange`] that takes a transfer from `current` (its lighting and material
/// state) to `target`, or `None` when a relight cannot express the difference (luminaires
/// added, removed, moved, re-aimed or recoloured unevenly; emitters or emission changed; a
/// material added or removed). An empty change means nothing changed.
#[must_use]
pub fn lighting_change(
    current: &TransferLighting,
    target: &TransferLighting,
    current_materials: &[(String, Rgb, Option<Rgb>)],
    target_materials: &[(String, Rgb, Option<Rgb>)],
) -> Option<LightingChange> {
    if current.emitters != target.emitters
        || current.luminaires.len() != target.luminaires.len()
        || current_materials.len() != target_materials.len()
    {
        return None;
    }
    let mut change = LightingChange::default();
    if current.sun != target.sun {
        change.sun = Some(target.sun);
    }
    if current.sky != target.sky {
        change.sky = Some(target.sky.clone());
    }
    for (built, now) in current.luminaires.iter().zip(&target.luminaires) {
        let dimming = dimming_between(built, now)?;
        if dimming.to_bits() != built.dimming.to_bits() {
            change.luminaire_dimming.push((built.name.clone(), dimming));
        }
    }
    for ((name, rho, emission), (name_now, rho_now, emission_now)) in
        current_materials.iter().zip(target_materials)
    {
        if name != name_now || emission != emission_now {
            return None;
        }
        // Bit comparison: any change of the value is a change to apply.
        if rho.map(f64::to_bits) != rho_now.map(f64::to_bits) {
            change
                .material_reflectance
                .push((name.clone(), rho_now.map(|r| r.clamp(0.0, 1.0))));
        }
    }
    Some(change)
}

/// Whether `change` changes nothing.
#[must_use]
pub fn is_empty(change: &LightingChange) -> bool {
    *change == LightingChange::default()
}

/// The material and its new reflectance when `change` changes one material's reflectance and
/// nothing else (the edit [`Transfer::relight_material`] tabulates).
fn single_material(change: &LightingChange) -> Option<(&str, Rgb)> {
    match change.material_reflectance.as_slice() {
        [(name, value)]
            if change.sun.is_none()
                && change.sky.is_none()
                && change.luminaire_dimming.is_empty() =>
        {
            Some((name.as_str(), *value))
        }
        _ => None,
    }
}

/// One of the two transfers with what it was last solved for.
struct Kept {
    transfer: Transfer,
    materials: Vec<(String, Rgb, Option<Rgb>)>,
}

/// The site's two transfers (with and without the artificial objects) kept between renders
/// (module doc).
pub struct SiteTransfers {
    with_artificial: Kept,
    without_artificial: Kept,
    /// Fingerprints of the two scenes with their parameters.
    fingerprint: [u64; 2],
    /// The view whose photo gave the natural elements their ρ_d (`None`: the library's).
    photo_view: Option<String>,
    light: Arc<RadiosityLight>,
    /// The build's report (element size, element counts, notes).
    pub report: RadiosityReport,
}

fn radiosity_error(e: &RadiosityError) -> SiteRenderError {
    SiteRenderError::Request {
        field: "render.radiosity",
        reason: e.to_string(),
    }
}

/// The lighting of the photographed state: the same, without the project's luminaires.
fn natural_lighting(lighting: &TransferLighting) -> TransferLighting {
    TransferLighting {
        luminaires: Vec::new(),
        ..lighting.clone()
    }
}

/// What the transfers of `scene` need: both lightings, both scenes, the parameters and notes.
struct Inputs {
    lighting: [TransferLighting; 2],
    scenes: [Scene; 2],
    params: TransferParams,
    element_edge_m: f64,
    notes: Vec<String>,
}

fn inputs(doc: &SiteDocument, scene: &Scene, view: &str) -> Result<Inputs, SiteRenderError> {
    let (lighting, notes) = site_transfer_lighting(doc, scene, view)?;
    let (solve, _) = site_solve_params(doc, scene)?;
    let params = TransferParams {
        solve,
        sky_tolerance: super::render_radiosity::SKY_TOLERANCE,
        ..TransferParams::default()
    };
    let mut inputs = scene_inputs(scene, &lighting, &params)?;
    inputs.notes = notes;
    Ok(inputs)
}

fn scene_inputs(
    scene: &Scene,
    lighting: &TransferLighting,
    params: &TransferParams,
) -> Result<Inputs, SiteRenderError> {
    Ok(Inputs {
        lighting: [lighting.clone(), natural_lighting(lighting)],
        scenes: [scene.clone(), natural_part(scene)?],
        params: params.clone(),
        element_edge_m: params.solve.mesh.max_element_edge_m,
        notes: Vec::new(),
    })
}

impl SiteTransfers {
    /// Builds both transfers for the site scene `scene` (natural and artificial objects, as
    /// rendered) lit for photo `view`, with the reflectances `photo` shows where given; their
    /// solutions are [`super::render_radiosity`]'s.
    ///
    /// # Errors
    /// The lighting's errors; a transfer error (a bad source, cancelled) as
    /// [`SiteRenderError::Request`] naming `render.radiosity`.
    pub fn build(
        doc: &SiteDocument,
        scene: &Scene,
        view: &str,
        photo: Option<&PhotoView<'_>>,
        cancel: &AtomicBool,
    ) -> Result<Self, SiteRenderError> {
        let start = Instant::now();
        let inputs = inputs(doc, scene, view)?;
        let mut built = Self::from_site_inputs(doc, view, inputs, photo, cancel, start)?;
        built.photo_view = photo.map(|_| view.to_owned());
        Ok(built)
    }

    /// [`SiteTransfers::build`] for a scene and lighting given directly (benches, tests):
    /// `lighting` for the scene with its artificial objects, the same without its luminaires
    /// for the natural part.
    ///
    /// # Errors
    /// As [`SiteTransfers::build`].
    pub fn build_for(
        scene: &Scene,
        lighting: &TransferLighting,
        params: &TransferParams,
        cancel: &AtomicBool,
    ) -> Result<Self, SiteRenderError> {
        let start = Instant::now();
        Self::from_inputs(scene_inputs(scene, lighting, params)?, None, cancel, start)
    }

    /// The relight step of [`SiteTransfers::update`] for a scene and lighting given directly
    /// (the studio's path after the site has been read; the latency bench times it): `Ok(None)`
    /// when the change needs a build.
    ///
    /// # Errors
    /// A relight error.
    pub fn relight_for(
        &mut self,
        scene: &Scene,
        lighting: &TransferLighting,
        params: &TransferParams,
    ) -> Result<Option<TransferUpdate>, SiteRenderError> {
        self.relight(&scene_inputs(scene, lighting, params)?)
    }

    /// [`SiteTransfers::from_inputs`] with `photo` and, as `site_radiosity_light` reads them,
    /// the site's other photos where `photo` does not see, each under the sun of its capture
    /// time.
    fn from_site_inputs(
        doc: &SiteDocument,
        view: &str,
        inputs: Inputs,
        photo: Option<&PhotoView<'_>>,
        cancel: &AtomicBool,
        start: Instant,
    ) -> Result<Self, SiteRenderError> {
        let others = other_photos_for(doc, &inputs.scenes[0], view, photo)?;
        let views = photo
            .zip(others.as_ref())
            .map(|(p, (o, l))| (o.views(*p, &l.reading), &l.transfer[..]));
        Self::from_inputs(
            inputs,
            views.as_ref().map(|(v, suns)| (v, *suns)),
            cancel,
            start,
        )
    }

    /// The transfers of `inputs`; with `photo`, the photo reflectances read off its views,
    /// those taken under other suns against the natural transfer relit to each of the given
    /// lightings ([`refit_transfer`]).
    fn from_inputs(
        inputs: Inputs,
        photo: Option<(&PhotoViews<'_>, &[TransferLighting])>,
        cancel: &AtomicBool,
        start: Instant,
    ) -> Result<Self, SiteRenderError> {
        let Inputs {
            lighting,
            scenes,
            params,
            element_edge_m,
            mut notes,
        } = inputs;
        // As `site_radiosity_light`: both meshes follow the shadows of the scene with and
        // without the artificial objects.
        let with_tracer = SceneTracer::new(&scenes[0], BuildQuality::Medium)?;
        let natural_tracer = SceneTracer::new(&scenes[1], BuildQuality::Medium)?;
        // The photographed state first: the build with the planned objects reads its sky rays
        // (`radiosity::twin`), as `site_radiosity_light` does.
        let artificial = artificial_part(&scenes[0])?;
        let build = |k: usize, natural: Option<&Transfer>| {
            Transfer::build_beside(
                &scenes[k],
                &[&with_tracer, &natural_tracer],
                &lighting[k],
                &params,
                cancel,
                &|_| {},
                natural.map(|t| (t, &artificial)),
            )
            .map(|transfer| Kept {
                transfer,
                materials: material_state(&scenes[k]),
            })
            .map_err(|e| radiosity_error(&e))
        };
        let mut without_artificial = build(1, None)?;
        let mut with_artificial = build(0, Some(&without_artificial.transfer))?;
        // As `site_radiosity_light`: the natural elements the photo sees take its ρ_d, refitted
        // on the photographed state, then carried to the same elements with the objects.
        let mut photo_reflectance = None;
        if let Some((view, other_suns)) = photo {
            let samples = PhotoSamples::from_views(
                &without_artificial.transfer.solution().mesh,
                &natural_tracer,
                view,
            );
            let mut refit = PhotoRefit::new(samples);
            refit_transfer(
                &mut without_artificial.transfer,
                &mut refit,
                other_suns,
                REFIT_ROUNDS,
            )
            .map_err(|e| radiosity_error(&e))?;
            notes.extend(refit.notes());
            photo_reflectance = refit.count();
            if photo_reflectance.is_some_and(|c| c.from_photo > 0) {
                let rho = same_elements(
                    &without_artificial.transfer.solution().mesh,
                    &twin_elements(
                        &without_artificial.transfer.solution().mesh,
                        &with_artificial.transfer.solution().mesh,
                    ),
                );
                with_artificial
                    .transfer
                    .set_element_reflectances(&rho)
                    .map_err(|e| radiosity_error(&e))?;
            }
        }
        let light = Arc::new(
            RadiosityLight::new(
                with_artificial.transfer.solution(),
                without_artificial.transfer.solution(),
                &RadiosityLight::traced_exactly,
            )
            .map_err(|e| radiosity_error(&e))?,
        );
        let report = RadiosityReport {
            element_edge_m,
            elements: [
                with_artificial.transfer.solution().mesh.elements.len(),
                without_artificial.transfer.solution().mesh.elements.len(),
            ],
            seconds: start.elapsed().as_secs_f64(),
            notes,
            photo_reflectance,
        };
        Ok(Self {
            fingerprint: [
                scene_fingerprint(&scenes[0], &params),
                scene_fingerprint(&scenes[1], &params),
            ],
            photo_view: None,
            with_artificial,
            without_artificial,
            light,
            report,
        })
    }

    /// The lighting the renderer reads (both solutions, the traced groups' direct light out).
    #[must_use]
    pub fn light(&self) -> Arc<RadiosityLight> {
        Arc::clone(&self.light)
    }

    /// The current solution with the artificial objects.
    #[must_use]
    pub fn with_artificial(&self) -> &Solution {
        self.with_artificial.transfer.solution()
    }

    /// Forgets both transfers' sun axis responses ([`Transfer::drop_sun_axes`]): the next sun
    /// step shoots them from nothing.
    pub fn drop_sun_axes(&mut self) {
        self.with_artificial.transfer.drop_sun_axes();
        self.without_artificial.transfer.drop_sun_axes();
    }

    /// The current solution of the photographed state.
    #[must_use]
    pub fn without_artificial(&self) -> &Solution {
        self.without_artificial.transfer.solution()
    }

    /// The transfers' current light groups, with and without the artificial objects.
    #[must_use]
    pub fn light_groups(&self) -> [&[crate::radiosity::LightGroup]; 2] {
        [
            self.with_artificial.transfer.light_groups(),
            self.without_artificial.transfer.light_groups(),
        ]
    }

    /// Relights both transfers to the lighting and materials of `doc`, `scene` and `view`
    /// (module doc), or builds them again when that cannot be expressed as a relight; `slot`
    /// holds the transfers between calls (`None` builds). A build with `photo` gives the
    /// natural elements it sees their ρ_d from it, as [`super::render_radiosity`] does; a relight
    /// keeps them. Switching the photo's reflectances on or off, or to another view's photo,
    /// builds again.
    ///
    /// # Errors
    /// As [`SiteTransfers::build`]; a relight error. On error `slot` is emptied (the next call
    /// builds).
    pub fn update(
        slot: &mut Option<Self>,
        doc: &SiteDocument,
        scene: &Scene,
        view: &str,
        photo: Option<&PhotoView<'_>>,
        cancel: &AtomicBool,
    ) -> Result<(Arc<RadiosityLight>, RelightReport), SiteRenderError> {
        let start = Instant::now();
        let inputs = inputs(doc, scene, view)?;
        // Reflectances read off another photo (or none where the photo's are wanted, or the
        // other way round) are not a relight: build again.
        let photo_view = photo.map(|_| view.to_owned());
        if let Some(kept) = slot.as_mut().filter(|k| k.photo_view == photo_view) {
            match kept.relight(&inputs) {
                Ok(Some(update)) => {
                    return Ok((
                        kept.light(),
                        RelightReport {
                            update,
                            seconds: start.elapsed().as_secs_f64(),
                            build: None,
                        },
                    ));
                }
                Ok(None) => {}
                Err(e) => {
                    *slot = None;
                    return Err(e);
                }
            }
        }
        *slot = None;
        let mut built = Self::from_site_inputs(doc, view, inputs, photo, cancel, start)?;
        built.photo_view = photo_view;
        let light = built.light();
        let build = Some(built.report.clone());
        *slot = Some(built);
        Ok((
            light,
            RelightReport {
                update: TransferUpdate::Built,
                seconds: start.elapsed().as_secs_f64(),
                build,
            },
        ))
    }

    /// Relights both transfers to `inputs`; `Ok(None)` when that needs a build.
    fn relight(&mut self, inputs: &Inputs) -> Result<Option<TransferUpdate>, SiteRenderError> {
        let fingerprint = [
            scene_fingerprint(&inputs.scenes[0], &inputs.params),
            scene_fingerprint(&inputs.scenes[1], &inputs.params),
        ];
        if fingerprint != self.fingerprint {
            return Ok(None);
        }
        let targets: Vec<_> = inputs.scenes.iter().map(material_state).collect();
        let kept = [&self.with_artificial, &self.without_artificial];
        let mut changes = Vec::with_capacity(2);
        for k in 0..2 {
            let Some(change) = lighting_change(
                kept[k].transfer.lighting(),
                &inputs.lighting[k],
                &kept[k].materials,
                &targets[k],
            ) else {
                return Ok(None);
            };
            changes.push(change);
        }
        if changes.iter().all(is_empty) {
            return Ok(Some(TransferUpdate::Unchanged));
        }
        let (with, without) = (&mut self.with_artificial, &mut self.without_artificial);
        // Rays first: the natural transfer's (a sun move's rays over every thread), then the
        // other's, which reads the natural sun counts through its twins (`radiosity::sun_rays`);
        // nothing changes until both are traced. A colour edit of one material goes through the
        // material's table instead (built on its first edit).
        let general = |c: &LightingChange| !is_empty(c) && single_material(c).is_none();
        let natural_traced = if general(&changes[1]) {
            Some(
                without
                    .transfer
                    .prepare_relight(&changes[1], None)
                    .map_err(|e| radiosity_error(&e))?,
            )
        } else {
            None
        };
        let traced = if general(&changes[0]) {
            Some(
                with.transfer
                    .prepare_relight(
                        &changes[0],
                        natural_traced
                            .as_ref()
                            .and_then(PreparedRelight::sun_counts),
                    )
                    .map_err(|e| radiosity_error(&e))?,
            )
        } else {
            None
        };
        let apply = |kept: &mut Kept,
                     change: &LightingChange,
                     traced: Option<PreparedRelight>|
         -> Result<(), RadiosityError> {
            if let Some(traced) = traced {
                kept.transfer.commit_relight(traced);
            } else if let Some((name, value)) = single_material(change) {
                kept.transfer.relight_material(name, value)?;
            }
            Ok(())
        };
        // The two solves are independent: run them side by side.
        let (a, b) = rayon::join(
            || apply(with, &changes[0], traced),
            || apply(without, &changes[1], natural_traced),
        );
        a.and(b).map_err(|e| radiosity_error(&e))?;
        let [t0, t1] = targets.try_into().unwrap_or_else(|_| unreachable!());
        self.with_artificial.materials = t0;
        self.without_artificial.materials = t1;
        self.light = Arc::new(
            self.light
                .relit(
                    self.with_artificial.transfer.solution(),
                    self.without_artificial.transfer.solution(),
                    &RadiosityLight::traced_exactly,
                    [
                        Some(self.with_artificial.transfer.element_reflectances()),
                        Some(self.without_artificial.transfer.element_reflectances()),
                    ],
                )
                .map_err(|e| radiosity_error(&e))?,
        );
        Ok(Some(TransferUpdate::Relit))
    }
}

#[cfg(test)]
#[path = "live_relight_tests.rs"]
mod tests;
