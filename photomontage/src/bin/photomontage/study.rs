//! `photomontage study SITE --view V --dates D1,D2 --times 09:00,12:00 --out DIR`: a sun and
//! shadow study (see [`photomontage::study`], run and written by
//! [`photomontage::study::series`]). Every daylight frame is rendered first, then all files are
//! written (a new DIR as a whole, else each file atomically): Ctrl-C or an error leaves nothing
//! in DIR.

use std::path::PathBuf;

use anyhow::{Context, bail};
use photomontage::site::SiteDocument;
use photomontage::study::series::{StudyEvent, StudyOptions, run_study};
use photomontage::study::{
    StudyError, StudyRequest, frame_plan, parse_dates, parse_times, plan_frames,
};

use crate::render::{install_cancel, tile_bar, with_threads};

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
    /// Write the shadow maps only, no montages (with --shadow-maps): the contact sheet then
    /// shows the maps.
    #[arg(long, requires = "shadow_maps")]
    no_montages: bool,
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
    // Planned here too (cheap: the SPA per frame) so that bad input is refused before the
    // Ctrl-C handler and the progress bar.
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

    // Render every frame before writing anything.
    let cancel = install_cancel()?;
    let bar = tile_bar(0);
    let options = StudyOptions {
        montages: !args.no_montages,
        shadow_maps: args.shadow_maps,
        cell_m: args.cell_m,
    };
    let on_event = |event: StudyEvent<'_>| match event {
        StudyEvent::Planned {
            frames,
            daylight,
            tiles_total,
        } => {
            bar.set_length(tiles_total);
            let size = frames
                .iter()
                .find(|f| f.is_daylight())
                .and_then(|f| frame_plan(&f.document(&doc), &request).ok())
                .map_or_else(String::new, |p| {
                    format!(" of {}×{} px", p.full_size_px[0], p.full_size_px[1])
                });
            bar.suspend(|| eprintln!("rendering {daylight} frames{size} (Ctrl-C cancels)"));
        }
        StudyEvent::Tile(_) => bar.inc(1),
        StudyEvent::FrameStarted { .. } | StudyEvent::FrameDone { .. } => {}
    };
    let result = with_threads(args.threads, || {
        Ok(run_study(&doc, &request, options, &on_event, cancel))
    })?;
    bar.finish_and_clear();
    let result = match result {
        Err(StudyError::Cancelled) => bail!(
            "cancelled (Ctrl-C): nothing written to {}",
            args.out.display()
        ),
        other => other?,
    };
    for out in &result.outputs {
        for warning in &out.warnings {
            eprintln!("warning: {} {warning}", out.frame.stem(&args.view));
        }
    }
    let written = result
        .write(&args.out, args.exr)
        .with_context(|| format!("writing the study to {}", args.out.display()))?;
    if args.json {
        println!("{}", written.to_json());
    } else {
        for w in &written.frames {
            if let Some(png) = &w.file {
                println!(
                    "{}  sun azimuth {:.2}°, elevation {:.2}°  {}",
                    w.frame.time_rfc3339(),
                    w.frame.sun_azimuth_deg,
                    w.frame.sun_elevation_deg,
                    png.display()
                );
            }
        }
        println!("contact sheet {}", written.contact_sheet.display());
    }
    Ok(())
}
