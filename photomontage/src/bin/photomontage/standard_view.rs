//! `photomontage view SITE --from V --projection planar --focal-equiv-mm 50 --out FILE`: a solved
//! photo re-projected to a standard focal length (TGN 06/19 planar views). The computation is
//! `photomontage::verified::planar_view`; this file parses, writes the image and the virtual
//! camera (`FILE` with the extension `.camera.json`), and prints a summary.

use anyhow::{Context, bail};
use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::ToneCurve;
use photomontage::render::output;
use photomontage::site::{SiteDocument, write_atomically};
use photomontage::verified::geometry::fields_of_view_deg;
use photomontage::verified::planar_view::planar_view;
use std::path::PathBuf;

/// How the view is projected.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Projection {
    /// A pinhole image (straight lines stay straight), one photo.
    Planar,
}

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Id of the solved photo the view is made from.
    #[arg(long, value_name = "PHOTO_ID")]
    from: String,
    /// Projection of the view.
    #[arg(long, value_enum, default_value = "planar")]
    projection: Projection,
    /// 35 mm-equivalent focal length of the view (diagonal convention), e.g. 50 or 75.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 50.0,
        allow_hyphen_values = true
    )]
    focal_equiv_mm: f64,
    /// Output size WIDTHxHEIGHT in pixels; default: the photo's size.
    #[arg(long, value_name = "WxH")]
    size: Option<String>,
    /// Output image: .exr (linear, alpha), .png, .jpg/.jpeg or .tif/.tiff (8-bit sRGB).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

fn parse_size(text: &str) -> anyhow::Result<[u32; 2]> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("--size {text}: expected WIDTHxHEIGHT, e.g. 1600x1200"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (1..=65_535).contains(v))
            .with_context(|| format!("--size {text}: {s} is not a size between 1 and 65535"))
    };
    Ok([parse(w)?, parse(h)?])
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    output::OutputFormat::from_path(&args.out)?;
    let size = args.size.as_deref().map(parse_size).transpose()?;
    if args.from.contains(',') {
        bail!(
            "--from {}: a planar view is made from one photo; several photos need a cylindrical \
             projection, which this build does not have",
            args.from
        );
    }
    let doc = SiteDocument::load(&args.site)?;
    let view = match args.projection {
        Projection::Planar => planar_view(&doc, &args.from, args.focal_equiv_mm, size)?,
    };
    let tone_map = ToneMap {
        exposure_stops: doc.site.render.exposure.log2(),
        curve: ToneCurve::Clamp,
    };
    output::write_output(
        &args.out,
        &view.image,
        &output::OutputLayers::default(),
        &tone_map,
    )?;
    let camera_path = args.out.with_extension("camera.json");
    let json = serde_json::to_string_pretty(&view.camera)?;
    write_atomically(&camera_path, json.as_bytes())
        .with_context(|| format!("cannot write {}", camera_path.display()))?;
    let [hfov, vfov] = fields_of_view_deg(&view.camera.intrinsics);
    let [w, h] = view.camera.intrinsics.image_size_px;
    println!(
        "planar view of photo {} at {} mm equivalent: {w}×{h} px, f {:.2} px, field of view \
         {hfov:.3}° × {vfov:.3}°, {:.1} % covered by the photo",
        args.from,
        args.focal_equiv_mm,
        view.camera.intrinsics.focal_px,
        100.0 * view.coverage
    );
    if view.coverage < 1.0 {
        eprintln!(
            "warning: the photo does not fill the view (its focal length is longer than {} mm \
             equivalent in some direction); uncovered pixels are transparent",
            args.focal_equiv_mm
        );
    }
    println!(
        "  wrote {} and its camera {}",
        args.out.display(),
        camera_path.display()
    );
    Ok(())
}
