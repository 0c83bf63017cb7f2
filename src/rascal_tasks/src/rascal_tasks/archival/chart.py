"""Find the colour chart and the scale bar in an archival photo, wherever they lie.

The method of the homography-based planar pose estimation (Paul et al., seed 003): a reference
image of each planar target is drawn from its published values (the chart's 24 sRGB patches on a
black card; the bar's 1 cm chequer and solid halves), SIFT keypoints of reference and photo are
matched with FLANN (k-d trees, Lowe's ratio test), and a homography reference -> photo is fitted
with RANSAC. The fit's reprojection error (RMS over the inliers, px) is reported with it. Nothing
here assumes where the targets are; the sizes of the physical targets are the only input.
No ROS here.
"""

import csv
import os
from dataclasses import dataclass
from typing import Optional, Tuple

import cv2
import numpy as np

DATA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
CHART_CSV = os.path.join(DATA_DIR, "colorchecker24_xrite_after2014_D50.csv")

REF_PX_PER_MM = 8.0  # reference images are drawn at this scale
MARGIN_MM = 4.0  # neutral grey around a reference target (its outer edges carry keypoints)
MARGIN_GREY = 128
MIN_INLIERS = {"chart": 12, "bar": 8}  # the bar's reference has few keypoints (about 30)
FEATURE_MAX_SIDE = 1000  # photos are searched at most this large (SIFT time), fits scaled back


class TargetNotFound(Exception):
    """A target (chart or bar) could not be located; the message says which and why."""


@dataclass(frozen=True)
class ChartSpec:
    """A 4 x 6 chart: card size [mm], patch side as a fraction of its cell, rows from the top."""

    width_mm: float = 70.0
    height_mm: float = 45.0
    patch_fraction: float = 0.8
    rows: int = 4
    cols: int = 6


@dataclass(frozen=True)
class BarSpec:
    """A bar of `cells` squares in two rows: the first half a chequer, the second half solid
    (black row over white row), as in the ArchAIDE photos."""

    length_mm: float = 100.0
    height_mm: float = 15.0
    cells: int = 10


@dataclass
class Located:
    """A target found in the photo: H maps reference-image pixels to photo pixels."""

    H: np.ndarray
    ref_size: Tuple[int, int]  # (width, height) of the reference image, margin included
    inliers: int
    matches: int
    reprojection_px: float  # RMS reprojection error of the inliers [px]

    def corners(self) -> np.ndarray:
        """The target's four corners in the photo (margin excluded), 4 x 2."""
        m = MARGIN_MM * REF_PX_PER_MM
        w, h = self.ref_size
        pts = np.float32([[m, m], [w - m, m], [w - m, h - m], [m, h - m]]).reshape(-1, 1, 2)
        return cv2.perspectiveTransform(pts, self.H).reshape(-1, 2)

    def polygon_mask(self, shape, grow_px: int = 0) -> np.ndarray:
        mask = np.zeros(shape[:2], np.uint8)
        pts = self.corners()
        if grow_px > 0:
            # grown by a disc: the hull of a circle around each corner (the Minkowski sum of a
            # convex polygon and a disc), not a dilation of the whole image (a second per photo)
            a = np.linspace(0.0, 2.0 * np.pi, 24, endpoint=False)
            disc = grow_px * np.stack([np.cos(a), np.sin(a)], axis=1)
            around = (pts[:, None, :] + disc[None, :, :]).reshape(-1, 2).astype(np.float32)
            pts = cv2.convexHull(around).reshape(-1, 2)
        cv2.fillConvexPoly(mask, np.round(pts).astype(np.int32), 255)
        return mask


def chart_reference_srgb() -> np.ndarray:
    """The 24 patches' published sRGB (8 bit, D65 via Bradford) in chart order, 24 x 3."""
    with open(CHART_CSV, newline="") as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["sRGB_R8"]), float(r["sRGB_G8"]), float(r["sRGB_B8"])] for r in rows])


def chart_reference_lab() -> np.ndarray:
    """The 24 patches' published CIE L*a*b* (D50, 2 degrees), 24 x 3."""
    with open(CHART_CSV, newline="") as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["L_D50"]), float(r["a_D50"]), float(r["b_D50"])] for r in rows])


def _canvas(w_mm, h_mm):
    s, m = REF_PX_PER_MM, MARGIN_MM
    w, h = int(round((w_mm + 2 * m) * s)), int(round((h_mm + 2 * m) * s))
    return np.full((h, w, 3), MARGIN_GREY, np.uint8)


def _fill(img, x0_mm, y0_mm, x1_mm, y1_mm, colour):
    s, m = REF_PX_PER_MM, MARGIN_MM
    x0, y0 = int(round((x0_mm + m) * s)), int(round((y0_mm + m) * s))
    x1, y1 = int(round((x1_mm + m) * s)), int(round((y1_mm + m) * s))
    img[y0:y1, x0:x1] = colour


def patch_boxes_mm(spec: ChartSpec):
    """(x0, y0, x1, y1) of each patch in mm from the card's top-left corner, chart order."""
    cw, ch = spec.width_mm / spec.cols, spec.height_mm / spec.rows
    out = []
    for r in range(spec.rows):
        for c in range(spec.cols):
            cx, cy = (c + 0.5) * cw, (r + 0.5) * ch
            hw, hh = cw * spec.patch_fraction / 2, ch * spec.patch_fraction / 2
            out.append((cx - hw, cy - hh, cx + hw, cy + hh))
    return out


def chart_reference(spec: ChartSpec = None) -> np.ndarray:
    """RGB reference image of the chart drawn from the published values."""
    spec = spec if spec is not None else ChartSpec()
    img = _canvas(spec.width_mm, spec.height_mm)
    _fill(img, 0, 0, spec.width_mm, spec.height_mm, (13, 13, 13))
    for box, rgb in zip(patch_boxes_mm(spec), chart_reference_srgb(), strict=True):
        _fill(img, *box, tuple(int(v) for v in rgb))
    return img


def bar_reference(spec: BarSpec = None) -> np.ndarray:
    """RGB reference image of the scale bar."""
    spec = spec if spec is not None else BarSpec()
    img = _canvas(spec.length_mm, spec.height_mm)
    cell, row = spec.length_mm / spec.cells, spec.height_mm / 2
    black, white = (10, 10, 10), (242, 242, 242)
    for i in range(spec.cells):
        for r in range(2):
            if i < spec.cells // 2:
                is_black = (i + r) % 2 == 0
            else:
                is_black = r == 0
            _fill(
                img, i * cell, r * row, (i + 1) * cell, (r + 1) * row, black if is_black else white
            )
    return img


def _features(gray: np.ndarray):
    # a detector per call: analyses may run in two threads at once (a re-shot photo)
    return cv2.SIFT_create(nfeatures=0, contrastThreshold=0.03).detectAndCompute(gray, None)


_REF_CACHE = {}


def _reference_features(kind: str, spec):
    key = (kind, spec)
    if key not in _REF_CACHE:
        img = chart_reference(spec) if kind == "chart" else bar_reference(spec)
        gray = cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)
        kp, des = _features(gray)
        _REF_CACHE[key] = (img, kp, des)
    return _REF_CACHE[key]


def photo_features(rgb: np.ndarray):
    """SIFT keypoints and descriptors of a photo (RGB, 8 bit), found at most FEATURE_MAX_SIDE
    px large: (keypoints, descriptors, scale of the searched image to the photo)."""
    gray = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)
    scale = min(1.0, FEATURE_MAX_SIDE / max(gray.shape[:2]))
    if scale < 1.0:
        gray = cv2.resize(gray, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    # stretch contrast so a dim or colour-cast photo gives keypoints like a bright one
    gray = cv2.normalize(gray, None, 0, 255, cv2.NORM_MINMAX)
    kp, des = _features(gray)
    return kp, des, scale


def locate(kind: str, photo_feats, spec=None, ratio: float = 0.75) -> Located:
    """Find `kind` ('chart' or 'bar') in a photo given its features (photo_features)."""
    spec = spec if spec is not None else (ChartSpec() if kind == "chart" else BarSpec())
    ref, kp_r, des_r = _reference_features(kind, spec)
    kp_p, des_p = photo_feats[0], photo_feats[1]
    name = "colour chart" if kind == "chart" else "scale bar"
    need = MIN_INLIERS[kind]
    if des_p is None or len(kp_p) < need:
        raise TargetNotFound("%s: too few keypoints in the photo (%d)" % (name, len(kp_p or [])))
    flann = cv2.FlannBasedMatcher({"algorithm": 1, "trees": 5}, {"checks": 64})
    pairs = flann.knnMatch(des_r.astype(np.float32), des_p.astype(np.float32), k=2)
    good = [p[0] for p in pairs if len(p) == 2 and p[0].distance < ratio * p[1].distance]
    if len(good) < need:
        raise TargetNotFound("%s: %d feature matches, need %d" % (name, len(good), need))
    src = np.float32([kp_r[m.queryIdx].pt for m in good]).reshape(-1, 1, 2)
    dst = np.float32([kp_p[m.trainIdx].pt for m in good]).reshape(-1, 1, 2)
    H, inl = cv2.findHomography(src, dst, cv2.RANSAC, 3.0, maxIters=4000, confidence=0.999)
    if H is None or inl is None or int(inl.sum()) < need:
        raise TargetNotFound("%s: no consistent homography (%d matches)" % (name, len(good)))
    keep = inl.ravel().astype(bool)
    # refine on the inliers (least squares), then report the RMS reprojection error
    H2, _ = cv2.findHomography(src[keep], dst[keep], 0)
    if H2 is not None:
        H = H2
    proj = cv2.perspectiveTransform(src[keep], H)
    err = float(np.sqrt(np.mean(np.sum((proj - dst[keep]) ** 2, axis=2))))
    # features were found in a photo shrunk by `scale`: map back to the full photo
    scale = photo_feats[2] if len(photo_feats) > 2 else 1.0
    if scale != 1.0:
        H = np.diag([1.0 / scale, 1.0 / scale, 1.0]) @ H
        err /= scale
    h, w = ref.shape[:2]
    loc = Located(H, (w, h), int(keep.sum()), len(good), err)
    _check_plausible(loc, name)
    return loc


def _check_plausible(loc: Located, name: str):
    """A homography of a flat target seen from above: convex, not folded, not tiny."""
    c = loc.corners()
    if not cv2.isContourConvex(np.round(c * 16).astype(np.int32).reshape(-1, 1, 2)):
        raise TargetNotFound("%s: the fitted outline is not convex" % name)
    area = abs(cv2.contourArea(c.astype(np.float32)))
    if area < 400:
        raise TargetNotFound("%s: the fitted outline is %.0f px^2, too small" % (name, area))
    sides = [np.linalg.norm(c[i] - c[(i + 1) % 4]) for i in range(4)]
    if max(sides[0], sides[2]) > 1.5 * min(sides[0], sides[2]) or max(
        sides[1], sides[3]
    ) > 1.5 * min(sides[1], sides[3]):
        raise TargetNotFound("%s: the fitted outline is strongly skewed" % name)


def sample_patches(rgb: np.ndarray, loc: Located, spec: ChartSpec = None):
    """Median 8-bit RGB of the central half of each patch, 24 x 3, and the count of clipped
    pixels per patch (any channel at 255 or 0)."""
    spec = spec if spec is not None else ChartSpec()
    w, h = loc.ref_size
    warped = cv2.warpPerspective(
        rgb, loc.H, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    ).astype(np.float64)
    s, m = REF_PX_PER_MM, MARGIN_MM
    means, clipped = [], []
    for x0, y0, x1, y1 in patch_boxes_mm(spec):
        cx, cy, hw, hh = (x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 4, (y1 - y0) / 4
        xa, xb = int((cx - hw + m) * s), int((cx + hw + m) * s)
        ya, yb = int((cy - hh + m) * s), int((cy + hh + m) * s)
        px = warped[ya:yb, xa:xb].reshape(-1, 3)
        means.append(np.median(px, axis=0))
        clipped.append(float(np.mean(np.any((px >= 254.5) | (px <= 0.5), axis=1))))
    return np.array(means), np.array(clipped)


def bar_px_per_cm(loc: Located, spec: BarSpec = None) -> float:
    """Image scale along the bar: its two long edges' lengths in the photo over its length."""
    spec = spec if spec is not None else BarSpec()
    c = loc.corners()
    top, bottom = np.linalg.norm(c[1] - c[0]), np.linalg.norm(c[2] - c[3])
    return float((top + bottom) / 2 / (spec.length_mm / 10.0))


def locate_all(rgb: np.ndarray, chart_spec=None, bar_spec=None):
    """(chart, bar) Located (either None) and the reasons for any not found."""
    feats = photo_features(rgb)
    out, why = [], []
    for kind, spec in (("chart", chart_spec), ("bar", bar_spec)):
        try:
            out.append(locate(kind, feats, spec))
        except TargetNotFound as e:
            out.append(None)
            why.append(str(e))
    return out[0], out[1], why


def find_chart(rgb: np.ndarray, spec: Optional[ChartSpec] = None) -> Located:
    return locate("chart", photo_features(rgb), spec)


def find_bar(rgb: np.ndarray, spec: Optional[BarSpec] = None) -> Located:
    return locate("bar", photo_features(rgb), spec)


def _x_corners_mm(spec: BarSpec):
    """The chequer half's inner corners (four cells meet) in mm from the bar's top-left."""
    cell, row = spec.length_mm / spec.cells, spec.height_mm / 2
    return [(i * cell, row) for i in range(1, spec.cells // 2)]


def _ref_px(points_mm):
    s, m = REF_PX_PER_MM, MARGIN_MM
    return np.float32([[(x + m) * s, (y + m) * s] for x, y in points_mm])


def locate_bar_outline(
    rgb: np.ndarray, spec: BarSpec = None, exclude: Optional[np.ndarray] = None
) -> Located:
    """The bar as the one black-and-white rectangle of its proportions (when its features
    are too few: a clipped or dim photo). Which end is the chequer is read from the pixels;
    the fit is checked on the chequer's inner corners (sub-pixel), whose RMS distance from
    where the fit puts them is the reprojection error reported."""
    spec = spec if spec is not None else BarSpec()
    gray = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float32)
    keep = np.ones(gray.shape, bool) if exclude is None else exclude == 0
    med = float(np.median(gray[::4, ::4][keep[::4, ::4]]))
    extreme = ((gray < 0.45 * med) | (gray > min(250.0, 1.45 * med))) & keep
    mask = cv2.morphologyEx(extreme.astype(np.uint8) * 255, cv2.MORPH_CLOSE, np.ones((3, 3)))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    aspect = spec.length_mm / spec.height_mm
    best = None
    for c in contours:
        area = cv2.contourArea(c)
        if area < 1500:
            continue
        (cx, cy), (w, h), ang = cv2.minAreaRect(c)
        lo, hi = min(w, h), max(w, h)
        if lo <= 0 or abs(hi / lo / aspect - 1) > 0.2 or area / (w * h) < 0.85:
            continue
        if best is None or area > best[0]:
            best = (area, c)
    if best is None:
        raise TargetNotFound("scale bar: no black-and-white rectangle of its proportions")
    box = cv2.boxPoints(cv2.minAreaRect(best[1])).astype(np.float32)
    ref = bar_reference(spec)
    ref_gray = cv2.cvtColor(ref, cv2.COLOR_RGB2GRAY).astype(np.float32)
    h_ref, w_ref = ref_gray.shape
    m = MARGIN_MM * REF_PX_PER_MM
    ref_corners = np.float32([[m, m], [w_ref - m, m], [w_ref - m, h_ref - m], [m, h_ref - m]])
    inner = (slice(int(m), int(h_ref - m)), slice(int(m), int(w_ref - m)))
    # the four corner orders that keep the bar's handedness; the best fit of the pixels wins
    scored = []
    for k in range(4):
        img_corners = np.roll(box, -k, axis=0)
        if np.linalg.norm(img_corners[1] - img_corners[0]) < np.linalg.norm(
            img_corners[2] - img_corners[1]
        ):
            continue  # the reference's long side first
        for order in (img_corners, img_corners[::-1]):
            H = cv2.getPerspectiveTransform(ref_corners, np.float32(order))
            warped = cv2.warpPerspective(
                gray, H, (w_ref, h_ref), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
            )
            a, b = warped[inner].ravel(), ref_gray[inner].ravel()
            corr = float(np.corrcoef(a, b)[0, 1])
            scored.append((corr, H))
    corr, H = max(scored, key=lambda t: t[0])
    if not corr > 0.6:
        raise TargetNotFound("scale bar: a rectangle of its proportions, but not its pattern")
    # check (and refine) on the chequer's inner corners
    xs = _ref_px(_x_corners_mm(spec)).reshape(-1, 1, 2)
    pred = cv2.perspectiveTransform(xs, H)
    found = pred.copy()
    win = max(3, int(0.25 * bar_px_per_cm(Located(H, (w_ref, h_ref), 0, 0, 0.0), spec)))
    cv2.cornerSubPix(
        gray,
        found,
        (win, win),
        (-1, -1),
        (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 40, 0.01),
    )
    err = float(np.sqrt(np.mean(np.sum((found - pred) ** 2, axis=2))))
    loc = Located(H, (w_ref, h_ref), len(xs), len(xs), err)
    _check_plausible(loc, "scale bar")
    return loc
