//! Irradiance at any point of a solved scene: interpolated from the elements where a point lies
//! on one ([`Solution::irradiance_at`]), with a final gather from the point itself where the
//! mesh is coarse or the point lies on no element ([`Transfer::irradiance_at`]).
//!
//! **Interpolation.** Each element's irradiance (direct, and total H = (B − π·L_e)/ρ) is averaged
//! at its vertices over the elements of the same plane that share the vertex (Cohen & Wallace,
//! seed 002, §9.2 "nodal averaging"); a point is located on its element through a hash grid of
//! element bounding boxes, one level per power-of-two size (module `element_grid`), and takes the
//! barycentric blend of the three vertex values. The lookup is built once per solution
//! ([`std::sync::OnceLock`]) and only read afterwards, so queries run from any number of threads.
//!
//! **Final gather** (Cohen & Wallace §9.3.2; the renderer's fallback): the direct term exactly
//! at the point (one shadow ray per distant source and point source, and the ground below the
//! horizon through its clusters), plus the interreflected term as the mean exitance B seen by
//! cosine-distributed rays (E = ∫ L cos ω dω = π·mean L = mean B for that distribution), each hit
//! located on its element. Rays come from a ChaCha8 stream seeded by the point's coordinates, so a
//! query is repeatable and independent of threads.
//!
//! # Known limitations
//! Vertex averaging smooths irradiance across an element's width (a shadow edge inside an element
//! is blurred over it; finer elements or the final gather are the cure). Elements of zero
//! reflectance carry no interreflected irradiance and are always gathered. The gathered indirect
//! term is a Monte Carlo estimate (error ∝ 1/√rays).

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::element_lookup::ElementLocator;
use super::sources::{DIRECT_RAY_OFFSET_M, DistantSource};
use super::surface_point::{cosine_direction, point_seed};
use super::vertex_gather::GatheredExitance;
use super::{RadiosityError, Rgb, Solution, Transfer};

pub use super::element_lookup::{NORMAL_MATCH_COS, ON_SURFACE_TOL_M};

/// Irradiance at a point, per channel, in the site's linear units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrradianceSample {
    /// Direct irradiance (sun, sky, luminaires, ground below the horizon; shadowed).
    pub direct_rgb: Rgb,
    /// Interreflected irradiance.
    pub indirect_rgb: Rgb,
    /// direct + indirect.
    pub total_rgb: Rgb,
    /// The element the value was interpolated on, `None` for a final gather.
    pub element: Option<usize>,
}

/// Query tunables of [`Transfer::irradiance_at`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QueryParams {
    /// Elements with a longer edge are too coarse to interpolate: the point is gathered, metres.
    pub max_interpolation_edge_m: f64,
    /// Cosine-distributed rays of a final gather.
    pub gather_rays: u32,
}

impl Default for QueryParams {
    /// Interpolate on elements up to 2 m, 256 gather rays.
    fn default() -> Self {
        Self {
            max_interpolation_edge_m: 2.0,
            gather_rays: 256,
        }
    }
}

impl Solution {
    /// The element lookup, built on this thread alone by the first query (module
    /// `element_lookup`: never a parallel build inside the cell).
    fn locator(&self) -> &ElementLocator {
        self.locator
            .get_or_init(|| ElementLocator::new(self, false))
    }

    /// Builds the element lookup that the first point query would build, over rayon's pool and
    /// outside the cell (so that two solutions can build theirs side by side before a render
    /// queries them).
    pub fn prepare_queries(&self) {
        if self.locator.get().is_none() {
            let _ = self.locator.set(ElementLocator::new(self, true));
        }
    }

    /// Irradiance at `point_in_world_m` on a surface of outward unit normal `normal_in_world`,
    /// interpolated from the element the point lies on (module doc); `None` when it lies on none.
    #[must_use]
    pub fn irradiance_at(
        &self,
        point_in_world_m: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
    ) -> Option<IrradianceSample> {
        let locator = self.locator();
        let (e, w) = locator.locate(point_in_world_m, normal_in_world)?;
        let values = locator.vertex_values(e)?;
        let mut total = [0.0; 3];
        let mut direct = [0.0; 3];
        for (k, (t, d)) in values.iter().enumerate() {
            for c in 0..3 {
                total[c] += w[k] * t[c];
                direct[c] += w[k] * d[c];
            }
        }
        let indirect: Rgb = std::array::from_fn(|c| (total[c] - direct[c]).max(0.0));
        Some(IrradianceSample {
            direct_rgb: direct,
            indirect_rgb: indirect,
            total_rgb: std::array::from_fn(|c| direct[c] + indirect[c]),
            element: Some(e),
        })
    }
}

/// Where a point lies on a solution's mesh: its element and barycentric weights of the element's
/// three vertices. It stays valid across relights of the same geometry (a relight changes
/// reflectances and light, not the mesh), so a caller can locate once and read the relit
/// solutions' values there ([`Solution::irradiance_gathered_on`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointOnElement {
    /// The element.
    pub element: u32,
    /// Barycentric weights of its three vertices.
    pub weights: [f64; 3],
}

impl Solution {
    /// Locates a point on this solution's elements as [`Solution::irradiance_gathered_at`] does;
    /// `None` when it lies on none.
    #[must_use]
    pub fn locate_point(
        &self,
        point_in_world_m: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
    ) -> Option<PointOnElement> {
        let (e, weights) = self.locator().locate(point_in_world_m, normal_in_world)?;
        #[allow(clippy::cast_possible_truncation)]
        Some(PointOnElement {
            element: e as u32,
            weights,
        })
    }

    /// Irradiance at a point as [`Solution::irradiance_at`], with the interreflected part taken
    /// from vertex gathers of this solution's mesh summing the exitances `gathered` holds
    /// instead of the elements' own values
    /// ([`super::vertex_gather`]); the direct part stays interpolated. `None` where the point
    /// lies on no element, or when the gathers belong to another geometry.
    #[must_use]
    pub fn irradiance_gathered_at(
        &self,
        point_in_world_m: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
        gathered: &GatheredExitance,
    ) -> Option<IrradianceSample> {
        if gathered.gather().mesh().geometry_hash != self.mesh.geometry_hash {
            return None;
        }
        let at = self.locate_point(point_in_world_m, normal_in_world)?;
        self.irradiance_gathered_on(&at, gathered)
    }

    /// [`Solution::irradiance_gathered_at`] at a point located before
    /// ([`Solution::locate_point`], on this solution or on another of the same geometry). `None`
    /// when the gathers or the point's element belong to another geometry.
    #[must_use]
    pub fn irradiance_gathered_on(
        &self,
        at: &PointOnElement,
        gathered: &GatheredExitance,
    ) -> Option<IrradianceSample> {
        if gathered.gather().mesh().geometry_hash != self.mesh.geometry_hash {
            return None;
        }
        let e = at.element as usize;
        let w = at.weights;
        let mut direct = [0.0; 3];
        for (k, (_, d)) in self.locator().vertex_values(e)?.iter().enumerate() {
            for c in 0..3 {
                direct[c] += w[k] * d[c];
            }
        }
        let indirect = gathered.indirect_rgb(e, w);
        Some(IrradianceSample {
            direct_rgb: direct,
            indirect_rgb: indirect,
            total_rgb: std::array::from_fn(|c| direct[c] + indirect[c]),
            element: Some(e),
        })
    }
}

impl Transfer {
    /// Irradiance at a point on a surface (module doc): interpolated where the point lies on a
    /// reflecting element no longer than [`QueryParams::max_interpolation_edge_m`], else a final
    /// gather from the point.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] for a non-finite point or a normal that is not a
    /// unit vector.
    pub fn irradiance_at(
        &self,
        point_in_world_m: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
        params: &QueryParams,
    ) -> Result<IrradianceSample, RadiosityError> {
        if !point_in_world_m.coords.iter().all(|c| c.is_finite()) {
            return Err(RadiosityError::InvalidParameter {
                name: "point",
                value: f64::NAN,
                reason: "coordinates must be finite",
            });
        }
        let norm = normal_in_world.norm();
        if !(norm.is_finite() && (norm - 1.0).abs() <= 1e-3) {
            return Err(RadiosityError::InvalidParameter {
                name: "normal length",
                value: norm,
                reason: "the normal must be a unit vector (length 1 ± 0.001)",
            });
        }
        let solution = self.solution();
        if let Some(sample) = solution.irradiance_at(point_in_world_m, normal_in_world) {
            let e = sample.element.unwrap_or(usize::MAX);
            let locator = solution.locator();
            if locator.reflects[e]
                && locator.geometry.shapes[e].longest_edge_m <= params.max_interpolation_edge_m
            {
                return Ok(sample);
            }
        }
        Ok(self.gather(point_in_world_m, &normal_in_world.normalize(), params))
    }

    /// Final gather at a point (module doc).
    fn gather(
        &self,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
        params: &QueryParams,
    ) -> IrradianceSample {
        let tracer = self.tracer();
        let solution = self.solution();
        let locator = solution.locator();
        #[allow(clippy::cast_possible_truncation)]
        let offset = DIRECT_RAY_OFFSET_M as f32;
        let origin = point + normal * DIRECT_RAY_OFFSET_M;
        let visible = |dir: &Vector3<f64>, length: f32| {
            !tracer.any_hit(&tracer.ray_from_world(&origin, dir, offset, length))
        };
        let distant = |sources: &[DistantSource]| -> Rgb {
            let mut e = [0.0; 3];
            for s in sources {
                let cos = normal.dot(&s.dir_in_world);
                if cos > 0.0 && visible(&s.dir_in_world, 1e7) {
                    for c in 0..3 {
                        e[c] += s.normal_irradiance_rgb[c] * cos;
                    }
                }
            }
            e
        };
        let mut direct = [0.0; 3];
        let ground_sources = self.ground().map(|g| (g, g.sources.clone()));
        for group in self.light_groups() {
            let mut add = distant(&group.sources);
            if let Some((g, sources)) = &ground_sources {
                let l = g.ground.radiance_rgb(&group.sources);
                let unit = distant(sources)[0];
                for c in 0..3 {
                    add[c] += l[c] * unit;
                }
            }
            for p in &group.points {
                let to_light = p.position_in_world_m - origin;
                let d2 = to_light.norm_squared();
                let d = d2.sqrt();
                let cos = normal.dot(&to_light) / d;
                #[allow(clippy::cast_possible_truncation)]
                if d2 > 0.0 && cos > 0.0 && visible(&(to_light / d), (d * (1.0 - 1e-4)) as f32) {
                    let i = p.intensity_toward_rgb(&(-to_light / d));
                    for c in 0..3 {
                        add[c] += i[c] * cos / d2;
                    }
                }
            }
            for c in 0..3 {
                direct[c] += add[c];
            }
        }
        // Interreflection: the mean exitance seen by cosine-distributed rays.
        let mut rng = ChaCha8Rng::seed_from_u64(point_seed(0xC0FF_EE00, point, normal));
        let mut sum = [0.0; 3];
        for _ in 0..params.gather_rays {
            let dir = cosine_direction(normal, rng.random(), rng.random());
            let ray = tracer.ray_from_world(&origin, &dir, offset, 1e7);
            let Some(hit) = tracer.closest_hit(&ray) else {
                continue;
            };
            let hit_normal = Vector3::from(hit.hit.normal_geometric.map(f64::from));
            if hit_normal.dot(&dir) >= 0.0 {
                continue; // the back of a one-sided surface emits nothing
            }
            let x = tracer.hit_point_in_world_m(&ray, hit.hit.t);
            if let Some((e, _)) = locator.locate(&x, &hit_normal) {
                for c in 0..3 {
                    sum[c] += locator.radiosity[e][c];
                }
            }
        }
        let rays = f64::from(params.gather_rays.max(1));
        let indirect = sum.map(|s| s / rays);
        IrradianceSample {
            direct_rgb: direct,
            indirect_rgb: indirect,
            total_rgb: std::array::from_fn(|c| direct[c] + indirect[c]),
            element: None,
        }
    }
}

/// One row of a points file: `id,X,Y,Z,nx,ny,nz` (world metres, outward unit normal).
#[derive(Debug, Clone, PartialEq)]
pub struct QueryPoint {
    /// The row's id.
    pub id: String,
    /// The point, world metres.
    pub point_in_world_m: Point3<f64>,
    /// Outward unit normal.
    pub normal_in_world: Vector3<f64>,
}

/// A normal is a unit vector when its length is within this of 1 (six significant digits in a
/// CSV give 1e-6; a hand-typed normal like 0.707,0.707 is 1.0001).
pub const UNIT_NORMAL_TOL: f64 = 1e-3;

/// Parses a points file (module doc of the `irradiance` command): one `id,X,Y,Z,nx,ny,nz` row
/// per point; a first row starting with `id` is a header; blank lines and `#` comments are
/// skipped.
///
/// # Errors
/// [`RadiosityError::PointsRow`] naming the line: a missing or extra column, a value that is not
/// a finite number, a normal that is not a unit vector, a repeated id.
pub fn parse_query_points(text: &str) -> Result<Vec<QueryPoint>, RadiosityError> {
    let mut out: Vec<QueryPoint> = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let row = raw.trim();
        if row.is_empty() || row.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        if out.is_empty() && index == 0 && fields[0].eq_ignore_ascii_case("id") {
            continue;
        }
        let bad = |message: String| RadiosityError::PointsRow { line, message };
        if fields.len() != 7 {
            return Err(bad(format!(
                "{} columns, expected 7 (id,X,Y,Z,nx,ny,nz)",
                fields.len()
            )));
        }
        if fields[0].is_empty() {
            return Err(bad("empty id".into()));
        }
        let names = ["X", "Y", "Z", "nx", "ny", "nz"];
        let mut v = [0.0; 6];
        for (k, name) in names.iter().enumerate() {
            let text = fields[k + 1];
            v[k] = text
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("{name} = `{text}` is not a finite number")))?;
        }
        let normal = Vector3::new(v[3], v[4], v[5]);
        let length = normal.norm();
        if (length - 1.0).abs() > UNIT_NORMAL_TOL {
            return Err(bad(format!(
                "normal ({}, {}, {}) has length {length:.6}, not 1 (± {UNIT_NORMAL_TOL})",
                v[3], v[4], v[5]
            )));
        }
        if out.iter().any(|p| p.id == fields[0]) {
            return Err(bad(format!("id `{}` repeats an earlier row", fields[0])));
        }
        out.push(QueryPoint {
            id: fields[0].to_owned(),
            point_in_world_m: Point3::new(v[0], v[1], v[2]),
            normal_in_world: normal / length,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_rows_are_parsed_and_bad_rows_named_by_line() {
        let ok = parse_query_points(
            "id,X,Y,Z,nx,ny,nz\np1,1,2,3,0,0,1\n\n# note\np2, 0,0,0, 0.6,0.8,0\n",
        )
        .unwrap();
        assert_eq!(ok.len(), 2);
        assert_eq!(ok[1].id, "p2");
        assert_eq!(ok[1].normal_in_world, Vector3::new(0.6, 0.8, 0.0));
        for (text, line, words) in [
            ("p1,1,2,3,0,0\n", 1, "6 columns"),
            ("id,X,Y,Z,nx,ny,nz\np1,1,2,3,0,0,2\n", 2, "length 2"),
            ("p1,1,NaN,3,0,0,1\n", 1, "Y = `NaN`"),
            ("p1,1,2,3,0,0,1\np2,1,2,x,0,0,1\n", 2, "Z = `x`"),
            ("p1,1,2,3,0,0,1\np1,1,2,3,0,0,1\n", 2, "repeats"),
            ("p1,1,2,3,0,0,1,9\n", 1, "8 columns"),
        ] {
            let err = parse_query_points(text).unwrap_err();
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("line {line}")) && msg.contains(words),
                "{msg}"
            );
        }
    }
}
