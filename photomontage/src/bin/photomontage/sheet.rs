//! `photomontage sheet SITE --view V --avr LEVEL --out sheet.pdf|.html`: the verified-view sheet
//! of one solved photo. The view is drawn (AVR0/1) or rendered (AVR2/3, the site's render
//! settings) unless `--image` gives it; the sheet itself is `photomontage::verified::sheet`.
//! The file is written through a temporary file and a rename: never a partial file.

use anyhow::{Context, bail};
use photomontage::colour::{ToneMap, encode_srgb8};
use photomontage::render::{DifferentialTracer, RenderedImage, render_view};
use photomontage::site::SiteDocument;
use photomontage::site::render::prepare_view;
use photomontage::verified::sheet::{SheetFormat, sheet_for_view_as, write_sheet};
use photomontage::verified::{
    AvrLevel, PaperSize, ViewGeometryOptions, apply_massing, avr_overlay,
};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Id of the solved photo.
    #[arg(long, value_name = "PHOTO_ID")]
    view: String,
    /// AVR level of the view: 0 silhouette, 1 wireline, 2 massing, 3 full montage.
    #[arg(long, value_name = "LEVEL", default_value_t = 3)]
    avr: u8,
    /// Use this image (the photo's size, any format the library reads) instead of drawing or
    /// rendering the view; it should show the stated AVR level.
    #[arg(long, value_name = "FILE")]
    image: Option<PathBuf>,
    /// Paper: A3 (default), A2 or A1, landscape.
    #[arg(long, value_name = "SIZE", default_value = "A3")]
    paper: PaperSize,
    /// Ground level below the camera (survey height, metres); default: the scene polygon below.
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    ground_level_m: Option<f64>,
    /// The sheet to write: .pdf, or .html (one self-contained file).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

fn to_rgb8(image: &RenderedImage, exposure: f64) -> image::RgbImage {
    let tone_map = ToneMap::clamp_with_exposure(exposure);
    let [w, h] = image.size_px;
    image::RgbImage::from_fn(w, h, |x, y| {
        let p = image.rgba[(y * w + x) as usize];
        image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone_map))
    })
}

fn view_image(doc: &SiteDocument, view: &str, avr: AvrLevel) -> anyhow::Result<RenderedImage> {
    if matches!(avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
        return Ok(avr_overlay(doc, view, avr)?.image);
    }
    let mut job = prepare_view(doc, view)?;
    for w in &job.warnings {
        eprintln!("warning: {w}");
    }
    if avr == AvrLevel::Avr2 {
        apply_massing(&mut job.scene.scene)?;
    }
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )?;
    eprintln!("rendering the {} view of {view}", avr.name());
    Ok(render_view(
        &tracer,
        &job.settings,
        &|_| {},
        &AtomicBool::new(false),
    )?)
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let Some(format) = SheetFormat::from_path(&args.out) else {
        bail!(
            "--out {}: the sheet is a PDF (.pdf) or an HTML file (.html)",
            args.out.display()
        );
    };
    let avr = AvrLevel::from_number(args.avr)?;
    let doc = SiteDocument::load(&args.site)?;
    let exposure = doc.site.render.exposure;
    let rgb = match &args.image {
        Some(path) => {
            let loaded = photomontage::photo::load(path)
                .with_context(|| format!("reading --image {}", path.display()))?;
            let linear = photomontage::render::linear_photo(&loaded);
            let [w, h] = [linear.width(), linear.height()];
            let rgba = linear
                .pixels()
                .map(|p| [p.0[0], p.0[1], p.0[2], 1.0])
                .collect();
            to_rgb8(
                &RenderedImage {
                    size_px: [w, h],
                    rgba,
                    changed_pixels: 0,
                    primary_rays: 0,
                },
                1.0,
            )
        }
        None => to_rgb8(&view_image(&doc, &args.view, avr)?, exposure),
    };
    let options = ViewGeometryOptions {
        paper: args.paper,
        ground_level_m: args.ground_level_m,
    };
    let pdf = sheet_for_view_as(&doc, &args.view, &rgb, avr, &options, format)?;
    write_sheet(&args.out, &pdf)?;
    println!(
        "wrote the {} {} sheet of view {} to {} ({} bytes)",
        args.paper.name(),
        avr.name(),
        args.view,
        args.out.display(),
        pdf.len()
    );
    Ok(())
}
