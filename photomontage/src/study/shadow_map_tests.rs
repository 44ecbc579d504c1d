//! The plan-view map against the montage: on the street sample site, ground cells the map calls
//! "added shadow" are the pixels the renderer darkens by losing the sun (its `shadow_change`
//! layer), and cells it calls "lit" are not.
#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use super::*;
use crate::render::output::LayerSet;
use crate::site::SiteDocument;
use crate::site::render::site_camera;
use crate::site::render_photo::{RenderPlan, RenderRequest};
use crate::study::{StudyRequest, frame_shadow_map, parse_dates, parse_times, plan_frames};

/// A pixel is "in added shadow" when the render's change of natural radiance is below this share
/// of the photo's radiance there: losing the direct sun (k_s ≈ 3 at 40° elevation against a sky
/// of k_h ≈ 0.8–1.4) removes well over half of a ground pixel's light, while the proposal's
/// occlusion of the sky alone removes at most k_h/(k_h + k_s cos Z) / 2 ≈ 25 % next to a wall.
const SHADOWED_CHANGE_SHARE: f64 = -0.35;
/// Depth of the pixel against the distance to the cell's point: the pixel must see that point
/// (not the proposal in front of it); 2 % plus the cell's half-diagonal.
const DEPTH_REL_TOL: f64 = 0.02;
/// Agreement required over cells whose eight neighbours share their class (one ray per cell
/// and 4 rays per pixel still disagree where a cell's footprint straddles a shadow edge).
const MIN_AGREEMENT: f64 = 0.95;
/// A meaningful comparison needs this many visible interior cells of added shadow.
const MIN_ADDED_CELLS: usize = 20;

/// The street sample, solved (it ships unsolved).
fn street() -> SiteDocument {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/street/site.toml");
    let mut doc = SiteDocument::load(&path).unwrap();
    let solution = crate::site::solve_site(&doc);
    crate::site::apply_solution(&mut doc.site, &solution);
    doc
}

#[test]
fn added_shadow_cells_are_the_montages_shadow_pixels_on_the_street_site() {
    let doc = street();
    let request = StudyRequest {
        view: "V1".into(),
        dates: parse_dates("2024-08-21").unwrap(),
        times: parse_times("10:44+02:00").unwrap(),
        spp_min: Some(4),
        spp_max: Some(4),
        seed: Some(1),
    };
    let frame = &plan_frames(&doc, &request).unwrap()[0];
    let map = frame_shadow_map(&doc, frame, "V1", DEFAULT_CELL_M).unwrap();
    assert!(
        map.count(CellClass::AddedShadow) > 0,
        "no added shadow at all"
    );

    let frame_doc = frame.document(&doc);
    let plan = RenderPlan::new(
        &frame_doc,
        &RenderRequest {
            spp_min: Some(4),
            spp_max: Some(4),
            seed: Some(1),
            layers: LayerSet {
                depth: true,
                object_id: false,
                shadow_change: true,
            },
            ..RenderRequest::view("V1")
        },
    )
    .unwrap();
    let rendered = plan
        .render(&frame_doc, &|_| {}, &AtomicBool::new(false))
        .unwrap();
    let depth = rendered.layers.depth_m.as_ref().unwrap();
    let change = rendered.layers.shadow_change_rgb.as_ref().unwrap();
    let camera = site_camera(&frame_doc, "V1").unwrap();
    let [w, _] = rendered.image.size_px;

    let [nx, ny] = map.size_cells;
    let (mut added, mut added_agree, mut lit, mut lit_agree) = (0usize, 0usize, 0usize, 0usize);
    for j in 1..ny - 1 {
        for i in 1..nx - 1 {
            let class = map.class(i, j);
            if !matches!(class, CellClass::AddedShadow | CellClass::Lit) {
                continue;
            }
            let uniform =
                (j - 1..=j + 1).all(|jj| (i - 1..=i + 1).all(|ii| map.class(ii, jj) == class));
            let Some(point) = map.cell_point_in_world_m(i, j) else {
                continue;
            };
            let Some(px) = camera.project(&point) else {
                continue;
            };
            if !uniform || !camera.intrinsics.contains(px) {
                continue;
            }
            let k = (px.y.round() as u32 * w + px.x.round() as u32) as usize;
            let distance_m = (point - camera.pose.camera_center_in_world).norm();
            let tol_m = DEPTH_REL_TOL * distance_m + map.cell_m;
            if (f64::from(depth[k]) - distance_m).abs() > tol_m {
                continue; // hidden behind something
            }
            let c: f64 = change[k].iter().map(|&v| f64::from(v)).sum();
            let shown: f64 = rendered.image.rgba[k][..3]
                .iter()
                .map(|&v| f64::from(v))
                .sum();
            let photo = shown - c;
            let shadowed = photo > 0.0 && c / photo < SHADOWED_CHANGE_SHARE;
            if class == CellClass::AddedShadow {
                added += 1;
                added_agree += usize::from(shadowed);
            } else {
                lit += 1;
                lit_agree += usize::from(!shadowed);
            }
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let share = |a: usize, n: usize| a as f64 / n.max(1) as f64;
    eprintln!(
        "street V1: {added_agree}/{added} added-shadow cells shadowed in the montage, \
         {lit_agree}/{lit} lit cells not"
    );
    assert!(added >= MIN_ADDED_CELLS, "only {added} comparable cells");
    assert!(lit >= MIN_ADDED_CELLS, "only {lit} comparable lit cells");
    assert!(
        share(added_agree, added) >= MIN_AGREEMENT,
        "{added_agree}/{added}"
    );
    assert!(share(lit_agree, lit) >= MIN_AGREEMENT, "{lit_agree}/{lit}");
}

#[test]
fn legend_and_classes_are_drawn_north_up() {
    let map = ShadowMap {
        min_xy_m: [0.0, 0.0],
        cell_m: 1.0,
        size_cells: [2, 2],
        // Row j = 0 is the south edge.
        classes: vec![
            CellClass::Lit,
            CellClass::ExistingShadow,
            CellClass::AddedShadow,
            CellClass::Proposal,
        ],
        surface_z_m: vec![0.0; 4],
    };
    let img = shadow_map_image(&map, "t");
    let scale = MIN_MAP_WIDTH_PX.div_ceil(2) as u32;
    let top = 8 + 12;
    let at = |i: u32, row: u32| {
        img.get_pixel(8 + i * scale + scale / 2, top + row * scale + scale / 2)
            .0
    };
    // The image's top row shows the north cells (j = 1).
    assert_eq!(at(0, 0), CellClass::AddedShadow.colour());
    assert_eq!(at(1, 0), CellClass::Proposal.colour());
    assert_eq!(at(0, 1), CellClass::Lit.colour());
    assert_eq!(at(1, 1), CellClass::ExistingShadow.colour());
    assert_eq!(map.count(CellClass::Lit), 1);
}

/// A 1 km natural ground with a planned 10 m cube: the map covers the cube's plan extent grown by
/// 3.75 × its height (37.5 m), not the whole ground, and further on the far side of a low sun;
/// with no planned object, the whole ground.
#[test]
fn the_map_covers_the_proposal_and_its_shadow_reach_not_the_whole_ground() {
    use crate::scene::{Material, ObjectKind, Scene, SceneObject};
    use nalgebra::{Point3, Vector3};
    let quad = |scene: &mut Scene, corners: [[f64; 3]; 4], kind: ObjectKind| {
        let m = scene
            .add_material(Material::diffuse("grey", [0.3; 3]))
            .unwrap();
        let o = scene
            .add_object(SceneObject {
                name: format!("o{}", scene.objects().len()),
                kind,
                image_attribute: None,
            })
            .unwrap();
        let poly: Vec<Point3<f64>> = corners.iter().map(|c| Point3::from(*c)).collect();
        scene.add_polygon(&poly, m, o).unwrap();
    };
    let mut scene = Scene::new();
    let g = 500.0;
    quad(
        &mut scene,
        [[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]],
        ObjectKind::Natural,
    );
    let sun = Vector3::new(0.3, -0.5, 0.8).normalize();
    let whole = shadow_map(&scene, &sun, 1.0).unwrap();
    assert_eq!(whole.size_cells, [1000, 1000]);
    // A 10 m planned cube at the origin (its roof is enough to give it a height in plan).
    let (h, s) = (10.0, 5.0);
    quad(
        &mut scene,
        [[-s, -s, h], [s, -s, h], [s, s, h], [-s, s, h]],
        ObjectKind::Artificial,
    );
    quad(
        &mut scene,
        [[-s, -s, 0.0], [-s, s, 0.0], [-s, s, h], [-s, -s, h]],
        ObjectKind::Artificial,
    );
    let map = shadow_map(&scene, &sun, 1.0).unwrap();
    let reach = SHADOW_REACH * h;
    assert!(
        (map.min_xy_m[0] - (-s - reach)).abs() < 1e-9,
        "{:?}",
        map.min_xy_m
    );
    assert!(
        (map.min_xy_m[1] - (-s - reach)).abs() < 1e-9,
        "{:?}",
        map.min_xy_m
    );
    let side = ((2.0 * (s + reach)) / 1.0).ceil() as usize;
    assert_eq!(map.size_cells, [side, side]);
    assert!(map.count(CellClass::AddedShadow) > 0);

    // A winter sun 5° up in the east (+x): the cube's roof casts its shadow 10 m × cot 5° =
    // 114.3 m to the west, past the 15° margin. The map grows to the west only, the shadow ends
    // inside it, and no added shadow touches its edge.
    let elevation = 5f64.to_radians();
    let low_sun = Vector3::new(elevation.cos(), 0.0, elevation.sin());
    let long = h / elevation.tan();
    let map = shadow_map(&scene, &low_sun, 1.0).unwrap();
    assert!(
        (map.min_xy_m[0] - (-s - long - MIN_MARGIN_M)).abs() < 1e-9,
        "{:?}",
        map.min_xy_m
    );
    assert!((map.min_xy_m[1] - (-s - reach)).abs() < 1e-9);
    let east_edge = map.min_xy_m[0] + map.size_cells[0] as f64 * map.cell_m;
    assert!((east_edge - (s + reach)).abs() < 1.0, "{east_edge}");
    let added_x: Vec<f64> = (0..map.classes.len())
        .filter(|&k| map.classes[k] == CellClass::AddedShadow)
        .map(|k| map.min_xy_m[0] + ((k % map.size_cells[0]) as f64 + 0.5) * map.cell_m)
        .collect();
    let west_end = added_x.iter().copied().fold(f64::INFINITY, f64::min);
    // The shadow's far end is the roof's west edge moved by the shadow length (one cell).
    assert!(
        (west_end - (-s - long)).abs() <= map.cell_m,
        "shadow ends at x {west_end}, expected {}",
        -s - long
    );
    assert!(west_end - map.min_xy_m[0] > MIN_MARGIN_M - map.cell_m);
}
