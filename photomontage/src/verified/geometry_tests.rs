use super::*;
use crate::camera::Pose;
use nalgebra::{Matrix3, Rotation3};

/// Angles recovered from a rotation built from them: round-off only (1e-9°).
const ANGLE_TOL_DEG: f64 = 1e-9;
/// Closed-form focal lengths: round-off only.
const FOCAL_TOL_MM: f64 = 1e-9;

/// world_from_camera of a camera at `center` looking at `target`, rolled by `roll_deg` about its
/// optical axis: the construction of the sample sites' generators (`rotation_look_at` in
/// `sample_sites/street/generate.py`), written out independently of the code under test.
fn look_at(center: [f64; 3], target: [f64; 3], roll_deg: f64) -> Rotation3<f64> {
    let z = (Vector3::from(target) - Vector3::from(center)).normalize();
    let x = z.cross(&Vector3::z()).normalize();
    let y = z.cross(&x);
    let r = Matrix3::from_columns(&[x, y, z]);
    let (s, c) = roll_deg.to_radians().sin_cos();
    let roll = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    Rotation3::from_matrix_unchecked(r * roll)
}

fn camera(rotation: Rotation3<f64>, focal_px: f64, size: [u32; 2]) -> Camera {
    Camera {
        intrinsics: Intrinsics::centred(focal_px, size),
        pose: Pose {
            rotation_world_from_camera: rotation,
            camera_center_in_world: Point3::new(100.0, 200.0, 10.0),
        },
    }
}

#[test]
fn angles_of_look_at_cameras() {
    // (target offset from the centre, roll): the four quadrants, up and down, both rolls.
    let cases = [
        ([3.0, 4.0, 1.0], 0.0),
        ([-2.0, 5.0, -1.5], 2.5),
        ([-4.0, -1.0, 0.3], -7.0),
        ([6.0, -6.0, -8.0], 30.0),
    ];
    for (offset, roll) in cases {
        let c = camera(look_at([0.0; 3], offset, roll), 1000.0, [800, 600]);
        let a = camera_angles(&c).expect("not vertical");
        let [dx, dy, dz] = offset;
        let bearing = normalise_deg(dx.atan2(dy).to_degrees());
        let pitch = dz.atan2(dx.hypot(dy)).to_degrees();
        assert!(
            (a.bearing_grid_deg - bearing).abs() < ANGLE_TOL_DEG,
            "{a:?}"
        );
        assert!((a.pitch_deg - pitch).abs() < ANGLE_TOL_DEG, "{a:?}");
        assert!((a.roll_deg - roll).abs() < ANGLE_TOL_DEG, "{a:?}");
    }
}

#[test]
fn positive_roll_puts_the_right_side_of_the_image_low() {
    // A level camera looking north, rolled +10°: the image x axis (to the right) points down.
    let c = camera(look_at([0.0; 3], [0.0, 1.0, 0.0], 10.0), 1000.0, [800, 600]);
    let x_axis = c.pose.rotation_world_from_camera * Vector3::x();
    assert!(x_axis.x > 0.0 && x_axis.z < 0.0, "{x_axis}");
    let a = camera_angles(&c).expect("not vertical");
    assert!((a.roll_deg - 10.0).abs() < ANGLE_TOL_DEG);
    assert!(a.bearing_grid_deg.abs() < ANGLE_TOL_DEG);
}

#[test]
fn vertical_axis_has_no_bearing() {
    let down = Rotation3::from_matrix_unchecked(Matrix3::new(
        1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0,
    ));
    assert!(camera_angles(&camera(down, 1000.0, [800, 600])).is_none());
}

#[test]
fn fields_of_view_closed_form() {
    let c = camera(look_at([0.0; 3], [0.0, 1.0, 0.0], 0.0), 1100.0, [1280, 960]);
    let [h, v] = fields_of_view_deg(&c.intrinsics);
    let want_h = 2.0 * (640.0_f64 / 1100.0).atan().to_degrees();
    let want_v = 2.0 * (480.0_f64 / 1100.0).atan().to_degrees();
    assert!((h - want_h).abs() < ANGLE_TOL_DEG && (v - want_v).abs() < ANGLE_TOL_DEG);
    // An off-centre principal point: the two half-angles differ, their sum is the field.
    let mut intr = c.intrinsics;
    intr.principal_point_px = [500.0, 479.5];
    let [h, _] = fields_of_view_deg(&intr);
    let want = (500.5_f64 / 1100.0).atan().to_degrees() + (779.5_f64 / 1100.0).atan().to_degrees();
    assert!((h - want).abs() < ANGLE_TOL_DEG);
}

#[test]
fn barrel_distortion_widens_the_field() {
    // k1 < 0 pulls the image edge inwards, so the edge pixel sees a wider angle than the pinhole.
    let mut intr = Intrinsics::centred(1500.0, [1600, 1200]);
    let [pinhole, _] = fields_of_view_deg(&intr);
    intr.distortion.k1 = -0.04;
    let [barrel, _] = fields_of_view_deg(&intr);
    assert!(barrel > pinhole, "{barrel} vs {pinhole}");
    // The edge ray's undistorted x solves x(1 + k1 x²) = 800/1500 (on the principal row).
    let xd: f64 = 800.0 / 1500.0;
    let mut x = xd;
    for _ in 0..50 {
        x -= (x * (1.0 - 0.04 * x * x) - xd) / (1.0 - 0.12 * x * x);
    }
    let want = 2.0 * x.atan().to_degrees();
    assert!((barrel - want).abs() < 1e-6, "{barrel} vs {want}");
}

#[test]
fn thirty_five_mm_equivalent() {
    // A 36 × 24 mm frame of 3600 × 2400 px (10 µm pixels) behind a 50 mm lens: f = 5000 px.
    let f35 = focal_35mm_equiv_mm(5000.0, [3600, 2400]).expect("convertible");
    assert!((f35 - 50.0).abs() < FOCAL_TOL_MM, "{f35}");
    // The same lens on a 4:3 crop of that frame keeps its diagonal convention (not the width).
    let f35 = focal_35mm_equiv_mm(5000.0, [3200, 2400]).expect("convertible");
    assert!((f35 - 5000.0 * FULL_FRAME_DIAGONAL_MM / 4000.0).abs() < FOCAL_TOL_MM);
    assert!(focal_35mm_equiv_mm(0.0, [3600, 2400]).is_none());
    assert!(focal_35mm_equiv_mm(f64::NAN, [3600, 2400]).is_none());
    assert!(focal_35mm_equiv_mm(5000.0, [0, 0]).is_none());
}

#[test]
fn normalised_angles() {
    assert!((normalise_deg(-10.0) - 350.0).abs() < ANGLE_TOL_DEG);
    assert!((normalise_deg(370.0) - 10.0).abs() < ANGLE_TOL_DEG);
    assert!(normalise_deg(-1e-18) < 360.0);
}
