#!/usr/bin/env bash
# Validates the Kubernetes manifests `photomontage k8s` writes against the Kubernetes JSON schema
# (kubernetes-validate from PyPI, strict: unknown fields are errors), and checks that the
# validator does reject a broken manifest, so a pass means something.
#
#   tests/k8s/validate.sh [PHOTOMONTAGE_BINARY]
#
# Not part of `cargo test` (it needs Python and PyPI); `.ci/run` runs it.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
PM="$(realpath "${1:-$ROOT/target/release/photomontage}")"
K8S_VERSIONS="${K8S_VERSIONS:-1.29.0 1.37.0}"
WORK="$(mktemp -d /tmp/photomontage-k8s.XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

python3 -m venv "$WORK/venv"
"$WORK/venv/bin/pip" install -q kubernetes-validate
KV="$WORK/venv/bin/kubernetes-validate"

"$PM" solve "$ROOT/sample_sites/street/site.toml" --out "$WORK/street.toml" >/dev/null
"$PM" k8s "$WORK/street.toml" --tiles 4 --out "$WORK/job" --image registry.example/photomontage:0.1 \
  --claim photomontage-work --volume-root "$WORK" --parallelism 4 >/dev/null
grep -q '"/data/job/jobs.json"' "$WORK/job/render-job.yaml" || fail "the pods' job list path is wrong"
grep -q 'completions: 12' "$WORK/job/render-job.yaml" || fail "expected 12 completions"

for v in $K8S_VERSIONS; do
  "$KV" --strict -k "$v" "$WORK/job/render-job.yaml" "$WORK/job/merge-job.yaml" \
    || fail "manifests do not validate against Kubernetes $v"
done

# The validator must reject a manifest with a wrongly typed field and one with an unknown field.
sed 's/^  parallelism: 4$/  parallelism: "four"/' "$WORK/job/render-job.yaml" > "$WORK/bad-type.yaml"
sed 's/^  completionMode: "Indexed"$/  completionMode: "Indexed"\n  completionsPerPod: 3/' \
  "$WORK/job/render-job.yaml" > "$WORK/bad-field.yaml"
for bad in bad-type bad-field; do
  if "$KV" --strict --quiet "$WORK/$bad.yaml" >/dev/null 2>&1; then
    fail "the validator accepted $bad.yaml"
  fi
done
echo "k8s manifests: valid against Kubernetes $K8S_VERSIONS (strict); broken ones rejected"
