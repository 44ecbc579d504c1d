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
//! Where a point lies on no element of a solution (a back face, geometry the mesh skipped), the
//! facet path of the ordinary mode is used for that ray.
//!
//! # Known limitations
//! The solution is interpolated on its elements (nodal averaging): a change of sky or bounce
//! light across an element is blurred over it, so coarse elements near the building blur the
//! sky it blocks (no final gather in this mode yet). The threshold hides changes below it
//! (by design: they leave the photo untouched). RGB mode only: the spectral passes ignore the
//! solutions and use the facets.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use crate::radiosity::Solution;
use crate::render::illumination::Rgb;

/// A radiosity change below this fraction of the natural irradiance, in every channel, leaves a
/// natural point unchanged: 1 %, about one 8-bit sRGB step at mid-grey, and above the difference
/// two solves of the same unchanged surroundings leave between them far from the building.
pub const DEFAULT_CHANGE_FRACTION: f64 = 0.01;

/// The two solutions the radiosity mode reads (module doc).
#[derive(Debug, Clone)]
pub struct RadiosityLight {
    /// With the artificial objects; the exactly traced groups' direct light taken out.
    pub with_artificial: Arc<Solution>,
    /// The photographed state (natural objects only); the same groups' direct light taken out.
    pub without_artificial: Arc<Solution>,
    /// The change threshold (module doc).
    pub change_fraction: f64,
}

impl RadiosityLight {
    /// From solutions of the scene with and without the artificial objects, taking out the direct
    /// light of the groups `traced_exactly` names (the sun and the luminaires, which the
    /// renderer traces itself).
    #[must_use]
    pub fn new(
        with_artificial: &Solution,
        without_artificial: &Solution,
        traced_exactly: &dyn Fn(&str) -> bool,
    ) -> Self {
        Self {
            with_artificial: Arc::new(with_artificial.without_direct_of(traced_exactly)),
            without_artificial: Arc::new(without_artificial.without_direct_of(traced_exactly)),
            change_fraction: DEFAULT_CHANGE_FRACTION,
        }
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
            .irradiance_at(point, normal)
            .map(|s| s.total_rgb)
    }

    /// Sky and interreflected irradiance at a surface point in the photographed state.
    #[must_use]
    pub fn without_at(&self, point: &Point3<f64>, normal: &Vector3<f64>) -> Option<Rgb> {
        self.without_artificial
            .irradiance_at(point, normal)
            .map(|s| s.total_rgb)
    }

    /// Whether a radiosity change `delta` counts against the natural irradiance `natural`.
    #[must_use]
    pub fn is_change(&self, delta: &Rgb, natural: &Rgb) -> bool {
        (0..3).any(|c| delta[c].abs() > self.change_fraction * natural[c].abs())
    }
}
