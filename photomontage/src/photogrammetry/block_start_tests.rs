use super::*;
use crate::photogrammetry::synthetic::{self, BlockSpec, rotation_error};
use crate::photogrammetry::{BundleOptions, BundlePhoto, SelfCalibration, bundle_adjust};

/// σ = 0.5 px on 3000 px focal at 60 m: a start from the exact relative orientation lands
/// within decimetres; the tolerance leaves a factor of a few.
const START_CENTER_TOLERANCE_M: f64 = 0.5;
const START_ROTATION_TOLERANCE_DEG: f64 = 0.5;
/// After the bundle adjustment the centres are as good as the weak datum allows (three control
/// points, one of them a single ray): within this multiple of their own reported σ.
const ADJUSTED_SIGMA_MULTIPLE: f64 = 3.0;

fn spec() -> BlockSpec {
    BlockSpec {
        photos: 4,
        points: 300,
        control: 3,
        control_sigma_m: 0.01,
        sigma_px: 0.5,
        initial_center_error_m: 0.0,
        initial_rotation_error: 0.0,
        seed: 15,
    }
}

/// The relative orientation of the true cameras (what a perfect five-point solver returns).
#[allow(clippy::type_complexity)] // the closure type of `RelativeOrientation`, spelled out
fn true_relative(
    cameras: &[Camera],
    ids: &[String],
) -> impl Fn(
    &StartPhoto,
    &StartPhoto,
    &[(Point2<f64>, Point2<f64>)],
) -> Result<RelativePose, PhotogrammetryError> {
    let cameras = cameras.to_vec();
    let ids = ids.to_vec();
    move |a: &StartPhoto, b: &StartPhoto, _matches: &[(Point2<f64>, Point2<f64>)]| {
        let find = |id: &str| cameras[ids.iter().position(|i| i == id).expect("known photo")];
        let (ca, cb) = (find(&a.id), find(&b.id));
        let rb_inv = cb.pose.rotation_world_from_camera.inverse();
        let t = rb_inv * (ca.pose.camera_center_in_world - cb.pose.camera_center_in_world);
        Ok(RelativePose {
            rotation_b_from_a: rb_inv * ca.pose.rotation_world_from_camera,
            translation_b_from_a: t.normalize(),
        })
    }
}

/// Every photo sees at most two control points, so none can be resected from control alone:
/// c0000 in photos 0 and 1, c0001 in photos 1 and 2, c0002 in photo 3 only.
fn block_without_resectable_photos() -> (synthetic::SyntheticBlock, Vec<StartPhoto>) {
    let block = synthetic::block(&spec());
    let keep = |photo: usize, id: &str| match id {
        "c0000" => photo <= 1,
        "c0001" => photo == 1 || photo == 2,
        "c0002" => photo == 3,
        _ => true,
    };
    let photos = block
        .observations
        .iter()
        .enumerate()
        .map(|(i, obs)| StartPhoto {
            id: format!("p{i}"),
            intrinsics: block.true_cameras[i].intrinsics,
            camera: None,
            observations: obs
                .iter()
                .filter(|o| keep(i, &o.point_id))
                .cloned()
                .collect(),
        })
        .collect();
    (block, photos)
}

#[test]
fn a_block_with_two_control_points_per_photo_is_placed_and_adjusted() {
    let (block, photos) = block_without_resectable_photos();
    for p in &photos {
        let control_seen = p
            .observations
            .iter()
            .filter(|o| o.point_id.starts_with('c'))
            .count();
        assert!(control_seen <= 2, "{}", p.id);
    }
    let ids: Vec<String> = photos.iter().map(|p| p.id.clone()).collect();
    let relative = true_relative(&block.true_cameras, &ids);
    let start = start_block(&photos, &block.control, Some(&relative), 0).expect("placed");
    assert!(start.unplaced.is_empty(), "{:?}", start.unplaced);
    for (i, c) in start.cameras.iter().enumerate() {
        let c = c.expect("placed");
        let truth = block.true_cameras[i];
        let dc = (c.pose.camera_center_in_world - truth.pose.camera_center_in_world).norm();
        let dr = rotation_error(
            &c.pose.rotation_world_from_camera,
            &truth.pose.rotation_world_from_camera,
        )
        .to_degrees();
        println!("start p{i}: centre {dc:.3} m, rotation {dr:.3}°");
        assert!(
            dc < START_CENTER_TOLERANCE_M && dr < START_ROTATION_TOLERANCE_DEG,
            "p{i}: {dc} m {dr}°"
        );
    }
    let bundle_photos: Vec<BundlePhoto> = photos
        .iter()
        .zip(&start.cameras)
        .map(|(p, c)| BundlePhoto {
            id: p.id.clone(),
            camera: c.expect("placed"),
            observations: p
                .observations
                .iter()
                .filter(|o| !start.rejected_ties.contains(&o.point_id))
                .cloned()
                .collect(),
            self_calibration: SelfCalibration::default(),
        })
        .collect();
    let report =
        bundle_adjust(&bundle_photos, &block.control, &BundleOptions::default()).expect("adjusted");
    for (i, pr) in report.photos.iter().enumerate() {
        let dc = (pr.camera.pose.camera_center_in_world
            - block.true_cameras[i].pose.camera_center_in_world)
            .norm();
        let sigma = nalgebra::Vector3::from(pr.sigma_center_m).norm();
        println!("adjusted p{i}: centre {dc:.4} m (σ {sigma:.4} m)");
        assert!(
            dc < ADJUSTED_SIGMA_MULTIPLE * sigma,
            "p{i}: {dc} m, σ {sigma} m"
        );
    }
}

#[test]
fn without_a_relative_orientation_or_enough_control_the_error_says_so() {
    let (block, photos) = block_without_resectable_photos();
    assert!(matches!(
        start_block(&photos, &block.control, None, 0),
        Err(PhotogrammetryError::NotEnoughPoints {
            required: 2,
            found: 0
        })
    ));
    // Only one control point left: the datum is undetermined.
    let ids: Vec<String> = photos.iter().map(|p| p.id.clone()).collect();
    let relative = true_relative(&block.true_cameras, &ids);
    let one_control = &block.control[..1];
    let trimmed: Vec<StartPhoto> = photos
        .iter()
        .map(|p| StartPhoto {
            observations: p
                .observations
                .iter()
                .filter(|o| o.point_id != "c0001" && o.point_id != "c0002")
                .cloned()
                .collect(),
            ..p.clone()
        })
        .collect();
    match start_block(&trimmed, one_control, Some(&relative), 0) {
        Err(PhotogrammetryError::Degenerate { reason }) => {
            assert!(
                reason.contains("c0000") && reason.contains("third"),
                "{reason}"
            );
        }
        other => panic!("expected the datum error, got {other:?}"),
    }
}
