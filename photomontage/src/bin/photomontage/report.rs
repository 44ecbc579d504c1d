//! The per-photo JSON record shared by `solve` and `resect`, and the residual table.

use photomontage::camera::{BrownConrady, Camera};
use photomontage::photogrammetry::ObservationResidual;
use photomontage::photogrammetry::radial_pattern::RadialPattern;
use serde::Serialize;

/// What `solve --json` and `resect --json` print for each photo.
#[derive(Serialize)]
pub struct PhotoRecord<'a> {
    pub id: &'a str,
    pub camera_center: [f64; 3],
    pub rotation_world_from_camera: [[f64; 3]; 3],
    pub focal_px: f64,
    pub principal_point_px: [f64; 2],
    pub distortion: BrownConrady,
    pub image_size_px: [u32; 2],
    pub rms_px: f64,
    pub redundancy: i64,
    pub sigma_center_m: [f64; 3],
    pub sigma_angles_deg: [f64; 3],
    pub sigma_focal_px: Option<f64>,
    pub outliers: &'a [String],
    pub warnings: &'a [String],
    pub residuals: &'a [ObservationResidual],
    pub solved_by: &'a str,
    /// How the control coordinates reached the CRS of `camera_center` (reprojected lists only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub control_crs: Option<String>,
    /// The site location the control points give (centroid, its CRS and grid convergence), for
    /// a site whose `[location]` is still empty (control from a list that names its CRS).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub site_location: Option<photomontage::site::Location>,
    /// Correlation of the radial residuals with r³ (uncorrected distortion when strong).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radial_pattern: Option<RadialPattern>,
}

pub fn rotation_rows(camera: &Camera) -> [[f64; 3]; 3] {
    let m = camera.pose.rotation_world_from_camera.matrix();
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// Prints one photo's solution and its residual table.
pub fn print_photo(r: &PhotoRecord<'_>) {
    println!(
        "photo {}  ({}; redundancy {})",
        r.id, r.solved_by, r.redundancy
    );
    if let Some(crs) = &r.control_crs {
        println!("  control    {crs}");
    }
    if let Some(l) = &r.site_location {
        println!(
            "  location   {:.6}° N {:.6}° E, crs {}, grid convergence {:.4}° (control centroid; \
             the site's [location] when empty)",
            l.latitude_deg,
            l.longitude_deg,
            l.crs.as_deref().unwrap_or("?"),
            l.grid_convergence_deg
        );
    }
    println!(
        "  centre     X {:.4}  Y {:.4}  Z {:.4}   σ {:.4} {:.4} {:.4} m",
        r.camera_center[0],
        r.camera_center[1],
        r.camera_center[2],
        r.sigma_center_m[0],
        r.sigma_center_m[1],
        r.sigma_center_m[2]
    );
    println!(
        "  angles σ   {:.4} {:.4} {:.4} deg",
        r.sigma_angles_deg[0], r.sigma_angles_deg[1], r.sigma_angles_deg[2]
    );
    let sigma_f = r
        .sigma_focal_px
        .map_or_else(String::new, |s| format!(" ± {s:.2}"));
    println!(
        "  focal      {:.2}{sigma_f} px   principal point ({:.2}, {:.2}) px   k1 {:.5} k2 {:.5}",
        r.focal_px,
        r.principal_point_px[0],
        r.principal_point_px[1],
        r.distortion.k1,
        r.distortion.k2
    );
    println!("  RMS        {:.3} px", r.rms_px);
    println!(
        "  {:<12} {:>9} {:>9} {:>9} {:>7}  flag",
        "point", "vx px", "vy px", "|v| px", "|v|/σ"
    );
    for res in r.residuals {
        let norm = res.residual_px[0].hypot(res.residual_px[1]);
        let w = res.normalised[0].hypot(res.normalised[1]);
        println!(
            "  {:<12} {:>9.3} {:>9.3} {:>9.3} {:>7.2}  {}",
            res.point_id,
            res.residual_px[0],
            res.residual_px[1],
            norm,
            w,
            if res.outlier { "OUTLIER" } else { "" }
        );
    }
    for w in r.warnings {
        println!("  warning: {w}");
    }
}
