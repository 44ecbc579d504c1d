"""Writes pavilion.obj and pavilion.mtl: the planned pavilion of the Berlin sample site.

A 4.8 x 4.8 m open pavilion, model coordinates in metres, Z up, origin at the centre of its
floor: a 0.15 m stone platform, four 12-sided columns (radius 0.14 m, 2.6 m tall) set 0.5 m in
from the corners, a 0.25 m roof slab with a 0.3 m overhang and a low pyramid roof (0.9 m). Every
face is outward-facing (counter-clockwise seen from outside). Plain Python 3, no dependencies:

    python3 sample_sites/berlin/pavilion.py
"""
import math
import os

HALF_PLATFORM_M = 2.4
PLATFORM_M = 0.15
COLUMN_RADIUS_M = 0.14
COLUMN_SIDES = 12
COLUMN_INSET_M = 0.5
COLUMN_HEIGHT_M = 2.6
SLAB_M = 0.25
OVERHANG_M = 0.3
ROOF_RISE_M = 0.9

vertices = []
faces = []  # (material, [1-based vertex indices])


def vertex(x, y, z):
    vertices.append((x, y, z))
    return len(vertices)


def box(material, x0, y0, z0, x1, y1, z1):
    v = [vertex(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    # v: 0 (x0,y0,z0) 1 (x1,y0,z0) 2 (x0,y1,z0) 3 (x1,y1,z0), 4..7 the same at z1
    quads = [
        (0, 2, 3, 1),  # bottom (normal -z)
        (4, 5, 7, 6),  # top
        (0, 1, 5, 4),  # south (-y)
        (1, 3, 7, 5),  # east (+x)
        (3, 2, 6, 7),  # north (+y)
        (2, 0, 4, 6),  # west (-x)
    ]
    for q in quads:
        faces.append((material, [v[q[0]], v[q[1]], v[q[2]]]))
        faces.append((material, [v[q[0]], v[q[2]], v[q[3]]]))


def column(material, cx, cy, z0, z1):
    ring0, ring1 = [], []
    for k in range(COLUMN_SIDES):
        a = 2 * math.pi * k / COLUMN_SIDES
        x, y = cx + COLUMN_RADIUS_M * math.cos(a), cy + COLUMN_RADIUS_M * math.sin(a)
        ring0.append(vertex(x, y, z0))
        ring1.append(vertex(x, y, z1))
    for k in range(COLUMN_SIDES):
        j = (k + 1) % COLUMN_SIDES
        faces.append((material, [ring0[k], ring0[j], ring1[j]]))
        faces.append((material, [ring0[k], ring1[j], ring1[k]]))
    for k in range(1, COLUMN_SIDES - 1):
        faces.append((material, [ring1[0], ring1[k], ring1[k + 1]]))  # top, +z
        faces.append((material, [ring0[0], ring0[k + 1], ring0[k]]))  # bottom, -z


h = HALF_PLATFORM_M
box("pavilion_stone", -h, -h, 0.0, h, h, PLATFORM_M)
c = h - COLUMN_INSET_M
for sx in (-1, 1):
    for sy in (-1, 1):
        column("pavilion_column", sx * c, sy * c, PLATFORM_M, PLATFORM_M + COLUMN_HEIGHT_M)
z_slab = PLATFORM_M + COLUMN_HEIGHT_M
r = c + COLUMN_RADIUS_M + OVERHANG_M
box("pavilion_roof", -r, -r, z_slab, r, r, z_slab + SLAB_M)
apex = vertex(0.0, 0.0, z_slab + SLAB_M + ROOF_RISE_M)
corners = [vertex(x, y, z_slab + SLAB_M) for x, y in ((-r, -r), (r, -r), (r, r), (-r, r))]
for k in range(4):
    faces.append(("pavilion_roof", [corners[k], corners[(k + 1) % 4], apex]))

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "pavilion.obj"), "w") as f:
    f.write("# Planned pavilion of the Berlin sample site (pavilion.py): 4.8 x 4.8 m, model\n")
    f.write("# coordinates in metres, Z up, origin at the centre of the floor.\n")
    f.write(f"# {len(vertices)} vertices, {len(faces)} triangles.\n")
    f.write("mtllib pavilion.mtl\no pavilion\n")
    for x, y, z in vertices:
        f.write(f"v {x:.4f} {y:.4f} {z:.4f}\n")
    current = None
    for material, idx in faces:
        if material != current:
            f.write(f"usemtl {material}\n")
            current = material
        f.write("f " + " ".join(str(i) for i in idx) + "\n")
with open(os.path.join(here, "pavilion.mtl"), "w") as f:
    f.write("# Materials of the planned pavilion (linear Lambertian albedos)\n")
    for name, kd in (
        ("pavilion_stone", (0.55, 0.52, 0.47)),
        ("pavilion_column", (0.75, 0.74, 0.72)),
        ("pavilion_roof", (0.18, 0.30, 0.26)),
    ):
        f.write(f"newmtl {name}\nKd {kd[0]:.2f} {kd[1]:.2f} {kd[2]:.2f}\nKs 0.00 0.00 0.00\nillum 1\n\n")
print(f"{len(vertices)} vertices, {len(faces)} triangles")
