//! `photomontage compare SITE --view V --out sheet.pdf [--png sheet.png] [--images DIR]
//! [--variants A,B]`: every design variant (default: all, in file order) of one view rendered
//! with the site's lighting, seed and settings, and a labelled comparison sheet
//! ([`photomontage::verified::comparison_sheet`]: one PDF page per variant, one PNG grid).
//! Every variant is checked before the first render and rendered before the first file is
//! written, each file atomically: an error or Ctrl-C leaves nothing.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use anyhow::{Context, bail};
use photomontage::site::SiteDocument;
use photomontage::site::render_photo::RenderRequest;
use photomontage::site::variant_renders::plan_variants;
use photomontage::site::variants::checked_variant_names;
use photomontage::verified::comparison_sheet::{
    ComparisonCell, comparison_pdf, comparison_subtitle, write_comparison_png,
};
use photomontage::verified::image_metadata::write_render;
use photomontage::verified::sheet::write_sheet;

use crate::render::{check_writable, install_cancel, tile_bar, view_of, with_threads};

#[derive(clap::Args)]
pub struct Args {
    /// The site file (TOML).
    site: PathBuf,
    /// Id of the solved photo to render into.
    #[arg(long, value_name = "PHOTO_ID")]
    view: String,
    /// The comparison sheet (PDF): one A3 landscape page per variant, titled with its name.
    #[arg(long, value_name = "FILE.pdf")]
    out: PathBuf,
    /// Also the sheet as one PNG: a labelled grid of all variants.
    #[arg(long, value_name = "FILE.png")]
    png: Option<PathBuf>,
    /// Also every variant's render as <view>_<variant>.png in this folder (created if
    /// missing), byte for byte what `render --variant` writes.
    #[arg(long, value_name = "DIR")]
    images: Option<PathBuf>,
    /// Variants to compare, comma-separated, in sheet order; default: all of the site's.
    #[arg(long, value_name = "LIST")]
    variants: Option<String>,
    /// Fewest rays per pixel; default: the site's render.spp_min.
    #[arg(long, value_name = "N")]
    spp_min: Option<u32>,
    /// Most rays per pixel; default: the site's render.spp_max.
    #[arg(long, value_name = "N")]
    spp_max: Option<u32>,
    /// Seed of the sample positions (the same for every variant); default: the site's
    /// render.seed.
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// Exposure multiplier for 8-bit output; default: the site's render.exposure.
    #[arg(long, value_name = "X")]
    exposure: Option<f64>,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
}

/// A variant name as a file-name part: ASCII letters, digits, `-`, `_` and `.` kept, the rest `_`.
pub fn file_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if !has_extension(&args.out, "pdf") {
        bail!("--out {} must be a .pdf file", args.out.display());
    }
    if let Some(png) = &args.png
        && !has_extension(png, "png")
    {
        bail!("--png {} must be a .png file", png.display());
    }
    if let Some(dir) = &args.images
        && dir.exists()
        && !dir.is_dir()
    {
        bail!("--images {} exists and is not a folder", dir.display());
    }
    let doc = SiteDocument::load(&args.site)?;
    let requested: Option<Vec<String>> = args.variants.as_ref().map(|list| {
        list.split(',')
            .map(|s| s.trim().to_owned())
            .filter(|s| !s.is_empty())
            .collect()
    });
    let names = checked_variant_names(&doc.site, requested.as_deref())?;
    let request = RenderRequest {
        spp_min: args.spp_min,
        spp_max: args.spp_max,
        seed: args.seed,
        exposure: args.exposure,
        ..RenderRequest::view(&args.view)
    };
    let jobs = plan_variants(&doc, Some(&names), &request)?;
    if let Some(files) = names
        .iter()
        .map(|n| file_part(n))
        .enumerate()
        .find(|(i, f)| names[..*i].iter().any(|n| file_part(n) == *f))
    {
        bail!(
            "variants `{}` and another variant have the same file name {}; rename one",
            names[files.0],
            files.1
        );
    }
    check_writable(&args.out)?;
    if let Some(png) = &args.png {
        check_writable(png)?;
    }

    let cancel = install_cancel()?;
    let [w, h] = jobs[0].plan.full_size_px;
    let bar = tile_bar(jobs.iter().map(|j| j.plan.tile_count()).sum());
    eprintln!(
        "rendering {} variants of view {} at {w}×{h} px (Ctrl-C cancels)",
        jobs.len(),
        args.view
    );
    let mut rendered = Vec::with_capacity(jobs.len());
    for job in &jobs {
        let result = with_threads(args.threads, || Ok(job.render(&|_| bar.inc(1), cancel)?));
        if cancel.load(Ordering::SeqCst) {
            bar.finish_and_clear();
            bail!(
                "cancelled (Ctrl-C): nothing written to {}",
                args.out.display()
            );
        }
        let variant = result?;
        for warning in &variant.photo.warnings {
            eprintln!("warning: variant {}: {warning}", job.name);
        }
        rendered.push(variant);
    }
    bar.finish_and_clear();

    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create --images {}", dir.display()))?;
        for (job, variant) in jobs.iter().zip(&rendered) {
            let path = dir.join(format!(
                "{}_{}.png",
                file_part(&args.view),
                file_part(&job.name)
            ));
            write_render(
                &path,
                &variant.photo.image,
                &variant.photo.layers,
                &job.plan.tone_map(),
                view_of(&job.document, &args.view).as_ref(),
            )?;
            println!("variant {}: {}", job.name, path.display());
        }
    }
    let cells: Vec<ComparisonCell<'_>> = rendered
        .iter()
        .map(|v| ComparisonCell {
            name: v.name.clone(),
            image: &v.srgb,
        })
        .collect();
    let subtitle = comparison_subtitle(&doc.site.name, &args.view, &jobs[0].plan.settings);
    if let Some(png) = &args.png {
        write_comparison_png(png, &cells)?;
        println!("comparison sheet {}", png.display());
    }
    write_sheet(&args.out, &comparison_pdf(&cells, &subtitle)?)?;
    println!(
        "comparison sheet {} ({} pages: {})",
        args.out.display(),
        names.len(),
        names.join(", ")
    );
    Ok(())
}
