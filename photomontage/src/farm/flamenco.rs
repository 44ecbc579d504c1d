//! Blender's Flamenco render manager: a custom job type (Flamenco manual, "Job Types": a
//! JavaScript file in the Manager's `scripts/` folder defining `JOB_TYPE` and `compileJob`) that
//! turns one [`super::JobList`] into Flamenco tasks — one `exec` task per job running
//! `photomontage run-job LIST --index K`, and a merge task that depends on all of them.
//!
//! Flamenco's job compiler cannot read files, so the job count is a setting of the submitted job;
//! `photomontage flamenco` writes the script and a submission body (`flamenco-job.json`, for the
//! Manager's `POST /api/v3/jobs`) with the count and paths filled in.
//!
//! # Known limitations
//! On paper: written to the documented job-type interface, not run against a Flamenco Manager
//! here.

use super::JobList;

/// The job type's name.
pub const JOB_TYPE_NAME: &str = "photomontage-jobs";

/// The job-type script (install as `scripts/photomontage_jobs.js` beside the Manager).
pub const JOB_TYPE_SCRIPT: &str = r#"// photomontage job type for Flamenco: runs a photomontage job list (jobs.json).
// Install beside flamenco-manager as scripts/photomontage_jobs.js and restart the Manager.
const JOB_TYPE = {
    label: "photomontage jobs",
    settings: [
        { key: "jobs_file", type: "string", subtype: "file_path", required: true,
          description: "jobs.json written by `photomontage flamenco` (as the Workers see it)" },
        { key: "job_count", type: "int32", required: true, propargs: {min: 1},
          description: "Number of jobs in jobs.json" },
        { key: "executable", type: "string", default: "photomontage",
          description: "The photomontage executable on the Workers" },
        { key: "threads", type: "int32", default: 1, propargs: {min: 1},
          description: "Threads per render task" },
    ]
};

function compileJob(job) {
    const s = job.settings;
    const renders = [];
    for (let k = 0; k < s.job_count; k++) {
        const task = author.Task(`render-${k}`, "misc");
        task.addCommand(author.Command("exec", {
            exe: s.executable,
            args: ["run-job", s.jobs_file, "--index", `${k}`, "--threads", `${s.threads}`],
        }));
        job.addTask(task);
        renders.push(task);
    }
    const merge = author.Task("merge", "misc");
    merge.addCommand(author.Command("exec", {
        exe: s.executable,
        args: ["run-job", s.jobs_file, "--merge"],
    }));
    for (const task of renders) {
        merge.addDependency(task);
    }
    job.addTask(merge);
}
"#;

/// The submission body for the Manager's `POST /api/v3/jobs`.
#[must_use]
pub fn submission(list: &JobList, list_on_workers: &str, executable: &str, threads: u32) -> String {
    let body = serde_json::json!({
        "name": format!("photomontage {}", list.site),
        "type": JOB_TYPE_NAME,
        "priority": 50,
        "submitter_platform": "linux",
        "settings": {
            "jobs_file": list_on_workers,
            "job_count": list.jobs.len(),
            "executable": executable,
            "threads": threads.max(1),
        },
    });
    serde_json::to_string_pretty(&body).unwrap_or_default()
}
