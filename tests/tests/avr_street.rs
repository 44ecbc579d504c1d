//! AVR render modes on the `street` sample site, checked against the generator's geometry
//! (sample_sites/street/generate.py: its boxes `BOXES`, the ground at local Z = 0, the planned
//! building's corners and the true cameras in truth.json), traced here independently of the
//! library's scene and BVH: an object mask of the truth (which face of the planned building, if
//! any, each pixel centre sees first) and the truth visibility of the building's twelve edges.
//!
//! The site's own scene polygons carry the generator's 1 cm survey noise; at 20–50 m that moves an
//! occluding edge by at most 0.6 px, inside the 1 px bound.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use nalgebra::{Point3, Rotation3, Vector3};
use photomontage::verified::avr::{AvrLevel, avr_overlay};
use photomontage::verified::wireline::LinePixel;
use photomontage_tests::truth::{site_with_true_cameras, true_rotation_rows, truth, vec3};

/// The bound: a drawn visible edge pixel lies within this many pixels (Chebyshev) of an
/// edge of the truth's object mask.
const EDGE_DISTANCE_PX: i64 = 1;
/// Truth edge samples within this many pixels of a change of visibility (along the edge, or of
/// a street box's outline in the image) are left out of the recall and hidden checks (the
/// scene's 1 cm survey noise moves that change by < 1 px).
const TRANSITION_MARGIN_PX: f64 = 2.0;
/// Share of the clearly visible truth edge samples that must have a drawn visible pixel within
/// [`EDGE_DISTANCE_PX`]: all of them.
const RECALL_MIN: f64 = 1.0;
/// An occluder hides a truth edge sample when it is this much nearer than the sample (m).
const OCCLUSION_MARGIN_M: f64 = 0.005;

const W: usize = 1280;
const H: usize = 960;
const FOCAL_PX: f64 = 1100.0;
const ORIGIN: [f64; 3] = [2_683_400.0, 1_247_600.0, 408.0];
/// `BOXES` of generate.py (local min and max corners).
const BOXES: [([f64; 3], [f64; 3]); 4] = [
    ([-20.0, -25.0, 0.0], [-8.0, 25.0, 15.0]),
    ([8.0, 5.0, 0.0], [22.0, 25.0, 11.0]),
    ([-12.0, 40.0, 0.0], [12.0, 52.0, 18.0]),
    ([6.6, -28.0, 0.0], [7.0, -2.0, 1.8]),
];

/// The planned building as a box frame: corner, unit axes and extents.
struct Planned {
    corner: Point3<f64>,
    axes: [Vector3<f64>; 3],
    size: [f64; 3],
}

/// Entry distance and entry face (0–5: −a, +a, −b, +b, −c, +c) of a ray into a box given in its
/// own frame (`o`, `d` already expressed in it), or `None`.
fn slab(o: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Option<(f64, usize)> {
    let (mut t0, mut t1, mut face) = (0.0_f64, f64::INFINITY, 6);
    for k in 0..3 {
        if d[k].abs() < 1e-15 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
        let (near, far, near_face) = if a < b {
            (a, b, 2 * k)
        } else {
            (b, a, 2 * k + 1)
        };
        if near > t0 {
            t0 = near;
            face = near_face;
        }
        t1 = t1.min(far);
    }
    (t0 <= t1 && face < 6).then_some((t0, face))
}

impl Planned {
    fn hit(&self, o: &Point3<f64>, d: &Vector3<f64>) -> Option<(f64, usize)> {
        let rel = o - self.corner;
        let oo = [0, 1, 2].map(|k| rel.dot(&self.axes[k]));
        let dd = [0, 1, 2].map(|k| d.dot(&self.axes[k]));
        slab(oo, dd, [0.0; 3], self.size)
    }
}

/// Nearest hit of the generator's other geometry (boxes and ground), distance only.
fn occluder_t(o: &Point3<f64>, d: &Vector3<f64>) -> f64 {
    let local = [o.x - ORIGIN[0], o.y - ORIGIN[1], o.z - ORIGIN[2]];
    let ground = if d.z < 0.0 {
        -local[2] / d.z
    } else {
        f64::INFINITY
    };
    ground.min(box_t(o, d))
}

/// Nearest hit of the generator's boxes A, B, C, W (not the ground), distance only.
fn box_t(o: &Point3<f64>, d: &Vector3<f64>) -> f64 {
    let local = [o.x - ORIGIN[0], o.y - ORIGIN[1], o.z - ORIGIN[2]];
    let mut t = f64::INFINITY;
    for (lo, hi) in BOXES {
        if let Some((tb, _)) = slab(local, [d.x, d.y, d.z], lo, hi) {
            t = t.min(tb);
        }
    }
    t
}

struct TrueView {
    centre: Point3<f64>,
    rotation: Rotation3<f64>,
    planned: Planned,
    corners: Vec<Point3<f64>>,
}

impl TrueView {
    fn new(id: &str) -> Self {
        let t = truth("street");
        let rows = true_rotation_rows(&t, id);
        let rotation =
            Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_fn(|r, c| rows[r][c]));
        let corners: Vec<Point3<f64>> = t["planned_building"]["corners"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| Point3::from(vec3(c)))
            .collect();
        let (a, b, c) = (
            corners[1] - corners[0],
            corners[3] - corners[0],
            corners[4] - corners[0],
        );
        Self {
            centre: Point3::from(vec3(&t["cameras"][id]["camera_center"])),
            rotation,
            planned: Planned {
                corner: corners[0],
                axes: [a.normalize(), b.normalize(), c.normalize()],
                size: [a.norm(), b.norm(), c.norm()],
            },
            corners,
        }
    }

    /// Pinhole of generate.py: principal point at the image centre, no distortion.
    fn project(&self, p: &Point3<f64>) -> [f64; 2] {
        let c = self.rotation.inverse() * (p - self.centre);
        [
            FOCAL_PX * c.x / c.z + (W as f64 - 1.0) / 2.0,
            FOCAL_PX * c.y / c.z + (H as f64 - 1.0) / 2.0,
        ]
    }

    /// The object mask: 0 for anything but the planned building, 1 + its face otherwise.
    fn object_mask(&self) -> Vec<u8> {
        let mut mask = vec![0_u8; W * H];
        for (i, m) in mask.iter_mut().enumerate() {
            let (x, y) = ((i % W) as f64, (i / W) as f64);
            let d = (self.rotation
                * Vector3::new(
                    x - (W as f64 - 1.0) / 2.0,
                    y - (H as f64 - 1.0) / 2.0,
                    FOCAL_PX,
                ))
            .normalize();
            if let Some((t, face)) = self.planned.hit(&self.centre, &d)
                && t < occluder_t(&self.centre, &d)
            {
                *m = 1 + u8::try_from(face).unwrap();
            }
        }
        mask
    }

    /// Whether a box of the existing street (A, B, C, W) hides `p` along the ray through the
    /// pixel `px` + `offset_px`: the occluders' image near the sample.
    fn box_hides_near(&self, p: &Point3<f64>, px: [f64; 2], offset_px: [f64; 2]) -> bool {
        let d = (self.rotation
            * Vector3::new(
                px[0] + offset_px[0] - (W as f64 - 1.0) / 2.0,
                px[1] + offset_px[1] - (H as f64 - 1.0) / 2.0,
                FOCAL_PX,
            ))
        .normalize();
        box_t(&self.centre, &d) < (p - self.centre).norm() - OCCLUSION_MARGIN_M
    }

    /// Whether the straight segment to `p` is free of the generator's geometry and the planned
    /// building (but for the margin at `p`, where the edge's own faces and the ground meet it).
    fn sees(&self, p: &Point3<f64>) -> bool {
        let v = p - self.centre;
        let dist = v.norm();
        let d = v / dist;
        let limit = dist - OCCLUSION_MARGIN_M;
        occluder_t(&self.centre, &d) >= limit
            && self
                .planned
                .hit(&self.centre, &d)
                .is_none_or(|(t, _)| t >= limit)
    }
}

/// Pixels of the mask where a 4-neighbour has another label and one of the two is the building.
fn mask_edges(mask: &[u8]) -> Vec<bool> {
    (0..W * H)
        .map(|i| {
            let (x, y) = (i % W, i / W);
            let mut n = Vec::new();
            if x > 0 {
                n.push(i - 1);
            }
            if x + 1 < W {
                n.push(i + 1);
            }
            if y > 0 {
                n.push(i - W);
            }
            if y + 1 < H {
                n.push(i + W);
            }
            n.iter()
                .any(|&j| mask[j] != mask[i] && (mask[i] > 0 || mask[j] > 0))
        })
        .collect()
}

fn near(set: &[bool], x: i64, y: i64, r: i64) -> bool {
    (-r..=r).any(|dy| {
        (-r..=r).any(|dx| {
            let (xx, yy) = (x + dx, y + dy);
            (0..W as i64).contains(&xx)
                && (0..H as i64).contains(&yy)
                && set[usize::try_from(yy).unwrap() * W + usize::try_from(xx).unwrap()]
        })
    })
}

#[test]
fn avr1_wireline_matches_the_truth_object_mask() {
    let doc = site_with_true_cameras("street");
    for id in ["V1", "V2", "V3"] {
        let view = TrueView::new(id);
        let overlay = avr_overlay(&doc, id, AvrLevel::Avr1).unwrap();
        let visible: Vec<bool> = overlay
            .lines
            .iter()
            .map(|l| *l == LinePixel::Visible)
            .collect();
        let hidden_drawn = overlay
            .lines
            .iter()
            .filter(|l| **l == LinePixel::Hidden)
            .count();
        let edges = mask_edges(&view.object_mask());
        // 1. Every drawn visible pixel is within 1 px of an edge of the truth's object mask.
        let mut stray = 0;
        let mut drawn = 0;
        for (i, v) in visible.iter().enumerate() {
            if *v {
                drawn += 1;
                let (x, y) = ((i % W) as i64, (i / W) as i64);
                if !near(&edges, x, y, EDGE_DISTANCE_PX) {
                    stray += 1;
                }
            }
        }
        // 2./3. The building's twelve edges, sampled every 0.25 px and classified by the truth.
        let c = &view.corners;
        let box_edges = [
            (0, 1),
            (1, 2),
            (2, 3),
            (3, 0),
            (4, 5),
            (5, 6),
            (6, 7),
            (7, 4),
            (0, 4),
            (1, 5),
            (2, 6),
            (3, 7),
        ];
        let (mut clear_visible, mut found, mut clear_hidden, mut hidden_as_visible) = (0, 0, 0, 0);
        let mut visible_samples: Vec<[f64; 2]> = Vec::new();
        let mut hidden_samples: Vec<[f64; 2]> = Vec::new();
        for (a, b) in box_edges {
            let (pa, pb) = (view.project(&c[a]), view.project(&c[b]));
            let len = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let n = (len / 0.25).ceil() as usize;
            let states: Vec<(bool, [f64; 2])> = (0..=n)
                .map(|i| {
                    let s = i as f64 / n as f64;
                    let p = c[a] + (c[b] - c[a]) * s;
                    (view.sees(&p), view.project(&p))
                })
                .collect();
            let margin = (TRANSITION_MARGIN_PX / 0.25).ceil() as usize;
            for (i, (seen, px)) in states.iter().enumerate() {
                let lo = i.saturating_sub(margin);
                let hi = (i + margin).min(n);
                // Clear: the same along the edge, and no street box's outline in the image
                // within the margin of the sample (an edge running along an occluder's outline,
                // such as the base behind the garden wall's top in V3, is left out).
                let p = c[a] + (c[b] - c[a]) * (i as f64 / n as f64);
                let m = TRANSITION_MARGIN_PX;
                let hidden_by_box = view.box_hides_near(&p, *px, [0.0, 0.0]);
                let clear = states[lo..=hi].iter().all(|(s, _)| s == seen)
                    && [[m, 0.0], [-m, 0.0], [0.0, m], [0.0, -m]]
                        .iter()
                        .all(|o| view.box_hides_near(&p, *px, *o) == hidden_by_box);
                let inside = px[0] >= 0.0
                    && px[1] >= 0.0
                    && px[0] <= W as f64 - 1.0
                    && px[1] <= H as f64 - 1.0;
                if !(clear && inside) {
                    continue;
                }
                if *seen {
                    visible_samples.push(*px);
                } else {
                    hidden_samples.push(*px);
                }
            }
        }
        for px in &visible_samples {
            clear_visible += 1;
            if near(
                &visible,
                px[0].round() as i64,
                px[1].round() as i64,
                EDGE_DISTANCE_PX,
            ) {
                found += 1;
            }
        }
        for px in &hidden_samples {
            // Where a hidden edge crosses a visible one in the image, the visible one is drawn.
            let crosses = visible_samples
                .iter()
                .any(|v| (v[0] - px[0]).hypot(v[1] - px[1]) < TRANSITION_MARGIN_PX);
            if crosses {
                continue;
            }
            clear_hidden += 1;
            if near(&visible, px[0].round() as i64, px[1].round() as i64, 0) {
                hidden_as_visible += 1;
            }
        }
        let recall = f64::from(found) / f64::from(clear_visible.max(1));
        println!(
            "{id}: {drawn} visible pixels drawn ({stray} farther than {EDGE_DISTANCE_PX} px from a \
             truth edge), {hidden_drawn} hidden (dashed); truth-visible edge samples found \
             {found}/{clear_visible} ({:.2} %); truth-hidden samples drawn as visible \
             {hidden_as_visible}/{clear_hidden}",
            100.0 * recall
        );
        assert!(drawn > 0 && clear_visible > 0, "{id}: nothing to compare");
        assert!(stray == 0, "{id}: {stray} stray visible pixels");
        assert!(recall >= RECALL_MIN, "{id}: recall {recall}");
        assert_eq!(hidden_as_visible, 0, "{id}: hidden edges drawn as visible");
    }
}

#[test]
fn avr0_silhouette_matches_the_truth_object_mask() {
    let doc = site_with_true_cameras("street");
    for id in ["V1", "V2", "V3"] {
        let view = TrueView::new(id);
        let overlay = avr_overlay(&doc, id, AvrLevel::Avr0).unwrap();
        let truth_mask: Vec<bool> = view.object_mask().iter().map(|m| *m > 0).collect();
        let edges = mask_edges(&view.object_mask());
        // Pixels where the silhouette and the truth mask disagree must lie on the truth mask's
        // boundary (within 1 px): pixel centres within the survey noise of an edge.
        let (mut disagree, mut off_edge, mut inside) = (0, 0, 0);
        for (i, (ours, theirs)) in overlay.silhouette.iter().zip(&truth_mask).enumerate() {
            inside += usize::from(*theirs);
            if ours != theirs {
                disagree += 1;
                if !near(&edges, (i % W) as i64, (i / W) as i64, EDGE_DISTANCE_PX) {
                    off_edge += 1;
                }
            }
        }
        println!(
            "{id}: truth silhouette {inside} px, {disagree} px differ, {off_edge} of them off the truth's edges"
        );
        assert!(inside > 0);
        assert_eq!(off_edge, 0, "{id}");
    }
}

#[test]
fn overlays_refuse_bad_views_by_name() {
    let doc = photomontage::site::SiteDocument::load(
        &photomontage_tests::sample_site("street").join("site.toml"),
    )
    .unwrap();
    let err = avr_overlay(&doc, "V3", AvrLevel::Avr1)
        .unwrap_err()
        .to_string();
    assert!(err.contains("V3") && err.contains("not solved"), "{err}");
    let mut doc = site_with_true_cameras("street");
    for m in &mut doc.site.models {
        m.visible = false;
    }
    let err = avr_overlay(&doc, "V1", AvrLevel::Avr0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("V1") && err.contains("no visible model"),
        "{err}"
    );
}

/// Mean blue/red ratio over the pixels the planned building covers in a render of view V1
/// (box-filtered 4 × 4, like street_render.rs), with or without the AVR2 massing material.
fn building_blue_over_red(massing: bool) -> f64 {
    use photomontage::render::{DifferentialTracer, render_view};
    use photomontage_tests::street::downscale;
    let doc = site_with_true_cameras("street");
    let mut job = photomontage::site::render::prepare_view(&doc, "V1").unwrap();
    if massing {
        photomontage::verified::apply_massing(&mut job.scene.scene).unwrap();
    }
    let scale = 4;
    let photo = downscale(&job.photo_linear, scale);
    let k = &mut job.camera.intrinsics;
    k.focal_px /= f64::from(scale);
    k.principal_point_px = k
        .principal_point_px
        .map(|c| (c + 0.5) / f64::from(scale) - 0.5);
    k.image_size_px = [photo.width(), photo.height()];
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &photo,
        job.settings.max_depth,
    )
    .unwrap();
    let out = render_view(
        &tracer,
        &job.settings,
        &|_| {},
        &std::sync::atomic::AtomicBool::new(false),
    )
    .unwrap();
    let (mut sum, mut n) = (0.0, 0.0);
    for p in out.rgba.iter().filter(|p| p[3] >= 1.0) {
        sum += f64::from(p[2]) / f64::from(p[0]);
        n += 1.0;
    }
    assert!(n > 0.0);
    sum / n
}

/// AVR2 shows the building in the neutral massing grey under the site's light, AVR3 in its own
/// material. The light's blue/red ratio is that of the sun (2.6/3.0) mixed with the sky
/// (0.45/0.25): a grey surface lies between 0.8 and 1.3; the blue-grey cladding (albedo
/// 0.30, 0.42, 0.55, ratio 1.83) times the same light lies above 1.4.
const MASSING_RATIO_RANGE: [f64; 2] = [0.8, 1.3];
const CLADDING_RATIO_MIN: f64 = 1.4;

#[test]
fn avr2_massing_is_neutral_under_the_site_light() {
    let massing = building_blue_over_red(true);
    let montage = building_blue_over_red(false);
    println!("building blue/red: AVR2 {massing:.3}, AVR3 {montage:.3}");
    assert!((MASSING_RATIO_RANGE[0]..=MASSING_RATIO_RANGE[1]).contains(&massing));
    assert!(montage > CLADDING_RATIO_MIN);
}
