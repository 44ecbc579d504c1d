#!/usr/bin/env python3
"""OpenCV check of photomontage's camera exports (issue 15, camera exchange).

Reads an export of the courtyard sample site made by
    photomontage solve sample_sites/courtyard/site.toml --out sample_sites/courtyard/solved.toml
    photomontage export-cameras sample_sites/courtyard/solved.toml --format colmap --out peers/camera_exchange/courtyard
    photomontage export-cameras sample_sites/courtyard/solved.toml --format opencv --out peers/camera_exchange/courtyard
    rm sample_sites/courtyard/solved.toml
and projects every point of points3D.txt into every image with cv2.projectPoints twice:
  * from the OpenCV YAML (read with cv2.FileStorage: camera_matrix, distortion_coefficients,
    rvec, tvec), and
  * from the COLMAP text model converted to OpenCV by COLMAP's documented conventions
    (R from the Hamilton quaternion QW QX QY QZ, t = T, principal point − 0.5 px for COLMAP's
    pixel-centre-at-0.5 convention, SIMPLE_RADIAL k -> (k, 0, 0, 0, 0)),
writing opencv_projections.csv: image,point,x_yaml,y_yaml,x_colmap,y_colmap (pixel (0,0) = centre
of the top-left pixel). tests/tests/camera_exchange.rs compares them with photomontage's own
projection of the imported COLMAP cameras.

Re-run:  /work/bench/.venv/bin/python peers/camera_exchange/opencv_project.py peers/camera_exchange/courtyard
"""
import csv
import os
import sys

import cv2
import numpy as np


def quat_to_r(qw, qx, qy, qz):
    return np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
        [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
        [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)],
    ])


def colmap_opencv(model, params):
    p = list(params)
    if model == "SIMPLE_PINHOLE":
        f, cx, cy = p; fx = fy = f; d = [0, 0, 0, 0, 0]
    elif model == "SIMPLE_RADIAL":
        f, cx, cy, k = p; fx = fy = f; d = [k, 0, 0, 0, 0]
    elif model == "RADIAL":
        f, cx, cy, k1, k2 = p; fx = fy = f; d = [k1, k2, 0, 0, 0]
    elif model == "OPENCV":
        fx, fy, cx, cy, k1, k2, p1, p2 = p; d = [k1, k2, p1, p2, 0]
    elif model == "FULL_OPENCV":
        fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6 = p
        assert k4 == k5 == k6 == 0
        d = [k1, k2, p1, p2, k3]
    else:
        raise ValueError(model)
    k = np.array([[fx, 0, cx - 0.5], [0, fy, cy - 0.5], [0, 0, 1.0]])
    return k, np.array(d, dtype=float)


def main():
    folder = sys.argv[1]
    cams = {}
    for line in open(os.path.join(folder, "cameras.txt")):
        if line.startswith("#") or not line.strip():
            continue
        f = line.split()
        cams[f[0]] = colmap_opencv(f[1], map(float, f[4:]))
    images = []
    lines = [l for l in open(os.path.join(folder, "images.txt")) if not l.startswith("#")]
    for i in range(0, len(lines), 2):
        f = lines[i].split()
        if not f:
            continue
        q = list(map(float, f[1:5]))
        t = np.array(list(map(float, f[5:8])))
        images.append((f[9], quat_to_r(*q), t, cams[f[8]]))
    names = {}
    for line in open(os.path.join(folder, "point_names.txt")):
        if line.startswith("#"):
            continue
        n, name = line.split()
        names[n] = name
    points = []
    for line in open(os.path.join(folder, "points3D.txt")):
        if line.startswith("#") or not line.strip():
            continue
        f = line.split()
        points.append((names[f[0]], np.array(list(map(float, f[1:4])))))
    out = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "opencv_projections.csv"), "w", newline="")
    w = csv.writer(out)
    w.writerow(["image", "point", "x_yaml", "y_yaml", "x_colmap", "y_colmap"])
    for image_name, r, t, (k, d) in images:
        stem = os.path.splitext(os.path.basename(image_name))[0]
        fs = cv2.FileStorage(os.path.join(folder, stem + ".yml"), cv2.FILE_STORAGE_READ)
        ky = fs.getNode("camera_matrix").mat()
        dy = fs.getNode("distortion_coefficients").mat()
        rv = fs.getNode("rvec").mat()
        tv = fs.getNode("tvec").mat()
        fs.release()
        for name, x in points:
            # Points behind a camera are skipped (photomontage does not project them).
            if (r @ x + t)[2] <= 0:
                continue
            py, _ = cv2.projectPoints(x.reshape(1, 3), rv, tv, ky, dy)
            rvc, _ = cv2.Rodrigues(r)
            pc, _ = cv2.projectPoints(x.reshape(1, 3), rvc, t, k, d)
            py = py.reshape(2); pc = pc.reshape(2)
            w.writerow([image_name, name, f"{py[0]:.9f}", f"{py[1]:.9f}", f"{pc[0]:.9f}", f"{pc[1]:.9f}"])
    print("written", out.name)


if __name__ == "__main__":
    main()
