//! Seeded synthetic photogrammetric scenes with known ground truth, for tests and benches
//! (the "seeded synthetic ground truth" of the project's test policy).
//!
//! Control points are drawn where the camera sees them: a random pixel inside the image (5 %
//! margin) is cast into the scene, to a random depth (non-planar) or onto a plane (planar). Image
//! observations are the exact projections plus Gaussian noise of σ_px; the chosen gross
//! outliers are displaced by 20–100 px in a random direction (≥ 40 σ for σ = 0.5 px).
//!
//! # Known limitations
//! Noise is isotropic Gaussian; real image measurements have heavier tails.

use nalgebra::{Point2, Point3, Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::{ControlPoint, ImageObservation};
use crate::camera::{Camera, Intrinsics, Pose};

/// A camera at `center` looking at `target`, image "up" towards world `up`.
#[must_use]
pub fn look_at(center: Point3<f64>, target: Point3<f64>, up: Vector3<f64>) -> Pose {
    let z = (target - center).normalize();
    let x = z.cross(&up).normalize();
    let y = z.cross(&x);
    Pose {
        rotation_world_from_camera: Rotation3::from_basis_unchecked(&[x, y, z]),
        camera_center_in_world: center,
    }
}

/// Layout of the control points of a synthetic scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Layout {
    /// Depths uniform in ±`depth_fraction` around the viewing distance.
    Volume { depth_fraction: f64 },
    /// All points on the world plane Z = 0, which the camera sees obliquely from above.
    Ground,
    /// All points on a plane parallel to the image plane (a facade seen head-on).
    FacadeHeadOn,
}

/// Description of a single-photo scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSpec {
    pub focal_px: f64,
    pub image_size_px: [u32; 2],
    pub distance_m: f64,
    pub points: usize,
    pub layout: Layout,
    pub sigma_px: f64,
    pub outlier_fraction: f64,
    pub seed: u64,
}

/// A generated scene and its truth.
#[derive(Debug, Clone)]
pub struct SyntheticScene {
    pub camera: Camera,
    pub control: Vec<ControlPoint>,
    pub observations: Vec<ImageObservation>,
    /// Ids of the observations displaced as gross errors.
    pub outlier_ids: Vec<String>,
}

/// Generates a seeded single-photo scene.
#[must_use]
pub fn single_photo(spec: &SceneSpec) -> SyntheticScene {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let intrinsics = Intrinsics::centred(spec.focal_px, spec.image_size_px);
    let d = spec.distance_m;
    let (center, target) = match spec.layout {
        // Oblique view of the ground from 45° elevation.
        Layout::Ground => (
            Point3::new(
                5.0,
                -d * std::f64::consts::FRAC_1_SQRT_2,
                d * std::f64::consts::FRAC_1_SQRT_2,
            ),
            Point3::new(5.0, 0.0, 0.0),
        ),
        _ => (
            Point3::new(-0.3 * d, -0.95 * d, 0.15 * d),
            Point3::new(0.0, 0.0, 0.0),
        ),
    };
    let pose = look_at(center, target, Vector3::z());
    let camera = Camera { intrinsics, pose };
    let [w, h] = spec.image_size_px.map(f64::from);
    let outliers = (spec.outlier_fraction * spec.points as f64).round() as usize;
    let mut control = Vec::with_capacity(spec.points);
    let mut observations = Vec::with_capacity(spec.points);
    let mut outlier_ids = Vec::new();
    while control.len() < spec.points {
        let pixel = Point2::new(
            rng.random_range(0.05 * w..0.95 * w),
            rng.random_range(0.05 * h..0.95 * h),
        );
        let ray = camera.ray_dir_in_world(pixel);
        let point = match spec.layout {
            Layout::Volume { depth_fraction } => {
                let depth = d * (1.0 + rng.random_range(-depth_fraction..depth_fraction));
                let along_axis = ray.dot(&pose.viewing_dir_in_world());
                center + ray * (depth / along_axis)
            }
            Layout::Ground => {
                if ray.z >= -1e-3 {
                    continue;
                }
                center + ray * (-center.z / ray.z)
            }
            Layout::FacadeHeadOn => {
                let along_axis = ray.dot(&pose.viewing_dir_in_world());
                center + ray * (d / along_axis)
            }
        };
        let Some(true_pixel) = camera.project(&point) else {
            continue;
        };
        let id = format!("p{:03}", control.len());
        let mut observed = Point2::new(
            true_pixel.x + spec.sigma_px * gaussian(&mut rng),
            true_pixel.y + spec.sigma_px * gaussian(&mut rng),
        );
        if control.len() < outliers {
            let angle = rng.random_range(0.0..std::f64::consts::TAU);
            let size = rng.random_range(20.0..100.0);
            observed += nalgebra::Vector2::new(angle.cos(), angle.sin()) * size;
            outlier_ids.push(id.clone());
        }
        control.push(ControlPoint {
            id: id.clone(),
            point_in_world: point,
            sigma_m: [0.0; 3],
        });
        observations.push(ImageObservation {
            point_id: id,
            pixel: observed,
            sigma_px: spec.sigma_px,
        });
    }
    SyntheticScene {
        camera,
        control,
        observations,
        outlier_ids,
    }
}

/// Angle (radians) of the rotation taking `a` to `b`.
#[must_use]
pub fn rotation_error(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
    (a.inverse() * b).angle()
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Description of a multi-photo block for bundle adjustment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockSpec {
    pub photos: usize,
    pub points: usize,
    /// The first `control` points are control (σ = `control_sigma_m`), the rest tie points.
    pub control: usize,
    pub control_sigma_m: f64,
    pub sigma_px: f64,
    /// Perturbation of the initial camera centres (metres, per axis, uniform ±).
    pub initial_center_error_m: f64,
    /// Perturbation of the initial camera rotations (radians, per axis, uniform ±).
    pub initial_rotation_error: f64,
    pub seed: u64,
}

/// A generated block: true cameras, perturbed initial cameras, points and observations.
#[derive(Debug, Clone)]
pub struct SyntheticBlock {
    pub true_cameras: Vec<Camera>,
    pub initial_cameras: Vec<Camera>,
    /// True positions of all points (control first).
    pub points: Vec<(String, Point3<f64>)>,
    /// Control as surveyed (true position, the survey error is not simulated).
    pub control: Vec<ControlPoint>,
    /// Observations per photo.
    pub observations: Vec<Vec<ImageObservation>>,
}

/// Generates a seeded block: points in a 40 × 40 × 10 m volume, cameras on a ring of radius
/// 60 m at 10–30 m height looking at the centre, focal 3000 px on 4000 × 3000 images.
#[must_use]
pub fn block(spec: &BlockSpec) -> SyntheticBlock {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let intrinsics = Intrinsics::centred(3000.0, [4000, 3000]);
    let points: Vec<(String, Point3<f64>)> = (0..spec.points)
        .map(|i| {
            let prefix = if i < spec.control { "c" } else { "t" };
            (
                format!("{prefix}{i:04}"),
                Point3::new(
                    rng.random_range(-20.0..20.0),
                    rng.random_range(-20.0..20.0),
                    rng.random_range(0.0..10.0),
                ),
            )
        })
        .collect();
    let mut true_cameras = Vec::with_capacity(spec.photos);
    let mut initial_cameras = Vec::with_capacity(spec.photos);
    let mut observations = Vec::with_capacity(spec.photos);
    for p in 0..spec.photos {
        let azimuth =
            std::f64::consts::TAU * p as f64 / spec.photos as f64 + rng.random_range(-0.05..0.05);
        let center = Point3::new(
            60.0 * azimuth.cos(),
            60.0 * azimuth.sin(),
            rng.random_range(10.0..30.0),
        );
        let target = Point3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            3.0,
        );
        let camera = Camera {
            intrinsics,
            pose: look_at(center, target, Vector3::z()),
        };
        let mut obs = Vec::new();
        for (id, x) in &points {
            if let Some(px) = camera.project(x).filter(|px| intrinsics.contains(*px)) {
                obs.push(ImageObservation {
                    point_id: id.clone(),
                    pixel: Point2::new(
                        px.x + spec.sigma_px * gaussian(&mut rng),
                        px.y + spec.sigma_px * gaussian(&mut rng),
                    ),
                    sigma_px: spec.sigma_px,
                });
            }
        }
        let e = spec.initial_rotation_error;
        let mut r = || rng.random_range(-1.0..1.0);
        let initial = Camera {
            intrinsics,
            pose: Pose {
                rotation_world_from_camera: camera.pose.rotation_world_from_camera
                    * Rotation3::new(Vector3::new(r() * e, r() * e, r() * e)),
                camera_center_in_world: center
                    + Vector3::new(r(), r(), r()) * spec.initial_center_error_m,
            },
        };
        true_cameras.push(camera);
        initial_cameras.push(initial);
        observations.push(obs);
    }
    let control = points[..spec.control]
        .iter()
        .map(|(id, x)| ControlPoint {
            id: id.clone(),
            point_in_world: *x,
            sigma_m: [spec.control_sigma_m; 3],
        })
        .collect();
    SyntheticBlock {
        true_cameras,
        initial_cameras,
        points,
        control,
        observations,
    }
}
