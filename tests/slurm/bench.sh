#!/usr/bin/env bash
# Scale-out benchmark (docs/benchmarks.md, "Render farm"): the street sample's three views in
# 4 tiles each (12 array tasks of 1 CPU) on a one-node loopback Slurm cluster, with at most
# 1, 2 and 4 tasks running at once (sbatch --array=…%K), at the site's own render settings.
# Prints the wall time from submission to the merged images, and the per-task render times
# from the task logs (for projecting larger studies).
#
#   tests/slurm/bench.sh [PHOTOMONTAGE_BINARY]      (a release build: cargo build --release)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
PM="$(realpath "${1:-$ROOT/target/release/photomontage}")"
THROTTLES="${THROTTLES:-1 2 4}"
WORK="$(mktemp -d /tmp/photomontage-slurm-bench.XXXXXX)"
source "$ROOT/tests/slurm/cluster.sh"
trap 'cluster_stop; rm -rf "$WORK"' EXIT

"$PM" solve "$ROOT/sample_sites/street/site.toml" --out "$WORK/street.toml" >/dev/null
cluster_start "$WORK/cluster"
echo "node: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
for k in $THROTTLES; do
  job="$WORK/job-$k"
  "$PM" slurm "$WORK/street.toml" --tiles 4 --throttle "$k" --cpus-per-task 1 --exe "$PM" \
    --out "$job" >/dev/null
  start=$(date +%s.%N)
  submitted="$("$job/submit.sh")"
  merge="$(echo "$submitted" | awk '{print $5}')"
  while :; do
    state="$(scontrol show job "$merge" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -1)"
    [ "$state" = COMPLETED ] && break
    case "$state" in FAILED|CANCELLED|TIMEOUT) echo "merge $state" >&2; exit 1 ;; esac
    sleep 0.2
  done
  end=$(date +%s.%N)
  # Each task log ends with run-job's line; the render's own time is in its "rendered" line.
  printf 'at most %s task(s) at once: %.1f s wall for 3 views x 4 tiles\n' "$k" "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')"
  # Per-task times (load, render, write), as run-job reports them.
  grep -ho 'rendered .* in [0-9.]* s' "$job"/logs/render-*.out | sed 's/.*parts\///; s/ rendered//' | sort
done
