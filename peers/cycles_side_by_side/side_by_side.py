"""Our radiosity montage against Blender Cycles on the same machine, in alternated pairs.

Issue 13's speed point: `render_bench` on the 1280x720 Mitsuba pair, radiosity lighting, 2 threads,
4 rays per pixel, at RMSE <= 0.005, in <= 1/3 of Cycles' 16-spp wall time *on the same machine*.
This VM's speed drifts by 1.5-2x between hours, so one figure from each program taken on different
days says little. This script alternates them: per pair, Cycles renders the pair's scene
(`peers/blender/cycles_render.py --threads 2` of the shared bench, 3 renders per scene, median)
and then `render_bench` renders the box into the photo (`--reps 3`, median; the precompute is
timed and printed beside it). Each pair's ratio is ours / Cycles' `with_box` render time.

Needs a writable copy of the shared bench folder with Blender's venv:
    cp -r ../shared/bench SCRATCH && chmod -R u+w SCRATCH
    (cd SCRATCH && python3 -m venv .venv-bpy && .venv-bpy/bin/pip install -r peers/requirements-bpy.txt)
and a release `render_bench`:
    cargo build --release --locked -p photomontage --features cli --bin render_bench
Then, from the workspace root (any Python 3):
    python3 peers/cycles_side_by_side/side_by_side.py --bench SCRATCH [--pairs 5]
Writes `peers/cycles_side_by_side/side_by_side.json` (or `--out FILE`): every pair, the medians and
the median ratio. Run it with nothing else loading the CPUs.
"""

import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TARGET = 1.0 / 3.0


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def run_cycles(bench: Path):
    py = bench / ".venv-bpy" / "bin" / "python"
    if not py.exists():
        sys.exit(f"no {py}: make Blender's venv in the bench copy first (see this script's doc)")
    subprocess.run([str(py), "peers/blender/cycles_render.py", "--threads", "2"], cwd=bench,
                   check=True, stdout=subprocess.DEVNULL)
    res = json.loads((bench / "peers" / "results" / "blender_threads2.json").read_text())
    box = res["renders"]["with_box"]
    return {"render_s_median": box["render_s_median"], "render_s_all": box["render_s_all"],
            "rmse_vs_mitsuba_1024spp": box.get("rmse_vs_mitsuba_1024spp"),
            "timestamp_utc": res["timestamp_utc"]}


def run_ours(bench: Path, binary: Path):
    out = subprocess.run([str(binary), str(bench), "--reps", "3", "--threads", "2", "--spp", "4-4",
                          "--lighting", "radiosity", "--peer-results", str(bench / "peers" / "results")],
                         cwd=ROOT, check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        cols = line.split()
        # lighting cache threads spp precompute_s setup_s render_s render_cpu_s rays/px changed RMSE
        if len(cols) == 11 and cols[0] == "radiosity":
            return {"precompute_s": float(cols[4]), "render_s": float(cols[6]),
                    "render_cpu_s": float(cols[7]), "changed_px": int(cols[9]), "rmse": float(cols[10])}
    sys.exit(f"no radiosity row in render_bench's output:\n{out}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", type=Path, required=True, help="writable copy of ../shared/bench with .venv-bpy")
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--binary", type=Path, default=ROOT / "target" / "release" / "render_bench")
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("side_by_side.json"))
    args = ap.parse_args()
    if not args.binary.exists():
        sys.exit(f"no {args.binary}: cargo build --release --locked -p photomontage --features cli --bin render_bench")
    pairs = []
    for i in range(args.pairs):
        start = datetime.datetime.now(datetime.timezone.utc).strftime("%H:%M:%S")
        load = loadavg()
        cycles = run_cycles(args.bench)
        ours = run_ours(args.bench, args.binary)
        ratio = ours["render_s"] / cycles["render_s_median"]
        pairs.append({"start_utc": start, "loadavg_at_start": load, "cycles": cycles, "ours": ours,
                      "ratio": ratio})
        print(f"pair {i + 1}: Cycles {cycles['render_s_median']:.2f} s, ours {ours['render_s']:.3f} s "
              f"(precompute {ours['precompute_s']:.2f} s, RMSE {ours['rmse']:.5f}), ratio {ratio:.3f}")
    med = {
        "cycles_render_s": statistics.median(p["cycles"]["render_s_median"] for p in pairs),
        "ours_render_s": statistics.median(p["ours"]["render_s"] for p in pairs),
        "ours_precompute_s": statistics.median(p["ours"]["precompute_s"] for p in pairs),
        "ratio": statistics.median(p["ratio"] for p in pairs),
    }
    met = sum(p["ratio"] <= TARGET and p["ours"]["rmse"] <= 0.005 for p in pairs)
    result = {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "cpu_count": os.cpu_count(), "target_ratio": TARGET, "pairs": pairs, "medians": med,
              "pairs_within_target": met}
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"medians: Cycles {med['cycles_render_s']:.2f} s, ours {med['ours_render_s']:.3f} s "
          f"(precompute {med['ours_precompute_s']:.2f} s); median ratio {med['ratio']:.3f} "
          f"(target <= {TARGET:.3f}); {met} of {len(pairs)} pairs within it; written to {args.out}")


if __name__ == "__main__":
    main()
