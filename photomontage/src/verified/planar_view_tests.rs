use super::*;
use crate::camera::{BrownConrady, Pose};
use nalgebra::{Matrix3, Point3, Rotation3, Vector3};

/// The bound: a world point lands within 0.1 px of the pinhole projection.
const POINT_TOL_PX: f64 = 0.1;
/// Closed forms: round-off only.
const EXACT_TOL: f64 = 1e-9;
/// Standard deviation of the synthetic blobs, source pixels (wide enough that bilinear
/// resampling moves their centroid by far less than the tolerance).
const BLOB_SIGMA_PX: f64 = 2.0;

/// The courtyard generator's camera (1600 × 1200, f 1500 px, K1 −0.04, K2 0.01) with an
/// off-centre principal point, looking north-east, pitched and rolled.
fn source_camera() -> Camera {
    let z = Vector3::new(0.6, 0.8, 0.1).normalize();
    let x = z.cross(&Vector3::z()).normalize();
    let y = z.cross(&x);
    let (s, c) = 1.5_f64.to_radians().sin_cos();
    let roll = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    Camera {
        intrinsics: Intrinsics {
            focal_px: 1500.0,
            principal_point_px: [805.0, 596.0],
            distortion: BrownConrady {
                k1: -0.04,
                k2: 0.01,
                ..BrownConrady::default()
            },
            image_size_px: [1600, 1200],
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(
                Matrix3::from_columns(&[x, y, z]) * roll,
            ),
            camera_center_in_world: Point3::new(2_683_000.0, 1_247_000.0, 401.6),
        },
    }
}

#[test]
fn world_points_land_where_the_pinhole_puts_them() {
    let source = source_camera();
    // World points 20–60 m away in directions spread over the 50 mm field.
    let dirs = [
        (0.0, 0.0, 20.0),
        (0.25, -0.15, 35.0),
        (-0.22, 0.12, 60.0),
        (0.2, 0.2, 25.0),
        (-0.28, -0.2, 40.0),
    ];
    let points: Vec<Point3<f64>> = dirs
        .iter()
        .map(|&(x, y, d)| {
            source
                .pose
                .world_from_camera(&Point3::from(Vector3::new(x, y, 1.0).normalize() * d))
        })
        .collect();
    // The photo: a Gaussian blob at each point's projection through the full lens model.
    let blobs: Vec<Point2<f64>> = points
        .iter()
        .map(|p| source.project(p).expect("in front"))
        .collect();
    let photo = Rgb32FImage::from_fn(1600, 1200, |x, y| {
        let v: f64 = blobs
            .iter()
            .map(|b| {
                let r2 = (f64::from(x) - b.x).powi(2) + (f64::from(y) - b.y).powi(2);
                (-r2 / (2.0 * BLOB_SIGMA_PX * BLOB_SIGMA_PX)).exp()
            })
            .sum();
        #[allow(clippy::cast_possible_truncation)]
        image::Rgb([v as f32; 3])
    });
    // A 50 mm-equivalent planar view, 1200 × 900 px.
    let size = [1200_u32, 900];
    let focal = focal_px_for_equivalent(50.0, size).expect("valid");
    let target = planar_camera(&source, focal, size);
    let out = reproject(&source, &photo, &target);
    // Where a pinhole with that focal length, centred principal point and the photo's pose puts
    // each point (written out here, not through the camera module).
    let r_inv = source.pose.rotation_world_from_camera.inverse();
    for p in &points {
        let c = r_inv * (p - source.pose.camera_center_in_world);
        let want = [
            50.0 * 1500.0 / FULL_FRAME_DIAGONAL_MM * c.x / c.z + 599.5,
            50.0 * 1500.0 / FULL_FRAME_DIAGONAL_MM * c.y / c.z + 449.5,
        ];
        // Intensity centroid in a window around it.
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let (cx, cy) = (want[0].round() as i64, want[1].round() as i64);
        for y in cy - 12..=cy + 12 {
            for x in cx - 12..=cx + 12 {
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                let v = f64::from(out.rgba[y as usize * 1200 + x as usize][0]);
                #[allow(clippy::cast_precision_loss)]
                {
                    sx += v * x as f64;
                    sy += v * y as f64;
                }
                sw += v;
            }
        }
        let got = [sx / sw, sy / sw];
        let err = (got[0] - want[0]).hypot(got[1] - want[1]);
        println!("{p}: at {got:.4?}, pinhole {want:.4?}, error {err:.4} px");
        assert!(err < POINT_TOL_PX, "{err}");
    }
    assert_eq!(
        out.changed_pixels,
        1200 * 900,
        "the 50 mm view lies inside the photo"
    );
}

#[test]
fn focal_length_of_an_equivalent() {
    // 36 × 24 mm frame at 100 px/mm: 50 mm is 5000 px.
    let f = focal_px_for_equivalent(50.0, [3600, 2400]).expect("valid");
    assert!((f - 5000.0).abs() < EXACT_TOL);
    assert!(focal_px_for_equivalent(0.0, [3600, 2400]).is_none());
    assert!(focal_px_for_equivalent(f64::INFINITY, [3600, 2400]).is_none());
    assert!(focal_px_for_equivalent(50.0, [0, 0]).is_none());
}

#[test]
fn a_wider_view_than_the_photo_is_transparent_outside_it() {
    let source = source_camera(); // about 32 mm equivalent
    let photo = Rgb32FImage::from_pixel(1600, 1200, image::Rgb([0.5; 3]));
    let size = [800, 600];
    let target = planar_camera(
        &source,
        focal_px_for_equivalent(20.0, size).expect("valid"),
        size,
    );
    let out = reproject(&source, &photo, &target);
    assert!(out.changed_pixels < 800 * 600);
    // Alpha is exactly 0 or 1.
    assert!(out.rgba[0][3] < 0.5 && out.rgba[300 * 800 + 400][3] > 0.5);
}

#[test]
fn bilinear_samples() {
    let img = Rgb32FImage::from_fn(2, 2, |x, y| {
        #[allow(clippy::cast_precision_loss)]
        image::Rgb([(x + 2 * y) as f32; 3])
    });
    let at = |x, y| sample_bilinear(&img, Point2::new(x, y)).map(|c| c[0]);
    assert_eq!(at(1.0, 1.0), Some(3.0));
    assert_eq!(at(0.5, 0.5), Some(1.5));
    assert_eq!(at(-0.5, 0.0), Some(0.0));
    assert_eq!(at(-0.6, 0.0), None);
    assert_eq!(at(1.0, 1.6), None);
}
