//! `photomontage resect POINTS`: solve one photo from a control-point file.

use crate::report::{PhotoRecord, print_photo, rotation_rows};
use anyhow::{Context, bail};
use photomontage::camera::Intrinsics;
use photomontage::geo::ProjectedCrs;
use photomontage::photo;
use photomontage::photogrammetry::control_io::{parse_odm_gcp_list, parse_points_csv};
use photomontage::photogrammetry::{ResectionOptions, SelfCalibration, resect};
use photomontage::site::control_location::location_from_points;
use std::path::PathBuf;

/// Standard deviation given to control points read from a file that states none.
const DEFAULT_CONTROL_SIGMA_M: [f64; 3] = [0.01, 0.01, 0.01];

#[derive(clap::Args)]
pub struct Args {
    /// Control points with their pixel positions: a CSV `id,X,Y,Z,x,y[,sigma_px]` (header row
    /// allowed) or an OpenDroneMap `gcp_list.txt` (then give --image). Pixel (0,0) is the centre
    /// of the top-left pixel, y down.
    points: PathBuf,
    /// Width and height of the photo in pixels (read from the photo when --image names a file
    /// that exists beside the points file).
    #[arg(long, num_args = 2, value_names = ["W", "H"])]
    image_size: Option<Vec<u32>>,
    /// Focal length in pixels (else from the photo's EXIF).
    #[arg(long)]
    focal_px: Option<f64>,
    /// The image name of the rows to use in an OpenDroneMap gcp_list.txt.
    #[arg(long)]
    image: Option<String>,
    /// Standard deviation of the pixel positions when the file gives none.
    #[arg(long, default_value_t = 1.0)]
    sigma_px: f64,
    /// Estimate these interior parameters where the geometry supports it (comma list of
    /// focal, principal_point, k1, k2).
    #[arg(long, value_delimiter = ',')]
    self_calibrate: Vec<String>,
    /// Seed of the robust start.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Projected CRS to solve in when the GCP list's header names another one (WGS84,
    /// EPSG:4326, a PROJ.4 string, an EPSG code): `EPSG:326NN`, `EPSG:2056`, a PROJ.4 string…
    /// Default: the list's own CRS when projected, else the UTM zone of the points' centroid.
    #[arg(long)]
    crs: Option<String>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.points)
        .with_context(|| format!("reading {}", args.points.display()))?;
    let first_line = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    let looks_odm = !first_line.contains(',');
    let target = args
        .crs
        .as_deref()
        .map(ProjectedCrs::from_name)
        .transpose()
        .context("--crs")?;
    let mut control_crs = None;
    let mut location_crs = None;
    let (control, observations, photo_id) = if looks_odm {
        let context = || {
            format!(
                "reading {} as an OpenDroneMap GCP list",
                args.points.display()
            )
        };
        let source = parse_odm_gcp_list(&text).with_context(context)?;
        let (list, crs) = source.reprojected(target.as_ref()).with_context(context)?;
        if list.crs != source.crs {
            control_crs = Some(format!(
                "reprojected from `{}` to `{}` ({}); heights as given (datum of the list, no geoid model)",
                source.crs,
                crs.definition(),
                if target.is_some() {
                    "--crs"
                } else {
                    "UTM zone of the points' centroid"
                }
            ));
        }
        location_crs = Some(crs);
        let Some(image) = args.image.clone() else {
            bail!(
                "{} is a GCP list for several images: choose one with --image (one of: {})",
                args.points.display(),
                list.images().join(", ")
            );
        };
        let obs = list.observations(&image, args.sigma_px);
        if obs.is_empty() {
            bail!(
                "no rows for image `{image}` in {} (images: {})",
                args.points.display(),
                list.images().join(", ")
            );
        }
        (list.control_points(DEFAULT_CONTROL_SIGMA_M)?, obs, image)
    } else {
        if target.is_some() {
            bail!("--crs applies to a gcp_list.txt whose header names its CRS; a CSV has none");
        }
        let csv = parse_points_csv(&text)
            .with_context(|| format!("reading {} as CSV", args.points.display()))?;
        let (c, o) = csv.split(DEFAULT_CONTROL_SIGMA_M, args.sigma_px);
        let id = args.image.clone().unwrap_or_else(|| {
            args.points
                .file_stem()
                .map_or_else(|| "photo".into(), |s| s.to_string_lossy().into_owned())
        });
        (c, o, id)
    };

    // A photo beside the points file gives the size and the EXIF focal length.
    let photo_path = args
        .image
        .as_ref()
        .map(|name| {
            args.points
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(name)
        })
        .filter(|p| p.is_file());
    let size = match (&args.image_size, &photo_path) {
        (Some(v), _) => [v[0], v[1]],
        (None, Some(p)) => photo::size_px(p)?,
        (None, None) => bail!("give --image-size W H (no photo file found to read it from)"),
    };
    let focal_px = match (args.focal_px, &photo_path) {
        (Some(f), _) => f,
        (None, Some(p)) => {
            let exif = photo::read_exif(p).with_context(|| {
                format!(
                    "no --focal-px given and the EXIF of {} is unreadable",
                    p.display()
                )
            })?;
            photo::focal_px_from_exif(&exif, size)
                .with_context(|| {
                    format!(
                        "no --focal-px given and {} gives no focal length in pixels",
                        p.display()
                    )
                })?
                .focal_px
        }
        (None, None) => bail!("give --focal-px F (no photo file found to read EXIF from)"),
    };
    let mut self_calibration = SelfCalibration::default();
    for name in &args.self_calibrate {
        match name.trim() {
            "focal" => self_calibration.focal = true,
            "principal_point" => self_calibration.principal_point = true,
            "k1" => self_calibration.k1 = true,
            "k2" => self_calibration.k2 = true,
            other => bail!("--self-calibrate: `{other}` is not focal, principal_point, k1 or k2"),
        }
    }
    let mut options = ResectionOptions::new(Intrinsics::centred(focal_px, size));
    options.self_calibration = self_calibration;
    options.seed = args.seed;
    let r = resect(&control, &observations, &options)?;
    let intr = r.camera.intrinsics;
    // The site's [location] from the control, when the list names its CRS.
    let site_location = match &location_crs {
        Some(crs) => {
            let points: Vec<[f64; 3]> = control
                .iter()
                .map(|c| c.point_in_world.coords.into())
                .collect();
            Some(
                location_from_points(&points, crs, &crs.site_name())
                    .context("site location from the control points")?,
            )
        }
        None => None,
    };
    let record = PhotoRecord {
        id: &photo_id,
        camera_center: r.camera.pose.camera_center_in_world.coords.into(),
        rotation_world_from_camera: rotation_rows(&r.camera),
        focal_px: intr.focal_px,
        principal_point_px: intr.principal_point_px,
        distortion: intr.distortion,
        image_size_px: intr.image_size_px,
        rms_px: r.rms_px,
        redundancy: r.redundancy,
        sigma_center_m: r.sigma_center_m,
        sigma_angles_deg: r.sigma_angles_deg,
        sigma_focal_px: r.sigma_focal_px,
        outliers: &r.outliers,
        warnings: &r.warnings,
        residuals: &r.residuals,
        solved_by: "resection",
        control_crs,
        site_location,
        radial_pattern: r.radial_pattern,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&record)?);
    } else {
        print_photo(&record);
    }
    Ok(())
}
