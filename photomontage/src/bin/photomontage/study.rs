//! `photomontage study SITE --view V --dates D1,D2 --times 09:00,12:00 --out DIR`: a sun and
//! shadow study (see [`photomontage::study`]). Every daylight frame is rendered first, then all
//! files are written (each atomically): Ctrl-C or an error leaves nothing in DIR.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use anyhow::{Context, bail};
use photomontage::colour::encode_srgb8;
use photomontage::render::output::OutputLayers;
use photomontage::site::SiteDocument;
use photomontage::study::contact_sheet::{SheetCell, contact_sheet};
use photomontage::study::shadow_map::shadow_map_image;
use photomontage::study::{
    StudyRequest, frame_shadow_map, parse_dates, parse_times, plan_frames, render_frame,
};
use photomontage::verified::image_metadata::write_render;

use crate::render::{install_cancel, tile_bar, view_of, with_threads};

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Id of the solved photo to render into.
    #[arg(long, value_name = "PHOTO_ID")]
    view: String,
    /// Dates, comma-separated (YYYY-MM-DD).
    #[arg(long, value_name = "LIST")]
    dates: String,
    /// Local clock times, comma-separated (HH:MM), in the site's location.time_zone; a time may
    /// carry its own UTC offset (09:00+01:00).
    #[arg(long, value_name = "LIST")]
    times: String,
    /// Output folder (created if missing): <view>_<date>_<HHMM>.png per frame and
    /// <view>_contact_sheet.png.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Also write each frame as linear EXR.
    #[arg(long)]
    exr: bool,
    /// Also write a plan-view shadow map per frame (<view>_<date>_<HHMM>_shadow.png): lit,
    /// existing shadow, shadow added by the proposal, proposal roof.
    #[arg(long)]
    shadow_maps: bool,
    /// Cell edge of the shadow maps, metres.
    #[arg(long, value_name = "M", default_value_t = photomontage::study::shadow_map::DEFAULT_CELL_M)]
    cell_m: f64,
    /// Print the frames as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Fewest rays per pixel; default: the site's render.spp_min.
    #[arg(long, value_name = "N")]
    spp_min: Option<u32>,
    /// Most rays per pixel; default: the site's render.spp_max.
    #[arg(long, value_name = "N")]
    spp_max: Option<u32>,
    /// Seed of the sample positions (the same for every frame); default: the site's render.seed.
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Writes `img` as PNG through a temporary file and a rename.
fn write_png(path: &Path, img: &image::RgbImage) -> anyhow::Result<()> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .with_context(|| format!("encoding {}", path.display()))?;
    photomontage::site::write_atomically(path, &bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let request = StudyRequest {
        view: args.view.clone(),
        dates: parse_dates(&args.dates)?,
        times: parse_times(&args.times)?,
        spp_min: args.spp_min,
        spp_max: args.spp_max,
        seed: args.seed,
    };
    if !(args.cell_m.is_finite() && args.cell_m > 0.0) {
        bail!(
            "--cell-m {} must be a positive number of metres",
            args.cell_m
        );
    }
    let doc = SiteDocument::load(&args.site)?;
    let frames = plan_frames(&doc, &request)?;
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {} exists and is not a folder", args.out.display());
    }
    for f in frames.iter().filter(|f| !f.is_daylight()) {
        eprintln!(
            "note: skipping {} ({}): the sun is {:.1}° below the horizon",
            f.stem(&args.view),
            f.time_rfc3339(),
            -f.sun_elevation_deg
        );
    }
    let daylight: Vec<_> = frames.iter().filter(|f| f.is_daylight()).collect();

    // Render every frame before writing anything.
    let cancel = install_cancel()?;
    let first = photomontage::study::frame_plan(&daylight[0].document(&doc), &request)?;
    let [w, h] = first.full_size_px;
    let bar = tile_bar(first.tile_count() * daylight.len() as u64);
    eprintln!(
        "rendering {} frames of {w}×{h} px (Ctrl-C cancels)",
        daylight.len()
    );
    let mut rendered = Vec::with_capacity(daylight.len());
    for frame in &daylight {
        let result = with_threads(args.threads, || {
            Ok(render_frame(
                &doc,
                frame,
                &request,
                &|_| bar.inc(1),
                cancel,
            )?)
        });
        if cancel.load(Ordering::SeqCst) {
            bar.finish_and_clear();
            bail!(
                "cancelled (Ctrl-C): nothing written to {}",
                args.out.display()
            );
        }
        let (plan, photo) = result?;
        for warning in &photo.warnings {
            eprintln!("warning: {} {warning}", frame.stem(&args.view));
        }
        let map = if args.shadow_maps {
            let map = frame_shadow_map(&doc, frame, &args.view, args.cell_m)?;
            Some(shadow_map_image(&map, &frame.label()))
        } else {
            None
        };
        rendered.push((frame, plan, photo, map));
    }
    bar.finish_and_clear();

    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create --out {}", args.out.display()))?;
    let mut json_frames = Vec::new();
    let mut thumbs = Vec::new();
    for (frame, plan, photo, map) in &rendered {
        let stem = frame.stem(&args.view);
        let png = args.out.join(format!("{stem}.png"));
        let tone_map = plan.tone_map();
        // The frame's own view geometry: its sun angles are those of the frame's time.
        let view = view_of(&frame.document(&doc), &args.view);
        write_render(
            &png,
            &photo.image,
            &OutputLayers::default(),
            &tone_map,
            view.as_ref(),
        )?;
        if args.exr {
            let exr = args.out.join(format!("{stem}.exr"));
            write_render(&exr, &photo.image, &photo.layers, &tone_map, view.as_ref())?;
        }
        let [fw, fh] = photo.image.size_px;
        thumbs.push(image::RgbImage::from_fn(fw, fh, |x, y| {
            let p = photo.image.rgba[(y * fw + x) as usize];
            image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone_map))
        }));
        let mut entry = serde_json::json!({
            "time": frame.time_rfc3339(),
            "sun_azimuth_deg": frame.sun_azimuth_deg,
            "sun_elevation_deg": frame.sun_elevation_deg,
            "file": file_name(&png),
        });
        if let Some(map) = map {
            let path = args.out.join(format!("{stem}_shadow.png"));
            write_png(&path, map)?;
            entry["shadow_map"] = file_name(&path).into();
        }
        json_frames.push(entry);
        if !args.json {
            println!(
                "{}  sun azimuth {:.2}°, elevation {:.2}°  {}",
                frame.time_rfc3339(),
                frame.sun_azimuth_deg,
                frame.sun_elevation_deg,
                png.display()
            );
        }
    }
    let mut thumb_iter = thumbs.iter();
    let cells: Vec<SheetCell<'_>> = frames
        .iter()
        .map(|f| SheetCell {
            image: if f.is_daylight() {
                thumb_iter.next()
            } else {
                None
            },
            label: if f.is_daylight() {
                f.label()
            } else {
                format!("{} {} night", f.date, f.clock.format("%H:%M"))
            },
        })
        .collect();
    let sheet = contact_sheet(&cells, request.times.len());
    let sheet_path = args.out.join(format!("{}_contact_sheet.png", args.view));
    write_png(&sheet_path, &sheet)?;
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "frames": json_frames,
                "contact_sheet": file_name(&sheet_path),
            })
        );
    } else {
        println!("contact sheet {}", sheet_path.display());
    }
    Ok(())
}
