//! The `photomontage` command-line tool.

mod luminaire;

use clap::{Parser, Subcommand};

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
    /// Read an IES LM-63 or EULUMDAT file: format, flux, max intensity, symmetry, plot.
    Luminaire(luminaire::LuminaireArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Luminaire(args) => luminaire::run(&args),
    }
}
