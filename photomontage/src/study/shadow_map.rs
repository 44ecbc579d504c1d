//! Plan-view shadow maps, as planning authorities ask for: the site seen from straight above on a
//! grid of square cells (0.25 m by default) over the extent of the existing ("natural") geometry,
//! each cell classed as lit, in an existing shadow, in a shadow added by the proposal, or covered
//! by the proposal itself.
//!
//! For the centre (x, y) of each cell a ray goes straight down from above the scene; its first hit
//! is the surface seen from above (the ground, or a roof). On a natural surface a shadow ray goes
//! towards the sun (the same direction the renderer uses, [`crate::site::render::site_sun_dir`]):
//! blocked by natural geometry → existing shadow (whatever the proposal does); blocked only by
//! artificial geometry → added shadow; unblocked → lit. This is the binary sun visibility of the
//! differential renderer's direct term (Durisch 1992 §6.2, cases B and C) sampled at one point per
//! cell, without the sun disc's penumbra.
//!
//! **Extent.** The natural geometry's plan extent, cut to the planned objects' plan extent grown
//! by [`SHADOW_REACH`] × their height (at least [`MIN_MARGIN_M`]): a site modelled on a 1 km
//! ground would otherwise be mapped at 1 km, with the proposal a speck in it. The margin holds a
//! shadow cast with the sun 15° or more above the horizon; for a lower sun the map grows on the side
//! away from the sun to the end of the proposal's shadow ([`planned_extent`]), so a winter
//! morning's long shadow is mapped whole. A scene without planned objects is mapped whole.
//!
//! Known limitations: one ray per cell (a cell on a shadow edge takes the class of its centre);
//! the sun is a point (no penumbra); surfaces under an overhang are not seen from above; frames of
//! one study with the sun lower than 15° are mapped over a larger extent than the others.

use image::{Rgb, RgbImage};
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::StudyError;
use crate::bvh::BuildQuality;
use crate::radiosity::convergence_plot::text;
use crate::scene::{ObjectKind, Scene, SceneTracer};

/// The map reaches this many times the planned objects' height beyond their plan extent: the
/// length of a shadow cast with the sun 15° above the horizon (cot 15° = 3.73).
pub const SHADOW_REACH: f64 = 3.75;

/// The map reaches at least this far beyond the planned objects' plan extent, metres.
pub const MIN_MARGIN_M: f64 = 20.0;

/// Default cell size, metres.
pub const DEFAULT_CELL_M: f64 = 0.25;
/// Most cells of one map; a larger site gets larger cells.
pub const MAX_CELLS: usize = 4_000_000;
/// Start of a shadow ray past its surface point, metres (above f32 resolution near the origin).
const SHADOW_RAY_OFFSET_M: f32 = 1e-3;
/// Most artificial surfaces a shadow ray passes through looking for a natural one behind them.
const MAX_ARTIFICIAL_CROSSINGS: usize = 64;
/// Smallest drawn size of a cell in the PNG, pixels, and the least map width, pixels.
const MIN_MAP_WIDTH_PX: usize = 480;

/// The class of one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellClass {
    /// No surface under the cell centre.
    Outside,
    /// Sunlit with and without the proposal.
    Lit,
    /// In the shadow of existing geometry (with or without the proposal).
    ExistingShadow,
    /// Lit today, in the proposal's shadow.
    AddedShadow,
    /// Covered by the proposal (seen from above).
    Proposal,
}

impl CellClass {
    /// Colour in the PNG.
    #[must_use]
    pub fn colour(self) -> [u8; 3] {
        match self {
            Self::Outside => [255, 255, 255],
            Self::Lit => [236, 226, 190],
            Self::ExistingShadow => [130, 130, 140],
            Self::AddedShadow => [214, 40, 40],
            Self::Proposal => [40, 70, 160],
        }
    }

    /// Legend text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Outside => "no surface",
            Self::Lit => "lit",
            Self::ExistingShadow => "existing shadow",
            Self::AddedShadow => "shadow added by the proposal",
            Self::Proposal => "proposal (roof)",
        }
    }
}

/// A plan-view shadow map: cells row-major from the south-west corner, +x east, +y north.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowMap {
    /// World x, y of the south-west corner of cell 0, metres.
    pub min_xy_m: [f64; 2],
    /// Cell edge, metres.
    pub cell_m: f64,
    /// Cells along x and y.
    pub size_cells: [usize; 2],
    /// Class per cell.
    pub classes: Vec<CellClass>,
    /// Height of the surface seen from above per cell (NaN for [`CellClass::Outside`]), metres.
    pub surface_z_m: Vec<f64>,
}

impl ShadowMap {
    /// The world point at the centre of cell (i, j) on its surface (`None` outside).
    #[must_use]
    pub fn cell_point_in_world_m(&self, i: usize, j: usize) -> Option<Point3<f64>> {
        let k = j * self.size_cells[0] + i;
        let z = *self.surface_z_m.get(k)?;
        #[allow(clippy::cast_precision_loss)]
        (!z.is_nan()).then(|| {
            Point3::new(
                self.min_xy_m[0] + (i as f64 + 0.5) * self.cell_m,
                self.min_xy_m[1] + (j as f64 + 0.5) * self.cell_m,
                z,
            )
        })
    }

    /// The class of cell (i, j).
    #[must_use]
    pub fn class(&self, i: usize, j: usize) -> CellClass {
        self.classes[j * self.size_cells[0] + i]
    }

    /// Number of cells of `class`.
    #[must_use]
    pub fn count(&self, class: CellClass) -> usize {
        self.classes.iter().filter(|&&c| c == class).count()
    }
}

/// Computes the map of `scene` for a sun in `sun_dir_in_world` (unit, pointing to the sun) with
/// cells of about `cell_m` (enlarged to stay within [`MAX_CELLS`]).
///
/// # Errors
/// [`StudyError::NoGround`] when the scene has no natural geometry with an extent in plan,
/// [`StudyError::Scene`] when its BVH cannot be built.
pub fn shadow_map(
    scene: &Scene,
    sun_dir_in_world: &Vector3<f64>,
    cell_m: f64,
) -> Result<ShadowMap, StudyError> {
    let natural = |t: &&crate::scene::SceneTriangle| {
        scene
            .objects()
            .get(t.object.0 as usize)
            .is_some_and(|o| o.kind == ObjectKind::Natural)
    };
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for t in scene.triangles().iter().filter(natural) {
        for v in &t.vertices_in_world_m {
            for a in 0..2 {
                lo[a] = lo[a].min(v[a]);
                hi[a] = hi[a].max(v[a]);
            }
        }
    }
    // Around the planned objects (module doc).
    let (mut art_lo, mut art_hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for t in scene.triangles().iter().filter(|t| !natural(t)) {
        for v in &t.vertices_in_world_m {
            for a in 0..3 {
                art_lo[a] = art_lo[a].min(v[a]);
                art_hi[a] = art_hi[a].max(v[a]);
            }
        }
    }
    let sun = sun_dir_in_world.normalize();
    if art_lo[2] <= art_hi[2] {
        let [cut_lo, cut_hi] = planned_extent(art_lo, art_hi, &sun);
        for a in 0..2 {
            lo[a] = lo[a].max(cut_lo[a]);
            hi[a] = hi[a].min(cut_hi[a]);
        }
    }
    let Some([_, top]) = scene.bounding_box_in_world_m() else {
        return Err(StudyError::NoGround);
    };
    if !(lo[0] < hi[0] && lo[1] < hi[1]) {
        return Err(StudyError::NoGround);
    }
    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    #[allow(clippy::cast_precision_loss)]
    let cell_m = cell_m.max((area / MAX_CELLS as f64).sqrt());
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let size = [
        (((hi[0] - lo[0]) / cell_m).ceil() as usize).max(1),
        (((hi[1] - lo[1]) / cell_m).ceil() as usize).max(1),
    ];
    let tracer = SceneTracer::new(scene, BuildQuality::default()).map_err(StudyError::Scene)?;
    let from_z = top.z + 1.0;
    #[allow(clippy::cast_possible_truncation)]
    let down_t_max = (from_z - scene_bottom(scene) + 1.0) as f32;
    let cells: Vec<(CellClass, f64)> = (0..size[0] * size[1])
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % size[0], k / size[0]);
            #[allow(clippy::cast_precision_loss)]
            let above = Point3::new(
                lo[0] + (i as f64 + 0.5) * cell_m,
                lo[1] + (j as f64 + 0.5) * cell_m,
                from_z,
            );
            classify(&tracer, &above, down_t_max, &sun)
        })
        .collect();
    Ok(ShadowMap {
        min_xy_m: lo,
        cell_m,
        size_cells: size,
        classes: cells.iter().map(|c| c.0).collect(),
        surface_z_m: cells.iter().map(|c| c.1).collect(),
    })
}

/// The plan extent kept around planned objects whose bounding box is `art_lo`..`art_hi` (world
/// metres) for a sun in `sun` (unit, towards the sun): their plan extent grown by [`SHADOW_REACH`]
/// × their height (at least [`MIN_MARGIN_M`]) on every side, and, when the sun is lower than
/// that margin allows, further on the side away from the sun, to the end of the shadow their top
/// casts on the level of their base (height × cot elevation) plus [`MIN_MARGIN_M`].
#[must_use]
pub fn planned_extent(art_lo: [f64; 3], art_hi: [f64; 3], sun: &Vector3<f64>) -> [[f64; 2]; 2] {
    let height = art_hi[2] - art_lo[2];
    let margin = MIN_MARGIN_M.max(SHADOW_REACH * height);
    let mut lo = [art_lo[0] - margin, art_lo[1] - margin];
    let mut hi = [art_hi[0] + margin, art_hi[1] + margin];
    if sun.z > 0.0 {
        // The top's shadow on the base level lies at −height·(sx, sy)/sz from the top.
        for a in 0..2 {
            let reach = -height * sun[a] / sun.z;
            if reach < 0.0 {
                lo[a] = lo[a].min(art_lo[a] + reach - MIN_MARGIN_M);
            } else {
                hi[a] = hi[a].max(art_hi[a] + reach + MIN_MARGIN_M);
            }
        }
    }
    [lo, hi]
}

fn scene_bottom(scene: &Scene) -> f64 {
    scene.bounding_box_in_world_m().map_or(0.0, |[lo, _]| lo.z)
}

/// The class of the surface under `above` and its height.
fn classify(
    tracer: &SceneTracer,
    above: &Point3<f64>,
    down_t_max: f32,
    sun: &Vector3<f64>,
) -> (CellClass, f64) {
    let down = tracer.ray_from_world(above, &-Vector3::z(), 0.0, down_t_max);
    let Some(surface) = tracer.closest_hit(&down) else {
        return (CellClass::Outside, f64::NAN);
    };
    let point = tracer.hit_point_in_world_m(&down, surface.hit.t);
    if surface.kind == ObjectKind::Artificial {
        return (CellClass::Proposal, point.z);
    }
    let mut origin = point;
    let mut artificial_seen = false;
    for _ in 0..MAX_ARTIFICIAL_CROSSINGS {
        let ray = tracer.ray_from_world(&origin, sun, SHADOW_RAY_OFFSET_M, f32::INFINITY);
        match tracer.closest_hit(&ray) {
            None => break,
            Some(h) if h.kind == ObjectKind::Natural => {
                return (CellClass::ExistingShadow, point.z);
            }
            Some(h) => {
                artificial_seen = true;
                origin = tracer.hit_point_in_world_m(&ray, h.hit.t);
            }
        }
    }
    let class = if artificial_seen {
        CellClass::AddedShadow
    } else {
        CellClass::Lit
    };
    (class, point.z)
}

/// The map as an image, north up, each cell a square of pixels, with a title line and a legend
/// (colour swatches, cell size, north arrow text) below it.
#[must_use]
pub fn shadow_map_image(map: &ShadowMap, title: &str) -> RgbImage {
    let [nx, ny] = map.size_cells;
    let scale = MIN_MAP_WIDTH_PX.div_ceil(nx).max(1);
    let (map_w, map_h) = (nx * scale, ny * scale);
    let legend = [
        CellClass::Lit,
        CellClass::ExistingShadow,
        CellClass::AddedShadow,
        CellClass::Proposal,
    ];
    let margin = 8;
    let line_h = 12;
    let legend_h = line_h * (legend.len() + 2);
    let width = (map_w + 2 * margin).max(240);
    let height = margin + line_h + map_h + margin + legend_h;
    let to_u32 = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let to_i64 = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
    let mut img = RgbImage::from_pixel(to_u32(width), to_u32(height), Rgb([255, 255, 255]));
    text(&mut img, to_i64(margin), to_i64(margin), title, [0, 0, 0]);
    let top = margin + line_h;
    for j in 0..ny {
        for i in 0..nx {
            let colour = Rgb(map.class(i, j).colour());
            // Row 0 of the image is the north edge (largest j).
            let py0 = top + (ny - 1 - j) * scale;
            for dy in 0..scale {
                for dx in 0..scale {
                    img.put_pixel(to_u32(margin + i * scale + dx), to_u32(py0 + dy), colour);
                }
            }
        }
    }
    let mut y = top + map_h + margin;
    for class in legend {
        for dy in 0..8 {
            for dx in 0..16 {
                img.put_pixel(to_u32(margin + dx), to_u32(y + dy), Rgb(class.colour()));
            }
        }
        text(
            &mut img,
            to_i64(margin + 22),
            to_i64(y),
            class.label(),
            [0, 0, 0],
        );
        y += line_h;
    }
    let note = format!("north up. cell {:.2} m", map.cell_m);
    text(&mut img, to_i64(margin), to_i64(y), &note, [0, 0, 0]);
    img
}

#[cfg(test)]
#[path = "shadow_map_tests.rs"]
mod tests;
