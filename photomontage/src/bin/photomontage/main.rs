//! The `photomontage` command-line tool.

use clap::{Parser, Subcommand};

mod sky;
mod sun;

/// Photogrammetric photomontage: solve site cameras, model daylight, render planned buildings.
///
/// Pixel convention everywhere: (0,0) is the centre of the top-left pixel of the photo as
/// displayed (EXIF orientation applied); x runs right, y runs down.
#[derive(Parser)]
#[command(name = "photomontage", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solar position (NREL SPA), sunrise and sunset.
    Sun(sun::SunArgs),
    /// CIE standard sky: E_h/L_z and a fisheye luminance map.
    Sky(sky::SkyArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Sun(args) => sun::run(&args),
        Command::Sky(args) => sky::run(&args),
    }
}
