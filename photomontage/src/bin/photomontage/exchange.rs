//! `photomontage export-cameras` and `photomontage import-cameras`: solved cameras out to
//! Blender, COLMAP and OpenCV; COLMAP and OpenSfM cameras in as initial values.

use anyhow::{Context, bail};
use photomontage::exchange::colmap::{ColmapModel, read_colmap, write_colmap};
use photomontage::exchange::import::apply_imported;
use photomontage::exchange::opensfm::read_opensfm;
use photomontage::exchange::{ExportSet, blender, opencv_yaml};
use photomontage::site::SiteDocument;
use std::path::PathBuf;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ExportFormat {
    /// A Python script creating one camera per photo with the photo as background.
    Blender,
    /// COLMAP text model: cameras.txt, images.txt, points3D.txt (+ point_names.txt).
    Colmap,
    /// One OpenCV FileStorage YAML per photo: camera_matrix, distortion_coefficients, rvec/tvec, R.
    Opencv,
}

#[derive(clap::Args)]
pub struct ExportArgs {
    /// The site file (its solved photos are exported).
    site: PathBuf,
    #[arg(long, value_enum)]
    format: ExportFormat,
    /// Folder to write into (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// COLMAP camera model: auto (the smallest that carries each photo's distortion),
    /// SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV.
    #[arg(long, default_value = "auto")]
    colmap_model: String,
    /// Print the written files as JSON.
    #[arg(long)]
    json: bool,
}

pub fn export(args: &ExportArgs) -> anyhow::Result<()> {
    let doc = SiteDocument::load(&args.site)?;
    let set =
        ExportSet::from_site(&doc).with_context(|| format!("exporting {}", args.site.display()))?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let files = match args.format {
        ExportFormat::Blender => blender::write_blender(&set, &args.out)?,
        ExportFormat::Colmap => {
            let Some(model) = ColmapModel::from_name(&args.colmap_model) else {
                bail!(
                    "--colmap-model `{}` is not auto, SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV",
                    args.colmap_model
                );
            };
            write_colmap(&set, model, &args.out)?
        }
        ExportFormat::Opencv => opencv_yaml::write_opencv(&set, &args.out)?,
    };
    let unsolved: Vec<&str> = doc
        .site
        .photos
        .iter()
        .filter(|p| !set.cameras.iter().any(|c| c.id == p.id))
        .map(|p| p.id.as_str())
        .collect();
    if args.json {
        let out = serde_json::json!({
            "files": files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
            "photos": set.cameras.iter().map(|c| c.id.as_str()).collect::<Vec<_>>(),
            "unsolved_photos": unsolved,
            "points": set.points.len(),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "exported {} photo camera(s) and {} point(s):",
            set.cameras.len(),
            set.points.len()
        );
        for f in &files {
            println!("  {}", f.display());
        }
        if !unsolved.is_empty() {
            println!("not solved, left out: {}", unsolved.join(", "));
        }
    }
    Ok(())
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ImportFormat {
    /// A COLMAP text model (the folder, or its cameras.txt/images.txt).
    Colmap,
    /// An OpenSfM reconstruction.json.
    Opensfm,
}

#[derive(clap::Args)]
pub struct ImportArgs {
    /// The site file to update (saved in place, comments kept).
    site: PathBuf,
    #[arg(long, value_enum)]
    format: ImportFormat,
    /// The reconstruction to read.
    file: PathBuf,
    /// Also write the poses as the photos' exterior orientation (only when the reconstruction
    /// is in the site's world frame, e.g. COLMAP after model_aligner).
    #[arg(long)]
    with_poses: bool,
    /// Print what was imported as JSON.
    #[arg(long)]
    json: bool,
}

pub fn import(args: &ImportArgs) -> anyhow::Result<()> {
    let mut doc = SiteDocument::load(&args.site)?;
    let (cameras, name) = match args.format {
        ImportFormat::Colmap => (read_colmap(&args.file)?, "colmap"),
        ImportFormat::Opensfm => (read_opensfm(&args.file)?, "opensfm"),
    };
    let report =
        apply_imported(&mut doc.site, &cameras, name, args.with_poses).with_context(|| {
            format!(
                "importing {} into {}",
                args.file.display(),
                args.site.display()
            )
        })?;
    if report.matched.is_empty() {
        bail!(
            "no image of {} matches a photo of {} (images: {}); the site is unchanged",
            args.file.display(),
            args.site.display(),
            report.unmatched_images.join(", ")
        );
    }
    let template = std::fs::read_to_string(&args.site).ok();
    doc.site
        .save_over(&args.site, template.as_deref())
        .with_context(|| format!("saving {}", args.site.display()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        for (photo, image) in &report.matched {
            println!(
                "photo {photo}: interior{} from {image}",
                if args.with_poses { " and pose" } else { "" }
            );
        }
        if !report.unmatched_images.is_empty() {
            println!(
                "images matching no photo: {}",
                report.unmatched_images.join(", ")
            );
        }
        if !report.exteriors_cleared.is_empty() {
            println!(
                "solved poses removed (they belong to the old interior; solve again): {}",
                report.exteriors_cleared.join(", ")
            );
        }
        if !report.photos_without_camera.is_empty() {
            println!(
                "photos left unchanged: {}",
                report.photos_without_camera.join(", ")
            );
        }
    }
    Ok(())
}
