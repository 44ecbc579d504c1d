"""Does IMG_0031 of odm_data_copr overlap IMG_0046 / IMG_0052? (peer check for
tests/tests/copr_tie_points.rs, OpenCV's Python bindings, independent of our Rust code.)

Run: /work/bench/.venv/bin/python peers/copr_overlap/overlap.py [SHARED]
(SHARED defaults to ../shared beside the checkout). Prints, per pair, at the settings of
`photomontage match` (longer side 3000 px, 4000 SIFT keypoints, ratio 0.8, mutual check,
fundamental-matrix RANSAC 2 px at full resolution), the ratio/mutual/verified counts; then at
half resolution with every keypoint, ratio 0.9 and a homography RANSAC (4 px) the inlier count.
Measured 2026-11-24 (OpenCV 5.0): 0031–0046 ratio 35, mutual 15, verified 9; 0031–0052 37/16/8;
0046–0052 920/862/792. Homography inliers: 0031–0046 17, 0031–0052 11, 0046–0052 7089.
"""
import itertools
import os
import sys

import cv2
import numpy as np

shared = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    os.path.dirname(__file__), "..", "..", "..", "shared")
folder = os.path.join(shared, "data", "real", "gcp", "odm_data_copr")
names = ["IMG_0031", "IMG_0046", "IMG_0052"]
images = {n: cv2.imread(os.path.join(folder, n + ".jpg"), cv2.IMREAD_GRAYSCALE) for n in names}


def mutual_ratio(kd, a, b, ratio):
    bf = cv2.BFMatcher(cv2.NORM_L2)
    fwd = [m[0] for m in bf.knnMatch(kd[a][1], kd[b][1], k=2)
           if len(m) == 2 and m[0].distance < ratio * m[1].distance]
    back = {m[0].queryIdx: m[0].trainIdx for m in bf.knnMatch(kd[b][1], kd[a][1], k=2)
            if len(m) == 2 and m[0].distance < ratio * m[1].distance}
    return fwd, [m for m in fwd if back.get(m.trainIdx) == m.queryIdx]


# 1. The settings of `photomontage match`.
sift = cv2.SIFT_create(4000)
kd, scale = {}, {}
for n, im in images.items():
    s = 3000 / max(im.shape)
    small = cv2.resize(im, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
    kd[n] = sift.detectAndCompute(small, None)
    scale[n] = 1 / s
for a, b in itertools.combinations(names, 2):
    fwd, mut = mutual_ratio(kd, a, b, 0.8)
    verified = 0
    if len(mut) >= 8:
        pa = np.float32([kd[a][0][m.queryIdx].pt for m in mut])
        pb = np.float32([kd[b][0][m.trainIdx].pt for m in mut])
        _, mask = cv2.findFundamentalMat(pa, pb, cv2.FM_RANSAC, 2.0 / scale[a], 0.999, 10000)
        verified = int(mask.sum()) if mask is not None else 0
    print(f"{a}-{b}: ratio {len(fwd)}, mutual {len(mut)}, verified {verified}")

# 2. Lenient: half resolution, all keypoints, ratio 0.9, homography (the ground is nearly flat).
sift = cv2.SIFT_create(0, 3, 0.02)
for n, im in images.items():
    kd[n] = sift.detectAndCompute(
        cv2.resize(im, None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA), None)
for a, b in itertools.combinations(names, 2):
    bf = cv2.BFMatcher(cv2.NORM_L2)
    good = [m[0] for m in bf.knnMatch(kd[a][1], kd[b][1], k=2)
            if len(m) == 2 and m[0].distance < 0.9 * m[1].distance]
    pa = np.float32([kd[a][0][m.queryIdx].pt for m in good])
    pb = np.float32([kd[b][0][m.trainIdx].pt for m in good])
    _, mask = cv2.findHomography(pa, pb, cv2.RANSAC, 4.0, maxIters=20000, confidence=0.999)
    print(f"{a}-{b}: {len(good)} ratio-0.9 matches, homography inliers {int(mask.sum())}")
