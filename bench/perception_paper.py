#!/usr/bin/python3
"""The published RASCAL's segmentation (seeds/000, §III-F), written plainly in Python + OpenCV as
the speed and quality baseline of bench/perception: k-means on the HSV values of a picture of the
empty background (k clusters), a pixel is background when its hue is within a tight bound and its
saturation within a loose bound of a cluster (value ignored: lighting), the rest are sherds;
contours and minAreaRect. For a photo there is no empty picture: its rim (2 % band) stands in.

  bench/perception_paper.py FRAMES_DIR PHOTOS_DIR
prints the median time per wrist frame and per photo (one thread) and the photo counts against
the hand ranges, then `python_ms frame=X photo=Y` for bench/perception."""

import json
import os
import statistics
import sys
import time

import cv2
import numpy as np

K = 3  # "a user-specified number of HSV values"
HUE_TOL = 8  # OpenCV hue units (0..180): "a fairly tight bound on hue"
SAT_TOL = 60  # 0..255: "a fairly loose bound on saturation"
MIN_AREA_FRACTION = 0.0005  # contours smaller than this part of the image are noise


def background_colours(bgr_sample):
    hsv = cv2.cvtColor(bgr_sample, cv2.COLOR_BGR2HSV).reshape(-1, 3).astype(np.float32)
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 20, 1.0)
    _, _, centres = cv2.kmeans(hsv[:, :2].copy(), K, None, criteria, 2, cv2.KMEANS_PP_CENTERS)
    return centres


def segment(bgr, centres):
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
    background = np.zeros(hsv.shape[:2], np.uint8)
    for h, s in centres:
        lo = (max(0, int(h - HUE_TOL)), max(0, int(s - SAT_TOL)), 0)
        hi = (min(179, int(h + HUE_TOL)), min(255, int(s + SAT_TOL)), 255)
        background |= cv2.inRange(hsv, lo, hi)
    sherds = cv2.bitwise_not(background)
    sherds = cv2.morphologyEx(sherds, cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
    contours, _ = cv2.findContours(sherds, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    min_area = MIN_AREA_FRACTION * bgr.shape[0] * bgr.shape[1]
    return [cv2.minAreaRect(c) for c in contours if cv2.contourArea(c) >= min_area]


def rim(bgr):
    h, w = bgr.shape[:2]
    b = max(2, min(h, w) // 50)
    return np.concatenate(
        [bgr[:b].reshape(-1, 3), bgr[-b:].reshape(-1, 3), bgr[:, :b].reshape(-1, 3)]
        + [bgr[:, -b:].reshape(-1, 3)]
    ).reshape(-1, 1, 3)


def timed(fn, *args, repeats=3):
    times = []
    for _ in range(repeats):
        t0 = time.thread_time()
        out = fn(*args)
        times.append(1e3 * (time.thread_time() - t0))
    return out, statistics.median(times)


def main(frames_dir, photos_dir):
    cv2.setNumThreads(1)
    frame_ms = []
    i = 0
    while os.path.exists(os.path.join(frames_dir, "frame_%d.png" % i)):
        frame = cv2.imread(os.path.join(frames_dir, "frame_%d.png" % i))
        empty = cv2.imread(os.path.join(frames_dir, "empty_%d.png" % i))
        centres = background_colours(empty)  # calibration, once per station: not timed
        _, ms = timed(segment, frame, centres)
        frame_ms.append(ms)
        i += 1
    with open(os.path.join(photos_dir, "photos_truth.json")) as f:
        truth = json.load(f)
    photo_ms, in_range = [], 0
    print("\nthe paper's pipeline (Python + OpenCV, one thread) on the real photos:")
    for name, t in sorted(truth.items()):
        bgr = cv2.imread(os.path.join(photos_dir, name))

        def whole(img):
            return segment(img, background_colours(rim(img)))

        boxes, ms = timed(whole, bgr)
        lo, hi = t["count_range"]
        in_range += lo <= len(boxes) <= hi
        photo_ms.append(ms)
        print("%-38s %5d %10s %8.1f ms" % (name, len(boxes), "%d..%d" % (lo, hi), ms))
    print(
        "paper's pipeline: count within the hand range on %d of %d photos; median %.2f ms per "
        "wrist frame (%d frames), %.1f ms per photo"
        % (
            in_range,
            len(truth),
            statistics.median(frame_ms or [0]),
            len(frame_ms),
            statistics.median(photo_ms),
        )
    )
    print(
        "python_ms frame=%.3f photo=%.3f"
        % (statistics.median(frame_ms or [0]), statistics.median(photo_ms))
    )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
