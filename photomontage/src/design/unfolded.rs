//! The "unfolded elevation" of Tonn & Donath: one object's façades (its vertical faces, grouped
//! by the azimuth of their outward normal) laid out flat side by side, N, E, S, W order (by
//! azimuth clockwise from north, +y), each seen from outside with up = +z, painted either with
//! their current diffuse colour or with the irradiance of a radiosity [`Solution`] in false
//! colour, with a labelled scale bar and (for irradiance) a labelled colour ramp.
//!
//! Frames: world x east, y north, z up (metres). A façade's horizontal axis is `right =
//! (−n) × z`, the viewer's right when looking at it from outside; all panels share the object's
//! z range, so their baselines line up.
//!
//! # Known limitations
//! Faces that are not vertical (|n_z| > [`UnfoldParams::max_normal_z`]: roofs, sloped glazing)
//! are left out. Façades whose azimuths differ by less than the tolerance are one panel, so a
//! wall with a slight kink is drawn as its projection. Irradiance is shown as luminance Y of the
//! site's RGB units, not photometric lux.

use image::{Rgb, RgbImage};
use nalgebra::{Point3, Vector3};

use crate::colour::designer::srgb8_from_linear;
use crate::colour::rgb::RgbColourSpace;
use crate::radiosity::Solution;
use crate::radiosity::convergence_plot::text;
use crate::scene::{ObjectId, Scene};

/// Margin around the drawing, pixels.
pub const MARGIN_PX: u32 = 20;
/// Gap between façade panels, pixels.
pub const GAP_PX: u32 = 16;
/// Height of the label strip under the panels, pixels.
const LABEL_STRIP_PX: u32 = 24;
/// Height of the scale bar and legend area, pixels.
const LEGEND_STRIP_PX: u32 = 40;
const BACKGROUND: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [0, 0, 0];
/// Façade pixels with no face behind them (openings, a gap in the outline).
const EMPTY: [u8; 3] = [230, 230, 230];
/// Face pixels where the solution has no element.
const NO_VALUE: [u8; 3] = [128, 128, 128];
/// The most pixels an elevation may have (keeps a bad scale from allocating gigabytes).
pub const MAX_PIXELS: u64 = 64_000_000;

/// Errors of the unfolded elevation.
#[derive(Debug, thiserror::Error)]
pub enum UnfoldError {
    /// The object has no vertical face.
    #[error("object `{object}` has no vertical faces to unfold")]
    NoVerticalFaces {
        /// Object name.
        object: String,
    },
    /// No such object.
    #[error("no object {index} in the scene")]
    NoObject {
        /// The index given.
        index: u32,
    },
    /// A parameter is out of range.
    #[error("{name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The accepted range.
        reason: &'static str,
    },
}

/// Tunables of [`unfold`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnfoldParams {
    /// Pixels per metre of the drawing.
    pub px_per_m: f64,
    /// Faces whose normal azimuths differ by less than this are one façade, degrees.
    pub azimuth_tolerance_deg: f64,
    /// Faces with |n_z| up to this count as vertical.
    pub max_normal_z: f64,
}

impl Default for UnfoldParams {
    fn default() -> Self {
        Self {
            px_per_m: 20.0,
            azimuth_tolerance_deg: 10.0,
            max_normal_z: 0.1,
        }
    }
}

/// One façade panel of the layout.
#[derive(Debug, Clone, PartialEq)]
pub struct FacadePanel {
    /// Azimuth of the outward normal, degrees clockwise from north (+y), area-weighted mean.
    pub azimuth_deg: f64,
    /// Outward horizontal unit normal.
    pub normal_in_world: Vector3<f64>,
    /// The panel's horizontal axis (viewer's right), unit.
    pub right_in_world: Vector3<f64>,
    /// Extent along `right`, metres.
    pub u_range_m: [f64; 2],
    /// Left edge of the panel in the image, pixels.
    pub x0_px: u32,
    /// Width of the panel, pixels (`round(width_m · px_per_m)`, at least 1).
    pub width_px: u32,
    /// The scene triangles drawn on it.
    pub triangles: Vec<usize>,
}

impl FacadePanel {
    /// Width along `right`, metres.
    #[must_use]
    pub fn width_m(&self) -> f64 {
        self.u_range_m[1] - self.u_range_m[0]
    }

    /// Compass label of the azimuth (N, NE, E, …).
    #[must_use]
    pub fn compass(&self) -> &'static str {
        const NAMES: [&str; 8] = ["n", "ne", "e", "se", "s", "sw", "w", "nw"];
        // The azimuth is in [0, 360), so the index is 0..=8 before the modulo.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let k = ((self.azimuth_deg / 45.0).round() as usize) % 8;
        NAMES[k]
    }
}

/// The façades of one object laid out flat.
#[derive(Debug, Clone, PartialEq)]
pub struct UnfoldedLayout {
    /// Object name.
    pub object: String,
    /// Panels left to right (azimuth increasing from north).
    pub panels: Vec<FacadePanel>,
    /// The object's vertical range, metres.
    pub z_range_m: [f64; 2],
    /// Scale.
    pub px_per_m: f64,
    /// Top edge of the panels, pixels.
    pub y0_px: u32,
    /// Height of the panels, pixels.
    pub height_px: u32,
    /// Image size, pixels.
    pub image_size_px: [u32; 2],
}

fn azimuth_deg(n: &Vector3<f64>) -> f64 {
    n.x.atan2(n.y).to_degrees().rem_euclid(360.0)
}

fn angle_between_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

fn to_px(v: f64) -> Result<u32, UnfoldError> {
    // Checked against MAX_PIXELS by the caller's size test; round to whole pixels.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let p = v.round().max(1.0) as u64;
    u32::try_from(p).map_err(|_| UnfoldError::InvalidParameter {
        name: "px_per_m",
        value: v,
        reason: "the drawing would be too large",
    })
}

/// Groups the vertical faces of `object` into façades and lays them out.
///
/// # Errors
/// [`UnfoldError`] for a missing object, no vertical faces, or a bad scale.
pub fn unfold(
    scene: &Scene,
    object: ObjectId,
    params: &UnfoldParams,
) -> Result<UnfoldedLayout, UnfoldError> {
    if !(params.px_per_m > 0.0 && params.px_per_m.is_finite()) {
        return Err(UnfoldError::InvalidParameter {
            name: "px_per_m",
            value: params.px_per_m,
            reason: "must be positive and finite",
        });
    }
    let name = scene
        .objects()
        .get(object.0 as usize)
        .ok_or(UnfoldError::NoObject { index: object.0 })?
        .name
        .clone();
    // (summed area-weighted normal, triangles) per façade.
    let mut groups: Vec<(Vector3<f64>, Vec<usize>)> = Vec::new();
    let mut z_range = [f64::INFINITY, f64::NEG_INFINITY];
    for (k, t) in scene.triangles().iter().enumerate() {
        if t.object != object {
            continue;
        }
        for p in &t.vertices_in_world_m {
            z_range = [z_range[0].min(p.z), z_range[1].max(p.z)];
        }
        let [a, b, c] = t.vertices_in_world_m;
        let cross = (b - a).cross(&(c - a));
        let area2 = cross.norm();
        if area2 <= 0.0 {
            continue;
        }
        let n = cross / area2;
        if n.z.abs() > params.max_normal_z {
            continue;
        }
        let az = azimuth_deg(&n);
        let weighted = Vector3::new(n.x, n.y, 0.0) * area2;
        match groups
            .iter_mut()
            .find(|(sum, _)| angle_between_deg(azimuth_deg(sum), az) < params.azimuth_tolerance_deg)
        {
            Some((sum, tris)) => {
                *sum += weighted;
                tris.push(k);
            }
            None => groups.push((weighted, vec![k])),
        }
    }
    if groups.is_empty() {
        return Err(UnfoldError::NoVerticalFaces { object: name });
    }
    groups.sort_by(|a, b| azimuth_deg(&a.0).total_cmp(&azimuth_deg(&b.0)));
    let height_px = to_px((z_range[1] - z_range[0]) * params.px_per_m)?;
    let mut x = MARGIN_PX;
    let mut panels = Vec::with_capacity(groups.len());
    for (sum, triangles) in groups {
        let normal = sum.normalize();
        let right = (-normal).cross(&Vector3::z()).normalize();
        let mut u_range = [f64::INFINITY, f64::NEG_INFINITY];
        for &k in &triangles {
            for p in &scene.triangles()[k].vertices_in_world_m {
                let u = p.coords.dot(&right);
                u_range = [u_range[0].min(u), u_range[1].max(u)];
            }
        }
        let width_px = to_px((u_range[1] - u_range[0]) * params.px_per_m)?;
        panels.push(FacadePanel {
            azimuth_deg: azimuth_deg(&normal),
            normal_in_world: normal,
            right_in_world: right,
            u_range_m: u_range,
            x0_px: x,
            width_px,
            triangles,
        });
        x = x.saturating_add(width_px).saturating_add(GAP_PX);
    }
    let width = (x - GAP_PX + MARGIN_PX).max(2 * MARGIN_PX + 200);
    let height = MARGIN_PX + height_px + LABEL_STRIP_PX + LEGEND_STRIP_PX + MARGIN_PX;
    if u64::from(width) * u64::from(height) > MAX_PIXELS {
        return Err(UnfoldError::InvalidParameter {
            name: "px_per_m",
            value: params.px_per_m,
            reason: "the drawing would exceed 64 megapixels",
        });
    }
    Ok(UnfoldedLayout {
        object: name,
        panels,
        z_range_m: z_range,
        px_per_m: params.px_per_m,
        y0_px: MARGIN_PX,
        height_px,
        image_size_px: [width, height],
    })
}

/// What the panels show.
#[derive(Clone, Copy)]
pub enum Shading<'a> {
    /// The current diffuse reflectance, sRGB-encoded.
    Colour,
    /// Irradiance (luminance Y of the total) from a radiosity solution, in false colour.
    Irradiance(&'a Solution),
}

/// The world point and outward normal behind the centre of pixel (`x`, `y`) of a panel, with
/// the index of the frontmost triangle there; `None` where no face is.
#[must_use]
pub fn point_at_pixel(
    scene: &Scene,
    layout: &UnfoldedLayout,
    panel: &FacadePanel,
    x_px: u32,
    y_px: u32,
) -> Option<(Point3<f64>, usize)> {
    let u = panel.u_range_m[0] + (f64::from(x_px) - f64::from(panel.x0_px) + 0.5) / layout.px_per_m;
    let z =
        layout.z_range_m[1] - (f64::from(y_px) - f64::from(layout.y0_px) + 0.5) / layout.px_per_m;
    let mut best: Option<(f64, Point3<f64>, usize)> = None;
    for &k in &panel.triangles {
        let v = scene.triangles()[k].vertices_in_world_m;
        let q = v.map(|p| (p.coords.dot(&panel.right_in_world), p.z));
        let det = (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[2].0 - q[0].0) * (q[1].1 - q[0].1);
        if det.abs() < 1e-12 {
            continue;
        }
        let l1 = ((u - q[0].0) * (q[2].1 - q[0].1) - (q[2].0 - q[0].0) * (z - q[0].1)) / det;
        let l2 = ((q[1].0 - q[0].0) * (z - q[0].1) - (u - q[0].0) * (q[1].1 - q[0].1)) / det;
        let l0 = 1.0 - l1 - l2;
        if l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9 {
            continue;
        }
        let p = Point3::from(v[0].coords * l0 + v[1].coords * l1 + v[2].coords * l2);
        let depth = p.coords.dot(&panel.normal_in_world);
        if best.as_ref().is_none_or(|(d, _, _)| depth > *d) {
            best = Some((depth, p, k));
        }
    }
    best.map(|(_, p, k)| (p, k))
}

/// False-colour ramp (blue → cyan → green → yellow → red) of `t` in [0, 1].
#[must_use]
pub fn ramp(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let s = t.clamp(0.0, 1.0) * 4.0;
    // s is in [0, 4]; the index is 0..=3.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i = (s.floor() as usize).min(3);
    let f = s - i as f64;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let c = |j: usize| ((STOPS[i][j] * (1.0 - f) + STOPS[i + 1][j] * f) * 255.0).round() as u8;
    [c(0), c(1), c(2)]
}

/// A drawn elevation.
#[derive(Debug, Clone)]
pub struct UnfoldedImage {
    /// The picture.
    pub image: RgbImage,
    /// For irradiance: the top of the colour ramp (largest Y on the panels).
    pub max_irradiance_y: Option<f64>,
}

/// A drawn pixel: position, a fixed colour, or a value for the ramp.
type Cell = (u32, u32, Option<[u8; 3]>, Option<f64>);

/// Draws the layout.
#[must_use]
pub fn draw(scene: &Scene, layout: &UnfoldedLayout, shading: Shading<'_>) -> UnfoldedImage {
    let [w, h] = layout.image_size_px;
    let mut img = RgbImage::from_pixel(w, h, Rgb(BACKGROUND));
    let space = RgbColourSpace::srgb();
    // First pass: values per pixel (Y for irradiance), so the ramp can be scaled to the maximum.
    let mut cells: Vec<Cell> = Vec::new();
    let mut max_y: f64 = 0.0;
    for panel in &layout.panels {
        for y in layout.y0_px..layout.y0_px + layout.height_px {
            for x in panel.x0_px..panel.x0_px + panel.width_px {
                let Some((p, k)) = point_at_pixel(scene, layout, panel, x, y) else {
                    cells.push((x, y, Some(EMPTY), None));
                    continue;
                };
                match shading {
                    Shading::Colour => {
                        let m = &scene.materials()[scene.triangles()[k].material.0 as usize];
                        cells.push((
                            x,
                            y,
                            Some(srgb8_from_linear(m.diffuse_reflectance_rgb())),
                            None,
                        ));
                    }
                    Shading::Irradiance(solution) => {
                        match solution.irradiance_at(&p, &panel.normal_in_world) {
                            Some(s) => {
                                let yv = space.luminance(s.total_rgb);
                                max_y = max_y.max(yv);
                                cells.push((x, y, None, Some(yv)));
                            }
                            None => cells.push((x, y, Some(NO_VALUE), None)),
                        }
                    }
                }
            }
        }
    }
    for (x, y, colour, value) in cells {
        let c = colour.unwrap_or_else(|| ramp(value.unwrap_or(0.0) / max_y.max(1e-300)));
        img.put_pixel(x, y, Rgb(c));
    }
    // Labels under each panel: compass, azimuth and width.
    let label_y = i64::from(layout.y0_px + layout.height_px + 4);
    for panel in &layout.panels {
        let line1 = format!("{} {:.0}", panel.compass(), panel.azimuth_deg);
        let line2 = format!("{:.2} m", panel.width_m());
        text(&mut img, i64::from(panel.x0_px), label_y, &line1, INK);
        text(&mut img, i64::from(panel.x0_px), label_y + 9, &line2, INK);
    }
    // Scale bar: the largest of 1, 2, 5, 10, 20, 50 m that fits in 200 px.
    let legend_y = layout.y0_px + layout.height_px + LABEL_STRIP_PX + 6;
    let bar_m = [50.0, 20.0, 10.0, 5.0, 2.0, 1.0]
        .into_iter()
        .find(|m| m * layout.px_per_m <= 200.0)
        .unwrap_or(1.0);
    // Fits in 200 px by the choice above (or 1 m at most the scale's pixels).
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let bar_px = ((bar_m * layout.px_per_m).round() as u32).min(w.saturating_sub(2 * MARGIN_PX));
    for x in MARGIN_PX..MARGIN_PX + bar_px {
        for y in legend_y..legend_y + 4 {
            if x < w && y < h {
                img.put_pixel(x, y, Rgb(INK));
            }
        }
    }
    text(
        &mut img,
        i64::from(MARGIN_PX),
        i64::from(legend_y + 7),
        &format!("{bar_m:.0} m"),
        INK,
    );
    let max_irradiance_y = matches!(shading, Shading::Irradiance(_)).then_some(max_y);
    if let Some(max_y) = max_irradiance_y {
        let x0 = MARGIN_PX + bar_px + 30;
        let ramp_px = 150u32;
        for i in 0..ramp_px {
            let c = ramp(f64::from(i) / f64::from(ramp_px - 1));
            for y in legend_y..legend_y + 8 {
                if x0 + i < w && y < h {
                    img.put_pixel(x0 + i, y, Rgb(c));
                }
            }
        }
        text(&mut img, i64::from(x0), i64::from(legend_y + 11), "0", INK);
        text(
            &mut img,
            i64::from(x0 + ramp_px) - 30,
            i64::from(legend_y + 11),
            &format!("{max_y:.3}"),
            INK,
        );
        text(
            &mut img,
            i64::from(x0 + ramp_px + 8),
            i64::from(legend_y),
            "irradiance y",
            INK,
        );
    }
    UnfoldedImage {
        image: img,
        max_irradiance_y,
    }
}

#[cfg(test)]
#[path = "unfolded_tests.rs"]
mod tests;
