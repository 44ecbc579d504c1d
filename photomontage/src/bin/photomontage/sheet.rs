//! `photomontage sheet SITE --view V[,V2,…] [--projection photo|planar|cylindrical] --avr LEVEL
//! --out sheet.pdf|.html`: the verified-view sheet of a solved photo, of a planar view at a
//! standard focal length, or of a cylindrical panorama. The view is drawn (AVR0/1) or rendered
//! (AVR2/3, the site's render settings) by `photomontage::verified::standard_view` unless
//! `--image` gives it; the sheet itself is `photomontage::verified::sheet`.
//! The file is written through a temporary file and a rename: never a partial file.

use anyhow::{Context, bail};
use photomontage::colour::{ToneMap, encode_srgb8};
use photomontage::render::RenderedImage;
use photomontage::site::SiteDocument;
use photomontage::verified::cylindrical_view::CylindricalOptions;
use photomontage::verified::sheet::{SheetFormat, sheet_for_geometry, write_sheet};
use photomontage::verified::standard_view::{StandardView, make_view};
use photomontage::verified::{AvrLevel, PaperSize, ViewGeometryOptions};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// Which view the sheet shows.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Projection {
    /// The photo as taken.
    Photo,
    /// The photo re-projected to a standard focal length (`--focal-equiv-mm`).
    Planar,
    /// A cylindrical panorama of the photos `--view V1,V2,…` taken from one point.
    Cylindrical,
}

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Id of the solved photo; several, comma-separated, for a cylindrical view.
    #[arg(long, value_name = "PHOTO_IDS")]
    view: String,
    /// The view on the sheet: the photo as taken, a planar view at `--focal-equiv-mm`, or a
    /// cylindrical panorama of the photos.
    #[arg(long, value_enum, default_value = "photo")]
    projection: Projection,
    /// Planar and cylindrical: 35 mm-equivalent focal length (diagonal convention), e.g. 50 or 75.
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
    /// AVR level of the view: 0 silhouette, 1 wireline, 2 massing, 3 full montage.
    #[arg(long, value_name = "LEVEL", default_value_t = 3)]
    avr: u8,
    /// Use this image (the view's size, any format the library reads) instead of drawing or
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
    let ids: Vec<String> = args.view.split(',').map(|s| s.trim().to_owned()).collect();
    let view = match (args.projection, ids.as_slice()) {
        (Projection::Photo, [id]) => StandardView::Photo { photo: id.clone() },
        (Projection::Planar, [id]) => StandardView::Planar {
            photo: id.clone(),
            focal_equiv_mm: args.focal_equiv_mm,
            size_px: None,
        },
        (Projection::Photo | Projection::Planar, _) => bail!(
            "--view {}: a photo or planar sheet shows one photo; use --projection cylindrical \
             for several",
            args.view
        ),
        (Projection::Cylindrical, _) => StandardView::Cylindrical {
            photos: ids.clone(),
            options: CylindricalOptions {
                focal_equiv_mm: args.focal_equiv_mm,
                max_centre_spread_m: args.max_centre_spread_m,
                ..CylindricalOptions::default()
            },
        },
    };
    let options = ViewGeometryOptions {
        paper: args.paper,
        ground_level_m: args.ground_level_m,
    };
    // With --image the view is only needed for its geometry: no render.
    let level = args.image.is_none().then_some(avr);
    if level.is_some_and(|l| matches!(l, AvrLevel::Avr2 | AvrLevel::Avr3)) {
        eprintln!("rendering the {} view of {}", avr.name(), args.view);
    }
    let made = make_view(
        &doc,
        &view,
        level,
        &options,
        &|_| {},
        &AtomicBool::new(false),
    )?;
    for w in &made.warnings {
        eprintln!("warning: {w}");
    }
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
        None => to_rgb8(&made.image, exposure),
    };
    let pdf = sheet_for_geometry(&doc, &made.geometry, &rgb, avr, format)?;
    write_sheet(&args.out, &pdf)?;
    println!(
        "wrote the {} {} sheet of view {} to {} ({} bytes)",
        args.paper.name(),
        avr.name(),
        made.geometry.photo_id,
        args.out.display(),
        pdf.len()
    );
    Ok(())
}
