//! The wireline of a proposal (LVMF SPG 2012 Appendix C, AVR1 "location, size and degree of
//! visibility"; TGN 06/19 "photowire"): the proposal's feature edges projected into the photo,
//! each point classified visible or hidden by the existing scene and by the proposal itself.
//!
//! **Feature edges** of the proposal's triangles (vertices joined by their exact `f64`
//! coordinates): boundary edges (one triangle), non-manifold edges (three or more) and creases,
//! where the two triangles' planes meet at more than [`CREASE_ANGLE_DEG`]; edges inside a flat
//! face (the diagonals of its triangulation) are left out.
//!
//! **Hidden-line removal** by ray casting (Appel 1967's quantitative invisibility, decided per
//! sample instead of per segment): every edge is sampled at most [`SAMPLE_STEP_PX`] apart in the
//! image (distortion included, since the samples are projected one by one), and a sample is
//! hidden when the segment from the camera centre to it first meets a surface (natural or
//! artificial) that the sample lies behind by more than [`contact_tolerance_m`], measured along
//! that surface's normal: `(d − t)·|n·r| >` tolerance, with `d` the sample's distance, `t` the
//! hit's, `r` the ray and `n` the surface normal. The edge's own faces, which the ray grazes at the
//! edge, are at `t ≈ d`; a building's base sunk a few millimetres into a surveyed ground polygon
//! (whose corners carry survey noise) is seen at a grazing angle far along the ray but only
//! millimetres behind the ground, so it stays visible.
//!
//! # Known limitations
//! Visibility is decided at the samples, so a gap in an occluder narrower than the sample step
//! may be missed; triangles that share an edge but not its exact vertex coordinates (a T-junction,
//! vertices welded differently) give two boundary edges there. Edges closer to the camera than
//! [`NEAR_M`] are clipped.

use std::collections::HashMap;

use nalgebra::{Point2, Point3, Vector3};

use crate::camera::Camera;
use crate::scene::{ObjectKind, Scene, SceneTracer};

/// Two adjacent triangles form a crease (drawn) when their planes meet at more than this: 20°
/// keeps the corners of buildings (90°) and roof pitches, and drops tessellation of gentle
/// curves.
pub const CREASE_ANGLE_DEG: f64 = 20.0;
/// Edge samples are at most this far apart in the image (half a pixel: each pixel an edge
/// crosses gets at least one sample).
pub const SAMPLE_STEP_PX: f64 = 0.5;
/// Points nearer the camera than this (along the optical axis) are not drawn.
pub const NEAR_M: f64 = 0.1;

/// How far behind an occluding surface (along its normal) an edge sample must lie to be hidden:
/// 2 cm, twice the default 1 cm survey σ of the points scene polygons are built from (a contact
/// within the survey's accuracy is not an occlusion), or 1e-4 of the distance when that is more
/// (the `f32` tracing frame's precision is far below both).
#[must_use]
pub fn contact_tolerance_m(distance_m: f64) -> f64 {
    (1e-4 * distance_m).max(0.02)
}

/// A feature edge of the proposal, world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureEdge {
    pub from_in_world_m: Point3<f64>,
    pub to_in_world_m: Point3<f64>,
}

type VertexKey = [u64; 3];
/// An edge's end points and the unit normals of the triangles sharing it.
type EdgeFaces = (Point3<f64>, Point3<f64>, Vec<Vector3<f64>>);

fn key(p: &Point3<f64>) -> VertexKey {
    // +0.0 and −0.0 are the same point.
    [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits)
}

/// The feature edges of `triangles` (definition in the module doc).
#[must_use]
pub fn feature_edges(triangles: &[[Point3<f64>; 3]]) -> Vec<FeatureEdge> {
    let cos_crease = CREASE_ANGLE_DEG.to_radians().cos();
    // Edge (ordered vertex keys) → its end points and the unit normals of its triangles.
    let mut edges: HashMap<(VertexKey, VertexKey), EdgeFaces> = HashMap::new();
    let mut order = Vec::new();
    for [a, b, c] in triangles {
        let n = (b - a).cross(&(c - a));
        let Some(n) = n.try_normalize(0.0) else {
            continue; // degenerate triangle
        };
        for (p, q) in [(a, b), (b, c), (c, a)] {
            let (kp, kq) = (key(p), key(q));
            if kp == kq {
                continue;
            }
            let k = if kp < kq { (kp, kq) } else { (kq, kp) };
            edges
                .entry(k)
                .or_insert_with(|| {
                    order.push(k);
                    (*p, *q, Vec::new())
                })
                .2
                .push(n);
        }
    }
    order
        .iter()
        .filter_map(|k| {
            let (p, q, normals) = edges.get(k)?;
            let feature = match normals.as_slice() {
                [n1, n2] => n1.dot(n2).abs() < cos_crease,
                _ => true,
            };
            feature.then_some(FeatureEdge {
                from_in_world_m: *p,
                to_in_world_m: *q,
            })
        })
        .collect()
}

/// A run of consecutive samples of one edge with the same visibility, as pixel positions.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeRun {
    pub points_px: Vec<Point2<f64>>,
    pub visible: bool,
}

/// The part of segment `a`–`b` in front of the camera's near plane, or `None`.
fn clip_to_near(camera: &Camera, a: &Point3<f64>, b: &Point3<f64>) -> Option<[Point3<f64>; 2]> {
    let za = camera.pose.camera_from_world(a).z - NEAR_M;
    let zb = camera.pose.camera_from_world(b).z - NEAR_M;
    match (za >= 0.0, zb >= 0.0) {
        (true, true) => Some([*a, *b]),
        (false, false) => None,
        (true, false) => Some([*a, a + (b - a) * (za / (za - zb))]),
        (false, true) => Some([a + (b - a) * (za / (za - zb)), *b]),
    }
}

/// Projects the feature edges of `scene`'s artificial objects into `camera` and classifies every
/// sample by a ray against the whole scene (module doc). Runs of samples outside the image are
/// dropped.
#[must_use]
pub fn wireline_runs(scene: &Scene, tracer: &SceneTracer, camera: &Camera) -> Vec<EdgeRun> {
    let objects = scene.objects();
    let artificial: Vec<[Point3<f64>; 3]> = scene
        .triangles()
        .iter()
        .filter(|t| {
            usize::try_from(t.object.0)
                .ok()
                .and_then(|i| objects.get(i))
                .is_some_and(|o| o.kind == ObjectKind::Artificial)
        })
        .map(|t| t.vertices_in_world_m)
        .collect();
    let centre = camera.pose.camera_center_in_world;
    // Samples of every edge: (edge index, world point, pixel).
    let mut samples: Vec<(usize, Point3<f64>, Point2<f64>)> = Vec::new();
    for (index, edge) in feature_edges(&artificial).iter().enumerate() {
        let Some([a, b]) = clip_to_near(camera, &edge.from_in_world_m, &edge.to_in_world_m) else {
            continue;
        };
        let (Some(pa), Some(pb)) = (camera.project(&a), camera.project(&b)) else {
            continue;
        };
        // Curved by distortion: sample densely on the straight estimate, at least 2 points.
        let length_px = (pb - pa).norm().min(1e6);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let steps = ((length_px / SAMPLE_STEP_PX).ceil() as usize).max(1) * 2;
        for i in 0..=steps {
            #[allow(clippy::cast_precision_loss)]
            let s = i as f64 / steps as f64;
            let p = a + (b - a) * s;
            if let Some(px) = camera.project(&p) {
                samples.push((index, p, px));
            }
        }
    }
    let rays: Vec<_> = samples
        .iter()
        .map(|(_, p, _)| {
            let d = p - centre;
            #[allow(clippy::cast_possible_truncation)]
            let t_max = d.norm() as f32;
            tracer.ray_from_world(&centre, &d, 0.0, t_max)
        })
        .collect();
    let blocked: Vec<bool> = tracer
        .closest_hits(&rays)
        .iter()
        .zip(&samples)
        .map(|(hit, (_, p, _))| {
            hit.is_some_and(|h| {
                let v = p - centre;
                let dist = v.norm();
                let n = h.hit.normal_geometric.map(f64::from);
                let cos = (Vector3::from(n).dot(&v) / dist).abs();
                (dist - f64::from(h.hit.t)) * cos > contact_tolerance_m(dist)
            })
        })
        .collect();
    let mut runs: Vec<EdgeRun> = Vec::new();
    let mut last_edge = usize::MAX;
    for ((edge, _, px), hidden) in samples.iter().zip(blocked) {
        if !camera.intrinsics.contains(*px) {
            last_edge = usize::MAX; // leaves the image: start a new run when it comes back
            continue;
        }
        let visible = !hidden;
        match runs.last_mut() {
            Some(run) if last_edge == *edge && run.visible == visible => run.points_px.push(*px),
            _ => runs.push(EdgeRun {
                points_px: vec![*px],
                visible,
            }),
        }
        last_edge = *edge;
    }
    runs
}

/// What a pixel of the wireline raster shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinePixel {
    #[default]
    None,
    /// A visible edge (drawn solid).
    Visible,
    /// A hidden edge (drawn dashed).
    Hidden,
}

/// Dash pattern of hidden edges: on for this many pixels of arc length...
pub const DASH_ON_PX: f64 = 6.0;
/// ...then off for this many.
pub const DASH_OFF_PX: f64 = 4.0;

/// Rasterises the runs one pixel wide into a `size_px` grid (row-major): visible runs solid,
/// hidden runs dashed; a pixel both visible and hidden is visible. A pixel is marked when a point
/// of the run, stepped at most 0.5 px apart, lies in it.
#[must_use]
pub fn rasterise(runs: &[EdgeRun], size_px: [u32; 2]) -> Vec<LinePixel> {
    let [w, h] = size_px.map(|v| v as usize);
    let mut out = vec![LinePixel::None; w * h];
    let mut mark = |p: Point2<f64>, kind: LinePixel| {
        let (x, y) = (p.x.round(), p.y.round());
        #[allow(clippy::cast_precision_loss)]
        if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
            return;
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let i = y as usize * w + x as usize;
        if out[i] != LinePixel::Visible {
            out[i] = kind;
        }
    };
    for run in runs {
        let kind = if run.visible {
            LinePixel::Visible
        } else {
            LinePixel::Hidden
        };
        let mut arc = 0.0;
        let dash_on =
            |arc: f64| run.visible || arc.rem_euclid(DASH_ON_PX + DASH_OFF_PX) < DASH_ON_PX;
        if let Some(first) = run.points_px.first() {
            mark(*first, kind);
        }
        for pair in run.points_px.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let len = (b - a).norm();
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let n = ((len / 0.5).ceil() as usize).clamp(1, 1 << 20);
            for i in 1..=n {
                #[allow(clippy::cast_precision_loss)]
                let s = i as f64 / n as f64;
                if dash_on(arc + len * s) {
                    mark(a + (b - a) * s, kind);
                }
            }
            arc += len;
        }
    }
    out
}

#[cfg(test)]
#[path = "wireline_tests.rs"]
mod tests;
