#!/usr/bin/env python3
"""Generate the `street` sample site: a small street rendered by Mitsuba 3 (path tracing), with
ground truth for the differential renderer (issue 4, item 8).

What it writes here (seeded; rerunning rewrites the same geometry, noise and site file, and
renders that agree to Monte Carlo noise):
  site.toml            the site: 3 photos with their true interior orientation (no exterior: `solve`
                       computes it), control points with survey noise, observations with click
                       noise, scene polygons, the planned building as a [[models]] entry, [lighting]
  materials.toml       the material library (mean albedos of the textured surfaces)
  planned_building.obj/.mtl   the planned building (model coordinates, placed by site.toml)
  photos/V*.png        the "photos": renders WITHOUT the planned building (8-bit sRGB PNG)
  truth/V*.png         the same views WITH the planned building (the montage's ground truth)
  truth.json           true cameras, sun, sky, albedos, points and the file list
  control_points.csv   id,E,N,H of the surveyed points (as in site.toml)

Scene (local metres, +X east, +Y north (grid north), Z up; world = ORIGIN + local, Swiss LV95-like
E/N/H): a street running north between building A (west, brick, 15 m) and building B (east,
plaster, 11 m), closed by building C (concrete panels, 18 m) at its north end; a 1.8 m garden wall
in front of the empty lot south of B where the planned building (blue-grey cladding, 14 m) goes;
a 1 km paved ground square. Façade textures are per-pixel Lambertian albedo bitmaps made here
(bricks, plaster, panels, windows with frames); every material is Lambertian (Mitsuba `diffuse`),
so the photo value of a point is albedo/π times its irradiance, Durisch's (1992) model.

Light, in the photo's linear units (the conventions of the site file's [lighting]): sun = Mitsuba
`directional` emitter of normal irradiance SUN_IRRADIANCE (→ sun_weight); sky = `constant`
environment of radiance SKY_RADIANCE (a uniform sky; its horizontal irradiance π·L → sky_weight);
no ambient term; clear air, horizon colour = sky radiance (what a ray leaving the scene sees).
The sun direction (→ sun_manual) agrees within 0.1° with NREL SPA's for SUN_TIME at LOCATION
(`photomontage sun`; the values are pinned below, nothing here depends on SPA).

Cameras: pinhole, focal FOCAL_PX, principal point at the image centre ((W-1)/2, (H-1)/2 in the
convention "pixel (0,0) is the centre of the top-left pixel"), no distortion. Mitsuba: integrator
`path`, max_depth 4 (up to three bounces), independent sampler, box reconstruction filter, SPP
samples per pixel (--quick: 16). Radiance is written as the photo's linear values, sRGB-encoded
to 8 bits (no value exceeds 1: albedos ≤ 0.8).

Control points (surveyed: true position + N(0, SIGMA_SURVEY_M) per axis, rounded to 1 mm): the
corners of every box (A1-A8, ..., W1-W8: 1-4 bottom SW, SE, NE, NW, 5-8 above them), window-frame
corners on five façades (AE*, AS*, BW*, BS*, CS*) and the ground square's corners G1-G4 (500 m
away: polygon vertices, never observed). Observations: true projections + N(0, SIGMA_PX) px,
rounded to 0.01 px, for points inside the frame (margin MARGIN_PX) and not hidden by a building in
the photo (segment test against the boxes). Polygons: every box face but the bottom and the ground
square, counter-clockwise seen from outside; `image` is the view seeing the face largest.

Runtime: each 256-spp view takes minutes on 2 cores (llvm variant); --quick for a pipeline check.

Needs Mitsuba 3.9.1 / Dr.Jit 1.5.0, numpy and pillow:
  python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 drjit==1.5.0 numpy pillow
  venv/bin/python generate.py [--quick] [--variant llvm_ad_rgb|scalar_rgb] [--out DIR]
The llvm variant needs libLLVM >= 17 (Debian: apt-get install libllvm19); else use scalar_rgb.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
ORIGIN = np.array([2683400.0, 1247600.0, 408.0])  # local origin (LV95 E, N, H)
W, H = 1280, 960
FOCAL_PX = 1100.0
SIGMA_PX = 0.3
SIGMA_SURVEY_M = 0.01
MARGIN_PX = 4.0
SPP, SPP_QUICK, MAX_DEPTH, RENDER_SEED = 256, 16, 4, 0
SEED = 20261121

LOCATION = {"latitude_deg": 47.3769, "longitude_deg": 8.5417, "elevation_m": 408.0}
SUN_TIME = "2024-08-21T10:44:00+02:00"
# The rendered sun. NREL SPA (`photomontage sun --lat 47.3769 --lon 8.5417 --elevation-m 408`)
# puts the sun at azimuth 121.94°, elevation 40.57° (refracted) at SUN_TIME: within 0.1°. The site
# gives the sun as sun_manual, so nothing depends on SPA; grid convergence is taken as 0 (survey
# +Y = true north) for this synthetic site.
SUN_AZIMUTH_DEG, SUN_ELEVATION_DEG = 121.87, 40.62
SUN_IRRADIANCE = [3.0, 2.85, 2.6]    # normal irradiance of the sun, linear RGB
SKY_RADIANCE = [0.25, 0.32, 0.45]    # constant sky radiance, linear RGB

# Boxes (local): name, min corner, max corner, façade style, roof albedo
BOXES = [
    ("A", (-20.0, -25.0, 0.0), (-8.0, 25.0, 15.0), "brick"),
    ("B", (8.0, 5.0, 0.0), (22.0, 25.0, 11.0), "plaster"),
    ("C", (-12.0, 40.0, 0.0), (12.0, 52.0, 18.0), "concrete"),
    ("W", (6.6, -28.0, 0.0), (7.0, -2.0, 1.8), "stone"),
]
ROOF_ALBEDO = [0.22, 0.20, 0.19]
GROUND_HALF_M = 500.0
GROUND_TILE_M = 10.0

# Planned building: a box in model coordinates (origin at its south-west corner), placed by
# scale → rotation about Z (counter-clockwise seen from above) → translation, as site.toml says.
BUILDING_SIZE_M = (10.0, 14.0, 14.0)
BUILDING_ROT_Z_DEG = -8.0
BUILDING_TRANSLATION_LOCAL = (8.5, -21.0, 0.0)
BUILDING_ALBEDO = [0.30, 0.42, 0.55]

# Views: id, camera centre (local), look-at target (local), roll (deg, about the view axis)
VIEWS = [
    ("V1", (-3.0, -50.0, 1.6), (6.0, -2.0, 5.0), 0.0),
    ("V2", (-6.0, -44.0, 1.7), (9.0, -6.0, 5.5), 1.2),
    ("V3", (-5.0, -36.0, 9.0), (6.0, -6.0, 3.0), -0.8),
]

STYLES = {
    # base albedo (linear RGB), per-cell variation, cell size (w, h) m, joint albedo, joint m
    "brick": ((0.40, 0.17, 0.11), 0.15, (0.25, 0.075), (0.55, 0.53, 0.50), 0.012),
    "plaster": ((0.62, 0.56, 0.45), 0.04, (1.0, 1.0), None, 0.0),
    "concrete": ((0.48, 0.48, 0.46), 0.06, (2.5, 1.5), (0.30, 0.30, 0.29), 0.02),
    "stone": ((0.45, 0.43, 0.40), 0.10, (0.4, 0.3), (0.33, 0.32, 0.30), 0.015),
    "paving": ((0.30, 0.29, 0.27), 0.08, (0.5, 0.5), (0.22, 0.21, 0.20), 0.01),
}
WINDOW_GLASS = (0.05, 0.06, 0.07)
WINDOW_FRAME = (0.70, 0.70, 0.68)
TEXEL_M = 0.02


def rotation_look_at(center, target, roll_deg):
    """world_from_camera: columns x right, y down, z forward (photomontage's camera frame)."""
    z = np.asarray(target, float) - np.asarray(center, float)
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    r = np.column_stack([x, y, z])
    c, s = math.cos(math.radians(roll_deg)), math.sin(math.radians(roll_deg))
    return r @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def project(center, r, p):
    pc = r.T @ (np.asarray(p, float) - np.asarray(center, float))
    if pc[2] <= 0.1:
        return None
    return np.array([FOCAL_PX * pc[0] / pc[2] + (W - 1) / 2, FOCAL_PX * pc[1] / pc[2] + (H - 1) / 2])


def box_corners(lo, hi):
    """1-4 bottom (SW, SE, NE, NW), 5-8 top, same order."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
            (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]


# Faces as (name, corner indices (1-based) counter-clockwise seen from outside: origin, +u, +u+v, +v)
BOX_FACES = [("south", (1, 2, 6, 5)), ("east", (2, 3, 7, 6)), ("north", (3, 4, 8, 7)),
             ("west", (4, 1, 5, 8)), ("roof", (5, 6, 7, 8))]


def face_frame(name, face):
    """Origin (bottom-left seen from outside), unit u (along the bottom edge) and its width,
    height of a box's vertical face."""
    for n, lo, hi, _ in BOXES:
        if n == name:
            c = [np.array(p, float) for p in box_corners(lo, hi)]
            idx = dict(BOX_FACES)[face]
            o, a = c[idx[0] - 1], c[idx[1] - 1] - c[idx[0] - 1]
            return o, a / np.linalg.norm(a), np.linalg.norm(a), hi[2] - lo[2]
    raise KeyError(name)


# Window corners surveyed as control points (the outer frame's bottom-left and top-right corners
# of the first and last window of the lowest and highest storey): façade, point-id prefix.
WINDOW_TARGETS = [("A", "east", "AE"), ("A", "south", "AS"), ("B", "west", "BW"),
                  ("B", "south", "BS"), ("C", "south", "CS")]


def window_points():
    pts = {}
    for name, face, prefix in WINDOW_TARGETS:
        style = next(b[3] for b in BOXES if b[0] == name)
        o, u, width, height = face_frame(name, face)
        rects = window_rects(WINDOWS[style], width, height)
        if not rects:
            continue
        zs = sorted({r[1] for r in rects})
        xs = sorted({r[0] for r in rects})
        k = 1
        for z0 in (zs[0], zs[-1]):
            for x0 in (xs[0], xs[-1]):
                r = next(r for r in rects if r[0] == x0 and r[1] == z0)
                for dx, dz in ((0.0, 0.0), (r[2], r[3])):
                    pts[f"{prefix}{k}"] = o + u * (r[0] + dx) + np.array([0.0, 0.0, r[1] + dz])
                    k += 1
    return pts


def building_corners_local():
    sx, sy, sz = BUILDING_SIZE_M
    c, s = math.cos(math.radians(BUILDING_ROT_Z_DEG)), math.sin(math.radians(BUILDING_ROT_Z_DEG))
    t = np.array(BUILDING_TRANSLATION_LOCAL)
    out = []
    for p in box_corners((0, 0, 0), (sx, sy, sz)):
        out.append(t + np.array([c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]]))
    return out


# ------------------------------------------------------------------ textures (linear albedo)
WINDOW_FRAME_M = 0.08


def window_rects(windows, width_m, height_m):
    """Window frames (x0, z0, width, height) in metres from the façade's bottom-left corner, as
    seen from outside; storeys of equal height, columns centred on the façade."""
    if not windows:
        return []
    storey, win_w, win_h, sill, pitch = windows
    n_cols = int((width_m - 1.0) // pitch)
    x_start = (width_m - (n_cols - 1) * pitch) / 2
    out = []
    for k in range(int(height_m // storey)):
        z0 = k * storey + sill
        if z0 + win_h > height_m - 0.3:
            break
        out += [(x_start + j * pitch - win_w / 2, z0, win_w, win_h) for j in range(n_cols)]
    return out


def texture(style, width_m, height_m, rng, windows):
    """Albedo bitmap (rows top to bottom) of a façade or ground patch of the given size."""
    base, var, (cw, ch), joint, joint_m = STYLES[style]
    w_px, h_px = max(2, round(width_m / TEXEL_M)), max(2, round(height_m / TEXEL_M))
    xs = (np.arange(w_px) + 0.5) * TEXEL_M
    zs = height_m - (np.arange(h_px) + 0.5) * TEXEL_M  # height above the bottom edge
    row = np.floor(zs / ch).astype(int)
    # running bond: odd courses shifted by half a cell
    xx = xs[None, :] + (row[:, None] % 2) * cw / 2
    col = np.floor(xx / cw).astype(int)
    ncol, nrow = col.max() + 2, row.max() + 2
    cell_gain = 1.0 + var * rng.uniform(-1.0, 1.0, size=(nrow, ncol))
    img = np.asarray(base)[None, None, :] * cell_gain[row[:, None].repeat(w_px, 1), col][..., None]
    img *= 1.0 + 0.02 * rng.standard_normal((h_px, w_px))[..., None]  # fine grain
    if joint is not None:
        fx = xx - col * cw
        fz = zs[:, None] - row[:, None] * ch
        mask = (fx < joint_m) | (fz < joint_m)
        img[mask] = joint
    for x0, z0, win_w, win_h in window_rects(windows, width_m, height_m):
        m = ((xs[None, :] >= x0) & (xs[None, :] < x0 + win_w)
             & (zs[:, None] >= z0) & (zs[:, None] < z0 + win_h))
        img[m] = WINDOW_FRAME
        f = WINDOW_FRAME_M
        inner = ((xs[None, :] >= x0 + f) & (xs[None, :] < x0 + win_w - f)
                 & (zs[:, None] >= z0 + f) & (zs[:, None] < z0 + win_h - f))
        img[inner] = WINDOW_GLASS
    return np.clip(img, 0.0, 0.8).astype(np.float32)


WINDOWS = {"brick": (3.6, 1.3, 1.8, 0.9, 3.2), "plaster": (3.4, 1.2, 1.6, 1.0, 2.8),
           "concrete": (3.6, 2.0, 1.9, 0.8, 3.0), "stone": None}


# ------------------------------------------------------------------ Mitsuba scene
def rect_to_world(mi, p0, p1, p3):
    """Mitsuba `rectangle` ([-1,1]², normal +Z) onto the parallelogram p0, p1 (=p0+u), p3 (=p0+v)."""
    p0, p1, p3 = (np.asarray(p, float) for p in (p0, p1, p3))
    u, v = p1 - p0, p3 - p0
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    c = p0 + (u + v) / 2
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, c
    return mi.ScalarTransform4f(m.tolist())


def bitmap_bsdf(mi, img, to_uv=None):
    tex = {"type": "bitmap", "bitmap": mi.Bitmap(img), "raw": True, "filter_type": "bilinear",
           "wrap_mode": "repeat"}
    if to_uv is not None:
        tex["to_uv"] = to_uv
    return {"type": "diffuse", "reflectance": tex}


def rgb_bsdf(rgb):
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(rgb)}}


def flip_v(img):
    """Mitsuba's bitmap texture puts row 0 at v = 0 (the rectangle's -Y edge, our bottom)."""
    return np.ascontiguousarray(img[::-1])


def build_scene_dict(mi, textures, view, spp, with_building):
    _, center, target, roll = view
    r = rotation_look_at(center, target, roll)
    up = -r[:, 1]
    fov_x = 2 * math.degrees(math.atan(W / 2 / FOCAL_PX))
    T = mi.ScalarTransform4f
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH},
        "sensor": {
            "type": "perspective", "fov": fov_x, "fov_axis": "x",
            "to_world": T().look_at(origin=list(center), target=list(np.asarray(center) + r[:, 2]),
                                    up=list(up)),
            "sampler": {"type": "independent", "sample_count": spp, "seed": RENDER_SEED},
            "film": {"type": "hdrfilm", "width": W, "height": H, "pixel_format": "rgb",
                     "component_format": "float32", "rfilter": {"type": "box"}},
        },
        "sun": {"type": "directional", "direction": [-v for v in sun_dir()],
                "irradiance": {"type": "rgb", "value": SUN_IRRADIANCE}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": SKY_RADIANCE}},
        "ground": {"type": "rectangle", "to_world": T().scale([GROUND_HALF_M, GROUND_HALF_M, 1.0]),
                   "bsdf": bitmap_bsdf(mi, flip_v(textures["ground"]),
                                       T().scale([2 * GROUND_HALF_M / GROUND_TILE_M] * 2 + [1.0]))},
    }
    for name, lo, hi, style in BOXES:
        c = box_corners(lo, hi)
        for face, idx in BOX_FACES:
            p = [c[i - 1] for i in idx]
            bsdf = rgb_bsdf(ROOF_ALBEDO) if face == "roof" else bitmap_bsdf(mi, flip_v(textures[f"{name}_{face}"]))
            d[f"{name}_{face}"] = {"type": "rectangle", "to_world": rect_to_world(mi, p[0], p[1], p[3]),
                                   "bsdf": bsdf}
    if with_building:
        c = building_corners_local()
        for face, idx in BOX_FACES:
            p = [c[i - 1] for i in idx]
            d[f"planned_{face}"] = {"type": "rectangle", "to_world": rect_to_world(mi, p[0], p[1], p[3]),
                                    "bsdf": rgb_bsdf(BUILDING_ALBEDO)}
    return d


def sun_dir():
    el, az = math.radians(SUN_ELEVATION_DEG), math.radians(SUN_AZIMUTH_DEG)
    return [math.cos(el) * math.sin(az), math.cos(el) * math.cos(az), math.sin(el)]


def srgb_encode(lin):
    lin = np.clip(lin, 0.0, 1.0)
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)


def write_png(path, lin):
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray((srgb_encode(lin) * 255.0 + 0.5).astype(np.uint8)).save(path, optimize=True)


def pick_libllvm():
    """Newest libLLVM >= 17 known to ldconfig (Dr.Jit's LLVM backend), unless already set."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return
    try:
        lines = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True).stdout.splitlines()
    except OSError:
        return
    best = None
    for line in lines:
        m = re.search(r"libLLVM[-.](?:so\.)?(\d+)[^ ]* .*=> (\S+)", line)
        if m and int(m.group(1)) >= 17 and (best is None or int(m.group(1)) > best[0]):
            best = (int(m.group(1)), m.group(2))
    if best:
        os.environ["DRJIT_LIBLLVM_PATH"] = best[1]


# ------------------------------------------------------------------ visibility (photos: no building)
def segment_blocked(origin, target):
    o = np.asarray(origin, float)
    d = np.asarray(target, float) - o
    for _, lo, hi, _ in BOXES:
        lo_, hi_ = np.array(lo) + 1e-3, np.array(hi) - 1e-3
        with np.errstate(divide="ignore", invalid="ignore"):
            t1, t2 = (lo_ - o) / d, (hi_ - o) / d
        tmin = np.nanmax(np.minimum(t1, t2))
        tmax = np.nanmin(np.maximum(t1, t2))
        if tmax >= max(tmin, 0.0) and tmin < 1.0 - 1e-4:
            return True
    return False


def fmt(x, nd):
    return repr(round(float(x), nd))


def vec(v, nd):
    return "[" + ", ".join(fmt(x, nd) for x in v) + "]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help=f"{SPP_QUICK} spp instead of {SPP}")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--out", type=Path, default=HERE)
    ap.add_argument("--no-render", action="store_true", help="write the site files only")
    args = ap.parse_args()
    spp = SPP_QUICK if args.quick else SPP
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)

    # ---- points: box corners (surveyed), ground corners, planned building corners (truth only)
    points = {}
    for name, lo, hi, _ in BOXES:
        for i, p in enumerate(box_corners(lo, hi), 1):
            points[f"{name}{i}"] = np.array(p, float)
    points.update(window_points())
    g = GROUND_HALF_M
    for i, p in enumerate([(-g, -g, 0), (g, -g, 0), (g, g, 0), (-g, g, 0)], 1):
        points[f"G{i}"] = np.array(p, float)
    surveyed = {k: v + rng.normal(0.0, SIGMA_SURVEY_M, 3) for k, v in points.items()}

    cameras = {}
    observations = []
    for vid, center, target, roll in VIEWS:
        r = rotation_look_at(center, target, roll)
        cameras[vid] = (np.array(center, float), r)
        for pid, p in points.items():
            px = project(center, r, p)
            if px is None or not (MARGIN_PX <= px[0] <= W - 1 - MARGIN_PX and MARGIN_PX <= px[1] <= H - 1 - MARGIN_PX):
                continue
            if pid.startswith("G") or segment_blocked(center, p):
                continue  # the ground's corners are 500 m away: surveyed extents, not targets
            noisy = px + rng.normal(0.0, SIGMA_PX, 2)
            observations.append((vid, pid, noisy))

    # ---- textures (drawn from the same seeded generator, after the noise)
    textures = {"ground": texture("paving", GROUND_TILE_M, GROUND_TILE_M, rng, None)}
    for name, lo, hi, style in BOXES:
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        for face, width in (("south", x1 - x0), ("east", y1 - y0), ("north", x1 - x0), ("west", y1 - y0)):
            textures[f"{name}_{face}"] = texture(style, width, z1 - z0, rng, WINDOWS[style])
    mean_albedo = {k: v.reshape(-1, 3).mean(0).tolist() for k, v in textures.items()}

    write_site(out, surveyed, observations, mean_albedo)
    write_obj(out)
    files = {"photos": {v[0]: f"photos/{v[0]}.png" for v in VIEWS},
             "truth": {v[0]: f"truth/{v[0]}.png" for v in VIEWS}}
    render_info = {}
    if args.no_render and (out / "truth.json").exists():
        render_info = json.loads((out / "truth.json").read_text()).get("render", {})
    if not args.no_render:
        if args.variant.startswith("llvm"):
            pick_libllvm()
        import drjit as dr
        import mitsuba as mi
        mi.set_variant(args.variant)
        render_info = {"renderer": "mitsuba", "version": mi.__version__, "drjit": dr.__version__,
                       "variant": args.variant, "integrator": "path", "max_depth": MAX_DEPTH,
                       "spp": spp, "seed": RENDER_SEED, "sampler": "independent",
                       "reconstruction_filter": "box", "seconds": {}}
        for view in VIEWS:
            for with_building, folder in ((False, "photos"), (True, "truth")):
                t0 = time.perf_counter()
                scene = mi.load_dict(build_scene_dict(mi, textures, view, spp, with_building))
                img = np.array(mi.render(scene, spp=spp, seed=RENDER_SEED))
                secs = time.perf_counter() - t0
                write_png(out / folder / f"{view[0]}.png", img)
                render_info["seconds"][f"{folder}/{view[0]}"] = round(secs, 1)
                print(f"{folder}/{view[0]}.png: {spp} spp in {secs:.1f} s, max {img.max():.3f}", flush=True)
    write_truth(out, points, cameras, mean_albedo, files, render_info)


def polygon_views(corner_pts, n=24):
    """Views seeing the polygon, best first, by its visible projected area: a grid of n x n
    samples, each in front, in frame and unoccluded, weighted by its pixel footprint."""
    p = [np.asarray(c, float) for c in corner_pts]
    normal = np.cross(p[1] - p[0], p[-1] - p[0])
    normal /= np.linalg.norm(normal)
    res = []
    for vid, center, target, roll in VIEWS:
        r = rotation_look_at(center, target, roll)
        score = 0.0
        for i in range(n):
            for j in range(n):
                a, b = (i + 0.5) / n, (j + 0.5) / n
                q = p[0] + a * (p[1] - p[0]) + b * (p[-1] - p[0])
                to_cam = np.asarray(center) - q
                dist = np.linalg.norm(to_cam)
                cos = float(np.dot(to_cam, normal)) / dist
                px = project(center, r, q)
                if cos <= 0 or px is None or not (0 <= px[0] < W and 0 <= px[1] < H):
                    continue
                if segment_blocked(center, q + normal * 1e-2):
                    continue
                score += cos / dist ** 2
        if score > 0:
            res.append((score, vid))
    return [v for _, v in sorted(res, reverse=True)]


WINDOW_POINTS = window_points()
MATERIAL_OF = {"brick": "brick_facade", "plaster": "plaster_facade", "concrete": "concrete_panels",
               "stone": "stone_wall"}


def write_site(out, surveyed, observations, mean_albedo):
    L = []
    a = L.append
    a("# Sample site generated by generate.py (Mitsuba 3 renders with ground truth; see truth.json).")
    a("schema_version = 1")
    a('name = "Street (Mitsuba-rendered, synthetic)"')
    a("")
    a("[location]")
    a(f"latitude_deg = {LOCATION['latitude_deg']}")
    a(f"longitude_deg = {LOCATION['longitude_deg']}")
    a(f"elevation_m = {LOCATION['elevation_m']}")
    a('crs = "EPSG:2056"')
    a("grid_convergence_deg = 0.0")
    a("")
    a("[lighting]")
    a(f'time = "{SUN_TIME}"')
    a(f"sun_manual = {{ azimuth_deg = {SUN_AZIMUTH_DEG}, elevation_deg = {SUN_ELEVATION_DEG} }}")
    a('sky_model = "uniform"')
    a(f"sun_weight = {vec(SUN_IRRADIANCE, 6)}  # normal irradiance of the sun")
    a(f"ambient_weight = [0.0, 0.0, 0.0]")
    a(f"sky_weight = {vec([math.pi * x for x in SKY_RADIANCE], 6)}  # pi x sky radiance {SKY_RADIANCE}")
    a('material_library = "materials.toml"')
    a("")
    a("[lighting.atmosphere]  # clear air; rays leaving the scene see the uniform sky's radiance")
    a("extinction_per_m = [0.0, 0.0, 0.0]")
    a(f"horizon_colour = {vec(SKY_RADIANCE, 6)}")
    for vid, _, _, _ in VIEWS:
        a("")
        a("[[photos]]")
        a(f'id = "{vid}"')
        a(f'file = "photos/{vid}.png"')
        a(f'taken_at = "{SUN_TIME}"')
        a("")
        a("[photos.interior]")
        a(f"focal_px = {FOCAL_PX}")
        a(f"principal_point_px = [{(W - 1) / 2}, {(H - 1) / 2}]")
        a(f"image_size_px = [{W}, {H}]")
    for pid, p in surveyed.items():
        a("")
        a("[[control_points]]")
        a(f'id = "{pid}"')
        a(f"xyz = {vec(ORIGIN + p, 3)}")
        a(f"sigma_m = [{SIGMA_SURVEY_M}, {SIGMA_SURVEY_M}, {SIGMA_SURVEY_M}]")
    for vid, pid, px in observations:
        a("")
        a("[[observations]]")
        a(f'photo = "{vid}"')
        a(f'point = "{pid}"')
        a(f"x_px = {fmt(px[0], 2)}")
        a(f"y_px = {fmt(px[1], 2)}")
        a(f"sigma_px = {SIGMA_PX}")
    polys = [("ground", ["G1", "G2", "G3", "G4"], "paving")]
    for name, lo, hi, style in BOXES:
        for face, idx in BOX_FACES:
            mat = "roof" if face == "roof" else MATERIAL_OF[style]
            polys.append((f"{name}_{face}", [f"{name}{i}" for i in idx], mat))
    for pid, verts, mat in polys:
        a("")
        a("[[polygons]]")
        a(f'id = "{pid}"')
        a("vertices = [" + ", ".join(f'"{v}"' for v in verts) + "]")
        a(f'material = "{mat}"')
        # the ground's far corners are behind every camera: its image is the first view
        views = [VIEWS[0][0]] if pid == "ground" else polygon_views([surveyed_true(v) for v in verts])
        if views:
            a(f'image = "{views[0]}"')
    a("")
    a("[[models]]")
    a('id = "planned"')
    a('file = "planned_building.obj"')
    a('units = "m"')
    a('up_axis = "z"')
    a("")
    a("[models.placement]")
    a(f"translation = {vec(ORIGIN + np.array(BUILDING_TRANSLATION_LOCAL), 3)}")
    a(f"rotation_z_deg = {BUILDING_ROT_Z_DEG}")
    a("scale = 1.0")
    (out / "site.toml").write_text("\n".join(L) + "\n")
    with open(out / "control_points.csv", "w") as f:
        f.write("id,E,N,H\n")
        for pid, p in surveyed.items():
            e, n, h = ORIGIN + p
            f.write(f"{pid},{e:.3f},{n:.3f},{h:.3f}\n")

    # material library: mean albedo of each textured surface family
    fam = {}
    for name, _, _, style in BOXES:
        for face in ("south", "east", "north", "west"):
            fam.setdefault(MATERIAL_OF[style], []).append(mean_albedo[f"{name}_{face}"])
    M = ["# Material library of the street sample site (generate.py). Linear Lambertian albedos:",
         "# the mean of each family's procedural texture (façades have windows and joints; the",
         "# renderer recovers the per-pixel albedo of natural surfaces from the photos).", ""]
    entries = [("paving", mean_albedo["ground"]), ("roof", ROOF_ALBEDO)]
    entries += [(k, np.mean(v, axis=0).tolist()) for k, v in fam.items()]
    entries.append(("cladding", BUILDING_ALBEDO))
    for k, v in entries:
        M += ["[[material]]", f'name = "{k}"', f"diffuse_rgb = {vec(v, 4)}", ""]
    (out / "materials.toml").write_text("\n".join(M))


def surveyed_true(pid):
    """True local coordinates of a named corner (box corners and ground corners)."""
    if pid in WINDOW_POINTS:
        return WINDOW_POINTS[pid]
    for name, lo, hi, _ in BOXES:
        if pid.startswith(name) and pid[len(name):].isdigit():
            return np.array(box_corners(lo, hi)[int(pid[len(name):]) - 1], float)
    g = GROUND_HALF_M
    return np.array([(-g, -g, 0), (g, -g, 0), (g, g, 0), (-g, g, 0)][int(pid[1:]) - 1], float)


def write_obj(out):
    sx, sy, sz = BUILDING_SIZE_M
    c = box_corners((0, 0, 0), (sx, sy, sz))
    L = ["# Planned building of the street sample site (generate.py): a 10 x 14 x 14 m block,",
         "# model coordinates in metres, Z up, origin at the south-west ground corner.",
         "mtllib planned_building.mtl", "o planned_building"]
    L += [f"v {p[0]:.3f} {p[1]:.3f} {p[2]:.3f}" for p in c]
    L.append("usemtl cladding")
    for _, idx in BOX_FACES:
        L.append("f " + " ".join(str(i) for i in idx))
    (out / "planned_building.obj").write_text("\n".join(L) + "\n")
    (out / "planned_building.mtl").write_text(
        "# Lambertian blue-grey cladding (linear albedo)\nnewmtl cladding\n"
        f"Kd {BUILDING_ALBEDO[0]:.2f} {BUILDING_ALBEDO[1]:.2f} {BUILDING_ALBEDO[2]:.2f}\n"
        "Ks 0.00 0.00 0.00\nillum 1\n")


def write_truth(out, points, cameras, mean_albedo, files, render_info):
    truth = {
        "description": "Ground truth of the street sample site (generate.py). World = origin + local; "
                       "camera frame x right, y down, z forward; pixel (0,0) = centre of the top-left pixel.",
        "origin": ORIGIN.tolist(),
        "cameras": {vid: {"camera_center": (ORIGIN + c).tolist(),
                          "rotation_world_from_camera": r.tolist(),
                          "focal_px": FOCAL_PX, "principal_point_px": [(W - 1) / 2, (H - 1) / 2],
                          "image_size_px": [W, H], "distortion": "none"}
                    for vid, (c, r) in cameras.items()},
        "sun": {"azimuth_deg": SUN_AZIMUTH_DEG, "elevation_deg": SUN_ELEVATION_DEG,
                "direction_to_sun": sun_dir(), "normal_irradiance_rgb": SUN_IRRADIANCE,
                "time": SUN_TIME, "location": LOCATION},
        "sky": {"model": "uniform (Mitsuba constant environment, whole sphere)",
                "radiance_rgb": SKY_RADIANCE, "sky_weight": [math.pi * x for x in SKY_RADIANCE]},
        "ambient_weight": [0.0, 0.0, 0.0],
        "albedos": {"mean_texture_rgb": mean_albedo, "roof_rgb": ROOF_ALBEDO,
                    "window_glass_rgb": WINDOW_GLASS, "window_frame_rgb": WINDOW_FRAME,
                    "planned_building_rgb": BUILDING_ALBEDO},
        "planned_building": {"obj": "planned_building.obj", "size_m": BUILDING_SIZE_M,
                             "rotation_z_deg": BUILDING_ROT_Z_DEG,
                             "translation": (ORIGIN + np.array(BUILDING_TRANSLATION_LOCAL)).tolist(),
                             "corners": [(ORIGIN + p).tolist() for p in building_corners_local()]},
        "points": {k: (ORIGIN + v).tolist() for k, v in points.items()},
        "noise": {"sigma_px": SIGMA_PX, "sigma_survey_m": SIGMA_SURVEY_M, "seed": SEED},
        "render": render_info,
        "files": files,
    }
    (out / "truth.json").write_text(json.dumps(truth, indent=1) + "\n")


if __name__ == "__main__":
    main()
