"""A courtyard of three walls and ground under a CIE standard general sky of type 12 with the sun,
irradiance by Radiance `rtrace -I` (pyradiance's Radiance 6.0a binaries) at points on the walls
and the ground. Writes the scene (so the Rust test builds exactly the same one), the sky's
normalisation and every point's irradiance to a JSON fixture.

Scene (metres, x east, y north, z up): ground ρ 0.2 (a 22 x 20 m "near" square around the court
and a 1 km "far" square around it, both at z = 0); three 0.3 m thick, 6 m high walls around a
10 x 8 m court open to the south: west (inner face x = 0, ρ 0.7), north (inner face y = 8,
ρ 0.6/0.45/0.3), east (inner face x = 10, ρ 0.35). Every face of every wall is modelled (no
single-sided sheets), so front and back faces shade alike in both programs.

Light: Zürich (47.3769 N, 8.5417 E, 408 m), 2025-06-21 15:00 CEST; sun position by pvlib's
NREL SPA; the sun is a 0.533° Radiance `source` of normal irradiance `SUN_NORMAL`; the sky is
the CIE S 011 general sky of type 12 as a `brightfunc` (`cie_general.cal`, written by this
script, the formula of lighting.md §1.1), zero below the horizon, with its zenith luminance set
so that the unobstructed diffuse horizontal irradiance is `SKY_HORIZONTAL` (quadrature here, and
checked by `rtrace` on an unobstructed point). No ground glow: below the horizon, beyond the
modelled ground, nothing is seen (as in our solver).

Points whose direct sun changes within `EDGE_CLEARANCE_M` (a sun shadow edge nearby, where a
point value and a mesh element's mean differ) are dropped; each point is checked at -ab N and
-ab N+1 to show the ambient bounces have converged.

Usage: python courtyard_radiance.py [--ab N] [--ad N] [--out FILE.json]
"""
import argparse
import json
import math
import os
import subprocess
import tempfile
import time
from pathlib import Path

import pyradiance  # noqa: F401  (sets PATH and RAYPATH for the binaries)
import pandas as pd
import pvlib

LAT, LON, ALT_M = 47.3769, 8.5417, 408.0
WHEN = "2025-06-21 15:00:00"
TZ = "Etc/GMT-2"  # CEST = UTC+2
SUN_NORMAL = 800.0  # W/m² on a plane facing the sun
SKY_HORIZONTAL = 120.0  # W/m² diffuse horizontal irradiance
SUN_DIAMETER_DEG = 0.533
CIE12 = dict(a=-1.0, b=-0.32, c=10.0, d=-3.0, e=0.45)
WALL_H, WALL_T = 6.0, 0.3
COURT_X, COURT_Y = 10.0, 8.0
EDGE_CLEARANCE_M = 0.5
POINT_OFFSET_M = 0.001

MATERIALS = {
    "ground": [0.2, 0.2, 0.2],
    "west_wall": [0.7, 0.7, 0.7],
    "north_wall": [0.6, 0.45, 0.3],
    "east_wall": [0.35, 0.35, 0.35],
}


def quad(a, b, c, d):
    return [list(map(float, p)) for p in (a, b, c, d)]


def box(lo, hi):
    """Outward faces of an axis-aligned box, each counter-clockwise seen from outside."""
    (ax, ay, az), (bx, by, bz) = lo, hi
    return [
        quad((ax, ay, az), (ax, ay, bz), (ax, by, bz), (ax, by, az)),  # -x
        quad((bx, ay, az), (bx, by, az), (bx, by, bz), (bx, ay, bz)),  # +x
        quad((ax, ay, az), (bx, ay, az), (bx, ay, bz), (ax, ay, bz)),  # -y
        quad((ax, by, az), (ax, by, bz), (bx, by, bz), (bx, by, az)),  # +y
        quad((ax, ay, az), (ax, by, az), (bx, by, az), (bx, ay, az)),  # -z
        quad((ax, ay, bz), (bx, ay, bz), (bx, by, bz), (ax, by, bz)),  # +z
    ]


def objects():
    """name -> (material, quads). Wall bottoms (on the ground) are left out."""
    t, h = WALL_T, WALL_H
    walls = {
        "west_wall": box((-t, 0.0, 0.0), (0.0, COURT_Y + t, h)),
        "north_wall": box((0.0, COURT_Y, 0.0), (COURT_X, COURT_Y + t, h)),
        "east_wall": box((COURT_X, 0.0, 0.0), (COURT_X + t, COURT_Y + t, h)),
    }
    out = {name: (name, [q for k, q in enumerate(qs) if k != 4]) for name, qs in walls.items()}
    n0, n1 = (-6.0, -6.0), (16.0, 14.0)
    f = 500.0
    up = lambda x0, y0, x1, y1: quad((x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0))
    out["near_ground"] = ("ground", [up(n0[0], n0[1], n1[0], n1[1])])
    out["far_ground"] = (
        "ground",
        [
            up(-f, -f, f, n0[1]),
            up(-f, n1[1], f, f),
            up(-f, n0[1], n0[0], n1[1]),
            up(n1[0], n0[1], f, n1[1]),
        ],
    )
    return out


def sun_direction():
    t = pd.DatetimeIndex([WHEN]).tz_localize(TZ)
    sp = pvlib.solarposition.get_solarposition(
        t, LAT, LON, altitude=ALT_M, method="nrel_numpy", delta_t=69.0,
        pressure=pvlib.atmosphere.alt2pres(ALT_M), temperature=12.0,
    )
    el = math.radians(float(sp["apparent_elevation"].iloc[0]))
    az = math.radians(float(sp["azimuth"].iloc[0]))
    d = [math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el)]
    return d, float(sp["apparent_elevation"].iloc[0]), float(sp["azimuth"].iloc[0])


def cie_relative(dx, dy, dz, sun):
    """L/L_z of the CIE general sky (lighting.md §1.1), 0 below the horizon."""
    if dz <= 0:
        return 0.0
    p = CIE12
    phi = lambda cz: 1 + p["a"] * math.exp(p["b"] / cz)
    f = lambda chi: 1 + p["c"] * (math.exp(p["d"] * chi) - math.exp(p["d"] * math.pi / 2)) \
        + p["e"] * math.cos(chi) ** 2
    chi = math.acos(max(-1.0, min(1.0, dx * sun[0] + dy * sun[1] + dz * sun[2])))
    zs = math.acos(sun[2])
    return phi(dz) * f(chi) / (phi(1.0) * f(zs))


def horizontal_over_zenith(sun, n=600):
    """∫ L/L_z cos Z dω over the upper hemisphere, midpoint rule in cos Z and azimuth."""
    total = 0.0
    for i in range(n):
        u = (i + 0.5) / n
        s = math.sqrt(1 - u * u)
        for j in range(2 * n):
            az = (j + 0.5) * math.pi / n
            total += cie_relative(math.sin(az) * s, math.cos(az) * s, u, sun) * u
    return total * (1.0 / n) * (math.pi / n)


CAL = """{ CIE S 011 general sky (lighting.md section 1.1); written by courtyard_radiance.py.
  A1..A5 = a b c d e; A6..A8 = unit vector to the sun; A9 = zenith radiance (W/sr/m2). }
phi(cz) = 1 + A1*exp(A2/cz);
f(chi) = 1 + A3*(exp(A4*chi) - exp(A4*PI/2)) + A5*cos(chi)^2;
chi = Acos(bound(-1, Dx*A6 + Dy*A7 + Dz*A8, 1));
zs = Acos(A8);
skybr = if(Dz, A9*phi(Dz)*f(chi)/(phi(1)*f(zs)), 0);
bound(a, x, b) = if(a-x, a, if(x-b, b, x));
"""


def scene_files(folder, sun, zenith, with_sky=True, with_sun=True):
    (folder / "cie_general.cal").write_text(CAL)
    omega = 2 * math.pi * (1 - math.cos(math.radians(SUN_DIAMETER_DEG / 2)))
    ls = SUN_NORMAL / omega
    p = CIE12
    lines = []
    if with_sun:
        lines += [f"void light solar 0 0 3 {ls:.9g} {ls:.9g} {ls:.9g}",
                  f"solar source sun 0 0 4 {sun[0]:.12f} {sun[1]:.12f} {sun[2]:.12f} {SUN_DIAMETER_DEG}"]
    if with_sky:
        args = f"{p['a']} {p['b']} {p['c']} {p['d']} {p['e']} {sun[0]:.12f} {sun[1]:.12f} {sun[2]:.12f} {zenith:.9g}"
        lines += [f"void brightfunc skyfunc 2 skybr cie_general.cal 0 9 {args}",
                  "skyfunc glow skyglow 0 0 4 1 1 1 0",
                  "skyglow source sky 0 0 4 0 0 1 180"]
    for name, rgb in MATERIALS.items():
        lines.append(f"void plastic {name} 0 0 5 {rgb[0]} {rgb[1]} {rgb[2]} 0 0")
    for obj, (mat, quads) in objects().items():
        for k, q in enumerate(quads):
            coords = " ".join(f"{c:.6f}" for p_ in q for c in p_)
            lines.append(f"{mat} polygon {obj}.{k} 0 0 12 {coords}")
    (folder / "scene.rad").write_text("\n".join(lines) + "\n")
    with open(folder / "scene.oct", "wb") as out:
        subprocess.run(["oconv", "scene.rad"], cwd=folder, stdout=out, check=True)


def rtrace(folder, rays, opts):
    text = "".join(" ".join(f"{v:.6f}" for v in r) + "\n" for r in rays)
    res = subprocess.run(["rtrace", "-h", "-I+", *opts, "scene.oct"], cwd=folder, input=text,
                         capture_output=True, text=True, check=True)
    return [[float(x) for x in line.split()[:3]] for line in res.stdout.strip().splitlines()]


def candidate_points():
    """(id, position on the surface, outward normal, in-plane unit vectors)."""
    pts = []
    ex, ey, ez = (1, 0, 0), (0, 1, 0), (0, 0, 1)
    for k, (x, y) in enumerate([(5, 4), (7, 2), (8, 6), (4, 6.5), (1, 4), (1, 6.5), (5, 1),
                                (9, 4), (3.5, 2.5), (6, 7.2), (0.6, 1.0), (12, 4), (-3, 4)]):
        pts.append((f"ground{k}", (x, y, 0.0), ez, (ex, ey)))
    for k, (y, z) in enumerate([(2, 1), (4, 3), (6, 5), (7, 1.5), (1, 4)]):
        pts.append((f"west{k}", (0.0, y, z), ex, (ey, ez)))
    for k, (x, z) in enumerate([(2, 1), (5, 3), (8, 5), (5, 0.7), (9, 2), (1.5, 4.5)]):
        pts.append((f"north{k}", (x, COURT_Y, z), (0, -1, 0), (ex, ez)))
    for k, (y, z) in enumerate([(2, 1), (4, 3), (6, 5), (3, 0.6), (7.2, 2)]):
        pts.append((f"east{k}", (COURT_X, y, z), (-1, 0, 0), (ey, ez)))
    return pts


def ray(pos, n, shift=(0, 0, 0)):
    return [pos[i] + shift[i] + POINT_OFFSET_M * n[i] for i in range(3)] + list(n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ab", type=int, default=8, help="ambient bounces of the reference")
    ap.add_argument("--ad", type=int, default=16384)
    ap.add_argument("--lw", type=float, default=1e-6)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "photomontage/tests/fixtures/peers/courtyard_radiance.json"))
    args = ap.parse_args()
    t0 = time.perf_counter()
    sun, el_deg, az_deg = sun_direction()
    ratio = horizontal_over_zenith(sun)
    zenith = SKY_HORIZONTAL / ratio
    folder = Path(tempfile.mkdtemp(prefix="courtyard_"))

    # Which points are clear of sun shadow edges: direct sun only, -ab 0, at the point and at
    # four neighbours EDGE_CLEARANCE_M away in the surface's plane.
    scene_files(folder, sun, zenith, with_sky=False)
    kept = []
    for pid, pos, n, (u, v) in candidate_points():
        shifts = [(0, 0, 0)] + [tuple(s * EDGE_CLEARANCE_M * w[i] for i in range(3))
                                for w in (u, v) for s in (1, -1)]
        e = [r[1] for r in rtrace(folder, [ray(pos, n, sh) for sh in shifts], ["-ab", "0"])]
        if max(e) - min(e) > 1e-6 * SUN_NORMAL:
            print(f"{pid}: near a sun shadow edge ({min(e):.1f}..{max(e):.1f}), dropped")
            continue
        kept.append((pid, pos, n, e[0]))

    # The sky's normalisation as Radiance sees it: an unobstructed point facing up, sky only.
    scene_files(folder, sun, zenith, with_sun=False)
    common = ["-aa", "0", "-as", "0", "-lw", str(args.lw), "-dj", "0", "-dt", "0", "-dc", "1",
              "-st", "0"]
    probe = rtrace(folder, [[0, 0, 900, 0, 0, 1]], ["-ab", "1", "-ad", "65536", *common])[0]

    scene_files(folder, sun, zenith)
    rays = [ray(pos, n) for _pid, pos, n, _s in kept]
    by_ab = {}
    for ab in (args.ab - 1, args.ab, args.ab + 1):
        t = time.perf_counter()
        by_ab[ab] = rtrace(folder, rays, ["-ab", str(ab), "-ad", str(args.ad), *common])
        print(f"-ab {ab}: {time.perf_counter() - t:.1f} s", flush=True)
    points = []
    worst = 0.0
    for k, (pid, pos, n, sun_direct) in enumerate(kept):
        ref, more = by_ab[args.ab], by_ab[args.ab + 1]
        change = max(abs(more[k][c] - ref[k][c]) / ref[k][c] for c in range(3))
        worst = max(worst, change)
        points.append({
            "id": pid, "position_m": list(pos), "normal": list(n),
            "irradiance_rgb": ref[k],
            "irradiance_rgb_one_bounce_less": by_ab[args.ab - 1][k],
            "irradiance_rgb_one_bounce_more": more[k],
            "direct_sun": sun_direct,
        })
        print(f"{pid:8s} E = {ref[k][0]:8.2f} {ref[k][1]:8.2f} {ref[k][2]:8.2f}   "
              f"-ab+1 {100 * change:.2f} %")
    print(f"{len(points)} points; largest change with one more bounce {100 * worst:.2f} %")
    out = {
        "peer": subprocess.run(["rtrace", "-version"], capture_output=True, text=True).stdout.strip(),
        "script": "peers/courtyard_radiance/courtyard_radiance.py",
        "options": {
            "rtrace": ["-I+", "-ab", str(args.ab), "-ad", str(args.ad), *common],
            "point_offset_m": POINT_OFFSET_M,
            "edge_clearance_m": EDGE_CLEARANCE_M,
            "largest_relative_change_one_more_bounce": worst,
        },
        "location": {"latitude_deg": LAT, "longitude_deg": LON, "elevation_m": ALT_M,
                     "local_time": WHEN, "utc_offset_h": 2, "delta_t_s": 69.0,
                     "temperature_c": 12.0, "pressure_pa": float(pvlib.atmosphere.alt2pres(ALT_M))},
        "sun": {"dir_in_world": sun, "elevation_deg": el_deg, "azimuth_deg": az_deg,
                "normal_irradiance": SUN_NORMAL, "diameter_deg": SUN_DIAMETER_DEG},
        "sky": {"cie_type": 12, "parameters": CIE12, "horizontal_irradiance": SKY_HORIZONTAL,
                "horizontal_over_zenith_radiance": ratio, "zenith_radiance": zenith,
                "rtrace_unobstructed_horizontal_rgb": probe},
        "materials_rgb": MATERIALS,
        "objects": [{"name": name, "material": mat, "quads_m": qs}
                    for name, (mat, qs) in objects().items()],
        "seconds": time.perf_counter() - t0,
        "points": points,
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", args.out, f"({out['seconds']:.0f} s); sky probe {probe} vs {SKY_HORIZONTAL}")


if __name__ == "__main__":
    main()
