#!/usr/bin/env python3
"""OpenCV reference for the Finse self-calibration (issue 15): cv2.calibrateCamera on the one
view of the Finse webcam with its 45 GCPs (../shared/data/real/gcp/projimdem/finse), f, k1, k2
free (principal point fixed at the centre, fx = fy, no tangential terms, k3 = 0), started from
the data-sheet focal length 1484 px. Writes opencv_finse.json beside this script: f, k1, k2, the
RMS over all 45 points (OpenCV's definition: sqrt(mean squared residual vector)), the camera
centre and its offsets from the authors' camera_pos.

Re-run: /work/bench/.venv/bin/python peers/finse/opencv_calibrate_finse.py ../shared/data/real/gcp/projimdem/finse
"""
import csv
import json
import os
import sys

import cv2
import numpy as np


def main():
    folder = sys.argv[1]
    rows = list(csv.DictReader(open(os.path.join(folder, "GCPs_pointagev4.csv"))))
    world = np.array([[float(r["x_world"]), float(r["y_world"]), float(r["z_world"])] for r in rows])
    pixels = np.array([[float(r["x_img"]), float(r["y_img"])] for r in rows])
    pos_text = open(os.path.join(folder, "camera_pos")).read().replace(",", " ").split()
    camera_pos = np.array([float(v) for v in pos_text if v.replace(".", "").replace("-", "").isdigit()])
    origin = world.mean(axis=0)
    obj = (world - origin).astype(np.float32)
    w, h = 1920, 1080
    k0 = np.array([[1484.0, 0, (w - 1) / 2], [0, 1484.0, (h - 1) / 2], [0, 0, 1]])
    flags = (cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_PRINCIPAL_POINT | cv2.CALIB_FIX_ASPECT_RATIO
             | cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3)
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 1000, 1e-12)
    rms, k, d, rvecs, tvecs = cv2.calibrateCamera([obj], [pixels.astype(np.float32)], (w, h), k0, np.zeros(5),
                                                 flags=flags, criteria=crit)
    r, _ = cv2.Rodrigues(rvecs[0])
    centre = (-r.T @ tvecs[0]).ravel() + origin
    off = centre - camera_pos
    out = {
        "peer": "opencv", "version": cv2.__version__, "flags": int(flags),
        "f_px": k[0, 0], "k1": float(d.ravel()[0]), "k2": float(d.ravel()[1]),
        "rms_px_all_45": rms,
        "camera_center": centre.tolist(),
        "horizontal_offset_m": float(np.hypot(off[0], off[1])), "vertical_offset_m": float(off[2]),
    }
    print(json.dumps(out, indent=1))
    json.dump(out, open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "opencv_finse.json"), "w"), indent=1)


if __name__ == "__main__":
    main()
