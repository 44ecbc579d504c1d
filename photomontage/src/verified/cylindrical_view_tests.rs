use super::*;
use crate::camera::{BrownConrady, Intrinsics, Pose};
use nalgebra::{Matrix3, Rotation3};

/// The bounds: seams (the photos' disagreement where they overlap) below 1 % mean
/// absolute difference of the signal range, world points within 0.5 px.
const SEAM_MAD_MAX: f64 = 0.01;
const POINT_TOL_PX: f64 = 0.5;
/// Angular σ of the synthetic marks, in units of 1/f (two pixels).
const MARK_SIGMA_PX: f64 = 2.0;
const W: u32 = 800;
const H: u32 = 600;

/// A camera at `centre` with bearing `yaw_deg`, pitch, roll; 800 × 600, f 700 px, and barrel
/// distortion on the middle photo.
fn camera(centre: [f64; 3], yaw_deg: f64, pitch_deg: f64, roll_deg: f64, k1: f64) -> Camera {
    let (yaw, pitch) = (yaw_deg.to_radians(), pitch_deg.to_radians());
    let z = Vector3::new(
        yaw.sin() * pitch.cos(),
        yaw.cos() * pitch.cos(),
        pitch.sin(),
    );
    let x = z.cross(&Vector3::z()).normalize();
    let y = z.cross(&x);
    let (s, c) = roll_deg.to_radians().sin_cos();
    let roll = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    Camera {
        intrinsics: Intrinsics {
            distortion: BrownConrady {
                k1,
                ..BrownConrady::default()
            },
            ..Intrinsics::centred(700.0, [W, H])
        },
        pose: Pose {
            rotation_world_from_camera: Rotation3::from_matrix_unchecked(
                Matrix3::from_columns(&[x, y, z]) * roll,
            ),
            camera_center_in_world: Point3::from(centre),
        },
    }
}

/// Three photos turning right by 45° from bearing 350° (across north), 1 cm apart.
fn cameras() -> Vec<Camera> {
    vec![
        camera([100.0, 200.0, 1.6], 350.0, 3.0, 0.8, 0.0),
        camera([100.01, 200.0, 1.6], 35.0, 2.0, -0.5, -0.03),
        camera([100.0, 200.01, 1.6], 80.0, 4.0, 0.0, 0.0),
    ]
}

/// A photo of a world of directions: `value(direction)` at every pixel's ray.
fn photograph(cam: &Camera, value: &dyn Fn(&Vector3<f64>) -> f64) -> Rgb32FImage {
    Rgb32FImage::from_fn(W, H, |x, y| {
        let d = cam.ray_dir_in_world(Point2::new(f64::from(x), f64::from(y)));
        #[allow(clippy::cast_possible_truncation)]
        let v = value(&d) as f32;
        image::Rgb([v; 3])
    })
}

#[test]
fn seams_of_three_overlapping_photos() {
    let cams = cameras();
    // A smooth texture on the sphere of directions, values in [0.2, 0.8].
    let texture = |d: &Vector3<f64>| {
        let (theta, phi) = (d.x.atan2(d.y), d.z.asin());
        0.5 + 0.15 * (6.0 * theta).sin() * (9.0 * phi).cos()
            + 0.15 * (4.0 * theta + 7.0 * phi).cos()
    };
    let images: Vec<Rgb32FImage> = cams.iter().map(|c| photograph(c, &texture)).collect();
    let ids = ["P1", "P2", "P3"];
    let photos: Vec<PanoramaPhoto<'_>> = (0..3)
        .map(|i| PanoramaPhoto {
            id: ids[i],
            camera: &cams[i],
            image: &images[i],
        })
        .collect();
    let view = cylindrical_view(&photos, &CylindricalOptions::default()).expect("panorama");
    let cyl = view.cylinder;
    // The span: from the first photo's left edge (about 350° − 30°) to the last one's right edge
    // (about 80° + 30°): some 150°.
    let span_deg = f64::from(cyl.size_px[0]) / cyl.focal_px * 180.0 / std::f64::consts::PI;
    println!(
        "panorama {:?} px, f {:.1} px, span {span_deg:.1}°",
        cyl.size_px, cyl.focal_px
    );
    assert!((140.0..160.0).contains(&span_deg), "{span_deg}");
    // In every overlap, the two photos' samples at the same panorama pixel.
    let (mut diff, mut n) = (0.0, 0usize);
    for y in (0..cyl.size_px[1]).step_by(2) {
        for x in (0..cyl.size_px[0]).step_by(2) {
            let dir = cyl.dir_in_world(Point2::new(f64::from(x), f64::from(y)));
            let samples: Vec<[f32; 3]> = photos
                .iter()
                .filter_map(|p| photo_sample(p, &dir).map(|(c, _)| c))
                .collect();
            if samples.len() >= 2 {
                diff += (f64::from(samples[0][0]) - f64::from(samples[1][0])).abs();
                n += 1;
            }
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let mad = diff / n as f64 / 0.6; // the texture's range is 0.6
    println!(
        "seams: {n} overlap samples, mean absolute difference {:.4} %",
        100.0 * mad
    );
    assert!(n > 1000, "overlaps expected");
    assert!(mad < SEAM_MAD_MAX, "{mad}");
    // The blend is continuous across a seam: no pixel jumps by more than the texture's own
    // gradient allows (0.15·(6 + 9) + 0.15·√65 per radian ≈ 3.5/rad ≈ 0.005 per pixel here).
    let max_step = view
        .image
        .rgba
        .windows(2)
        .filter(|w| w[0][3] > 0.0 && w[1][3] > 0.0)
        .map(|w| (w[0][0] - w[1][0]).abs())
        .fold(0.0_f32, f32::max);
    println!("largest step between neighbours {max_step:.4}");
    assert!(max_step < 0.02, "{max_step}");
}

#[test]
fn world_points_land_on_their_cylindrical_projection() {
    let cams = cameras();
    // Far points in directions inside single photos and in overlaps (bearing, elevation).
    let marks: Vec<(f64, f64)> = vec![
        (345.0, 2.0),
        (12.0, -5.0),
        (35.0, 8.0),
        (58.0, 0.0),
        (95.0, 10.0),
    ];
    let points: Vec<Point3<f64>> = marks
        .iter()
        .map(|&(b, e): &(f64, f64)| {
            let (b, e) = (b.to_radians(), e.to_radians());
            Point3::new(100.0, 200.0, 1.6)
                + 500.0 * Vector3::new(b.sin() * e.cos(), b.cos() * e.cos(), e.sin())
        })
        .collect();
    let sigma = MARK_SIGMA_PX / 700.0;
    let marks_fn = |d: &Vector3<f64>| -> f64 {
        points
            .iter()
            .map(|p| {
                let to = (p - Point3::new(100.0, 200.0, 1.6)).normalize();
                let angle = to.cross(d).norm().atan2(to.dot(d));
                (-angle * angle / (2.0 * sigma * sigma)).exp()
            })
            .sum()
    };
    let images: Vec<Rgb32FImage> = cams.iter().map(|c| photograph(c, &marks_fn)).collect();
    let ids = ["P1", "P2", "P3"];
    let photos: Vec<PanoramaPhoto<'_>> = (0..3)
        .map(|i| PanoramaPhoto {
            id: ids[i],
            camera: &cams[i],
            image: &images[i],
        })
        .collect();
    let options = CylindricalOptions {
        focal_equiv_mm: 30.0,
        ..CylindricalOptions::default()
    };
    let view = cylindrical_view(&photos, &options).expect("panorama");
    let cyl = view.cylinder;
    let [w, h] = cyl.size_px;
    for (p, mark) in points.iter().zip(&marks) {
        // Where the cylinder puts it, written out: azimuth and height from the mean centre.
        let c = Point3::from(cyl.centre_in_world_m);
        let d = p - c;
        let theta = d.x.atan2(d.y);
        let rel = (theta - cyl.azimuth_left).rem_euclid(std::f64::consts::TAU);
        let want = [
            cyl.focal_px * rel - 0.5,
            cyl.focal_px * (cyl.height_top - d.z / d.x.hypot(d.y)) - 0.5,
        ];
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        #[allow(clippy::cast_possible_truncation)]
        let (cx, cy) = (want[0].round() as i64, want[1].round() as i64);
        for y in (cy - 10).max(0)..=(cy + 10).min(i64::from(h) - 1) {
            for x in (cx - 10).max(0)..=(cx + 10).min(i64::from(w) - 1) {
                #[allow(clippy::cast_sign_loss, clippy::cast_possible_truncation)]
                let v = f64::from(view.image.rgba[(y as u32 * w + x as u32) as usize][0]);
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
        println!("mark {mark:?}: at {got:.3?}, cylinder {want:.3?}, error {err:.4} px");
        assert!(err < POINT_TOL_PX, "{err}");
        // The library's own projection agrees.
        let lib = cyl.project(p).expect("not vertical");
        assert!((lib.x - want[0]).abs() < 1e-9 && (lib.y - want[1]).abs() < 1e-9);
    }
}

#[test]
fn photos_from_different_points_are_refused_by_name() {
    let mut cams = cameras();
    cams[2] = camera([100.0, 200.5, 1.6], 80.0, 4.0, 0.0, 0.0);
    let img = Rgb32FImage::new(W, H);
    let ids = ["P1", "P2", "P3"];
    let photos: Vec<PanoramaPhoto<'_>> = (0..3)
        .map(|i| PanoramaPhoto {
            id: ids[i],
            camera: &cams[i],
            image: &img,
        })
        .collect();
    let err = cylindrical_view(&photos, &CylindricalOptions::default()).unwrap_err();
    assert!(
        matches!(&err, CylindricalError::NotOnePoint { photo, .. } if photo == "P3"),
        "{err}"
    );
    assert!(err.to_string().contains("P3"));
    assert!(matches!(
        cylindrical_view(&[], &CylindricalOptions::default()),
        Err(CylindricalError::NoPhotos)
    ));
}
