//! Slurm job arrays (Slurm `sbatch` manual: `--array=0-N%K`, `--requeue`, `--dependency`): one
//! array task per job of the [`JobList`], throttled to `K` at once, and a merge job that starts
//! when every task has succeeded.
//!
//! Files written into the job folder: `render.sbatch` (the array), `merge.sbatch`, `submit.sh`
//! (submits both, the merge with `--dependency=afterok:ARRAY`) and `logs/`. Each task runs
//! `photomontage run-job jobs.json --index $SLURM_ARRAY_TASK_ID`, which skips a part that is
//! already there, so a requeue only redoes what is missing. Tasks are submitted `--requeue`
//! (Slurm requeues them when their node fails), and a task whose render is killed by a signal
//! requeues itself (`scontrol requeue`, up to [`MAX_RESTARTS`] times): a failed task would
//! otherwise leave the merge's `afterok` dependency unsatisfiable for good.
//!
//! # Known limitations
//! Partition, account and time limit are passed through as given; nothing checks them against
//! the cluster. The memory request is an estimate ([`super::resources`]).

use std::path::Path;

use super::{JobList, Resources, shell_quote};

/// How often a task killed by a signal requeues itself before it is left failed.
pub const MAX_RESTARTS: u32 = 3;

/// Options of the generated scripts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlurmOptions {
    /// The `photomontage` executable as the nodes see it.
    pub executable: String,
    /// Most array tasks running at once (`%K`); `None`: no throttle.
    pub throttle: Option<u32>,
    /// CPUs and memory per task.
    pub resources: Resources,
    /// `--partition`, if any.
    pub partition: Option<String>,
    /// `--time` limit per task (`HH:MM:SS`), if any.
    pub time_limit: Option<String>,
    /// The job folder as the nodes see it (absolute).
    pub job_dir: String,
}

fn header(name: &str, options: &SlurmOptions, log: &str) -> String {
    let mut s = String::from("#!/bin/bash\n");
    s += &format!("#SBATCH --job-name={name}\n");
    s += &format!("#SBATCH --chdir={}\n", options.job_dir);
    s += &format!("#SBATCH --output=logs/{log}\n");
    s += &format!("#SBATCH --cpus-per-task={}\n", options.resources.cpus);
    s += &format!("#SBATCH --mem={}M\n", options.resources.memory_mib);
    if let Some(p) = &options.partition {
        s += &format!("#SBATCH --partition={p}\n");
    }
    if let Some(t) = &options.time_limit {
        s += &format!("#SBATCH --time={t}\n");
    }
    s
}

/// The files for `list`: `(name, contents, executable)`.
#[must_use]
pub fn scripts(
    list: &JobList,
    list_file: &Path,
    options: &SlurmOptions,
) -> Vec<(String, String, bool)> {
    let exe = shell_quote(&options.executable);
    let list_name = shell_quote(&list_file.to_string_lossy());
    let last = list.jobs.len().saturating_sub(1);
    let throttle = options
        .throttle
        .map(|k| format!("%{k}"))
        .unwrap_or_default();
    let mut render = header("photomontage-render", options, "render-%A_%a.out");
    render += &format!("#SBATCH --array=0-{last}{throttle}\n");
    render += "#SBATCH --requeue\n#SBATCH --open-mode=append\n";
    render += &format!(
        "# {} jobs: {} view(s) x {} tile(s) of {}; made by photomontage {}\n",
        list.jobs.len(),
        list.merges.len(),
        list.tiles,
        list.site,
        env!("CARGO_PKG_VERSION")
    );
    render += "set -uo pipefail\n";
    render += &format!(
        "status=0\n\
         {exe} run-job {list_name} --index \"$SLURM_ARRAY_TASK_ID\" --threads \"${{SLURM_CPUS_PER_TASK:-1}}\" || status=$?\n\
         # Killed by a signal (OOM killer, kill -9, a lost node's cleanup): requeue this task, up to\n\
         # {MAX_RESTARTS} times; a requeued task skips a part that is already complete. Errors\n\
         # (exit status 1: bad input) are not retried.\n\
         if [ \"$status\" -gt 128 ] && [ \"${{SLURM_RESTART_COUNT:-0}}\" -lt {MAX_RESTARTS} ]; then\n\
         \x20 echo \"run-job killed by signal $((status - 128)); requeueing (restart ${{SLURM_RESTART_COUNT:-0}})\" >&2\n\
         \x20 if scontrol requeue \"${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}\"; then exit 0; fi\n\
         fi\n\
         exit \"$status\"\n"
    );
    let mut merge = header("photomontage-merge", options, "merge-%j.out");
    merge += "set -euo pipefail\n";
    merge += &format!("exec {exe} run-job {list_name} --merge\n");
    let submit = format!(
        "#!/bin/sh\n\
         # Submits the render array, then the merge once every array task has succeeded.\n\
         set -eu\n\
         cd {dir}\n\
         mkdir -p logs\n\
         render=$(sbatch --parsable render.sbatch)\n\
         render=${{render%%;*}}\n\
         merge=$(sbatch --parsable --dependency=afterok:\"$render\" merge.sbatch)\n\
         merge=${{merge%%;*}}\n\
         echo \"render array $render, merge $merge\"\n",
        dir = shell_quote(&options.job_dir)
    );
    vec![
        ("render.sbatch".into(), render, false),
        ("merge.sbatch".into(), merge, false),
        ("submit.sh".into(), submit, true),
    ]
}
