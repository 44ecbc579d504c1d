//! The sun's shadow rays of a relight, counted per element, and the twin rays of the sun
//! ([`super::twin`]): the transfer with the planned objects reads the natural transfer's counts.
//!
//! A sun move re-traces every element's sample rays towards the sun
//! ([`super::sources::direct_irradiance_at`] with the sun as its one source: all N points). The
//! scene with the planned objects is the natural scene plus those objects, so a ray escapes it iff
//! it escapes the natural scene and misses the planned objects. An element with a twin in the
//! natural mesh (same vertices, same sample points) therefore takes its count from its twin's:
//! none of the N rays escaped → none escapes here; all escaped → only the planned objects' own
//! BVH is tested, and not at all outside the cone towards them; a mixed count (an element on a
//! shadow edge) traces its rays through the whole scene. The tracers share one local frame, so
//! the counts are those of tracing every ray in the whole scene, bit for bit (test
//! `sun_twin_counts_equal_tracing_every_ray`), and so is the direct irradiance made from them.
//!
//! The studio relights the natural transfer's sun first (its rays spread over every thread), then
//! the twin counts, then both solves side by side (`site::live_relight`): the transfer with the
//! planned objects no longer traces its natural elements' sun rays a second time.

use rayon::prelude::*;

use super::Rgb;
use super::form_factor::FormFactorEngine;
use super::sources::{DIRECT_RAY_LENGTH_M, DIRECT_RAY_OFFSET_M, DirectSamples, DistantSource};
use super::twin::Twin;

/// The sun's visible-ray counts of every element of a natural transfer, for one direction.
#[derive(Debug, Clone)]
pub struct SunCounts {
    /// The direction the rays were traced towards (its bits are compared).
    pub(super) dir_in_world: [u64; 3],
    /// Per element, how many of its rays escaped (elements facing away: 0, not traced).
    pub(super) escaped: Vec<u8>,
}

/// Per element of `engine`'s mesh, how many of its `samples` rays towards `source` escape the
/// scene (0 for an element facing away); with `twin` = (the twins, the natural transfer's counts
/// for the same direction), from the twins' counts where they decide (module doc). With them,
/// in the same pass over the elements (one read of each element's node), the source's direct
/// irradiance E_n·cos·(escaped / rays): the same operations in the same order as
/// [`super::sources::direct_irradiance_at`], so the same bits.
///
/// # Panics
/// When `samples` were drawn for another mesh, or an element has more than 255 points.
#[must_use]
pub(super) fn sun_counts(
    engine: &FormFactorEngine<'_>,
    samples: &DirectSamples,
    source: &DistantSource,
    twin: Option<(&Twin, &SunCounts)>,
) -> (SunCounts, Vec<Rgb>) {
    let mesh = engine.mesh();
    let tracer = engine.tracer();
    let visibility = engine.params().visibility;
    let dir = source.dir_in_world;
    let bits = dir.map(f64::to_bits);
    let twin = twin.filter(|(t, natural)| {
        t.twin_of.len() == mesh.elements.len() && natural.dir_in_world == [bits.x, bits.y, bits.z]
    });
    let (escaped, direct): (Vec<u8>, Vec<Rgb>) = (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let node = mesh.element_node(e);
            let cos = node.normal_in_world.dot(&dir);
            if cos <= 0.0 {
                return (0, [0.0; 3]);
            }
            let escaped = escaped_rays(e, samples, twin, tracer, &dir, visibility);
            #[allow(clippy::cast_precision_loss)]
            let visible = f64::from(escaped) / samples.of_element(e).len() as f64;
            let mut e_rgb = [0.0; 3];
            for c in 0..3 {
                e_rgb[c] += source.normal_irradiance_rgb[c] * cos * visible;
            }
            (escaped, e_rgb)
        })
        .unzip();
    (
        SunCounts {
            dir_in_world: [bits.x, bits.y, bits.z],
            escaped,
        },
        direct,
    )
}

/// How many of element `e`'s sample rays towards `dir` escape (it faces the sun), from its
/// twin's count where that decides ([`sun_counts`]).
fn escaped_rays(
    e: usize,
    samples: &DirectSamples,
    twin: Option<(&Twin, &SunCounts)>,
    tracer: &crate::scene::SceneTracer,
    dir: &nalgebra::Vector3<f64>,
    visibility: bool,
) -> u8 {
    let points = samples.of_element(e);
    let rays = u8::try_from(points.len()).unwrap_or_else(|_| unreachable!("≤ 255 points"));
    let mut only_planned = None;
    if let Some((t, natural)) = twin
        && let Some(w) = t.twin_of[e]
    {
        let n = natural.escaped[w as usize];
        if n == 0 {
            return 0;
        }
        if n == rays {
            if t.element_cone(e)
                .is_some_and(|(axis, cos)| axis.dot(dir) < cos)
            {
                return n;
            }
            only_planned = Some(t);
        }
    }
    let mut hits = 0u8;
    for p in points {
        if only_planned.is_some_and(|t| !t.may_meet_artificial(p, dir)) {
            hits += 1;
            continue;
        }
        #[allow(clippy::cast_possible_truncation)]
        let ray = tracer.ray_from_world(p, dir, DIRECT_RAY_OFFSET_M as f32, DIRECT_RAY_LENGTH_M);
        let blocked = match only_planned {
            Some(t) => t.artificial.as_ref().is_some_and(|a| a.any_hit(&ray)),
            None => tracer.any_hit(&ray),
        };
        if !visibility || !blocked {
            hits += 1;
        }
    }
    hits
}
