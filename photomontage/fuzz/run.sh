#!/usr/bin/env bash
# Fuzz campaign for every parser (cargo-fuzz / libFuzzer). See docs/fuzzing.md.
#
#   photomontage/fuzz/run.sh [-t SECONDS] [-j PARALLEL] [-w WORKDIR] [--no-build] [TARGET...]
#
# Builds the targets (nightly, release + debug assertions, no sanitizer), seeds a scratch corpus
# per target from /work/shared/data/real (or $PHOTOMONTAGE_REAL_DATA), the sample sites and the
# test fixtures, runs each target for SECONDS (default 600) at most PARALLEL (default 2) at a
# time under `nice -n 19`, and prints execs, corpus sizes and findings. Corpora persist in
# WORKDIR/corpus/<target> (outside the repository), so a re-run continues from them; crashes,
# timeouts and OOMs are saved in WORKDIR/artifacts/<target>/ and logs in WORKDIR/logs/.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
crate="$(dirname "$here")"
repo="$(dirname "$crate")"
seconds=600
parallel=2
work="${PHOTOMONTAGE_FUZZ_WORK:-${TMPDIR:-/tmp}/photomontage-fuzz}"
real="${PHOTOMONTAGE_REAL_DATA:-$(dirname "$repo")/shared/data/real}"
[ -d "$real" ] || real=/work/shared/data/real
build=1
all_targets=(site_toml material_toml control_csv gcp_list ies eulumdat obj_mtl gltf dxf exif photo)
targets=()
while [ $# -gt 0 ]; do
    case "$1" in
        -t) seconds="$2"; shift 2 ;;
        -j) parallel="$2"; shift 2 ;;
        -w) work="$2"; shift 2 ;;
        --no-build) build=0; shift ;;
        -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
        *) targets+=("$1"); shift ;;
    esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
mkdir -p "$work"/{corpus,artifacts,logs,seeds}

if [ "$build" = 1 ]; then
    (cd "$crate" && nice -n 19 cargo +nightly fuzz build -s none)
fi
bin_dir="$here/target/x86_64-unknown-linux-gnu/release"

# Copies the files matched by find arguments, each no larger than 200 KB, into a seed folder.
seed() {
    local target="$1" from="$2"; shift 2
    [ -d "$from" ] || return 0
    find "$from" -type f -size -200k "$@" -print0 |
        while IFS= read -r -d '' f; do
            cp "$f" "$work/corpus/$target/seed_$(echo "$f" | sha1sum | cut -c1-12)_$(basename "$f")"
        done
}

# OBJ seeds: the OBJ, the MTL marker, then the MTL it names (the target writes it back under that name).
seed_obj() {
    local obj="$1" mtl="$2"
    { cat "$obj"; if [ -f "$mtl" ]; then printf '\n#%%MTL%%\n'; cat "$mtl"; fi; } \
        > "$work/corpus/obj_mtl/seed_$(basename "$obj")"
}

if [ ! -d "$real" ]; then
    echo "notice: real data folder $real is absent; seeding from the repository only" >&2
fi
for t in "${targets[@]}"; do
    mkdir -p "$work/corpus/$t" "$work/artifacts/$t"
    case "$t" in
        site_toml) seed "$t" "$repo/sample_sites" -name '*.toml' ! -name 'materials.toml' ;;
        material_toml) seed "$t" "$repo/sample_sites" -name 'materials.toml'
                       seed "$t" "$repo/docs" -name '*.toml' ;;
        control_csv) seed "$t" "$repo/sample_sites" -name '*.csv'
                     seed "$t" "$real/gcp" \( -name '*.csv' -o -name '*.dat' -o -name '*.inp' \) ;;
        gcp_list) seed "$t" "$real/gcp" -name '*.txt' ;;
        ies) seed "$t" "$real/ies" -iname '*.ies'
             seed "$t" "$crate/tests/fixtures" -iname '*.ies' ;;
        eulumdat) seed "$t" "$real/ldt" -iname '*.ldt' ;;
        obj_mtl) seed_obj "$crate/tests/fixtures/house.obj" "$crate/tests/fixtures/house.mtl"
                 seed_obj "$repo/sample_sites/street/planned_building.obj" "$repo/sample_sites/street/planned_building.mtl"
                 for f in "$crate"/tests/fixtures/*.obj; do seed_obj "$f" /nonexistent; done ;;
        gltf) seed "$t" "$crate/tests/fixtures" -name '*.gltf'
              python3 "$here/seeds.py" "$crate/tests/fixtures" "$work/seeds"
              cp "$work/seeds/gltf/"* "$work/corpus/$t/" ;;
        dxf) seed "$t" "$crate/tests/fixtures" -name '*.dxf' ;;
        exif) seed "$t" "$real/exif" -iname '*.jpg' ;;
        photo) seed "$t" "$real/exif" -iname '*.jpg' -size -50k
               seed "$t" "$repo/sample_sites" -name '*.png'
               python3 "$here/seeds.py" "$crate/tests/fixtures" "$work/seeds"
               cp "$work/seeds/photo/"* "$work/corpus/$t/" ;;
        *) echo "unknown target $t (known: ${all_targets[*]})" >&2; exit 2 ;;
    esac
done

# One target for $seconds; the summary line goes to $work/logs/<target>.summary.
run_one() {
    local t="$1"
    local max_len=65536 log="$work/logs/$t.log"
    case "$t" in photo|exif) max_len=262144 ;; esac
    local seeds start end
    seeds=$(find "$work/corpus/$t" -type f | wc -l)
    # Run a copy, so that a rebuild during a long campaign cannot touch a running binary.
    mkdir -p "$work/bin"
    cp "$bin_dir/$t" "$work/bin/$t"
    start=$(date +%s)
    set +e
    nice -n 19 "$work/bin/$t" "$work/corpus/$t" \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" \
        -artifact_prefix="$work/artifacts/$t/" -print_final_stats=1 > "$log" 2>&1
    local rc=$?
    set -e
    end=$(date +%s)
    local execs files bytes findings
    execs=$(grep -a -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    files=$(find "$work/corpus/$t" -type f | wc -l)
    bytes=$(du -sb "$work/corpus/$t" | cut -f1)
    findings=$(find "$work/artifacts/$t" -type f | wc -l)
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$t" "$((end - start))" "${execs:-?}" "$seeds" \
        "$files" "$bytes" "$findings" "$rc" > "$work/logs/$t.summary"
    echo "done $t: $((end - start)) s, ${execs:-?} execs, corpus $seeds -> $files files, exit $rc, $findings artifacts"
}
export -f run_one
export work seconds bin_dir

printf '%s\n' "${targets[@]}" | xargs -P "$parallel" -I{} bash -c 'run_one "$@"' _ {}

echo
printf 'target\twall_s\texecs\tseeds\tcorpus_files\tcorpus_bytes\tartifacts\texit\n'
for t in "${targets[@]}"; do cat "$work/logs/$t.summary"; done
echo "engine: libFuzzer (libfuzzer-sys $(grep -A1 '^name = "libfuzzer-sys"' "$here/Cargo.lock" | grep -o '[0-9][0-9.]*')) via $(cargo fuzz --version 2>/dev/null), $(rustc +nightly --version)"
echo "corpora: $work/corpus   artifacts: $work/artifacts   logs: $work/logs"
