//! Kubernetes Indexed Jobs (Kubernetes `batch/v1` Job, `completionMode: Indexed`): completion
//! index K runs job K of the [`JobList`]; a second Job merges once the first has completed.
//!
//! The site and the job folder live on one shared volume (a PersistentVolumeClaim) mounted at
//! [`MOUNT_PATH`] in every pod; `volume_root` is the local folder that is the volume's root, so
//! the list's path inside the pod is `MOUNT_PATH/<list relative to volume_root>`. Each pod gets
//! its index from the `batch.kubernetes.io/job-completion-index` annotation, and
//! `backoffLimitPerIndex` retries a failed index on its own (Kubernetes ≥ 1.29); a retried
//! index skips a part that is already there.
//!
//! Written files: `render-job.yaml`, `merge-job.yaml`, `submit.sh` (`kubectl apply` the render
//! Job, `kubectl wait` for it, apply the merge Job). YAML is written with every string
//! double-quoted (JSON escapes are valid YAML).
//!
//! # Known limitations
//! Validated against the Kubernetes JSON schema (`kubernetes-validate`, see docs/scale-out.md),
//! not run on a cluster here. The image must contain the `photomontage` binary.

use super::{JobList, Resources};

/// Where the shared volume is mounted in the pods.
pub const MOUNT_PATH: &str = "/data";

/// Options of the manifests.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct K8sOptions {
    /// Container image holding `photomontage`.
    pub image: String,
    /// The PersistentVolumeClaim holding site and job folder.
    pub claim: String,
    /// The job list's path inside the pod (under [`MOUNT_PATH`]).
    pub list_in_pod: String,
    /// Pods running at once.
    pub parallelism: u32,
    /// Retries per index.
    pub backoff_limit_per_index: u32,
    /// CPUs and memory per pod.
    pub resources: Resources,
    /// Job name prefix (DNS label).
    pub name: String,
}

fn q(s: &str) -> String {
    serde_json::Value::String(s.to_owned()).to_string()
}

fn job(options: &K8sOptions, name: &str, indexed: Option<usize>, args: &[&str]) -> String {
    let r = options.resources;
    let mut y = String::new();
    y += "apiVersion: \"batch/v1\"\nkind: \"Job\"\nmetadata:\n";
    y += &format!("  name: {}\n", q(name));
    y += "  labels:\n    app.kubernetes.io/name: \"photomontage\"\n";
    y += &format!("    app.kubernetes.io/instance: {}\n", q(&options.name));
    y += "spec:\n";
    if let Some(n) = indexed {
        y += "  completionMode: \"Indexed\"\n";
        y += &format!("  completions: {n}\n");
        y += &format!("  parallelism: {}\n", options.parallelism.max(1));
        y += &format!(
            "  backoffLimitPerIndex: {}\n",
            options.backoff_limit_per_index
        );
    } else {
        y += "  backoffLimit: 2\n";
    }
    y += "  template:\n    spec:\n      restartPolicy: \"Never\"\n      containers:\n";
    y += "        - name: \"photomontage\"\n";
    y += &format!("          image: {}\n", q(&options.image));
    y += "          command:\n            - \"photomontage\"\n";
    y += "          args:\n";
    for a in args {
        y += &format!("            - {}\n", q(a));
    }
    if indexed.is_some() {
        y += "          env:\n            - name: \"JOB_INDEX\"\n              valueFrom:\n";
        y += "                fieldRef:\n                  fieldPath: \"metadata.annotations['batch.kubernetes.io/job-completion-index']\"\n";
    }
    y += "          resources:\n";
    for kind in ["requests", "limits"] {
        y += &format!(
            "            {kind}:\n              cpu: \"{}\"\n              memory: \"{}Mi\"\n",
            r.cpus, r.memory_mib
        );
    }
    y += &format!(
        "          volumeMounts:\n            - name: \"work\"\n              mountPath: {}\n",
        q(MOUNT_PATH)
    );
    y += &format!(
        "      volumes:\n        - name: \"work\"\n          persistentVolumeClaim:\n            claimName: {}\n",
        q(&options.claim)
    );
    y
}

/// The files for `list`: `(name, contents, executable)`.
#[must_use]
pub fn manifests(list: &JobList, options: &K8sOptions) -> Vec<(String, String, bool)> {
    let threads = options.resources.cpus.to_string();
    let render_name = format!("{}-render", options.name);
    let merge_name = format!("{}-merge", options.name);
    let render = job(
        options,
        &render_name,
        Some(list.jobs.len()),
        &[
            "run-job",
            &options.list_in_pod,
            "--index",
            "$(JOB_INDEX)",
            "--threads",
            &threads,
        ],
    );
    let merge = job(
        options,
        &merge_name,
        None,
        &["run-job", &options.list_in_pod, "--merge"],
    );
    let submit = format!(
        "#!/bin/sh\n\
         # Applies the render Job, waits for every index to complete, then applies the merge Job.\n\
         set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         kubectl apply -f render-job.yaml\n\
         kubectl wait --for=condition=complete --timeout=24h job/{render_name}\n\
         kubectl apply -f merge-job.yaml\n\
         kubectl wait --for=condition=complete --timeout=1h job/{merge_name}\n"
    );
    vec![
        ("render-job.yaml".into(), render, false),
        ("merge-job.yaml".into(), merge, false),
        ("submit.sh".into(), submit, true),
    ]
}

/// A DNS-1123 label from `text` (lower case, `-` for anything else, at most 40 characters so
/// that `-render`/`-merge` and the pods' suffixes fit in 63).
#[must_use]
pub fn dns_label(text: &str) -> String {
    let mut s: String = text
        .to_ascii_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    s.truncate(40);
    let s = s.trim_matches('-').to_owned();
    if s.is_empty() {
        "photomontage".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_dns_safe() {
        assert_eq!(dns_label("Street_Site 2026"), "street-site-2026");
        assert_eq!(dns_label("__"), "photomontage");
        assert!(dns_label(&"x".repeat(90)).len() <= 40);
    }
}
