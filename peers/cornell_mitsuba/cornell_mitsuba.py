"""Diffuse Cornell box (lighting.md §5.2 geometry, Tungsten's RGB reflectances) path traced by
Mitsuba 3: patch-mean irradiance on every face, one `irradiancemeter` sensor per patch.

The box is the Cornell Program of Computer Graphics data set converted to metres (x, y, z kept;
y is up); the lamp is lowered to y = 0.548 m (0.8 mm below the ceiling) so that lamp and
ceiling are not coplanar. The floor and the back wall are cut into 2 x 2 quarters so that the
comparison also sees the light's position, not only face totals. Every face is one-sided
(Mitsuba's `diffuse` BSDF reflects from the front only), normals point into the room.

An `irradiancemeter` attached to a shape samples points uniformly on it and cosine-weighted
directions about its normal; its value is the patch-mean irradiance E = (1/A) ∫_A ∫ L cos θ dω dA.
Each patch is rendered in `passes` independent passes (seeds 0..passes-1) of `spp` samples on a
1 x 1 film; the JSON records the mean and the standard error of the mean over the passes.

Usage: python cornell_mitsuba.py [--spp N] [--passes K] [--variant V] [--out FILE.json]
"""
import argparse
import json
import math
import time
from pathlib import Path

import mitsuba as mi

MM = 1e-3
WHITE = [0.725, 0.71, 0.68]
RED = [0.63, 0.065, 0.05]
GREEN = [0.14, 0.45, 0.091]
LAMP_RADIANCE = [17.0, 12.0, 4.0]
LAMP_Y_M = 0.548


def quad(a, b, c, d):
    """Vertices (metres) of a quad whose normal is (b - a) x (c - a), counter-clockwise."""
    return [[v * MM for v in p] for p in (a, b, c, d)]


def split4(q):
    """A planar quad a b c d cut into 2 x 2 quads (bilinear midpoints), same orientation."""
    a, b, c, d = q
    mid = lambda p, r: [(p[i] + r[i]) / 2 for i in range(3)]
    ab, bc, cd, da = mid(a, b), mid(b, c), mid(c, d), mid(d, a)
    o = mid(ab, cd)
    return [[a, ab, o, da], [ab, b, bc, o], [o, bc, c, cd], [da, o, cd, d]]


def block(top, bottom_y):
    """The top and four sides of a block whose top quad is `top` (counter-clockwise seen from
    above, i.e. normal +y) at its height, down to y = bottom_y."""
    faces = [("top", top)]
    n = len(top)
    for k in range(n):
        p, q = top[k], top[(k + 1) % n]
        faces.append(
            (f"side{k}", [q, p, [p[0], bottom_y, p[2]], [q[0], bottom_y, q[2]]])
        )
    return faces


def normal(q):
    a, b, c = q[0], q[1], q[2]
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    s = math.sqrt(sum(x * x for x in n))
    return [x / s for x in n]


def patches():
    """(name, material, quad in metres, is_lamp) for every surface of the box."""
    floor = quad((552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2))
    ceiling = quad((556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0))
    back = quad((549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2))
    right = quad((0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2))
    left = quad((552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0))
    lamp = quad((343, 548.0, 227), (343, 548.0, 332), (213, 548.0, 332), (213, 548.0, 227))
    # Orient every face into the room (the data set's vertex order varies).
    centre = [0.278, 0.274, 0.28]
    out = []

    def add(name, mat, q, lamp=False):
        n = normal(q)
        a = q[0]
        to_centre = [centre[i] - a[i] for i in range(3)]
        if sum(n[i] * to_centre[i] for i in range(3)) < 0 and not lamp:
            q = list(reversed(q))
        if lamp and normal(q)[1] > 0:
            q = list(reversed(q))
        out.append((name, mat, q, lamp))

    for k, q in enumerate(split4(floor)):
        add(f"floor{k}", "white", q)
    add("ceiling", "white", ceiling)
    for k, q in enumerate(split4(back)):
        add(f"back{k}", "white", q)
    add("right_green", "green", right)
    add("left_red", "red", left)
    add("lamp", "lamp", lamp, lamp=True)
    short = quad((130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114))
    tall = quad((423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406))
    for block_name, top in (("short", short), ("tall", tall)):
        if normal(top)[1] < 0:
            top = list(reversed(top))
        for face, q in block(top, 0.0):
            # Block faces point out of the block.
            out.append((f"{block_name}_{face}", "white", q, False))
    return out


def write_obj(path, q):
    """A quad as a two-triangle OBJ (vertex order kept, so the normal is kept)."""
    with open(path, "w") as f:
        for p in q:
            f.write("v %.9f %.9f %.9f\n" % tuple(p))
        f.write("f 1 2 3\nf 1 3 4\n")


def build_scene(patch_list, folder, meter):
    """The scene dict with an irradiancemeter on patch `meter` (index into patch_list)."""
    rgb = lambda v: {"type": "rgb", "value": v}
    bsdfs = {
        "white": {"type": "diffuse", "reflectance": rgb(WHITE)},
        "red": {"type": "diffuse", "reflectance": rgb(RED)},
        "green": {"type": "diffuse", "reflectance": rgb(GREEN)},
        "lamp": {"type": "diffuse", "reflectance": rgb([0.0, 0.0, 0.0])},
    }
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5}}
    for k, (name, mat, _q, lamp) in enumerate(patch_list):
        shape = {
            "type": "obj",
            "filename": str(folder / f"{name}.obj"),
            "face_normals": True,
            "bsdf": bsdfs[mat],
        }
        if lamp:
            shape["emitter"] = {"type": "area", "radiance": rgb(LAMP_RADIANCE)}
        if k == meter:
            shape["sensor"] = {
                "type": "irradiancemeter",
                "film": {
                    "type": "hdrfilm",
                    "width": 1,
                    "height": 1,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
            }
        scene[name] = shape
    return scene


def area(q):
    """Area of a planar quad (two triangles)."""
    def tri(a, b, c):
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        return 0.5 * math.sqrt(sum(x * x for x in n))
    return tri(q[0], q[1], q[2]) + tri(q[0], q[2], q[3])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=1048576, help="samples per pass (>= 4096)")
    ap.add_argument("--passes", type=int, default=16, help="independent passes per patch")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--only", default=None, help="comma-separated patch names (testing)")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "photomontage/tests/fixtures/peers/cornell_mitsuba.json"))
    args = ap.parse_args()
    mi.set_variant(args.variant)
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="cornell_"))
    plist = patches()
    for name, _m, q, _l in plist:
        write_obj(folder / f"{name}.obj", q)
    wanted = set(args.only.split(",")) if args.only else None
    rows = []
    t0 = time.perf_counter()
    for k, (name, mat, q, lamp) in enumerate(plist):
        if lamp or (wanted and name not in wanted):
            continue
        scene = mi.load_dict(build_scene(plist, folder, k))
        values = []
        for seed in range(args.passes):
            img = mi.render(scene, spp=args.spp, seed=seed)
            values.append([float(x) for x in mi.TensorXf(img).numpy().reshape(-1)[:3]])
        mean = [sum(v[c] for v in values) / len(values) for c in range(3)]
        sem = [
            math.sqrt(sum((v[c] - mean[c]) ** 2 for v in values) / (len(values) - 1) / len(values))
            for c in range(3)
        ] if len(values) > 1 else [float("nan")] * 3
        rows.append({
            "name": name,
            "material": mat,
            "vertices_m": q,
            "area_m2": area(q),
            "normal": normal(q),
            "irradiance_rgb": mean,
            "standard_error_rgb": sem,
        })
        print(f"{name:14s} E = {mean[0]:.5f} {mean[1]:.5f} {mean[2]:.5f}  "
              f"sem {100 * max(s / m for s, m in zip(sem, mean) if m > 0):.3f} %", flush=True)
    out = {
        "peer": "Mitsuba " + mi.__version__,
        "script": "peers/cornell_mitsuba/cornell_mitsuba.py",
        "options": {
            "variant": args.variant,
            "integrator": "path, max_depth -1, rr_depth 5",
            "spp_per_pass": args.spp,
            "passes": args.passes,
            "sensor": "irradiancemeter on each patch (patch-mean irradiance)",
        },
        "units": "irradiance in the lamp's radiance units x sr (lamp radiance 17, 12, 4)",
        "materials_rgb": {"white": WHITE, "red": RED, "green": GREEN, "lamp_reflectance": [0, 0, 0]},
        "lamp": {"vertices_m": [p for n, _m, p, l in plist if l][0], "radiance_rgb": LAMP_RADIANCE},
        "seconds": time.perf_counter() - t0,
        "patches": rows,
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", args.out, f"({out['seconds']:.0f} s)")


if __name__ == "__main__":
    main()
