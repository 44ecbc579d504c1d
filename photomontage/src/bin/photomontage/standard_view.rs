//! `photomontage view SITE --from V1[,V2,…] --projection planar|cylindrical --focal-equiv-mm 50
//! --out FILE`: a solved photo re-projected to a standard focal length (TGN 06/19 planar views),
//! or a cylindrical panorama of several photos taken from one point. The computations are
//! `photomontage::verified::{planar_view, cylindrical_view}`; this file parses, writes the image
//! and its projection (`FILE` with the extension `.camera.json` or `.cylinder.json`), and prints a
//! summary.

use anyhow::{Context, bail};
use photomontage::colour::ToneMap;
use photomontage::render::output;
use photomontage::render::{DifferentialTracer, render_view};
use photomontage::site::{SiteDocument, write_atomically};
use photomontage::verified::cylindrical_view::{CylindricalOptions, site_cylindrical_view};
use photomontage::verified::geometry::fields_of_view_deg;
use photomontage::verified::planar_view::{planar_view, planar_view_job};
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
    /// Planar: render the montage (AVR3, the site's render settings) into the view, as into a
    /// photo, instead of writing the re-projected photo alone.
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
    let ids: Vec<&str> = args.from.split(',').map(str::trim).collect();
    let doc = SiteDocument::load(&args.site)?;
    let (image, projection_json, summary) = match args.projection {
        Projection::Planar => {
            let [id] = ids.as_slice() else {
                bail!(
                    "--from {}: a planar view is made from one photo; use --projection \
                     cylindrical for several",
                    args.from
                );
            };
            let (view, image) = if args.montage {
                let (view, job) = planar_view_job(&doc, id, args.focal_equiv_mm, size)?;
                for w in &job.warnings {
                    eprintln!("warning: {w}");
                }
                let tracer = DifferentialTracer::new(
                    &job.scene.scene,
                    &job.lighting,
                    &job.camera,
                    &job.photo_linear,
                    job.settings.max_depth,
                )?;
                eprintln!("rendering the montage into the view");
                let montage =
                    render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false))?;
                (view, montage)
            } else {
                let view = planar_view(&doc, id, args.focal_equiv_mm, size)?;
                let image = view.image.clone();
                (view, image)
            };
            let [hfov, vfov] = fields_of_view_deg(&view.camera.intrinsics);
            let [w, h] = view.camera.intrinsics.image_size_px;
            if view.coverage < 1.0 {
                eprintln!(
                    "warning: the photo does not fill the view (its focal length is longer than \
                     {} mm equivalent in some direction); uncovered pixels are transparent",
                    args.focal_equiv_mm
                );
            }
            let summary = format!(
                "planar view of photo {id} at {} mm equivalent: {w}×{h} px, f {:.2} px, field of \
                 view {hfov:.3}° × {vfov:.3}°, {:.1} % covered by the photo",
                args.focal_equiv_mm,
                view.camera.intrinsics.focal_px,
                100.0 * view.coverage
            );
            (
                image,
                ("camera.json", serde_json::to_string_pretty(&view.camera)?),
                summary,
            )
        }
        Projection::Cylindrical => {
            if args.montage {
                bail!("--montage is for planar views (the renderer needs a pinhole camera)");
            }
            if size.is_some() {
                bail!(
                    "--size is for planar views; a cylindrical view's size follows from its photos"
                );
            }
            let options = CylindricalOptions {
                focal_equiv_mm: args.focal_equiv_mm,
                max_centre_spread_m: args.max_centre_spread_m,
                ..CylindricalOptions::default()
            };
            let view = site_cylindrical_view(&doc, &ids, &options)?;
            let c = view.cylinder;
            let summary = format!(
                "cylindrical view of photos {} at {} mm equivalent: {}×{} px, radius {:.2} px, \
                 {:.2}° wide from bearing {:.3}° (grid)",
                ids.join(", "),
                args.focal_equiv_mm,
                c.size_px[0],
                c.size_px[1],
                c.focal_px,
                f64::from(c.size_px[0]) / c.focal_px * 180.0 / std::f64::consts::PI,
                c.azimuth_left.to_degrees().rem_euclid(360.0)
            );
            (
                view.image,
                ("cylinder.json", serde_json::to_string_pretty(&c)?),
                summary,
            )
        }
    };
    let tone_map = ToneMap::clamp_with_exposure(doc.site.render.exposure);
    output::write_output(
        &args.out,
        &image,
        &output::OutputLayers::default(),
        &tone_map,
    )?;
    let (extension, json) = projection_json;
    let side_path = args.out.with_extension(extension);
    write_atomically(&side_path, json.as_bytes())
        .with_context(|| format!("cannot write {}", side_path.display()))?;
    println!("{summary}");
    println!(
        "  wrote {} and its projection {}",
        args.out.display(),
        side_path.display()
    );
    Ok(())
}
