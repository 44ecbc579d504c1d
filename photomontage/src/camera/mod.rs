//! The camera model: a pinhole with Brown–Conrady lens distortion (Durisch 1992 §3.5, "camera
//! model"; Brown 1966; the coefficient convention of OpenCV's `calib3d`).
//!
//! # Conventions
//! - **World frame**: right-handed, Z up, metres (survey coordinates may be large: keep `f64`).
//! - **Camera frame**: x right, y down, z forward along the optical axis (OpenCV).
//!   `point_in_camera = rotation_world_from_camera⁻¹ · (point_in_world − camera_center_in_world)`.
//! - **Pixel frame**: (0, 0) is the *centre* of the top-left pixel of the image *as displayed*
//!   (after the EXIF orientation is applied); x runs right, y runs down. The image covers
//!   `[-0.5, width − 0.5] × [-0.5, height − 0.5]`.
//! - **Intrinsics**: square pixels, no skew: `x_px = focal_px · x_d + principal_point_px.x`,
//!   where `x_d` is the distorted normalised coordinate.
//! - **Distortion** (normalised coordinates x, y, r² = x² + y²):
//!   `x_d = x·(1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²)`,
//!   `y_d = y·(1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y`.
//!
//! # Known limitations
//! Square pixels and zero skew are assumed (true of every digital camera we target). Fisheye
//! lenses beyond the range where the polynomial is monotonic are not modelled.

pub mod brown_conrady;
pub mod undistort;

pub use brown_conrady::BrownConrady;

use nalgebra::{Matrix3, Point2, Point3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// Interior orientation: focal length, principal point, lens distortion and image size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    /// Focal length in pixels (square pixels).
    pub focal_px: f64,
    /// Principal point in pixels, in the pixel frame described in the module doc.
    pub principal_point_px: [f64; 2],
    /// Brown–Conrady distortion coefficients.
    #[serde(default)]
    pub distortion: BrownConrady,
    /// Image width and height in pixels, as displayed.
    pub image_size_px: [u32; 2],
}

impl Intrinsics {
    /// A distortion-free camera with the principal point at the image centre.
    #[must_use]
    pub fn centred(focal_px: f64, image_size_px: [u32; 2]) -> Self {
        Self {
            focal_px,
            principal_point_px: [
                (f64::from(image_size_px[0]) - 1.0) / 2.0,
                (f64::from(image_size_px[1]) - 1.0) / 2.0,
            ],
            distortion: BrownConrady::default(),
            image_size_px,
        }
    }

    /// The 3×3 calibration matrix K (pixel from normalised, distortion excluded).
    #[must_use]
    pub fn calibration_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.focal_px,
            0.0,
            self.principal_point_px[0],
            0.0,
            self.focal_px,
            self.principal_point_px[1],
            0.0,
            0.0,
            1.0,
        )
    }

    /// Pixel position of an (undistorted) normalised image coordinate, distortion applied.
    #[must_use]
    pub fn pixel_from_normalised(&self, normalised: Point2<f64>) -> Point2<f64> {
        let d = self.distortion.distort(normalised);
        Point2::new(
            self.focal_px * d.x + self.principal_point_px[0],
            self.focal_px * d.y + self.principal_point_px[1],
        )
    }

    /// Undistorted normalised coordinate of a pixel (iterative inversion of the distortion).
    #[must_use]
    pub fn normalised_from_pixel(&self, pixel: Point2<f64>) -> Point2<f64> {
        let distorted = Point2::new(
            (pixel.x - self.principal_point_px[0]) / self.focal_px,
            (pixel.y - self.principal_point_px[1]) / self.focal_px,
        );
        self.distortion.undistort(distorted)
    }

    /// Whether a pixel position lies on the image (pixel-centre convention).
    #[must_use]
    pub fn contains(&self, pixel: Point2<f64>) -> bool {
        pixel.x >= -0.5
            && pixel.y >= -0.5
            && pixel.x <= f64::from(self.image_size_px[0]) - 0.5
            && pixel.y <= f64::from(self.image_size_px[1]) - 0.5
    }
}

/// Exterior orientation: where the camera is and which way it looks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Rotation taking camera-frame vectors to world-frame vectors.
    pub rotation_world_from_camera: Rotation3<f64>,
    /// Projection centre in world coordinates (metres).
    pub camera_center_in_world: Point3<f64>,
}

impl Pose {
    /// A camera-frame point for a world point.
    #[must_use]
    pub fn camera_from_world(&self, point_in_world: &Point3<f64>) -> Point3<f64> {
        Point3::from(
            self.rotation_world_from_camera.inverse()
                * (point_in_world - self.camera_center_in_world),
        )
    }

    /// A world-frame point for a camera-frame point.
    #[must_use]
    pub fn world_from_camera(&self, point_in_camera: &Point3<f64>) -> Point3<f64> {
        self.camera_center_in_world + self.rotation_world_from_camera * point_in_camera.coords
    }

    /// The optical axis (camera +z) in the world frame.
    #[must_use]
    pub fn viewing_dir_in_world(&self) -> Vector3<f64> {
        self.rotation_world_from_camera * Vector3::z()
    }
}

/// A complete camera: interior and exterior orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub intrinsics: Intrinsics,
    pub pose: Pose,
}

impl Camera {
    /// Pixel position of a world point, or `None` when the point is not in front of the camera.
    #[must_use]
    pub fn project(&self, point_in_world: &Point3<f64>) -> Option<Point2<f64>> {
        let p = self.pose.camera_from_world(point_in_world);
        if p.z <= 0.0 {
            return None;
        }
        Some(
            self.intrinsics
                .pixel_from_normalised(Point2::new(p.x / p.z, p.y / p.z)),
        )
    }

    /// Unit ray direction in the world frame through a pixel.
    #[must_use]
    pub fn ray_dir_in_world(&self, pixel: Point2<f64>) -> Vector3<f64> {
        let n = self.intrinsics.normalised_from_pixel(pixel);
        (self.pose.rotation_world_from_camera * Vector3::new(n.x, n.y, 1.0)).normalize()
    }
}
