//! `photomontage view SITE --from V1[,V2,…] --projection planar|cylindrical --focal-equiv-mm 50
//! --out FILE`: a solved photo re-projected to a standard focal length (TGN 06/19 planar views),
//! or a cylindrical panorama of several photos taken from one point. The computations are
//! `photomontage::verified::standard_view`; this file parses, writes the image carrying the
//! view's geometry (EXIF and XMP, or EXR attributes) and its projection (`FILE` with the extension
//! `.camera.json` or `.cylinder.json`), and prints a summary.

use anyhow::{Context, bail};
use photomontage::colour::ToneMap;
use photomontage::render::output;
use photomontage::site::{SiteDocument, write_atomically};
use photomontage::verified::cylindrical_view::CylindricalOptions;
use photomontage::verified::image_metadata::write_render;
use photomontage::verified::standard_view::{StandardView, make_view};
use photomontage::verified::{AvrLevel, ViewGeometryOptions, ViewMetadata};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// How the view is projected.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Projection {
    /// A pinhole image (straight lines stay straight), one photo.
    Planar,
    /// A level cylinder (up to 360°) composed from several photos taken from one point.
    Cylindrical,
}

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Id of the solved photo the view is made from; several, comma-separated, for a
    /// cylindrical view.
    #[arg(long, value_name = "PHOTO_IDS")]
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
    /// Cylindrical: photos whose centre is farther than this from the photos' mean centre are
    /// refused (metres).
    #[arg(long, value_name = "M", default_value_t = 0.1)]
    max_centre_spread_m: f64,
    /// Render the montage (AVR3, the site's render settings) into the view, as into a photo,
    /// instead of writing the re-projected photos alone (cylindrical: each photo's montage,
    /// composed on the cylinder).
    #[arg(long)]
    montage: bool,
    /// Planar: output size WIDTHxHEIGHT in pixels; default: the photo's size.
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
    let ids: Vec<String> = args.from.split(',').map(|s| s.trim().to_owned()).collect();
    let doc = SiteDocument::load(&args.site)?;
    let view = match args.projection {
        Projection::Planar => {
            let [id] = ids.as_slice() else {
                bail!(
                    "--from {}: a planar view is made from one photo; use --projection \
                     cylindrical for several",
                    args.from
                );
            };
            StandardView::Planar {
                photo: id.clone(),
                focal_equiv_mm: args.focal_equiv_mm,
                size_px: size,
            }
        }
        Projection::Cylindrical => {
            if size.is_some() {
                bail!(
                    "--size is for planar views; a cylindrical view's size follows from its photos"
                );
            }
            StandardView::Cylindrical {
                photos: ids.clone(),
                options: CylindricalOptions {
                    focal_equiv_mm: args.focal_equiv_mm,
                    max_centre_spread_m: args.max_centre_spread_m,
                    ..CylindricalOptions::default()
                },
            }
        }
    };
    let avr = args.montage.then_some(AvrLevel::Avr3);
    if avr.is_some() {
        eprintln!("rendering the montage into the view");
    }
    let made = make_view(
        &doc,
        &view,
        avr,
        &ViewGeometryOptions::default(),
        &|_| {},
        &AtomicBool::new(false),
    )?;
    for w in &made.warnings {
        eprintln!("warning: {w}");
    }
    let g = &made.geometry;
    let [w, h] = g.image_size_px;
    if made.coverage < 1.0 {
        eprintln!(
            "warning: the photos cover {:.1} % of the view (a focal length shorter than the \
             photo's, or gaps between the photos); uncovered pixels are transparent",
            100.0 * made.coverage
        );
    }
    let summary = match args.projection {
        Projection::Planar => format!(
            "planar view of photo {} at {} mm equivalent: {w}×{h} px, f {:.2} px, field of view \
             {:.3}° × {:.3}°, {:.1} % covered by the photo",
            g.photo_id,
            args.focal_equiv_mm,
            g.focal_px,
            g.hfov_deg,
            g.vfov_deg,
            100.0 * made.coverage
        ),
        Projection::Cylindrical => format!(
            "cylindrical view of photos {} at {} mm equivalent: {w}×{h} px, radius {:.2} px, \
             {:.2}° wide centred on bearing {:.3}° (grid)",
            ids.join(", "),
            args.focal_equiv_mm,
            g.focal_px,
            g.hfov_deg,
            g.bearing_grid_deg
        ),
    };
    let tone_map = ToneMap::clamp_with_exposure(doc.site.render.exposure);
    let metadata = ViewMetadata::from(g);
    write_render(
        &args.out,
        &made.image,
        &output::OutputLayers::default(),
        &tone_map,
        Some(&metadata),
    )?;
    println!("{summary}");
    if let Some((extension, json)) = &made.projection_json {
        let side_path = args.out.with_extension(extension);
        write_atomically(&side_path, json.as_bytes())
            .with_context(|| format!("cannot write {}", side_path.display()))?;
        println!(
            "  wrote {} (with its view geometry) and its projection {}",
            args.out.display(),
            side_path.display()
        );
    }
    Ok(())
}
