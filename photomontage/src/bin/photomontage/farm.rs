//! Render-farm commands: `jobs` (the job list), `run-job` (one job or the merges, what every
//! scheduler runs), and `slurm`, `k8s`, `flamenco` (the job list plus that scheduler's files).

use anyhow::{Context, bail};
use photomontage::farm::flamenco;
use photomontage::farm::k8s::{self, K8sOptions};
use photomontage::farm::slurm::{self, SlurmOptions};
use photomontage::farm::{JobList, JobOptions, JobOutcome, JobRender, relative_path, resources};
use photomontage::site::SiteDocument;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// What to list: the site, its views, the band count and the shared render settings.
#[derive(clap::Args)]
pub struct ListArgs {
    /// The site file (TOML), solved.
    site: PathBuf,
    /// Views to render, comma-separated (default: every solved photo).
    #[arg(long, value_name = "V1,V2,…", value_delimiter = ',')]
    views: Vec<String>,
    /// Horizontal bands per view (at most the view's rows of render tiles).
    #[arg(long, value_name = "N", default_value_t = 1)]
    tiles: u32,
    /// Extension of the merged images: exr, png, jpg, tif.
    #[arg(long, value_name = "EXT", default_value = "exr")]
    image_format: String,
    /// Fewest rays per pixel (default: the site's).
    #[arg(long, value_name = "N")]
    spp_min: Option<u32>,
    /// Most rays per pixel (default: the site's).
    #[arg(long, value_name = "N")]
    spp_max: Option<u32>,
    /// Seed (default: the site's).
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// Spectral mode.
    #[arg(long)]
    spectral: bool,
    /// Extra EXR layers, comma-separated: depth, object_id, shadow_change.
    #[arg(long, value_name = "LIST", default_value = "")]
    layers: String,
    /// Exposure for 8-bit images (default: the site's).
    #[arg(long, value_name = "X")]
    exposure: Option<f64>,
}

impl ListArgs {
    /// Builds and writes the list as `list_path`; prints a summary.
    fn write_list(&self, list_path: &Path) -> anyhow::Result<JobList> {
        let doc = SiteDocument::load(&self.site)?;
        let options = JobOptions {
            views: self.views.clone(),
            tiles: self.tiles,
            render: JobRender {
                spp_min: self.spp_min,
                spp_max: self.spp_max,
                seed: self.seed,
                spectral: self.spectral,
                layers: self.layers.clone(),
                exposure: self.exposure,
            },
            image_format: self.image_format.clone(),
        };
        let list = JobList::build(&doc, &self.site, list_path, &options)?;
        list.write(list_path)?;
        println!(
            "{}: {} jobs ({} view(s) × {} tile(s)) and {} merge(s)",
            list_path.display(),
            list.jobs.len(),
            list.merges.len(),
            list.tiles,
            list.merges.len()
        );
        Ok(list)
    }
}

#[derive(clap::Args)]
pub struct JobsArgs {
    #[command(flatten)]
    list: ListArgs,
    /// The job list to write (JSON); parts go to `parts/` beside it.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

pub fn jobs(args: &JobsArgs) -> anyhow::Result<()> {
    args.list.write_list(&args.out).map(|_| ())
}

#[derive(clap::Args)]
pub struct RunJobArgs {
    /// The job list (JSON).
    list: PathBuf,
    /// Run job K (0-based, as a scheduler's array index).
    #[arg(
        long,
        value_name = "K",
        conflicts_with = "merge",
        required_unless_present = "merge"
    )]
    index: Option<usize>,
    /// Merge the parts of every view (or of --view) instead.
    #[arg(long)]
    merge: bool,
    /// With --merge: only this view.
    #[arg(long, value_name = "V", requires = "merge")]
    view: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
}

pub fn run_job(args: &RunJobArgs) -> anyhow::Result<()> {
    if args.merge {
        let written = photomontage::farm::jobs::run_merges(&args.list, args.view.as_deref())?;
        for path in written {
            println!("merged {}", path.display());
        }
        return Ok(());
    }
    let Some(index) = args.index else {
        bail!("give --index K or --merge");
    };
    let cancel = super::render::install_cancel()?;
    let start = std::time::Instant::now();
    let bar = super::render::tile_bar(0);
    let outcome = super::render::with_threads(args.threads, || {
        Ok(photomontage::farm::jobs::run_job(
            &args.list,
            index,
            &|t| {
                bar.set_length(t.tile_count as u64);
                bar.inc(1);
            },
            cancel,
        )?)
    });
    bar.finish_and_clear();
    if cancel.load(Ordering::SeqCst) {
        bail!("cancelled (Ctrl-C): job {index} wrote nothing");
    }
    match outcome? {
        JobOutcome::Rendered {
            output,
            changed_pixels,
        } => println!(
            "job {index}: rendered {} in {:.2} s ({changed_pixels} changed pixels)",
            output.display(),
            start.elapsed().as_secs_f64()
        ),
        JobOutcome::AlreadyDone { output } => {
            println!(
                "job {index}: {} is already complete; skipped",
                output.display()
            );
        }
    }
    Ok(())
}

/// The absolute path of `path` (made absolute from the current folder).
fn absolute(path: &Path) -> anyhow::Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("resolving {}", path.display()))
}

fn utf8(path: &Path) -> anyhow::Result<String> {
    path.to_str()
        .map(str::to_owned)
        .with_context(|| format!("{} is not valid UTF-8", path.display()))
}

/// The executable for the scripts: `--exe` or this program's own path.
fn executable(exe: Option<&PathBuf>) -> anyhow::Result<String> {
    match exe {
        Some(p) => utf8(p),
        None => utf8(&std::env::current_exe().context("finding this program's path")?),
    }
}

#[derive(clap::Args)]
pub struct SlurmArgs {
    #[command(flatten)]
    list: ListArgs,
    /// The job folder to write (job list, sbatch scripts, submit.sh, logs/, parts/).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Most array tasks at once (sbatch --array=…%K).
    #[arg(long, value_name = "K")]
    throttle: Option<u32>,
    /// CPUs (threads) per task.
    #[arg(long, value_name = "C", default_value_t = 1)]
    cpus_per_task: u32,
    /// Memory per task, MiB (default: estimated from the image size).
    #[arg(long, value_name = "MIB")]
    mem_mib: Option<u64>,
    /// Slurm partition.
    #[arg(long)]
    partition: Option<String>,
    /// Time limit per task (HH:MM:SS).
    #[arg(long, value_name = "T")]
    time: Option<String>,
    /// The photomontage executable as the nodes see it (default: this program).
    #[arg(long, value_name = "PATH")]
    exe: Option<PathBuf>,
}

pub fn slurm(args: &SlurmArgs) -> anyhow::Result<()> {
    if args.throttle == Some(0) {
        bail!("--throttle must be at least 1");
    }
    let dir = absolute(&args.out)?;
    let list_path = dir.join("jobs.json");
    let list = args.list.write_list(&list_path)?;
    let options = SlurmOptions {
        executable: executable(args.exe.as_ref())?,
        throttle: args.throttle,
        resources: resources(&list, args.cpus_per_task, args.mem_mib),
        partition: args.partition.clone(),
        time_limit: args.time.clone(),
        job_dir: utf8(&dir)?,
    };
    std::fs::create_dir_all(dir.join("logs"))
        .with_context(|| format!("creating {}", dir.join("logs").display()))?;
    let files = slurm::scripts(&list, Path::new("jobs.json"), &options);
    for p in photomontage::farm::write_files(&dir, &files)? {
        println!("wrote {}", p.display());
    }
    println!(
        "submit with {}/submit.sh ({} CPU(s), {} MiB per task)",
        dir.display(),
        options.resources.cpus,
        options.resources.memory_mib
    );
    Ok(())
}

#[derive(clap::Args)]
pub struct K8sArgs {
    #[command(flatten)]
    list: ListArgs,
    /// The job folder to write (job list, manifests, submit.sh, parts/); must lie under
    /// --volume-root.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Container image with the photomontage binary on its PATH.
    #[arg(long)]
    image: String,
    /// PersistentVolumeClaim holding the site and the job folder.
    #[arg(long, value_name = "NAME")]
    claim: String,
    /// The local folder that is the volume's root (default: the current folder).
    #[arg(long, value_name = "DIR", default_value = ".")]
    volume_root: PathBuf,
    /// Pods at once.
    #[arg(long, value_name = "P", default_value_t = 4)]
    parallelism: u32,
    /// CPUs (threads) per pod.
    #[arg(long, value_name = "C", default_value_t = 1)]
    cpus_per_task: u32,
    /// Memory per pod, MiB (default: estimated from the image size).
    #[arg(long, value_name = "MIB")]
    mem_mib: Option<u64>,
    /// Retries of a failed index.
    #[arg(long, value_name = "N", default_value_t = 3)]
    retries: u32,
}

pub fn k8s(args: &K8sArgs) -> anyhow::Result<()> {
    let dir = absolute(&args.out)?;
    let root = absolute(&args.volume_root)?;
    let list_path = dir.join("jobs.json");
    let inside = relative_path(&list_path, &root);
    if inside.is_absolute() || inside.starts_with("..") {
        bail!(
            "the job folder {} is not under --volume-root {}: the pods could not see it",
            dir.display(),
            root.display()
        );
    }
    let site_inside = relative_path(&absolute(&args.list.site)?, &root);
    if site_inside.is_absolute() || site_inside.starts_with("..") {
        bail!(
            "the site {} is not under --volume-root {}: the pods could not see it",
            args.list.site.display(),
            root.display()
        );
    }
    let list = args.list.write_list(&list_path)?;
    let name = k8s::dns_label(&format!(
        "pm-{}-{}",
        dir.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        &list.site_sha256[..8]
    ));
    let options = K8sOptions {
        image: args.image.clone(),
        claim: args.claim.clone(),
        list_in_pod: format!("{}/{}", k8s::MOUNT_PATH, utf8(&inside)?),
        parallelism: args.parallelism,
        backoff_limit_per_index: args.retries,
        resources: resources(&list, args.cpus_per_task, args.mem_mib),
        name,
    };
    for p in photomontage::farm::write_files(&dir, &k8s::manifests(&list, &options))? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

#[derive(clap::Args)]
pub struct FlamencoArgs {
    #[command(flatten)]
    list: ListArgs,
    /// The job folder to write (job list, job-type script, submission body, parts/).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// The job list's path as the Workers see it (default: its path here).
    #[arg(long, value_name = "PATH")]
    list_on_workers: Option<String>,
    /// The photomontage executable on the Workers.
    #[arg(long, value_name = "PATH", default_value = "photomontage")]
    exe: String,
    /// Threads per render task.
    #[arg(long, value_name = "T", default_value_t = 1)]
    threads: u32,
}

pub fn flamenco(args: &FlamencoArgs) -> anyhow::Result<()> {
    let dir = absolute(&args.out)?;
    let list_path = dir.join("jobs.json");
    let list = args.list.write_list(&list_path)?;
    let on_workers = match &args.list_on_workers {
        Some(p) => p.clone(),
        None => utf8(&list_path)?,
    };
    let files = vec![
        (
            "photomontage_jobs.js".to_owned(),
            flamenco::JOB_TYPE_SCRIPT.to_owned(),
            false,
        ),
        (
            "flamenco-job.json".to_owned(),
            flamenco::submission(&list, &on_workers, &args.exe, args.threads),
            false,
        ),
    ];
    for p in photomontage::farm::write_files(&dir, &files)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}
