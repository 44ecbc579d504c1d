//! The radiosity lighting mode of the differential renderer (issue 13 item 7): sky and
//! multi-bounce interreflected light at a changed point come from two radiosity solutions of the
//! site ([`crate::radiosity`], Tonn & Donath's "radiosity underneath"), one of the photographed
//! state (natural objects only) and one with the artificial objects, while the sun and the
//! artificial lights stay exact shadow rays.
//!
//! - **Case C** (artificial point): E = sun (shadow ray) + ambient + artificial lights (shadow
//!   rays) + E_rad,with(x), the interpolated irradiance of the "with" solution without the sun's
//!   and the luminaires' direct term (sky direct, ground below the horizon and every bounce).
//! - **Case D** (natural point): the eq. 10 inversion divides by the natural irradiance
//!   E_nat = sun (shadow ray against natural geometry) + ambient + E_rad,without(x); the change
//!   is D1 (artificial lights) − D3 (the sun blocked only by artificial objects, exact) +
//!   ΔE_rad = E_rad,with(x) − E_rad,without(x), which holds the sky the building blocks, the
//!   light it reflects and the bounce light it removes from the surroundings.
//! - **Unchanged**: a natural point is returned as the photo, bit for bit, unless the sun is
//!   blocked by an artificial object, an artificial light reaches it, or |ΔE_rad| exceeds
//!   [`RadiosityLight::change_fraction`] of E_nat in some channel ([`DEFAULT_CHANGE_FRACTION`]).
//!
//! In both solutions the sky's direct light (and the ground below the horizon) is interpolated
//! on the elements (nodal averaging), and the interreflected light is a **final gather** at the
//! element vertices ([`crate::radiosity::vertex_gather`]): the exitances of the elements the
//! vertex sees, not the element's own value, which a hierarchical solution only knows as a mean
//! over a coarse receiver node. The gathers trace their rays once per vertex the renderer
//! reaches and are kept across relights of the same meshes ([`RadiosityLight::relit`]); the
//! with-objects gathers are built over the photographed state's, so one trace fills both
//! ([`VertexGather::over`]), and each vertex's sum is kept per solution.
//!
//! Where a point lies on no element of a solution (a back face, geometry the mesh skipped), the
//! facet path of the ordinary mode is used for that ray.
//!
//! # Known limitations
//! The sky's direct light is interpolated on the elements: a change across an element is
//! blurred over it, so coarse elements near the building blur the sky it blocks. The gathered
//! light is a Monte Carlo estimate (1024 stratified rays per vertex). The threshold hides changes
//! below it (by design: they leave the photo untouched). In spectral mode each pass reads its
//! own pair of solutions ([`crate::render::spectral::SpectralRadiosity`]); RGB solutions in a
//! spectral render are refused.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use crate::radiosity::vertex_gather::DEFAULT_RAYS_PER_AXIS;
use crate::radiosity::{GatheredExitance, PointOnElement, RadiosityError, Solution, VertexGather};
use crate::render::illumination::Rgb;

/// A radiosity change below this fraction of the natural irradiance, in every channel, leaves a
/// natural point unchanged: 1 %, about one 8-bit sRGB step at mid-grey, and above the difference
/// two solves of the same unchanged surroundings leave between them far from the building.
pub const DEFAULT_CHANGE_FRACTION: f64 = 0.01;

/// Σ over groups of the exitance per element (as [`Solution::total_radiosity_rgb`], the same sum
/// in the same order), element-parallel: it runs on every relight of the studio.
fn total_radiosity(solution: &Solution) -> Vec<Rgb> {
    (0..solution.mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let mut sum = [0.0; 3];
            for g in &solution.groups {
                for c in 0..3 {
                    sum[c] += g.radiosity_rgb[e][c];
                }
            }
            sum
        })
        .collect()
}

/// The two solutions the radiosity mode reads (module doc).
#[derive(Debug, Clone)]
pub struct RadiosityLight {
    /// With the artificial objects; the exactly traced groups' direct light taken out.
    pub with_artificial: Arc<Solution>,
    /// The photographed state (natural objects only); the same groups' direct light taken out.
    pub without_artificial: Arc<Solution>,
    /// The change threshold (module doc).
    pub change_fraction: f64,
    /// Vertex gathers of the two meshes (with, without) and the exitance per element of the two
    /// solutions as solved (every group's direct light in) that they sum.
    gathered: [GatheredExitance; 2],
}

impl RadiosityLight {
    /// From solutions of the scene with and without the artificial objects, taking out the direct
    /// light of the groups `traced_exactly` names (the sun and the luminaires, which the
    /// renderer traces itself).
    ///
    /// # Errors
    /// A tracer error while setting up the vertex gathers (not reachable for solved meshes).
    pub fn new(
        with_artificial: &Solution,
        without_artificial: &Solution,
        traced_exactly: &(dyn Fn(&str) -> bool + Sync),
    ) -> Result<Self, RadiosityError> {
        let without = Arc::new(VertexGather::new(
            Arc::clone(&without_artificial.mesh),
            DEFAULT_RAYS_PER_AXIS,
        )?);
        let with = Arc::new(VertexGather::over(
            Arc::clone(&with_artificial.mesh),
            DEFAULT_RAYS_PER_AXIS,
            Arc::clone(&without),
        )?);
        let light = Self::with_gathers(
            [with_artificial, without_artificial],
            traced_exactly,
            [with, without],
            [None, None],
            None,
        )?;
        light.prepare_queries();
        Ok(light)
    }

    /// The same for relit solutions: the vertex gathers (the rays they traced) are kept where a
    /// solution's mesh has the geometry this light was built on (a relight changes at most its
    /// reflectances), and set up anew where it has not (those with the artificial objects on
    /// those without, which share their traces, [`VertexGather::over`]).
    ///
    /// # Errors
    /// As [`RadiosityLight::new`].
    /// `element_rho`: ρ per element of each solution where the caller keeps it (the studio's
    /// transfers), so that it is not read again from the meshes.
    pub fn relit(
        &self,
        with_artificial: &Solution,
        without_artificial: &Solution,
        traced_exactly: &(dyn Fn(&str) -> bool + Sync),
        element_rho: [Option<&[Rgb]>; 2],
    ) -> Result<Self, RadiosityError> {
        let kept = |k: usize, s: &Solution| {
            let g = self.gathered[k].gather();
            (g.mesh().geometry_hash == s.mesh.geometry_hash).then(|| Arc::clone(g))
        };
        let without = match kept(1, without_artificial) {
            Some(g) => g,
            None => Arc::new(VertexGather::new(
                Arc::clone(&without_artificial.mesh),
                DEFAULT_RAYS_PER_AXIS,
            )?),
        };
        let with = match kept(0, with_artificial) {
            Some(g) => g,
            None => Arc::new(VertexGather::over(
                Arc::clone(&with_artificial.mesh),
                DEFAULT_RAYS_PER_AXIS,
                Arc::clone(&without),
            )?),
        };
        let gathers = [with, without];
        Self::with_gathers(
            [with_artificial, without_artificial],
            traced_exactly,
            gathers,
            element_rho,
            Some([&self.with_artificial, &self.without_artificial]),
        )
    }

    /// `previous`: the solutions this light replaces, whose point lookups' geometry the new
    /// ones take over where the meshes' geometry is the same
    /// ([`Solution::reuse_query_geometry`]).
    fn with_gathers(
        solutions: [&Solution; 2],
        traced_exactly: &(dyn Fn(&str) -> bool + Sync),
        gathers: [Arc<VertexGather>; 2],
        element_rho: [Option<&[Rgb]>; 2],
        previous: Option<[&Solution; 2]>,
    ) -> Result<Self, RadiosityError> {
        // The two solutions are independent: side by side.
        let side = |k: usize, gather: Arc<VertexGather>| -> Result<_, RadiosityError> {
            let s = solutions[k];
            let without_exact = s.without_direct_of_given(traced_exactly, element_rho[k]);
            if let Some(previous) = previous {
                without_exact.reuse_query_geometry(previous[k]);
            }
            Ok((
                Arc::new(without_exact),
                GatheredExitance::new(gather, total_radiosity(s))?,
            ))
        };
        let [with_gather, without_gather] = gathers;
        let (with, without) = rayon::join(|| side(0, with_gather), || side(1, without_gather));
        let ((with, with_gathered), (without, without_gathered)) = (with?, without?);
        Ok(Self {
            with_artificial: with,
            without_artificial: without,
            change_fraction: DEFAULT_CHANGE_FRACTION,
            gathered: [with_gathered, without_gathered],
        })
    }

    /// Builds both solutions' point lookups side by side over rayon's pool, before a first query
    /// would build them one after the other, each on one thread (a relit light's are built by
    /// its first query, or here).
    pub fn prepare_queries(&self) {
        rayon::join(
            || self.with_artificial.prepare_queries(),
            || self.without_artificial.prepare_queries(),
        );
    }

    /// The groups the renderer traces exactly: the sun and every luminaire.
    #[must_use]
    pub fn traced_exactly(group: &str) -> bool {
        group == "sun" || group.starts_with("luminaire")
    }

    /// Sky and interreflected irradiance at a surface point with the artificial objects.
    #[must_use]
    pub fn with_at(&self, point: &Point3<f64>, normal: &Vector3<f64>) -> Option<Rgb> {
        self.with_artificial
            .irradiance_gathered_at(point, normal, &self.gathered[0])
            .map(|s| s.total_rgb)
    }

    /// Sky and interreflected irradiance at a surface point in the photographed state.
    #[must_use]
    pub fn without_at(&self, point: &Point3<f64>, normal: &Vector3<f64>) -> Option<Rgb> {
        self.without_artificial
            .irradiance_gathered_at(point, normal, &self.gathered[1])
            .map(|s| s.total_rgb)
    }

    /// Where a surface point lies on the two solutions' meshes (with, without the artificial
    /// objects), for reading relit solutions of the same geometry there later
    /// ([`Self::with_on`], [`Self::without_on`]).
    #[must_use]
    pub fn locate(
        &self,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> [Option<PointOnElement>; 2] {
        [
            self.with_artificial.locate_point(point, normal),
            self.without_artificial.locate_point(point, normal),
        ]
    }

    /// [`Self::with_at`] at a point located by [`Self::locate`] on a light of the same geometry
    /// (a relight of the one it was located on).
    #[must_use]
    pub fn with_on(&self, at: &PointOnElement) -> Option<Rgb> {
        self.with_artificial
            .irradiance_gathered_on(at, &self.gathered[0])
            .map(|s| s.total_rgb)
    }

    /// [`Self::without_at`] at a point located by [`Self::locate`].
    #[must_use]
    pub fn without_on(&self, at: &PointOnElement) -> Option<Rgb> {
        self.without_artificial
            .irradiance_gathered_on(at, &self.gathered[1])
            .map(|s| s.total_rgb)
    }

    /// The vertex gathers of the two meshes (with, without the artificial objects).
    #[must_use]
    pub fn gathers(&self) -> [&Arc<VertexGather>; 2] {
        self.gathered.each_ref().map(GatheredExitance::gather)
    }

    /// Whether a radiosity change `delta` counts against the natural irradiance `natural`.
    #[must_use]
    pub fn is_change(&self, delta: &Rgb, natural: &Rgb) -> bool {
        (0..3).any(|c| delta[c].abs() > self.change_fraction * natural[c].abs())
    }
}

/// The radiosity solutions of each pass of a spectral render (the radiosity lighting mode in
/// spectral mode): pass `k`'s solutions were solved with the pass's reflectances and light
/// colours, so that interreflection is computed per spectral sample.
#[derive(Debug, Clone)]
pub struct SpectralRadiosity {
    /// The sample set the passes belong to.
    pub sample_set: crate::colour::SampleSet,
    /// One radiosity light per pass, in pass order.
    pub passes: Vec<Arc<RadiosityLight>>,
}
