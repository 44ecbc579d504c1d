//! The `photomontage` command-line tool.

mod calibrate;
mod calibrate_opencv;
mod colour;
mod compare;
mod elevation;
mod exchange;
mod farm;
mod fit;
mod info;
mod irradiance;
mod luminaire;
mod merge;
mod radiosity;
mod render;
mod report;
mod resect;
mod sheet;
mod sky;
mod solve;
mod standard_view;
mod study;
mod sun;
mod tie_match;
mod view_report;

use clap::{Parser, Subcommand};

/// Photogrammetric photomontage: solve site cameras, model daylight, render planned buildings.
///
/// Pixel convention everywhere: (0,0) is the centre of the top-left pixel of the photo as
/// displayed (EXIF orientation applied); x runs right, y runs down. World coordinates are
/// right-handed with Z up, in metres.
#[derive(Parser)]
#[command(name = "photomontage", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Largest photo any command decodes, in megapixels (checked against the file header before
    /// a pixel is allocated; larger photos are refused naming the file and its size).
    #[arg(long, global = true, value_name = "MP", default_value_t = 250.0)]
    max_photo_megapixels: f64,
    /// Most memory decoding one photo may take (decoder plus float copy), in MiB.
    #[arg(long, global = true, value_name = "MIB", default_value_t = 8192)]
    max_decode_memory_mib: u64,
}

#[derive(Subcommand)]
enum Command {
    /// Show what a site holds: photos (size, solved or not), points, polygons, models.
    Info(info::Args),
    /// Solve every photo of a site (resection, then bundle adjustment), print the residuals
    /// and write the cameras back into the site atomically.
    Solve(solve::Args),
    /// Render the site's planned models into one solved photo (differential ray tracing) and
    /// write EXR (linear, alpha, optional layers) or 8-bit sRGB PNG/JPEG/TIFF.
    Render(render::Args),
    /// Sun and shadow study: render a view at every date × local time (SPA sun at [location],
    /// times in location.time_zone) into a folder, with a contact sheet.
    Study(study::Args),
    /// Design variants side by side: render every `[[variants]]` entry of a view under the same
    /// light and write a labelled comparison sheet (PDF, one page per variant; PNG grid).
    Compare(compare::Args),
    /// Solve one photo from a control-point file (CSV or OpenDroneMap gcp_list.txt).
    Resect(resect::Args),
    /// Solar position (NREL SPA), sunrise and sunset.
    Sun(sun::SunArgs),
    /// CIE standard sky: E_h/L_z and a fisheye luminance map.
    Sky(sky::SkyArgs),
    /// A designer's colour (hex, L*a*b*, LCh or a RAL Design code) as sRGB hex, linear
    /// reflectance, L*a*b*, LCh, nearest RAL Design code and LRV; with two, their LRV difference.
    Colour(colour::Args),
    /// Read an IES LM-63 or EULUMDAT file: format, flux, max intensity, symmetry, plot.
    Luminaire(luminaire::LuminaireArgs),
    /// Fit the atmosphere and daylight weights to the site's colour samples (Durisch §4.2–4.3),
    /// cross-check the sun against shadows, and write the lighting back atomically.
    Fit(fit::Args),
    /// Merge the partial EXRs of one view (`render --tile I/N`) into the whole image.
    Merge(merge::Args),
    /// List a site's views cut into tiles as independent jobs (JSON) for a render farm.
    Jobs(farm::JobsArgs),
    /// Run one job of a job list (`--index K`), or merge its views (`--merge`); a job whose
    /// part is already complete is skipped.
    RunJob(farm::RunJobArgs),
    /// Write a job list and Slurm scripts: an sbatch job array plus a dependent merge job.
    Slurm(farm::SlurmArgs),
    /// Write a job list and Kubernetes manifests: an Indexed Job plus a merge Job.
    K8s(farm::K8sArgs),
    /// Write a job list and a Flamenco job type with its submission body.
    Flamenco(farm::FlamencoArgs),
    /// The view geometry report of one solved photo (TGN 06/19 / LVMF verified view): camera
    /// position and height, bearing, pitch, roll, fields of view, 35 mm equivalent, sun at
    /// capture, residuals, distance to the proposal, viewing distance of the sheet.
    Report(view_report::Args),
    /// A solved photo re-projected to a standard focal length (planar view at a 50 mm or 75 mm
    /// equivalent), with its virtual camera.
    View(standard_view::Args),
    /// The verified-view sheet (PDF or HTML) of one solved photo: the view at print scale with its
    /// viewing distance, ruler, geometry table, map inset, AVR level, methodology and residuals.
    Sheet(sheet::Args),
    /// Radiosity on the site's scene: mesh into patches and elements, light by the sun, the sky
    /// and emitting materials as separate groups, solve the interreflection (hierarchical,
    /// progressive or direct); report patches, links, passes, time and residual, optionally
    /// write the mesh (PLY) and the convergence record (CSV); `render --radiosity` lights the
    /// montage with the same solve.
    Radiosity(radiosity::Args),
    /// Export the site's solved cameras for Blender (Python script), COLMAP (text model) or
    /// OpenCV (FileStorage YAML); a format that cannot carry a distortion term is refused.
    ExportCameras(exchange::ExportArgs),
    /// Import cameras from a COLMAP text model or an OpenSfM reconstruction.json as initial
    /// values (interior; --with-poses also the exterior) for the site's photos.
    ImportCameras(exchange::ImportArgs),
    /// Lens calibration from chessboard photos (own corner detector, Zhang 2000): fx, fy,
    /// principal point, k1, k2, p1, p2, written as a camera profile (TOML) that sites reuse.
    Calibrate(calibrate::Args),
    /// Irradiance at points (CSV rows `id,X,Y,Z,nx,ny,nz`) from the site's radiosity solution:
    /// sun, sky, luminaires and interreflection, split into direct and indirect (JSON with
    /// `--json`).
    Irradiance(irradiance::Args),
    /// The unfolded elevation of one CAD model: its façades side by side with their colours,
    /// or (`--irradiance`) the irradiance of the site's radiosity solution, as a PNG.
    Elevation(elevation::Args),
    /// Tie points by feature matching (SIFT, ratio test, fundamental-matrix RANSAC, tracks),
    /// written into the site atomically; `solve` then uses them. Needs a build with the
    /// `opencv` feature.
    Match(tie_match::Args),
    /// Lens calibration from chessboard photos (OpenCV's findChessboardCorners, cornerSubPix,
    /// calibrateCamera): fx, fy, cx, cy, k1, k2, p1, p2, k3 and RMS; the corners as CSV. Needs
    /// a build with the `opencv` feature.
    CalibrateOpencv(calibrate_opencv::Args),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    photomontage::photo::DecodeLimits::set_for_process(
        photomontage::photo::DecodeLimits::from_megapixels_and_mib(
            cli.max_photo_megapixels,
            cli.max_decode_memory_mib,
        )?,
    )?;
    match cli.command {
        Command::Info(args) => info::run(&args),
        Command::Solve(args) => solve::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Study(args) => study::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Resect(args) => resect::run(&args),
        Command::Sun(args) => sun::run(&args),
        Command::Colour(args) => colour::run(&args),
        Command::Sky(args) => sky::run(&args),
        Command::Luminaire(args) => luminaire::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Jobs(args) => farm::jobs(&args),
        Command::RunJob(args) => farm::run_job(&args),
        Command::Slurm(args) => farm::slurm(&args),
        Command::K8s(args) => farm::k8s(&args),
        Command::Flamenco(args) => farm::flamenco(&args),
        Command::Report(args) => view_report::run(&args),
        Command::View(args) => standard_view::run(&args),
        Command::Sheet(args) => sheet::run(&args),
        Command::Radiosity(args) => radiosity::run(&args),
        Command::ExportCameras(args) => exchange::export(&args),
        Command::ImportCameras(args) => exchange::import(&args),
        Command::Calibrate(args) => calibrate::run(&args),
        Command::Irradiance(args) => irradiance::run(&args),
        Command::Elevation(args) => elevation::run(&args),
        Command::Match(args) => tie_match::run(&args),
        Command::CalibrateOpencv(args) => calibrate_opencv::run(&args),
    }
}
