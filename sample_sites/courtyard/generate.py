#!/usr/bin/env python3
"""Generate the `courtyard` sample site: a synthetic courtyard with three buildings and a wall,
three photos with known cameras, surveyed control points with noise, tie points and polygons.

Seeded and deterministic: running it again rewrites byte-identical files.
Needs numpy and pillow:  python3 -m venv .venv && .venv/bin/pip install numpy pillow
Usage: python3 generate.py   (writes site.toml, control_points.csv, truth.json, photos/*.png here)

World frame: Swiss LV95-like projected coordinates (E, N, H in metres), Z up. Camera frame and
pixel convention as in photomontage's `camera` module: x right, y down, z forward; pixel (0,0) is
the centre of the top-left pixel.
"""
import json
import math
import os

import numpy as np
from PIL import Image, ImageDraw

HERE = os.path.dirname(os.path.abspath(__file__))
ORIGIN = np.array([2683000.0, 1247000.0, 400.0])  # local origin of the generator's geometry
W, H = 1600, 1200
FOCAL_PX = 1500.0
K1, K2 = -0.04, 0.01
SIGMA_PX = 0.5
SIGMA_SURVEY_M = 0.01
RNG = np.random.default_rng(20261121)

# Boxes: (name, min corner, max corner, wall colour, material)
BOXES = [
    ("A", (2, 18, 0), (14, 28, 12), (196, 170, 140), "plaster"),
    ("B", (26, 16, 0), (38, 28, 9), (150, 80, 60), "brick"),
    ("C", (28, 2, 0), (38, 10, 15), (170, 172, 176), "concrete"),
    ("W", (2, 4, 0), (20, 4.4, 2.2), (120, 110, 100), "concrete"),
]
GROUND = [(0, 0, 0), (40, 0, 0), (40, 30, 0), (0, 30, 0)]
TERRAIN = [(-400, -400, -0.01), (400, -400, -0.01), (400, 400, -0.01), (-400, 400, -0.01)]

CAMERAS = {
    "P1": ((5.0, -22.0, 1.6), (20.0, 16.0, 5.0)),
    "P2": ((35.0, -20.0, 1.7), (18.0, 16.0, 5.0)),
    "P3": ((20.0, -34.0, 10.0), (20.0, 14.0, 3.0)),
}

CONTROL = {
    "A1": (2, 18, 0), "A2": (14, 18, 0), "A3": (2, 18, 12), "A4": (14, 18, 12),
    "B1": (26, 16, 0), "B2": (38, 16, 0), "B3": (26, 16, 9), "B4": (38, 16, 9),
    "C1": (28, 2, 0), "C2": (38, 2, 0), "C3": (28, 2, 15), "C4": (38, 2, 15), "C5": (28, 10, 15),
    "W1": (2, 4, 0), "W2": (20, 4, 0), "W3": (2, 4, 2.2), "W4": (20, 4, 2.2),
    "M1": (10, 10, 0), "M2": (22, 8, 0), "M3": (21, 13, 0),
    "G1": (0, 0, 0), "G2": (40, 0, 0), "G3": (40, 30, 0), "G4": (0, 30, 0),
}
# Window corners on the facades: observed in the photos but not surveyed.
TIE = {"T1": (5, 18, 6), "T2": (31, 16, 4.5), "T3": (33, 2, 7.5), "T4": (10, 18, 9)}


def look_at(center, target):
    c, t = np.array(center), np.array(target)
    z = t - c
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])  # world_from_camera: columns are camera axes


def project(cam, p):
    center, r = cam
    pc = r.T @ (np.asarray(p, float) - center)
    if pc[2] <= 0.05:
        return None
    x, y = pc[0] / pc[2], pc[1] / pc[2]
    r2 = x * x + y * y
    rad = 1 + K1 * r2 + K2 * r2 * r2
    return np.array([FOCAL_PX * x * rad + (W - 1) / 2, FOCAL_PX * y * rad + (H - 1) / 2])


def box_faces(lo, hi):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    return [
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],  # south (-y)
        [(x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)],  # north
        [(x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)],  # west
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],  # east
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # roof
    ]


def ray_blocked(origin, target):
    """Whether the segment origin→target passes through any box (slab test, small margin)."""
    d = np.array(target, float) - origin
    for _, lo, hi, _, _ in BOXES:
        lo_, hi_ = np.array(lo, float) + 1e-3, np.array(hi, float) - 1e-3
        with np.errstate(divide="ignore", invalid="ignore"):
            t1, t2 = (lo_ - origin) / d, (hi_ - origin) / d
        tmin = np.nanmax(np.minimum(t1, t2))
        tmax = np.nanmin(np.maximum(t1, t2))
        if tmax >= max(tmin, 0.0) and tmin < 1.0 - 1e-4:
            return True
    return False


def subdivide(poly, n=48):
    out = []
    for a, b in zip(poly, poly[1:] + poly[:1]):
        a, b = np.array(a, float), np.array(b, float)
        for i in range(n):
            out.append(a + (b - a) * i / n)
    return out


def shade(colour, normal):
    sun = np.array([0.4, -0.6, 0.7])
    sun /= np.linalg.norm(sun)
    k = 0.45 + 0.55 * max(0.0, float(np.dot(normal, sun)))
    return tuple(int(min(255, c * k)) for c in colour)


def clip_near(points_cam, near=0.1):
    """Sutherland-Hodgman clip of a camera-frame polygon against the plane z = near."""
    out = []
    for a, b in zip(points_cam, points_cam[1:] + points_cam[:1]):
        ina, inb = a[2] >= near, b[2] >= near
        if ina:
            out.append(a)
        if ina != inb:
            t = (near - a[2]) / (b[2] - a[2])
            out.append(a + (b - a) * t)
    return out


def project_cam(pc):
    x, y = pc[0] / pc[2], pc[1] / pc[2]
    r2 = x * x + y * y
    rad = 1 + K1 * r2 + K2 * r2 * r2
    return (FOCAL_PX * x * rad + (W - 1) / 2 + 0.5, FOCAL_PX * y * rad + (H - 1) / 2 + 0.5)


def draw_polygon(draw, cam, poly, colour):
    center, r = cam
    pts_cam = clip_near([r.T @ (p - center) for p in subdivide(poly)])
    if len(pts_cam) < 3:
        return
    draw.polygon([project_cam(p) for p in pts_cam], fill=colour)


def render(cam):
    img = Image.new("RGB", (W, H))
    draw = ImageDraw.Draw(img)
    for y in range(H):  # sky gradient
        t = y / H
        draw.line([(0, y), (W, y)], fill=(int(120 + 80 * t), int(160 + 60 * t), int(220 + 20 * t)))
    center = cam[0]
    draw_polygon(draw, cam, TERRAIN, (112, 124, 96))
    draw_polygon(draw, cam, GROUND, (92, 94, 90))
    for name in ("M1", "M2", "M3"):  # painted ground marks
        x, y, _ = CONTROL[name]
        draw_polygon(draw, cam, [(x - 0.3, y - 0.3, 0), (x + 0.3, y - 0.3, 0), (x + 0.3, y + 0.3, 0), (x - 0.3, y + 0.3, 0)], (235, 235, 230))
        draw_polygon(draw, cam, [(x - 0.3, y - 0.3, 0), (x, y - 0.3, 0), (x, y, 0), (x - 0.3, y, 0)], (30, 30, 30))
    faces = []
    for _, lo, hi, colour, _ in BOXES:
        for f in box_faces(lo, hi):
            a, b, c = (np.array(v, float) for v in f[:3])
            normal = np.cross(b - a, c - a)
            normal /= np.linalg.norm(normal)
            centroid = np.mean(np.array(f, float), axis=0)
            if np.dot(normal, center - centroid) <= 0:
                continue  # back face
            faces.append((np.linalg.norm(centroid - center), f, shade(colour, normal), normal))
    for _, f, colour, normal in sorted(faces, key=lambda t: -t[0]):
        draw_polygon(draw, cam, f, colour)
        if abs(normal[2]) < 0.5:  # windows on walls: a grid of darker panes
            a, b = np.array(f[0], float), np.array(f[1], float)
            top = f[2][2]
            length = np.linalg.norm(b - a)
            u = (b - a) / length
            for i in range(1, int(length // 3)):
                for z in np.arange(1.5, top - 1.0, 3.0):
                    p0 = a + u * (i * 3 - 0.7) + normal * 0.01
                    p1 = a + u * (i * 3 + 0.7) + normal * 0.01
                    pane = [(p0[0], p0[1], z), (p1[0], p1[1], z), (p1[0], p1[1], z + 1.4), (p0[0], p0[1], z + 1.4)]
                    draw_polygon(draw, cam, pane, tuple(int(c * 0.35) for c in colour))
    return img


def fmt(v):
    return repr(float(v))


def main():
    os.makedirs(os.path.join(HERE, "photos"), exist_ok=True)
    cams = {pid: (np.array(c, float), look_at(c, t)) for pid, (c, t) in CAMERAS.items()}
    survey = {k: np.array(v, float) + RNG.normal(0, SIGMA_SURVEY_M, 3) for k, v in CONTROL.items()}
    observations = []
    for pid, cam in cams.items():
        render(cam).save(os.path.join(HERE, "photos", f"{pid}.png"), optimize=True)
        for name, p in list(CONTROL.items()) + list(TIE.items()):
            px = project(cam, p)
            if px is None or not (20 <= px[0] <= W - 21 and 20 <= px[1] <= H - 21):
                continue
            if ray_blocked(cam[0], p):
                continue
            noisy = px + RNG.normal(0, SIGMA_PX, 2)
            observations.append([pid, name, noisy[0], noisy[1]])
    # One mislabelled observation: in P2 the point clicked as A3 is really A4.
    for o in observations:
        if o[0] == "P2" and o[1] == "A3":
            px = project(cams["P2"], CONTROL["A4"]) + RNG.normal(0, SIGMA_PX, 2)
            o[2], o[3] = px[0], px[1]

    lines = [
        "# Sample site generated by generate.py (seeded synthetic ground truth; see truth.json).",
        "schema_version = 1",
        'name = "Courtyard (synthetic)"',
        "",
        "[location]",
        "latitude_deg = 47.3769",
        "longitude_deg = 8.5417",
        "elevation_m = 400.0",
        'crs = "EPSG:2056"',
        "grid_convergence_deg = 0.0",
        "",
        "[lighting]",
        'time = "2024-06-21T15:00:00+02:00"',
        'sky_model = "cie_general:12"',
        "sun_weight = [1.0, 1.0, 1.0]",
        "ambient_weight = [0.0, 0.0, 0.0]",
        "sky_weight = [1.0, 1.0, 1.0]",
        "",
    ]
    for pid in cams:
        lines += [
            "[[photos]]", f'id = "{pid}"', f'file = "photos/{pid}.png"',
            'taken_at = "2024-06-21T15:00:00+02:00"', "",
            "[photos.interior]",
            "focal_px = 1450.0  # a rough guess; the solve refines it",
            f"image_size_px = [{W}, {H}]", "",
            "[photos.self_calibration]", "focal = true", "k1 = true", "",
        ]
    for name, p in survey.items():
        e = p + ORIGIN
        lines += ["[[control_points]]", f'id = "{name}"', f"xyz = [{fmt(round(e[0], 3))}, {fmt(round(e[1], 3))}, {fmt(round(e[2], 3))}]",
                  f"sigma_m = [{SIGMA_SURVEY_M}, {SIGMA_SURVEY_M}, {SIGMA_SURVEY_M}]", ""]
    for pid, name, x, y in observations:
        lines += ["[[observations]]", f'photo = "{pid}"', f'point = "{name}"', f"x_px = {round(x, 2)}", f"y_px = {round(y, 2)}", "sigma_px = 0.5", ""]
    polygons = [("ground", ["G1", "G2", "G3", "G4"], "asphalt"),
                ("A_south", ["A1", "A2", "A4", "A3"], "plaster"),
                ("B_south", ["B1", "B2", "B4", "B3"], "brick"),
                ("C_south", ["C1", "C2", "C4", "C3"], "concrete"),
                ("wall_south", ["W1", "W2", "W4", "W3"], "concrete")]
    for pid_, verts, mat in polygons:
        lines += ["[[polygons]]", f'id = "{pid_}"', "vertices = [" + ", ".join(f'"{v}"' for v in verts) + "]",
                  f'material = "{mat}"', 'image = "P1"', ""]
    with open(os.path.join(HERE, "site.toml"), "w") as f:
        f.write("\n".join(lines))
    with open(os.path.join(HERE, "control_points.csv"), "w") as f:
        f.write("id,X,Y,Z\n")
        for name, p in survey.items():
            e = p + ORIGIN
            f.write(f"{name},{e[0]:.3f},{e[1]:.3f},{e[2]:.3f}\n")
    truth = {
        "description": "True cameras and points of the courtyard sample site (world = EPSG:2056-like E,N,H metres)",
        "image_size_px": [W, H], "focal_px": FOCAL_PX, "distortion": {"k1": K1, "k2": K2},
        "sigma_px": SIGMA_PX, "sigma_survey_m": SIGMA_SURVEY_M,
        "mislabelled": {"photo": "P2", "point": "A3"},
        "cameras": {pid: {"camera_center": list(cams[pid][0] + ORIGIN),
                          "rotation_world_from_camera": cams[pid][1].tolist()} for pid in cams},
        "points": {k: list(np.array(v, float) + ORIGIN) for k, v in {**CONTROL, **TIE}.items()},
    }
    with open(os.path.join(HERE, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
    print(f"{len(observations)} observations written")


if __name__ == "__main__":
    main()
