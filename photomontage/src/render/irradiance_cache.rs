//! Irradiance caching of the one-bounce gathers of [`super::differential`] (Ward, Rubinstein &
//! Clear 1988, "A ray tracing solution for diffuse interreflection", SIGGRAPH '88, §2–3).
//!
//! A gather over the Durisch dome (upper and mirrored lower hemisphere, ~100 rays, some with a
//! nested gather of their own) is far dearer than the rest of a ray sample, and the irradiance it
//! returns varies slowly over a surface: it changes on the scale of the distance to the geometry
//! the gather rays hit. Ward's cache stores each computed irradiance as a **record** (point,
//! normal, value, validity radius R = harmonic mean distance of the gather rays' hits, misses
//! left out) and
//! answers a later gather at point p with normal n from the records whose error estimate
//! (Ward 1988 eq. 3, the `ε_i = ‖p − p_i‖ / R_i + √(1 − n·n_i)` form)
//! is below the accuracy `a`, weighted `w_i = 1 − ε_i / a` (the smooth weight of Tabellion &
//! Lamorlette 2004, §3.2, which goes to zero at the edge of a record's reach so no seam shows where
//! records start and stop overlapping). Records lying in front of p (`(p − p_i)·(n + n_i)/2 < 0`
//! beyond a tolerance) are not used (Ward 1988 §3). R is clamped to
//! [[`IrradianceCacheSettings::min_radius_px`], [`IrradianceCacheSettings::max_radius_px`]]
//! pixel footprints at the record's distance from the camera (Tabellion & Lamorlette 2004 §3.1:
//! screen-space clamping keeps records dense enough in open areas and stops them crowding into
//! corners).
//!
//! **Determinism.** Each image tile has its own cache ([`TileScope`], opened by the tile loop of
//! [`super::render_view`] and [`super::render_view_spectral`]), kept per tracer (the spectral
//! passes do not share records). Tiles are fixed by the tile size, not the thread count, and a
//! tile is traced in a fixed pixel order on one thread, so the records, and therefore the image,
//! are the same bits for any thread count. Outside a tile scope (a tracer called directly) every
//! gather is computed exactly. The cost: records are not shared across tile borders, so a tile
//! recomputes what its neighbour had.
//!
//! # Known limitations
//! No irradiance gradients (Ward & Heckbert 1992): the interpolation is a weighted mean, so it
//! smooths rather than extrapolates, and near contact edges (a façade meeting the ground, where
//! the gathered irradiance changes within a few centimetres) the result is an average over the
//! records' reach — contact darkening is softened by up to `a·R_min`. The error estimate looks at
//! geometry only: a change in the gathered irradiance that comes from lighting (a sun-shadow
//! boundary on a surface the gather rays see) is smoothed over the records' reach too. Records are
//! per tile, not shared across tiles.

use std::cell::RefCell;

use nalgebra::{Point3, Vector3};

use super::illumination::Rgb;

/// Ward's accuracy `a`: a record answers for points whose error estimate `ε` is below it.
/// 0.2 keeps the interpolated irradiance within a few per cent of a fresh gather in the
/// accuracy scenes (Ward 1988 used 0.1–0.2 for final frames of indoor scenes with far more
/// variation in the indirect light than a one-bounce outdoor gather).
pub const DEFAULT_ACCURACY: f64 = 0.2;

/// Smallest validity radius, pixel footprints at the record's distance: `a·R_min` = 0.4 px, so
/// near contact edges almost every pixel gathers afresh (the smoothing stays below a pixel).
pub const DEFAULT_MIN_RADIUS_PX: f64 = 2.0;

/// Largest validity radius, pixel footprints: `a·R_max` ≈ 10 px reach in open areas, where bounce
/// light from surfaces metres away is smooth over many pixels; a 32-px tile then needs a few
/// dozen gathers instead of thousands.
pub const DEFAULT_MAX_RADIUS_PX: f64 = 48.0;

/// Records kept per tile and gather kind; past it gathers are computed without being stored
/// (bounds memory and the linear lookup on pathological tiles, e.g. water-wave normals).
pub const DEFAULT_MAX_RECORDS_PER_TILE: usize = 2048;

/// Records in front of the lookup point by more than this fraction of their radius are skipped
/// (they see a different part of the scene; Ward 1988 §3).
const IN_FRONT_TOLERANCE: f64 = 0.05;

/// Settings of the irradiance cache (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrradianceCacheSettings {
    /// Ward's accuracy `a` (dimensionless, > 0).
    pub accuracy: f64,
    /// Smallest validity radius, pixel footprints.
    pub min_radius_px: f64,
    /// Largest validity radius, pixel footprints.
    pub max_radius_px: f64,
    /// Records per tile and gather kind at most.
    pub max_records_per_tile: usize,
}

impl Default for IrradianceCacheSettings {
    /// The `DEFAULT_*` constants of this module.
    fn default() -> Self {
        Self {
            accuracy: DEFAULT_ACCURACY,
            min_radius_px: DEFAULT_MIN_RADIUS_PX,
            max_radius_px: DEFAULT_MAX_RADIUS_PX,
            max_records_per_tile: DEFAULT_MAX_RECORDS_PER_TILE,
        }
    }
}

/// Which gather a record holds (their values are not interchangeable).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum GatherKind {
    /// At a changed natural point: interreflection before, after, light from artificial objects.
    NaturalPoint = 0,
    /// At an artificial point: the photo bounce over the main dome.
    ArtificialPoint = 1,
    /// At an artificial point seen by another gather: the photo bounce over the nested dome.
    ArtificialNested = 2,
}

const KINDS: usize = 3;

/// Harmonic mean of the hit distances of a gather's rays that hit something. Misses are left
/// out (Radiance counts them as infinitely far): outdoors most gather rays escape to the sky, and
/// counting them would stretch the radius of a point a metre from a wall to several metres,
/// while the wall's share of its irradiance changes on the scale of that metre.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct MeanDistance {
    inverse_sum_per_m: f64,
    count: u32,
}

impl MeanDistance {
    /// Counts one traced ray that hit at `distance_m` (`f64::INFINITY` for a miss, not counted).
    pub(super) fn add(&mut self, distance_m: f64) {
        if distance_m.is_finite() && distance_m > 0.0 {
            self.count += 1;
            self.inverse_sum_per_m += 1.0 / distance_m;
        }
    }

    /// The harmonic mean distance (`f64::INFINITY` when nothing was hit or nothing traced).
    pub(super) fn harmonic_mean_m(&self) -> f64 {
        if self.inverse_sum_per_m > 0.0 {
            f64::from(self.count) / self.inverse_sum_per_m
        } else {
            f64::INFINITY
        }
    }
}

#[derive(Debug, Clone)]
struct Record {
    point: Point3<f64>,
    normal: Vector3<f64>,
    radius_m: f64,
    value: [Rgb; 3],
}

#[derive(Debug, Default)]
struct TileCache {
    tracer_id: u64,
    records: [Vec<Record>; KINDS],
}

impl TileCache {
    /// Ward's weighted mean of the records valid at (`point`, `normal`), if any.
    fn lookup(
        &self,
        kind: GatherKind,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
        accuracy: f64,
    ) -> Option<[Rgb; 3]> {
        let mut sum = [[0.0; 3]; 3];
        let mut weight_sum = 0.0;
        for r in &self.records[kind as usize] {
            let offset = point - r.point;
            let dist = offset.norm();
            if dist >= accuracy * r.radius_m {
                continue;
            }
            let epsilon = dist / r.radius_m + (1.0 - normal.dot(&r.normal)).max(0.0).sqrt();
            if epsilon >= accuracy {
                continue;
            }
            if offset.dot(&(normal + r.normal)) * 0.5 < -IN_FRONT_TOLERANCE * r.radius_m {
                continue;
            }
            let w = 1.0 - epsilon / accuracy;
            weight_sum += w;
            for (s, v) in sum.iter_mut().zip(&r.value) {
                for k in 0..3 {
                    s[k] += w * v[k];
                }
            }
        }
        (weight_sum > 0.0).then(|| sum.map(|s| s.map(|x| x / weight_sum)))
    }
}

thread_local! {
    /// The caches of the tile being traced on this thread, one per tracer; `None` outside a
    /// tile scope.
    static TILE_CACHES: RefCell<Option<Vec<TileCache>>> = const { RefCell::new(None) };
}

/// While alive, gathers on this thread go through a fresh per-tile cache; dropping it discards
/// the records (and restores any scope it was opened inside).
#[derive(Debug)]
pub struct TileScope {
    previous: Option<Vec<TileCache>>,
}

impl TileScope {
    /// Opens a tile's cache on the current thread.
    #[must_use]
    pub fn enter() -> Self {
        let previous = TILE_CACHES.with(|c| c.borrow_mut().replace(Vec::new()));
        Self { previous }
    }
}

impl Drop for TileScope {
    fn drop(&mut self) {
        let previous = self.previous.take();
        TILE_CACHES.with(|c| *c.borrow_mut() = previous);
    }
}

/// The gather of `kind` at (`point`, unit `normal`) for the tracer `tracer_id`: interpolated from
/// the current tile's records when some are valid there, else `compute`d (value and harmonic mean
/// hit distance) and stored with its radius clamped to `[min, max]·footprint_m` (one pixel's
/// footprint at the point). Without a tile scope `compute` is simply called.
pub(super) fn cached_gather(
    settings: &IrradianceCacheSettings,
    tracer_id: u64,
    kind: GatherKind,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
    footprint_m: f64,
    compute: impl FnOnce() -> ([Rgb; 3], MeanDistance),
) -> [Rgb; 3] {
    let found = TILE_CACHES.with(|c| {
        let caches = c.borrow();
        let caches = caches.as_ref()?;
        Some(
            caches
                .iter()
                .find(|t| t.tracer_id == tracer_id)
                .and_then(|t| t.lookup(kind, point, normal, settings.accuracy)),
        )
    });
    let in_scope = match found {
        None => false,
        Some(Some(value)) => return value,
        Some(None) => true,
    };
    // Computed without holding the cache: the gather may itself look up nested records.
    let (value, distance) = compute();
    if !(in_scope && footprint_m.is_finite() && footprint_m > 0.0) {
        return value;
    }
    let radius_m = distance.harmonic_mean_m().clamp(
        settings.min_radius_px * footprint_m,
        settings.max_radius_px * footprint_m,
    );
    TILE_CACHES.with(|c| {
        let mut caches = c.borrow_mut();
        let Some(caches) = caches.as_mut() else {
            return;
        };
        let index = match caches.iter().position(|t| t.tracer_id == tracer_id) {
            Some(i) => i,
            None => {
                caches.push(TileCache {
                    tracer_id,
                    ..TileCache::default()
                });
                caches.len() - 1
            }
        };
        let records = &mut caches[index].records[kind as usize];
        if records.len() < settings.max_records_per_tile {
            records.push(Record {
                point: *point,
                normal: *normal,
                radius_m,
                value,
            });
        }
    });
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact equality: the cache must return a stored value unaltered at its own point.
    const EXACT: f64 = 0.0;

    fn footprint() -> f64 {
        0.01
    }

    fn gather_at(p: &Point3<f64>, calls: &mut u32) -> [Rgb; 3] {
        let settings = IrradianceCacheSettings::default();
        cached_gather(
            &settings,
            7,
            GatherKind::NaturalPoint,
            p,
            &Vector3::z(),
            footprint(),
            || {
                *calls += 1;
                // A linear field, irradiance = x, hits 1 m away.
                let mut d = MeanDistance::default();
                d.add(1.0);
                ([[p.x; 3], [0.0; 3], [0.0; 3]], d)
            },
        )
    }

    #[test]
    fn without_scope_every_gather_is_computed() {
        let mut calls = 0;
        for _ in 0..3 {
            let v = gather_at(&Point3::new(0.5, 0.0, 0.0), &mut calls);
            assert!((v[0][0] - 0.5).abs() <= EXACT);
        }
        assert_eq!(calls, 3);
    }

    #[test]
    fn records_are_reused_within_reach_and_not_beyond() {
        let _scope = TileScope::enter();
        let mut calls = 0;
        let first = gather_at(&Point3::new(0.0, 0.0, 0.0), &mut calls);
        assert!((first[0][0]).abs() <= EXACT);
        // R = 1 m clamped to the largest radius (48 footprints = 0.48 m).
        let r_m = DEFAULT_MAX_RADIUS_PX * footprint();
        let near = gather_at(
            &Point3::new(0.5 * DEFAULT_ACCURACY * r_m, 0.0, 0.0),
            &mut calls,
        );
        assert_eq!(calls, 1, "a point within reach reuses the record");
        assert!(near[0][0].abs() <= EXACT, "one record: its value");
        let _far = gather_at(
            &Point3::new(2.0 * DEFAULT_ACCURACY * r_m, 0.0, 0.0),
            &mut calls,
        );
        assert_eq!(calls, 2, "a point beyond reach gathers afresh");
    }

    #[test]
    fn interpolation_between_two_records_is_a_convex_mean() {
        let _scope = TileScope::enter();
        let mut calls = 0;
        let r_m = DEFAULT_MAX_RADIUS_PX * footprint();
        let step = 1.5 * DEFAULT_ACCURACY * r_m;
        gather_at(&Point3::new(0.0, 0.0, 0.0), &mut calls);
        gather_at(&Point3::new(step, 0.0, 0.0), &mut calls);
        let mid = gather_at(&Point3::new(0.5 * step, 0.0, 0.0), &mut calls);
        assert_eq!(calls, 2);
        // Equal weights at the midpoint: the mean of the two values, 0.5·step.
        assert!((mid[0][0] - 0.5 * step).abs() <= 1e-12 * step);
    }

    #[test]
    fn a_different_normal_or_tracer_does_not_reuse() {
        let _scope = TileScope::enter();
        let settings = IrradianceCacheSettings::default();
        let mut calls = 0;
        let p = Point3::origin();
        let mut run = |normal: Vector3<f64>, id: u64| {
            cached_gather(
                &settings,
                id,
                GatherKind::ArtificialPoint,
                &p,
                &normal,
                footprint(),
                || {
                    calls += 1;
                    ([[1.0; 3]; 3], MeanDistance::default())
                },
            )
        };
        run(Vector3::z(), 1);
        run(Vector3::x(), 1);
        run(Vector3::z(), 2);
        run(Vector3::z(), 1);
        assert_eq!(
            calls, 3,
            "perpendicular normal and another tracer gather afresh"
        );
    }

    #[test]
    fn harmonic_mean_of_hits_leaves_misses_out() {
        let mut d = MeanDistance::default();
        d.add(1.0);
        d.add(3.0);
        d.add(f64::INFINITY);
        // 2 / (1 + 1/3) = 1.5 m.
        assert!((d.harmonic_mean_m() - 1.5).abs() <= 1e-12);
        assert!(MeanDistance::default().harmonic_mean_m().is_infinite());
    }
}
