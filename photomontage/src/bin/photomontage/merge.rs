//! `photomontage merge PARTS… --out FILE`: assemble the partial EXRs of one view (written by
//! `render --tile I/N` or `run-job`) into the whole image — EXR with its layers, or 8-bit sRGB
//! with the parts' exposure. Missing, duplicate and foreign parts (another site, view, settings
//! or seed) are named and nothing is written.

use anyhow::bail;
use photomontage::farm::jobs::merge_to_file;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The parts: every tile of one view.
    #[arg(required = true, value_name = "PART")]
    parts: Vec<PathBuf>,
    /// The merged image: .exr, .png, .jpg/.jpeg or .tif/.tiff.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if args.parts.iter().any(|p| p == &args.out) {
        bail!("--out {} is one of the parts", args.out.display());
    }
    super::render::check_writable(&args.out)?;
    let merged = merge_to_file(&args.parts, &args.out)?;
    let [w, h] = merged.image.size_px;
    println!(
        "merged {} tiles of view {} ({w}×{h} px) into {}",
        args.parts.len(),
        merged.info.identity.get("view").map_or("?", String::as_str),
        args.out.display()
    );
    Ok(())
}
