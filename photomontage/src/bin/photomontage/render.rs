//! `photomontage render SITE --view PHOTO --out FILE`: render the site's visible models into one
//! solved photo with the differential ray tracer and write EXR or 8-bit sRGB. Ctrl-C cancels
//! the render between tiles; nothing is written then and the exit status is non-zero.
//! `--variant NAME` renders a design variant (`photomontage::site::variants`).

use anyhow::{Context, bail};
use indicatif::{HumanDuration, ProgressBar, ProgressState, ProgressStyle};
use photomontage::colour::ToneMap;
use photomontage::render::Band;
use photomontage::render::output::{self, LayerSet, OutputFormat};
use photomontage::render::partial::write_part;
use photomontage::site::SiteDocument;
use photomontage::site::render_photo::{RenderPlan, RenderRequest};
use photomontage::site::variants::variant_document;
use photomontage::verified::ViewMetadata;
use photomontage::verified::image_metadata::{view_metadata, write_render};
use photomontage::verified::{AvrLevel, apply_massing, avr_overlay};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

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
    /// Radiosity lighting mode: sky and interreflected light from radiosity solutions of the
    /// site with and without the planned objects (also when the site's render.radiosity is true).
    #[arg(long)]
    radiosity: bool,
    /// Extra EXR layers, comma-separated: depth, object_id, shadow_change.
    #[arg(long, value_name = "LIST", default_value = "")]
    layers: String,
    /// Exposure multiplier for 8-bit output (EXR stays linear); default: the site's
    /// render.exposure.
    #[arg(long, value_name = "X")]
    exposure: Option<f64>,
    /// Render only horizontal band I of N (1-based, whole rows of render tiles) into a partial
    /// EXR for `photomontage merge`; the band's pixels are bit for bit those of the whole render.
    #[arg(long, value_name = "I/N")]
    tile: Option<String>,
    /// Accurate Visual Representation level (LVMF): 0 silhouette, 1 wireline (hidden edges
    /// dashed), 2 massing in a neutral material under the site's light, 3 the full montage.
    #[arg(long, value_name = "LEVEL", default_value_t = 3)]
    avr: u8,
    /// Render the site as design variant NAME (`[[variants]]`) sees it: its visible models,
    /// placements and materials, with the site's lighting, seed and settings.
    #[arg(long, value_name = "NAME")]
    variant: Option<String>,
}

/// The view geometry the output carries (EXIF and XMP, EXR attributes); a warning (and none)
/// when it cannot be had.
pub fn view_of(doc: &SiteDocument, view: &str) -> Option<ViewMetadata> {
    match view_metadata(doc, view) {
        Ok(m) => Some(m),
        Err(e) => {
            eprintln!("warning: no view geometry in the image's metadata: {e}");
            None
        }
    }
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
    let tone_map = ToneMap::clamp_with_exposure(exposure);
    write_render(
        &args.out,
        &overlay.image,
        &output::OutputLayers::default(),
        &tone_map,
        view_of(doc, &args.view).as_ref(),
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

/// Fails early (before the render) when `path` cannot be created or written.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
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

/// A progress bar over `tiles` render tiles with a time estimate: elapsed × remaining / done
/// ([`time_left`]). Tiles start in a fixed shuffled order, so the finished ones are a fair sample
/// of the image's cost; indicatif's own `{eta}` follows the recent rate instead, which swings
/// between the cheap sky tiles and the costly building ones.
pub fn tile_bar(tiles: u64) -> ProgressBar {
    let bar = ProgressBar::new(tiles);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} tiles {elapsed} (left {left})")
            .map(|style| {
                style.with_key(
                    "left",
                    |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let left = time_left(state.elapsed(), state.pos(), state.len());
                        let _ = match left {
                            Some(d) => write!(w, "{}", HumanDuration(d)),
                            None => write!(w, "…"),
                        };
                    },
                )
            })
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Time left of a job `done` of whose `total` units took `elapsed`, at the mean cost per unit so
/// far: elapsed × (total − done) / done; `None` before the first unit or without a total.
#[must_use]
pub fn time_left(elapsed: Duration, done: u64, total: Option<u64>) -> Option<Duration> {
    let total = total?;
    if done == 0 {
        return None;
    }
    #[allow(clippy::cast_precision_loss)]
    let per_unit = elapsed.as_secs_f64() / done as f64;
    #[allow(clippy::cast_precision_loss)]
    Some(Duration::from_secs_f64(
        per_unit * total.saturating_sub(done) as f64,
    ))
}

/// Runs `work` on `threads` worker threads (all cores for `None`).
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
) -> anyhow::Result<T> {
    match threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t.max(1))
            .build()
            .context("building the thread pool")?
            .install(work),
        None => work(),
    }
}

/// Installs the Ctrl-C handler that raises [`CANCEL`].
pub fn install_cancel() -> anyhow::Result<&'static AtomicBool> {
    ctrlc::set_handler(|| CANCEL.store(true, Ordering::SeqCst))
        .context("installing the Ctrl-C handler")?;
    Ok(&CANCEL)
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
    let band = match &args.tile {
        Some(text) => {
            let band = Band::parse(text)?;
            if format != OutputFormat::Exr {
                bail!(
                    "--tile {band} writes a partial EXR for `photomontage merge`; name an .exr \
                     output, not {}",
                    args.out.display()
                );
            }
            Some(band)
        }
        None => None,
    };
    let doc = variant_document(&SiteDocument::load(&args.site)?, args.variant.as_deref())?;
    let request = RenderRequest {
        view: args.view.clone(),
        spp_min: args.spp_min,
        spp_max: args.spp_max,
        seed: args.seed,
        spectral: args.spectral,
        radiosity: args.radiosity,
        layers,
        exposure: args.exposure,
        band: band.unwrap_or(Band::WHOLE),
    };
    let mut plan = RenderPlan::new(&doc, &request)?;
    if let Some(name) = &args.variant {
        // Parts of two variants must not merge.
        plan.identity.insert("variant".into(), name.clone());
    }
    let avr = AvrLevel::from_number(args.avr)?;
    if matches!(avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
        if plan.spectral || !layers.is_empty() || band.is_some() {
            bail!(
                "--avr {} draws over the photo: no --spectral, --layers or --tile",
                args.avr
            );
        }
        return draw_overlay(args, &doc, avr, plan.exposure);
    }
    if avr == AvrLevel::Avr2 {
        // Parts of a massing render must not merge with parts of the montage.
        plan.identity.insert("avr".into(), avr.name().into());
    }
    check_writable(&args.out)?;

    let start = Instant::now();
    let [w, h] = plan.full_size_px;
    let bar = tile_bar(plan.tile_count());
    let cancel = install_cancel()?;
    match band {
        Some(b) => eprintln!(
            "rendering tile {b}: rows {}..{} of {w}×{h} px (Ctrl-C cancels)",
            plan.rows_px[0], plan.rows_px[1]
        ),
        None => eprintln!("rendering {w}×{h} px (Ctrl-C cancels)"),
    }
    let massing = |scene: &mut photomontage::scene::Scene| {
        if avr == AvrLevel::Avr2 {
            apply_massing(scene)?;
        }
        Ok(())
    };
    let result = with_threads(args.threads, || {
        Ok(plan.render_edited(&doc, &massing, &|_| bar.inc(1), cancel)?)
    });
    bar.finish_and_clear();
    if CANCEL.load(Ordering::SeqCst) {
        bail!(
            "cancelled (Ctrl-C): nothing written to {}",
            args.out.display()
        );
    }
    let rendered = result?;
    for warning in &rendered.warnings {
        eprintln!("warning: {warning}");
    }
    let elapsed_s = start.elapsed().as_secs_f64();
    let image = &rendered.image;
    let view = view_of(&doc, &args.view);
    let table = if band.is_some() {
        let mut info = plan.part_info(&rendered);
        info.view_json = view.as_ref().map(ViewMetadata::to_ascii_json);
        write_part(&args.out, image, &rendered.layers, &info)?;
        None
    } else {
        write_render(
            &args.out,
            image,
            &rendered.layers,
            &plan.tone_map(),
            view.as_ref(),
        )?;
        if layers.object_id {
            Some(output::write_object_table(
                &args.out,
                &rendered.object_names,
            )?)
        } else {
            None
        }
    };

    let pixels = f64::from(w) * f64::from(plan.rows_px[1] - plan.rows_px[0]);
    #[allow(clippy::cast_precision_loss)]
    let (changed_pct, rays_per_pixel) = (
        100.0 * image.changed_pixels as f64 / pixels,
        image.primary_rays as f64 / pixels,
    );
    let mut what = match band {
        Some(b) => format!("tile {b} of view"),
        None => "view".to_owned(),
    };
    if let Some(name) = &args.variant {
        what = format!("variant {name}, {what}");
    }
    println!(
        "rendered {what} {} ({w}×{h} px, {}) into {}",
        args.view,
        if plan.spectral {
            "spectral, 9 bands"
        } else {
            "RGB"
        },
        args.out.display()
    );
    println!(
        "  changed pixels {} ({changed_pct:.1} %), {rays_per_pixel:.2} rays/pixel, {elapsed_s:.2} s",
        image.changed_pixels
    );
    if let Some(r) = &rendered.radiosity {
        println!(
            "  radiosity precompute {:.2} s (included above): {} / {} elements with / without the \
             planned objects, {:.2} m element edge",
            r.seconds, r.elements[0], r.elements[1], r.element_edge_m
        );
        if let Some(p) = &r.photo_reflectance {
            println!(
                "  reflectance from the photos on {} of {} natural elements ({} of them from the \
                 site's other photos; {} clamped to 1; last refit moved them by {:.2} % on \
                 average), the others from the material library",
                p.from_photo,
                p.elements,
                p.from_other_photos,
                p.clamped,
                100.0 * p.mean_change_rel
            );
        }
        for note in &r.notes {
            println!("  radiosity note: {note}");
        }
    }
    match rendered.sun_dir_in_world {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_left_is_the_mean_cost_so_far_times_what_remains() {
        let ten_s = Duration::from_secs(10);
        // 10 s for 25 of 100 tiles: 0.4 s each, 75 left.
        let left = time_left(ten_s, 25, Some(100)).expect("an estimate");
        assert!((left.as_secs_f64() - 30.0).abs() < 1e-9, "{left:?}");
        assert_eq!(time_left(ten_s, 100, Some(100)), Some(Duration::ZERO));
        // Nothing done yet, or no total: no estimate.
        assert_eq!(time_left(ten_s, 0, Some(100)), None);
        assert_eq!(time_left(ten_s, 5, None), None);
    }
}
