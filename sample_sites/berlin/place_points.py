"""Prints the [[control_points]] that carry the Berlin site's scene polygons (docs/berlin.md,
"How the scene was placed"). Plain Python 3, no dependencies:

    python3 sample_sites/berlin/place_points.py

The numbers below were measured on the photos with the cameras solved from G01-G10 (local frame:
E - 391470 m, N - 5819980 m, heights as the control gives them):
- the ground is the plane z = 0.20 m: the feet and heads of two people standing on the square in
  photo 02 give 1.72 m and 1.63 m tall people there (z = 0 would make them 1.92 m and 1.82 m);
- the foot of the steps is where photo 02's rays through the bottom of the lowest riser
  (pixels (300, 2238) and (2900, 2238)) meet that plane: a line at azimuth 129 deg through
  (3.76, 0.51); the steps climb along azimuth 39 deg, at right angles to it;
- the top of the steps is 17.24 m up the slope at z = 4.20 m (photo 02's ray through the landing's
  front edge; G04 at the foot of the left gate pillar, z = 6.02 m, sits 1.8 m above it), so one
  plane stands for both flights and the landing between them (the plinth foot F triangulated in
  photos 01 and 02 at z = 2.62 m lies 0.11 m below it);
- the portal façade is the vertical plane at the top of the steps, from the landing to z = 20 m.
"""
import math

E0, N0 = 391470.0, 5819980.0
GROUND_Z_M = 0.20
FOOT_MID = (3.76, 0.51)
UP_AZIMUTH_DEG = 39.0
STEPS_RUN_M = 17.24
TOP_Z_M = 4.20
FACADE_TOP_Z_M = 20.0
STEPS_HALF_WIDTH_M = 12.0
GROUND_HALF_WIDTH_M = 30.0
GROUND_DEPTH_M = 40.0

up = (math.sin(math.radians(UP_AZIMUTH_DEG)), math.cos(math.radians(UP_AZIMUTH_DEG)))
along = (up[1], -up[0])  # azimuth 129 deg: to the right when facing the portal


def at(s_along, s_up, z):
    x = FOOT_MID[0] + s_along * along[0] + s_up * up[0]
    y = FOOT_MID[1] + s_along * along[1] + s_up * up[1]
    return (E0 + x, N0 + y, z)


points = {
    # Ground: from 40 m in front of the steps to their foot, counter-clockwise seen from above.
    "SQ1": at(-GROUND_HALF_WIDTH_M, -GROUND_DEPTH_M, GROUND_Z_M),
    "SQ2": at(GROUND_HALF_WIDTH_M, -GROUND_DEPTH_M, GROUND_Z_M),
    "SQ3": at(GROUND_HALF_WIDTH_M, 0.0, GROUND_Z_M),
    "SQ4": at(-GROUND_HALF_WIDTH_M, 0.0, GROUND_Z_M),
    # Steps: foot (left, right), top (right, left).
    "ST1": at(-STEPS_HALF_WIDTH_M, 0.0, GROUND_Z_M),
    "ST2": at(STEPS_HALF_WIDTH_M, 0.0, GROUND_Z_M),
    "ST3": at(STEPS_HALF_WIDTH_M, STEPS_RUN_M, TOP_Z_M),
    "ST4": at(-STEPS_HALF_WIDTH_M, STEPS_RUN_M, TOP_Z_M),
    # Portal façade: its bottom is the top of the steps (ST4, ST3); top (right, left).
    "PF3": at(STEPS_HALF_WIDTH_M, STEPS_RUN_M, FACADE_TOP_Z_M),
    "PF4": at(-STEPS_HALF_WIDTH_M, STEPS_RUN_M, FACADE_TOP_Z_M),
}
for name, (e, n, z) in points.items():
    print(f'[[control_points]]\nid = "{name}"\nxyz = [{e:.3f}, {n:.3f}, {z:.3f}]\nsigma_m = [0.5, 0.5, 0.5]\n')
