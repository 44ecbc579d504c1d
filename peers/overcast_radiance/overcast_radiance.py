"""The overcast ground + box scene of ../shared/reference/lighting.md §3.1, irradiance by Radiance
`rtrace -I` (pyradiance's Radiance 6.0a binaries) at its five points, written to a JSON fixture
that `photomontage/src/radiosity/radiance_tests.rs` reads.

Scene (metres, z up): a 2 km ground of ρ 0.2 (`grey20`, ±1000 m), a 2 m cube of ρ 0.5 (`grey50`,
x, y ∈ [−1, 1], z ∈ [0, 2]) on it; a CIE traditional overcast sky (`gensky 3 21 12 -c`) scaled by
`-B 55.866` to a diffuse horizontal irradiance of 55.866 W/m², i.e. 10 000 lx at Radiance's
179 lm/W, with the standard sky glow and ground glow (`-g 0.2`). Irradiance is reported as
illuminance, 179·(0.265 R + 0.670 G + 0.065 B) lx, as lighting.md does.

Points (position, normal): box top (0, 0, 2.001) up; ground 50 m away (50, 0, 0.001) up; ground
0.5 m from the box face (1.5, 0, 0.001) up; a vertical 50 m away facing away from the box
(−50, 0, 1) towards −x; the box's wall (−1.001, 0, 1) facing out.

Each point is traced at `--ab` ambient bounces (default 8, converged: ρ ≤ 0.5) and at `--ab` − 1,
and the fixture records both, so the test can check the reference has converged. lighting.md
recorded these points at -ab 2 (its table); the two values differ where light bounces between the
box and the ground.

Usage: python overcast_radiance.py [--ab N] [--ad N] [--lw X] [--out FILE.json]
"""
import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

import pyradiance  # noqa: F401  (sets PATH and RAYPATH for the binaries)

POINTS = [
    ("box_top", [0.0, 0.0, 2.001], [0.0, 0.0, 1.0]),
    ("ground_50m", [50.0, 0.0, 0.001], [0.0, 0.0, 1.0]),
    ("ground_near_box", [1.5, 0.0, 0.001], [0.0, 0.0, 1.0]),
    ("vertical_50m_facing_away", [-50.0, 0.0, 1.0], [-1.0, 0.0, 0.0]),
    ("box_wall", [-1.001, 0.0, 1.0], [-1.0, 0.0, 0.0]),
]
SKY_HORIZONTAL_W = 55.866
GROUND_RHO = 0.2
BOX_RHO = 0.5
WHITE_EFFICACY = 179.0

MATERIALS = f"""void plastic grey20 0 0 5 {GROUND_RHO} {GROUND_RHO} {GROUND_RHO} 0 0
void plastic grey50 0 0 5 {BOX_RHO} {BOX_RHO} {BOX_RHO} 0 0
grey20 polygon ground 0 0 12 -1000 -1000 0 1000 -1000 0 1000 1000 0 -1000 1000 0
"""
GLOWS = """skyfunc glow skyglow 0 0 4 1 1 1 0
skyglow source sky 0 0 4 0 0 1 180
skyfunc glow groundglow 0 0 4 1 1 1 0
groundglow source ground 0 0 4 0 0 -1 180
"""


def run(args, cwd, text=None):
    return subprocess.run(args, cwd=cwd, input=text, capture_output=True, text=True, check=True).stdout


def build(folder):
    sky = run(["gensky", "3", "21", "12", "-c", "-B", str(SKY_HORIZONTAL_W), "-g", str(GROUND_RHO),
               "-a", "47", "-o", "-8", "-m", "-15"], folder)
    (folder / "sky.rad").write_text(sky + GLOWS)
    (folder / "mat.rad").write_text(MATERIALS)
    box = run(["genbox", "grey50", "box", "2", "2", "2"], folder)
    (folder / "box.rad").write_text(run(["xform", "-t", "-1", "-1", "0"], folder, box))
    with open(folder / "scene.oct", "w") as out:
        subprocess.run(["oconv", "sky.rad", "mat.rad", "box.rad"], cwd=folder, stdout=out, check=True)
    return sky


def illuminance(folder, opts):
    text = "".join(" ".join(map(str, p + n)) + "\n" for _, p, n in POINTS)
    out = run(["rtrace", "-h", "-I+", *opts, "scene.oct"], folder, text)
    rows = [list(map(float, line.split()[:3])) for line in out.strip().splitlines()]
    return [WHITE_EFFICACY * (0.265 * r + 0.670 * g + 0.065 * b) for r, g, b in rows]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ab", type=int, default=8, help="ambient bounces of the reference")
    ap.add_argument("--ad", type=int, default=65536)
    ap.add_argument("--lw", type=float, default=1e-6)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[2]
                                         / "photomontage/tests/fixtures/peers/overcast_radiance.json"))
    args = ap.parse_args()
    start = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        sky = build(folder)
        common = ["-ad", str(args.ad), "-as", "0", "-aa", "0", "-lw", str(args.lw)]
        opts = {ab: ["-ab", str(ab), *common] for ab in (args.ab - 1, args.ab)}
        values = {ab: illuminance(folder, o) for ab, o in opts.items()}
    out = {
        "peer": run(["rtrace", "-version"], ".").strip(),
        "script": "peers/overcast_radiance/overcast_radiance.py",
        "options": {"rtrace": " ".join(["-I+", *opts[args.ab]]),
                    "rtrace_one_bounce_less": " ".join(["-I+", *opts[args.ab - 1]])},
        "gensky": [line for line in sky.splitlines() if line and not line.startswith("#")],
        "sky_horizontal_lx": SKY_HORIZONTAL_W * WHITE_EFFICACY,
        "ground_rho": GROUND_RHO,
        "box_rho": BOX_RHO,
        "seconds": time.monotonic() - start,
        "points": [
            {"id": pid, "position_m": p, "normal": n,
             "illuminance_lx": values[args.ab][i],
             "illuminance_one_bounce_less_lx": values[args.ab - 1][i]}
            for i, (pid, p, n) in enumerate(POINTS)
        ],
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    for q in out["points"]:
        print(f"{q['id']:26s} {q['illuminance_lx']:9.1f} lx (one bounce less {q['illuminance_one_bounce_less_lx']:9.1f})")
    print(f"{out['seconds']:.1f} s, written to {args.out}")


if __name__ == "__main__":
    main()
