//! `photomontage render SITE --view PHOTO --out FILE`: render the site's visible models into one
//! solved photo with the differential ray tracer and write EXR or 8-bit sRGB. Ctrl-C cancels
//! the render between tiles; nothing is written then and the exit status is non-zero.

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use photomontage::colour::SampleSet;
use photomontage::colour::ToneMap;
use photomontage::colour::encode_srgb8;
use photomontage::colour::tonemap::ToneCurve;
use photomontage::render::RenderedImage;
use photomontage::render::output::{self, LayerSet, OutputFormat};
use photomontage::render::{DifferentialTracer, render_view_spectral, render_view_with_layers};
use photomontage::site::SiteDocument;
use photomontage::site::render::prepare_view;
use photomontage::verified::image_metadata::{exif_block, write_8bit_with_exif};
use photomontage::verified::{
    AvrLevel, ViewGeometryOptions, apply_massing, avr_overlay, view_geometry,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Set by the Ctrl-C handler; the renderer polls it between tiles.
static CANCEL: AtomicBool = AtomicBool::new(false);

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Id of the solved photo to render into.
    #[arg(long, value_name = "PHOTO_ID")]
    view: String,
    /// Output file: .exr (linear, with alpha and layers), .png, .jpg/.jpeg or .tif/.tiff (8-bit sRGB).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Fewest rays per pixel (multiple of 4, 4–64); default: the site's render.spp_min.
    #[arg(long, value_name = "N")]
    spp_min: Option<u32>,
    /// Most rays per pixel (multiple of 4, 4–64); default: the site's render.spp_max.
    #[arg(long, value_name = "N")]
    spp_max: Option<u32>,
    /// Seed of the sample positions; default: the site's render.seed.
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
    /// Trace Durisch's 9 spectral samples instead of RGB (also when the site's render.spectral
    /// is true); about 3× the time. Not combinable with --layers.
    #[arg(long)]
    spectral: bool,
    /// Extra EXR layers, comma-separated: depth, object_id, shadow_change.
    #[arg(long, value_name = "LIST", default_value = "")]
    layers: String,
    /// Exposure multiplier for 8-bit output (EXR stays linear); default: the site's
    /// render.exposure.
    #[arg(long, value_name = "X")]
    exposure: Option<f64>,
    /// Accurate Visual Representation level (LVMF): 0 silhouette, 1 wireline (hidden edges
    /// dashed), 2 massing in a neutral material under the site's light, 3 the full montage.
    #[arg(long, value_name = "LEVEL", default_value_t = 3)]
    avr: u8,
}

/// Writes a render: JPEG and PNG carry the view geometry as EXIF (camera position as GPS,
/// bearing, capture time, 35 mm equivalent, the report's key numbers); other formats as before.
fn write_image(
    path: &Path,
    doc: &SiteDocument,
    view: &str,
    image: &RenderedImage,
    layers: &output::OutputLayers,
    tone_map: &ToneMap,
) -> anyhow::Result<()> {
    let format = OutputFormat::from_path(path)?;
    if !matches!(format, OutputFormat::Jpeg | OutputFormat::Png) {
        output::write_output(path, image, layers, tone_map)?;
        return Ok(());
    }
    match view_geometry(doc, view, &ViewGeometryOptions::default()) {
        Ok(report) => {
            let [w, h] = image.size_px;
            let rgb = image::RgbImage::from_fn(w, h, |x, y| {
                let p = image.rgba[(y * w + x) as usize];
                image::Rgb(encode_srgb8([p[0], p[1], p[2]], tone_map))
            });
            write_8bit_with_exif(path, &rgb, exif_block(&report), output::JPEG_QUALITY)?;
        }
        Err(e) => {
            eprintln!("warning: no view geometry in the image's EXIF: {e}");
            output::write_output(path, image, layers, tone_map)?;
        }
    }
    Ok(())
}

/// AVR0/AVR1: the silhouette or wireline drawn over the photo, written like a render.
fn draw_overlay(
    args: &Args,
    doc: &SiteDocument,
    avr: AvrLevel,
    exposure: f64,
) -> anyhow::Result<()> {
    check_writable(&args.out)?;
    let overlay = avr_overlay(doc, &args.view, avr)?;
    let tone_map = ToneMap {
        exposure_stops: exposure.log2(),
        curve: ToneCurve::Clamp,
    };
    write_image(
        &args.out,
        doc,
        &args.view,
        &overlay.image,
        &output::OutputLayers::default(),
        &tone_map,
    )?;
    println!(
        "drew {} ({}) of view {} into {}: {} pixels",
        avr.name(),
        avr.description(),
        args.view,
        args.out.display(),
        overlay.image.changed_pixels
    );
    Ok(())
}

fn check_spp(name: &str, n: u32) -> anyhow::Result<u32> {
    if !(4..=64).contains(&n) || !n.is_multiple_of(4) {
        bail!("--{name} {n}: rays per pixel must be a multiple of 4 between 4 and 64");
    }
    Ok(n)
}

/// Fails early (before the render) when `path` cannot be created or written.
fn check_writable(path: &Path) -> anyhow::Result<()> {
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .with_context(|| format!("cannot write the output file {}", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    // Cheap checks first, so a typo does not cost a render.
    let format = OutputFormat::from_path(&args.out)?;
    let layers = LayerSet::parse(&args.layers)?;
    if format != OutputFormat::Exr && !layers.is_empty() {
        bail!(
            "--layers {} need an .exr output, not {}",
            layers.names(),
            args.out.display()
        );
    }
    let doc = SiteDocument::load(&args.site)?;
    let spectral = args.spectral || doc.site.render.spectral;
    if spectral && !layers.is_empty() {
        bail!(
            "--layers {} are computed in RGB mode only; render without --spectral (and with \
             render.spectral = false) to get them",
            layers.names()
        );
    }
    let exposure = args.exposure.unwrap_or(doc.site.render.exposure);
    if !(exposure.is_finite() && exposure > 0.0) {
        bail!("exposure {exposure} must be a finite positive multiplier");
    }
    let avr = AvrLevel::from_number(args.avr)?;
    if matches!(avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
        if spectral || !layers.is_empty() {
            bail!(
                "--avr {} draws over the photo: no --spectral or --layers",
                args.avr
            );
        }
        return draw_overlay(args, &doc, avr, exposure);
    }
    let mut job = prepare_view(&doc, &args.view)?;
    if avr == AvrLevel::Avr2 {
        apply_massing(&mut job.scene.scene)?;
    }
    for w in &job.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(n) = args.spp_min {
        job.settings.min_rays_per_pixel = check_spp("spp-min", n)?;
    }
    if let Some(n) = args.spp_max {
        job.settings.max_rays_per_pixel = check_spp("spp-max", n)?;
    }
    if job.settings.min_rays_per_pixel > job.settings.max_rays_per_pixel {
        bail!(
            "spp-min {} is above spp-max {}",
            job.settings.min_rays_per_pixel,
            job.settings.max_rays_per_pixel
        );
    }
    if let Some(seed) = args.seed {
        job.settings.seed = seed;
    }
    check_writable(&args.out)?;

    let start = Instant::now();
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )?;
    let [w, h] = job.camera.intrinsics.image_size_px;
    let ts = job.settings.tile_size_px.max(1);
    let bar = ProgressBar::new(u64::from(w.div_ceil(ts) * h.div_ceil(ts)));
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} tiles {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    ctrlc::set_handler(|| CANCEL.store(true, Ordering::SeqCst))
        .context("installing the Ctrl-C handler")?;
    eprintln!("rendering {w}×{h} px (Ctrl-C cancels)");
    let cancel = &CANCEL;
    let render = || -> anyhow::Result<_> {
        let on_tile = |_| bar.inc(1);
        if spectral {
            let image = render_view_spectral(
                &tracer,
                &job.settings,
                SampleSet::Durisch9,
                &on_tile,
                cancel,
            )?;
            Ok((image, output::OutputLayers::default()))
        } else {
            Ok(render_view_with_layers(
                &tracer,
                &job.settings,
                layers,
                &on_tile,
                cancel,
            )?)
        }
    };
    let result = match args.threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t.max(1))
            .build()
            .context("building the thread pool")?
            .install(render),
        None => render(),
    };
    bar.finish_and_clear();
    if CANCEL.load(Ordering::SeqCst) {
        bail!(
            "cancelled (Ctrl-C): nothing written to {}",
            args.out.display()
        );
    }
    let (image, out_layers) = result?;
    let elapsed_s = start.elapsed().as_secs_f64();

    let tone_map = ToneMap {
        exposure_stops: exposure.log2(),
        curve: ToneCurve::Clamp,
    };
    write_image(&args.out, &doc, &args.view, &image, &out_layers, &tone_map)?;
    let table = if layers.object_id {
        let names: Vec<String> = job
            .scene
            .object_sources
            .iter()
            .map(photomontage::site::render::ObjectSource::label)
            .collect();
        Some(output::write_object_table(&args.out, &names)?)
    } else {
        None
    };

    let pixels = f64::from(w) * f64::from(h);
    #[allow(clippy::cast_precision_loss)]
    let (changed_pct, rays_per_pixel) = (
        100.0 * image.changed_pixels as f64 / pixels,
        image.primary_rays as f64 / pixels,
    );
    println!(
        "rendered view {} ({w}×{h} px, {}) into {}",
        args.view,
        if spectral { "spectral, 9 bands" } else { "RGB" },
        args.out.display()
    );
    println!(
        "  changed pixels {} ({changed_pct:.1} %), {rays_per_pixel:.2} rays/pixel, {elapsed_s:.2} s",
        image.changed_pixels
    );
    match job.sun_dir_in_world {
        Some(d) => println!(
            "  sun elevation {:.2}°, grid azimuth {:.2}°",
            d.z.asin().to_degrees(),
            d.x.atan2(d.y).to_degrees().rem_euclid(360.0)
        ),
        None => println!("  no direct sun"),
    }
    if let Some(t) = table {
        println!("  object ids: {}", t.display());
    }
    Ok(())
}
