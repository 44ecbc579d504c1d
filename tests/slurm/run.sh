#!/usr/bin/env bash
# The scale-out acceptance test on a real Slurm cluster (docs/scale-out.md): a one-node cluster
# on loopback, the street sample's three views in 4 tiles each as one job array plus the merge
# job, one task killed with SIGKILL mid-run (it requeues itself and the job finishes), and every
# merged image compared byte for byte with a whole-image render.
#
#   tests/slurm/run.sh [PHOTOMONTAGE_BINARY]
#
# Needs Debian's slurm-wlm and munge and root (the daemons run as root). Not part of
# `cargo test`; `.ci/run` runs it when slurm-wlm installs. Exit 0 only when everything holds.
# SPP_MAX (default 8) keeps the renders short; the bit-identity holds for any setting.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
PM="$(realpath "${1:-$ROOT/target/release/photomontage}")"
SPP_MAX="${SPP_MAX:-8}"
WORK="$(mktemp -d /tmp/photomontage-slurm.XXXXXX)"
# shellcheck source=tests/slurm/cluster.sh
source "$ROOT/tests/slurm/cluster.sh"
finish() {
  local rc=$?
  cluster_stop
  if [ "$rc" = 0 ]; then rm -rf "$WORK"; else echo "work folder kept: $WORK" >&2; fi
}
trap finish EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

[ -x "$PM" ] || fail "no photomontage binary at $PM (build it first)"
command -v slurmctld >/dev/null || fail "slurmctld not installed (apt-get install slurm-wlm munge)"

echo "== solving the street sample site"
"$PM" solve "$ROOT/sample_sites/street/site.toml" --out "$WORK/street.toml" >/dev/null

echo "== starting a one-node Slurm cluster on loopback"
cluster_start "$WORK/cluster"
sinfo

echo "== writing the job array: 3 views x 4 tiles"
"$PM" slurm "$WORK/street.toml" --tiles 4 --spp-max "$SPP_MAX" --throttle 4 \
  --cpus-per-task 1 --exe "$PM" --out "$WORK/job"
jobs_count="$(grep -c '"index"' "$WORK/job/jobs.json")"
[ "$jobs_count" = 12 ] || fail "expected 12 jobs, the list has $jobs_count"

submitted="$("$WORK/job/submit.sh")"
echo "$submitted"
array="$(echo "$submitted" | awk '{print $3}' | tr -d ,)"
merge="$(echo "$submitted" | awk '{print $5}')"

echo "== killing one running task mid-run"
victim=""
for _ in $(seq 1 120); do
  victim="$(squeue -h -t R -j "$array" -o '%K' | head -1)"
  if [ -n "$victim" ] && pgrep -f "run-job jobs.json --index $victim " >/dev/null; then break; fi
  victim=""
  sleep 0.5
done
[ -n "$victim" ] || fail "no array task started running"
# The part must not exist yet: the kill lands mid-render.
part="$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['jobs'][int(sys.argv[2])]['output'])" "$WORK/job/jobs.json" "$victim")"
pkill -9 -f "run-job jobs.json --index $victim " || fail "could not kill task $victim"
[ ! -e "$WORK/job/$part" ] || echo "note: task $victim had already written its part"
echo "killed array task ${array}_$victim (part $part)"

echo "== waiting for the array and the merge"
for _ in $(seq 1 720); do
  state="$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -1)"
  case "$state" in
    COMPLETED) break ;;
    FAILED|CANCELLED|TIMEOUT|OUT_OF_MEMORY|NODE_FAIL)
      cat "$WORK"/job/logs/*.out >&2 || true
      fail "merge job $merge ended $state" ;;
  esac
  if scontrol show job "$merge" 2>/dev/null | grep -q DependencyNeverSatisfied; then
    cat "$WORK"/job/logs/*.out >&2 || true
    fail "merge job $merge can never run: a render task failed for good"
  fi
  sleep 1
done
[ "$state" = COMPLETED ] || fail "merge job $merge did not finish in 12 minutes (state $state)"
restarts="$(scontrol show job "${array}_$victim" | sed -n 's/.*Restarts=\([0-9]*\).*/\1/p')"
[ "${restarts:-0}" -ge 1 ] || fail "task $victim shows no restart (Restarts=$restarts)"
grep -q "requeueing" "$WORK/job/logs/render-${array}_$victim.out" \
  || fail "task $victim's log does not show the requeue"
echo "task $victim was requeued $restarts time(s) and finished"

echo "== comparing merged images with whole-image renders"
for view in V1 V2 V3; do
  "$PM" render "$WORK/street.toml" --view "$view" --spp-max "$SPP_MAX" \
    --out "$WORK/whole-$view.exr" >/dev/null
  cmp "$WORK/whole-$view.exr" "$WORK/job/$view.exr" \
    || fail "merged $view.exr differs from the whole-image render"
  echo "$view: merged = whole-image render, byte for byte"
done
leftovers="$(find "$WORK/job" -name '.*.tmp' | wc -l)"
[ "$leftovers" = 0 ] || echo "note: $leftovers temporary file(s) of killed writers left (ignored by readers)"
echo "slurm scale-out test: passed"
