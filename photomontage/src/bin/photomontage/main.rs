//! The `photomontage` command-line tool.

mod fit;
mod info;
mod luminaire;
mod render;
mod report;
mod resect;
mod sheet;
mod sky;
mod solve;
mod standard_view;
mod sun;
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
    /// Solve one photo from a control-point file (CSV or OpenDroneMap gcp_list.txt).
    Resect(resect::Args),
    /// Solar position (NREL SPA), sunrise and sunset.
    Sun(sun::SunArgs),
    /// CIE standard sky: E_h/L_z and a fisheye luminance map.
    Sky(sky::SkyArgs),
    /// Read an IES LM-63 or EULUMDAT file: format, flux, max intensity, symmetry, plot.
    Luminaire(luminaire::LuminaireArgs),
    /// Fit the atmosphere and daylight weights to the site's colour samples (Durisch §4.2–4.3),
    /// cross-check the sun against shadows, and write the lighting back atomically.
    Fit(fit::Args),
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
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Info(args) => info::run(&args),
        Command::Solve(args) => solve::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Resect(args) => resect::run(&args),
        Command::Sun(args) => sun::run(&args),
        Command::Sky(args) => sky::run(&args),
        Command::Luminaire(args) => luminaire::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Report(args) => view_report::run(&args),
        Command::View(args) => standard_view::run(&args),
        Command::Sheet(args) => sheet::run(&args),
    }
}
