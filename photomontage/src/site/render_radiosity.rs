//! The site's radiosity solutions for the renderer's radiosity mode (`[render] radiosity = true`,
//! `render --radiosity`; [`crate::render::differential::radiosity_light`]): the site scene is
//! solved twice with the site's light groups ([`super::radiosity_lighting`]), once with natural
//! objects only (the photographed state, without the project's luminaires) and once with
//! everything.
//!
//! Elements are [`ELEMENT_EDGE_M`] long, or longer where the scene's area would need more than
//! [`ELEMENT_BUDGET`] of them (the size is then √(area / budget), stated in the report); patches
//! are [`PATCH_PER_ELEMENT`] elements long. Elements that a shadow edge of the view's sun crosses
//! are split down to [`SHADOW_ELEMENT_EDGE_M`], in both meshes along the shadows of the scene
//! with and without the artificial objects (the studio's transfers mesh the same way, for the
//! sun they are built with). Away from the solved photos' cameras and the artificial objects
//! every size is graded ([`crate::radiosity::mesh_grading`], [`GRADING_TAN_ANGLE`]): on the
//! street site's 1 km ground this leaves 50 000 elements of the 137 000 an ungraded mesh has,
//! and the same mesh within 140 m of a camera or the planned building. The hierarchical solver
//! and the seed's stop rule of [`SolveParams::default`] are used.
//!
//! # Known limitations
//! Both solves run before every render of the CLI (the studio keeps them between renders as
//! transfers, [`super::live_relight`]); a large
//! ground plane takes the element size up for every object, blurring the sky a building blocks
//! over that size (docs/methodology.md). The budget is reckoned on the ungraded area, so a graded
//! mesh stays well below it.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use nalgebra::Point3;

use super::SiteDocument;
use super::other_photos::other_photos_for;
use super::photo_reflectance::{
    PhotoRefit, PhotoReflectanceCount, PhotoSamples, PhotoView, PhotoViews, REFIT_ROUNDS,
};
use super::radiosity_lighting::{site_ground_below_horizon, site_transfer_lighting};
use super::render_error::SiteRenderError;
use crate::bvh::BuildQuality;
use crate::radiosity::mesh_grading::Grading;
use crate::radiosity::twin::{Twin, twin_elements};
use crate::radiosity::{
    LightGroup, Mesh, MeshParams, Rgb, SkyRays, Solution, SolveParams, TransferLighting,
    solve_on_mesh_twinned, sun_directions,
};
use crate::render::differential::radiosity_light::RadiosityLight;
use crate::scene::{ObjectKind, Scene, SceneError, SceneTracer};
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// Longest element edge where the budget allows, metres.
pub const ELEMENT_EDGE_M: f64 = 1.0;
/// At most about this many elements per solve (the scene's area over the element area).
pub const ELEMENT_BUDGET: f64 = 20_000.0;
/// Elements that a sun shadow edge crosses are split down to this edge, metres
/// ([`crate::radiosity::shadow_refinement`]).
pub const SHADOW_ELEMENT_EDGE_M: f64 = 1.0;
/// Patch edge in element edges (the hierarchy's roots).
pub const PATCH_PER_ELEMENT: f64 = 4.0;
/// Sky clustering tolerance of the icosahedral dome (as the `radiosity` CLI's default).
pub const SKY_TOLERANCE: f64 = 0.1;
/// Beyond the cameras and the planned objects an element subtends at most about this angle,
/// as tan θ (θ ≈ 2.9°), seen from the nearest of them ([`crate::radiosity::mesh_grading`]).
pub const GRADING_TAN_ANGLE: f64 = 0.05;

/// What the precompute did, for reports and benches.
#[derive(Debug, Clone, PartialEq)]
pub struct RadiosityReport {
    /// Element edge used, metres.
    pub element_edge_m: f64,
    /// Elements of the solve with / without the artificial objects.
    pub elements: [usize; 2],
    /// Wall time of both solves, seconds.
    pub seconds: f64,
    /// Notes for the user (terms the solve ignores).
    pub notes: Vec<String>,
    /// Natural elements whose ρ_d came from the photo ([`super::photo_reflectance`]); `None`
    /// when no photo was read.
    pub photo_reflectance: Option<PhotoReflectanceCount>,
}

/// The natural objects of `scene` alone (materials, names and triangle order kept).
///
/// # Errors
/// Scene id overflow (not reachable from a valid scene).
pub fn natural_part(scene: &Scene) -> Result<Scene, SceneError> {
    scene.part_of_kind(ObjectKind::Natural)
}

/// The artificial objects of `scene` alone (the planned ones), as [`natural_part`].
///
/// # Errors
/// As [`natural_part`].
pub fn artificial_part(scene: &Scene) -> Result<Scene, SceneError> {
    scene.part_of_kind(ObjectKind::Artificial)
}

fn area_m2(scene: &Scene) -> f64 {
    scene
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.vertices_in_world_m;
            (b - a).cross(&(c - a)).norm() / 2.0
        })
        .sum()
}

pub(super) fn radiosity_error(e: &crate::radiosity::RadiosityError) -> SiteRenderError {
    SiteRenderError::Request {
        field: "render.radiosity",
        reason: e.to_string(),
    }
}

/// The solve parameters of the site scene `scene` (module doc: element size from the budget,
/// patches, the ground below the horizon) and the element edge used, metres.
///
/// # Errors
/// [`SiteRenderError::Request`] for a ground albedo outside [0, 1].
pub fn site_solve_params(
    doc: &SiteDocument,
    scene: &Scene,
) -> Result<(SolveParams, f64), SiteRenderError> {
    let element_edge_m = ELEMENT_EDGE_M.max((area_m2(scene) / ELEMENT_BUDGET).sqrt());
    let params = SolveParams {
        mesh: MeshParams {
            max_patch_edge_m: PATCH_PER_ELEMENT * element_edge_m,
            max_element_edge_m: element_edge_m,
            shadow_edge_element_m: Some(SHADOW_ELEMENT_EDGE_M.min(element_edge_m)),
            grading: Grading::around(mesh_focus(doc, scene), GRADING_TAN_ANGLE),
            ..MeshParams::default()
        },
        ground: site_ground_below_horizon(doc, scene)?,
        ..SolveParams::default()
    };
    Ok((params, element_edge_m))
}

/// Where the mesh keeps its sizes (module doc): the centre of every solved photo's camera and
/// the box of `scene`'s artificial objects.
fn mesh_focus(doc: &SiteDocument, scene: &Scene) -> Vec<[Point3<f64>; 2]> {
    let cameras = doc
        .site
        .photos
        .iter()
        .filter_map(|p| p.exterior.as_ref())
        .map(|e| Point3::from(e.camera_center))
        .filter(|c| c.iter().all(|x| x.is_finite()))
        .map(|c| [c, c]);
    let planned = artificial_part(scene)
        .ok()
        .and_then(|s| s.bounding_box_in_world_m());
    cameras.chain(planned).collect()
}

/// Solves the site scene `scene` (natural and artificial objects, as rendered) with and without
/// its artificial objects under the lighting of photo `view` (module doc). With `photo`, the
/// natural elements it sees take their ρ_d from it ([`super::photo_reflectance`]), in both
/// solves; those it does not see, from the site's other solved photos, each read under the sun
/// of its capture time ([`super::other_photos`], [`solve_pair`]).
///
/// # Errors
/// The lighting's errors; a solve error (a scene too large, a bad source) as
/// [`SiteRenderError::Request`] naming `render.radiosity`.
pub fn site_radiosity_light(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
    photo: Option<&PhotoView<'_>>,
    cancel: &AtomicBool,
) -> Result<(RadiosityLight, RadiosityReport), SiteRenderError> {
    let start = Instant::now();
    let (lighting, notes) = site_transfer_lighting(doc, scene, view)?;
    let (params, element_edge_m) = site_solve_params(doc, scene)?;
    let others = other_photos_for(doc, scene, view, photo)?;
    let views = photo
        .zip(others.as_ref())
        .map(|(p, (o, l))| o.views(*p, &l.reading));
    let pair = solve_pair(
        scene,
        &SunLightings {
            rendered: &lighting,
            others: others.as_ref().map_or(&[], |(_, l)| &l.transfer),
        },
        &params,
        views.as_ref(),
        None,
        cancel,
    )?;
    let report = RadiosityReport {
        element_edge_m,
        elements: [
            pair.with.mesh.elements.len(),
            pair.without.mesh.elements.len(),
        ],
        seconds: start.elapsed().as_secs_f64(),
        notes: notes.into_iter().chain(pair.photo_notes).collect(),
        photo_reflectance: pair.photo_reflectance,
    };
    let light = RadiosityLight::new(&pair.with, &pair.without, &RadiosityLight::traced_exactly)
        .map_err(|e| radiosity_error(&e))?;
    Ok((light, report))
}

/// The site's two solutions (with and without the artificial objects) and what the photo gave.
pub(super) struct SolvedPair {
    /// With the artificial objects.
    pub with: crate::radiosity::Solution,
    /// The photographed state.
    pub without: crate::radiosity::Solution,
    /// Natural elements whose ρ_d came from the photo.
    pub photo_reflectance: Option<PhotoReflectanceCount>,
    /// What the other photos gave ([`super::photo_reflectance::PhotoSamples::notes`]).
    pub photo_notes: Vec<String>,
    /// What the photographed state's solve lends a solve of the same scene in other colours.
    pub(super) reuse: Option<PassReuse>,
    /// Whether the photographed state's solve read the `reuse` it was given.
    pub(super) read_reuse: bool,
}

/// What a solve of the photographed state lends the solves of the same scene in other colours
/// (the later spectral passes, [`super::spectral_radiosity`]): its mesh, its tracer's local
/// frame, its sky rays and form factors.
pub(super) struct PassReuse {
    mesh: Arc<Mesh>,
    frame_origin: nalgebra::Point3<f64>,
    sky: SkyRays,
}

/// The lighting of [`solve_pair`]: the rendered photo's, and that of each other sun the photo
/// reflectances read ([`super::other_photos`]).
pub(super) struct SunLightings<'a> {
    /// The rendered photo's lighting (both solves).
    pub rendered: &'a TransferLighting,
    /// Per other sun, the site's lighting at its time (the photographed state's solve only).
    pub others: &'a [TransferLighting],
}

/// The two solves of [`site_radiosity_light`] for the given lighting and parameters (the
/// site's, or their colours on one spectral pass, [`super::spectral_radiosity`]). Where the
/// photo reflectances read photos taken under other suns, the photographed state's solve also
/// carries each other sun's natural light groups (its sun and sky: more groups on the links
/// refined for the rendered photo's light, the sky from the same sky rays), so that each refit
/// round reads every photo against the solution for its own sun; the solution returned keeps
/// the rendered photo's groups only. With `reuse` (the first pass's) the photographed state's
/// solve reads the sky rays and form factors of that solve where its mesh is the same
/// ([`Twin::identity`]: the same answers, not traced again); the returned
/// [`SolvedPair::reuse`] is this solve's, for the passes after it.
pub(super) fn solve_pair(
    scene: &Scene,
    lighting: &SunLightings<'_>,
    params: &SolveParams,
    photo: Option<&PhotoViews<'_>>,
    reuse: Option<&PassReuse>,
    cancel: &AtomicBool,
) -> Result<SolvedPair, SiteRenderError> {
    let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath())?;
    let (groups, _warnings) = lighting
        .rendered
        .light_groups(&dome, SKY_TOLERANCE)
        .map_err(|e| radiosity_error(&e))?;
    let natural = natural_part(scene)?;
    // Both meshes follow the sun's shadow edges in the scene with and without the artificial
    // objects, so that their natural surfaces are meshed alike and each resolves its shadows
    // (an old shadow edge inside a new shadow shows in the photographed state only).
    let tracer = SceneTracer::new(scene, BuildQuality::Medium)?;
    let natural_tracer = SceneTracer::new(&natural, BuildQuality::Medium)?;
    let dirs_to_sun = sun_directions(&groups);
    let mesh = |s: &Scene| {
        Mesh::build_lit(s, &params.mesh, &dirs_to_sun, &[&tracer, &natural_tracer])
            .map_err(|e| radiosity_error(&e))
    };
    // The photographed state has none of the project's luminaires.
    let natural_only = |g: &LightGroup| !g.name.starts_with("luminaire");
    let mut natural_groups: Vec<LightGroup> =
        groups.iter().filter(|g| natural_only(g)).cloned().collect();
    let rendered_groups = natural_groups.len();
    // Each other sun's groups after the rendered photo's (module doc), with their sun.
    let mut group_sun = vec![0; rendered_groups];
    if photo.is_some() {
        for (k, other) in lighting.others.iter().enumerate() {
            let (other_groups, _) = other
                .light_groups(&dome, SKY_TOLERANCE)
                .map_err(|e| radiosity_error(&e))?;
            for g in other_groups.into_iter().filter(natural_only) {
                // Carried on the links refined for the rendered photo's light, so that its
                // solution is the one it would be without the other suns.
                natural_groups.push(LightGroup {
                    refines_links: false,
                    ..g
                });
                group_sun.push(k + 1);
            }
        }
    }
    let natural_mesh = mesh(&natural)?;
    let samples = photo.map(|p| PhotoSamples::from_views(&natural_mesh, &natural_tracer, p));
    let mut refit = samples.map(PhotoRefit::new);
    let rounds = if refit.is_some() { REFIT_ROUNDS } else { 0 };
    let frame_origin = natural_tracer.local_origin_in_world_m();
    let identity = reuse
        .filter(|r| {
            r.frame_origin == frame_origin
                && r.mesh.elements.len() == natural_mesh.elements.len()
                && twin_elements(&r.mesh, &natural_mesh)
                    .iter()
                    .zip(0u32..)
                    .all(|(t, e)| *t == Some(e))
        })
        .map(|r| (Twin::identity(&natural_mesh), &r.sky));
    let read_reuse = identity.is_some();
    let (without, natural_sky) = solve_on_mesh_twinned(
        natural_mesh,
        &natural_tracer,
        &natural_groups,
        params,
        cancel,
        &|_| {},
        &mut |solution: &Solution| {
            refit
                .as_mut()
                .map(|r| refit_round_per_sun(r, solution, &group_sun))
        },
        rounds,
        identity.as_ref().map(|(t, sky)| (t, *sky)),
    )
    .map_err(|e| radiosity_error(&e))?;
    let without = if natural_groups.len() > rendered_groups {
        without.groups_where(|g| g < rendered_groups)
    } else {
        without
    };
    let photo_notes = refit.as_ref().map(PhotoRefit::notes).unwrap_or_default();
    let mut with_mesh = mesh(scene)?;
    let twin_of = twin_elements(&without.mesh, &with_mesh);
    if without.mesh.node_reflectance_rgb.is_some() {
        let rho = same_elements(&without.mesh, &twin_of);
        with_mesh
            .set_element_reflectances(&rho)
            .map_err(|e| radiosity_error(&e))?;
    }
    // The solve with the planned objects reuses the natural solve's sky rays
    // (`radiosity::twin`, as `Transfer::build_beside` does).
    let twin = Twin::new(
        twin_of,
        without.mesh.elements.len(),
        &natural_tracer,
        &tracer,
        &artificial_part(scene)?,
        &with_mesh,
    )?;
    let (with, _) = solve_on_mesh_twinned(
        with_mesh,
        &tracer,
        &groups,
        params,
        cancel,
        &|_| {},
        &mut |_| None,
        0,
        twin.as_ref().zip(natural_sky.as_ref()),
    )
    .map_err(|e| radiosity_error(&e))?;
    let reuse = natural_sky.map(|sky| PassReuse {
        mesh: Arc::clone(&without.mesh),
        frame_origin,
        sky,
    });
    Ok(SolvedPair {
        with,
        without,
        photo_reflectance: refit.as_ref().and_then(PhotoRefit::count),
        photo_notes,
        reuse,
        read_reuse,
    })
}

/// One refit round ([`PhotoRefit::next_round`]) on `solution`, a solve whose group `g` carries
/// the light of sun `group_sun[g]` (0 the rendered photo's; [`solve_pair`]): each sun's
/// solution is its groups'.
pub(super) fn refit_round_per_sun(
    refit: &mut PhotoRefit,
    solution: &Solution,
    group_sun: &[usize],
) -> Vec<Option<Rgb>> {
    if refit.suns() == 1 {
        return refit.next_round(&[solution]);
    }
    let per_sun: Vec<Solution> = (0..refit.suns())
        .map(|k| solution.groups_where(|g| group_sun[g] == k))
        .collect();
    refit.next_round(&per_sun.iter().collect::<Vec<_>>())
}

/// The per-element reflectances of `from` carried to the elements of another mesh whose twins
/// in `from` are `twin_of` ([`twin_elements`]: the same vertices, the natural surfaces meshed
/// alike in both, module doc); `None` elsewhere.
#[must_use]
pub fn same_elements(from: &Mesh, twin_of: &[Option<u32>]) -> Vec<Option<Rgb>> {
    let overrides = from.element_reflectance_overrides();
    twin_of
        .iter()
        .map(|t| t.and_then(|w| overrides[w as usize]))
        .collect()
}

/// [`site_radiosity_light`] shared behind an [`Arc`] for [`crate::render::Lighting::radiosity`].
///
/// # Errors
/// As [`site_radiosity_light`].
pub fn site_radiosity_arc(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
    photo: Option<&PhotoView<'_>>,
    cancel: &AtomicBool,
) -> Result<(Arc<RadiosityLight>, RadiosityReport), SiteRenderError> {
    site_radiosity_light(doc, scene, view, photo, cancel).map(|(l, r)| (Arc::new(l), r))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use crate::site::render::prepare_view;
    use crate::site::render::tests::fixture;

    /// The site's solves are graded around the solved photos' cameras and the planned objects'
    /// box; the fits' solve of the photographed state around the cameras alone; a site with
    /// neither is meshed at one size.
    #[test]
    fn the_mesh_is_graded_around_the_cameras_and_the_planned_objects() {
        let dir = tempfile::tempdir().unwrap();
        let mut doc = fixture(dir.path());
        let scene = prepare_view(&doc, "p1").unwrap().scene.scene;
        let camera = Point3::new(0.5, -10.0, 1.5);
        let planned = artificial_part(&scene)
            .unwrap()
            .bounding_box_in_world_m()
            .unwrap();
        let (params, _) = site_solve_params(&doc, &scene).unwrap();
        let grading = params.mesh.grading.unwrap();
        assert!((grading.tan_angle - GRADING_TAN_ANGLE).abs() < f64::EPSILON);
        // p2 is not solved: p1's camera and the box.
        assert_eq!(grading.focus_in_world_m, vec![[camera; 2], planned]);
        let natural = natural_part(&scene).unwrap();
        let (fits, _) = site_solve_params(&doc, &natural).unwrap();
        assert_eq!(
            fits.mesh.grading.unwrap().focus_in_world_m,
            vec![[camera; 2]]
        );
        doc.site.photos[0].exterior = None;
        let (none, _) = site_solve_params(&doc, &natural).unwrap();
        assert!(none.mesh.grading.is_none());
    }
}
