"""The sherd in the archival photo: its mask, its length and width in mm, its robust colour.

The table around the sherd is one colour: pixels far from the table's colour (CIE L*a*b*
distance), outside the chart and the bar, form the candidate regions; the largest (or the one
nearest a hint point, when one is given) is the sherd, holes filled. Length and width are the
extents along and across the mask's principal axis (the definition the wrist camera's
measurement and the simulator's ground truth use), in mm through the bar's px/cm, corrected
for the height of the sherd's outline above the bar (parallax) when the camera height is known.
No ROS here.
"""

from dataclasses import dataclass
from typing import Optional, Tuple

import cv2
import numpy as np

MIN_DISTANCE = 4.0  # [L*a*b* units] least distance from the table colour (smoothed) for a sherd
MIN_SHERD_PX = 800  # a region smaller than this is not a sherd
MIN_COLOUR_PX = 300  # fewer pixels left for the colour: too small to tell
HIGHLIGHT_PCT = 95.0  # brighter pixels than this percentile are highlights
SHADOW_PCT = 10.0  # darker pixels than this percentile are shadows
# a faint sherd (find_faint_sherd): farther from the table around it than this many times the
# table's own median distance there (the ring may cross the chart or the bar), and than this
# many L*a*b* units
FAINT_SPREADS = 4.0
MIN_FAINT_DISTANCE = 2.0
_DISC5 = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))
_SEAM = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (11, 11))  # a paint's seam, closed


@dataclass
class SherdRegion:
    mask: np.ndarray  # uint8 0/255, photo size
    area_px: int
    length_px: float
    width_px: float
    axis_deg: float  # principal axis in the photo


def _lab(rgb8):
    return cv2.cvtColor(rgb8.astype(np.float32) / 255.0, cv2.COLOR_RGB2Lab)


def find_sherd(
    rgb8: np.ndarray,
    exclude: Optional[np.ndarray] = None,
    hint_px: Optional[Tuple] = None,
    lightness_weight: float = 1.0,
) -> Optional[SherdRegion]:
    """The sherd's region in the photo (best the colour-corrected one); None if nothing stands
    out from the table. `exclude`: uint8 mask of what is not sherd (chart, bar); `hint_px`: a
    point the sherd is expected near (only chooses between candidate regions);
    `lightness_weight` < 1 makes a shadow on the table (darker, same colour) count less.

    Candidates: pixels of a smoothed photo farther from the table's colour than the table's own
    noise allows. The chosen region's edge is then put where the distance is half the sherd's
    own contrast against the table (a half-step edge: no growth or shrinkage from smoothing)."""
    lab = _lab(rgb8)
    lab[..., 0] *= lightness_weight
    keep = np.ones(rgb8.shape[:2], bool) if exclude is None else exclude == 0
    table = np.median(lab[::4, ::4][keep[::4, ::4]], axis=0)
    smooth = cv2.GaussianBlur(lab, (0, 0), 2.0)
    dist = np.sqrt(np.sum((smooth - table) ** 2, axis=2))
    spread = np.median(dist[::4, ::4][keep[::4, ::4]])
    cand = ((dist > max(MIN_DISTANCE, 5.0 * spread)) & keep).astype(np.uint8) * 255
    cand = cv2.morphologyEx(cand, cv2.MORPH_OPEN, _DISC5)
    best = _pick(cand, hint_px)
    if best is None:
        return None
    inner = cv2.erode(best, _DISC5, iterations=3) > 0
    contrast = float(np.median(dist[inner])) if inner.any() else float(np.median(dist[best > 0]))
    half_step = max(0.5 * MIN_DISTANCE, 0.5 * contrast)
    refined = _edge_refined(lab, table, half_step, best, keep, hint_px)
    return _filled(best if refined is None else refined, rgb8.shape[:2])


def find_faint_sherd(
    rgb8: np.ndarray,
    exclude: Optional[np.ndarray],
    hint_px: Tuple[float, float],
    radius_px: float,
) -> Optional[SherdRegion]:
    """A sherd close to the table's colour (or whose body is, under a bright paint that alone
    stood out), expected within `radius_px` of `hint_px`: the table's colour and its spread
    (median distance) from a ring just outside that circle (the light falls off towards the
    photo's corners, so the whole photo's median is not the table here), and every pixel
    inside farther from it than FAINT_SPREADS times that spread (and MIN_FAINT_DISTANCE).
    None if nothing stands out."""
    h, w = rgb8.shape[:2]
    r_out = 1.5 * radius_px
    x0, x1 = int(max(0, hint_px[0] - r_out)), int(min(w, hint_px[0] + r_out + 1))
    y0, y1 = int(max(0, hint_px[1] - r_out)), int(min(h, hint_px[1] + r_out + 1))
    if x1 - x0 < 8 or y1 - y0 < 8:
        return None
    lab = _lab(rgb8[y0:y1, x0:x1])
    smooth = cv2.GaussianBlur(lab, (0, 0), 2.0)
    keep = np.ones(lab.shape[:2], bool) if exclude is None else exclude[y0:y1, x0:x1] == 0
    yy, xx = np.mgrid[y0:y1, x0:x1]
    r = np.hypot(xx - hint_px[0], yy - hint_px[1])
    ring = keep & (r >= 1.2 * radius_px) & (r <= r_out)
    if ring.sum() < 100:
        return None
    table = np.median(smooth[ring], axis=0)
    dist = np.sqrt(np.sum((smooth - table) ** 2, axis=2))
    cut = max(MIN_FAINT_DISTANCE, FAINT_SPREADS * float(np.median(dist[ring])))
    cand = ((dist > cut) & keep & (r < 1.2 * radius_px)).astype(np.uint8) * 255
    cand = cv2.morphologyEx(cand, cv2.MORPH_OPEN, _DISC5)
    # where a paint paler than the table meets a body darker than it, the smoothed colour
    # passes through the table's: a seam a few pixels wide, closed here
    cand = cv2.morphologyEx(cand, cv2.MORPH_CLOSE, _SEAM)
    hint = (hint_px[0] - x0, hint_px[1] - y0)
    best = _pick(cand, hint)
    if best is None:
        return None
    # its edge from the barely smoothed photo: smoothing spreads a bright paint's edge outwards
    best = _edge_refined(lab, table, cut, best, keep, hint, seam=True)
    return None if best is None else _filled(best, (h, w), (x0, y0))


def _edge_refined(lab, table, cut, best, keep, hint_px, seam=False) -> Optional[np.ndarray]:
    """`best`, a region found on the smoothed photo, with its edge put where the barely smoothed
    `lab` lies farther than `cut` from the `table` colour, within a few pixels of it (smoothing
    grows a bright region and shrinks a faint one); `seam`: a paint's seam closed again. None
    when nothing is left."""
    edge = np.sqrt(np.sum((cv2.GaussianBlur(lab, (3, 3), 0) - table) ** 2, axis=2))
    near = cv2.dilate(best, _DISC5, iterations=3) > 0
    refined = ((edge > cut) & near & keep).astype(np.uint8) * 255
    refined = cv2.morphologyEx(refined, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    if seam:
        refined = cv2.morphologyEx(refined, cv2.MORPH_CLOSE, _SEAM)
    return _pick(refined, hint_px) if refined.any() else None


def _filled(region: np.ndarray, shape, offset=(0, 0)) -> SherdRegion:
    """The largest outline of `region` (a window of the photo at `offset`), holes (paint, glare)
    filled, as a photo-sized mask, measured."""
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    mask = np.zeros(shape, np.uint8)
    c = max(contours, key=cv2.contourArea) + np.array(offset)
    cv2.drawContours(mask, [c], -1, 255, thickness=cv2.FILLED)
    return region_of(mask)


def region_of(mask: np.ndarray) -> SherdRegion:
    """A sherd's mask (uint8, 0/255) measured: area, extents along and across its principal
    axis [px]."""
    pts = np.argwhere(mask > 0)[:, ::-1].astype(np.float64)  # (x, y) of every pixel
    m = cv2.moments(mask, binaryImage=True)
    angle = 0.5 * np.arctan2(2 * m["mu11"], m["mu20"] - m["mu02"])
    major = np.array([np.cos(angle), np.sin(angle)])
    minor = np.array([-major[1], major[0]])
    # pixel edges: a run of n pixels is n px long, its centres span n - 1
    length = np.ptp(pts @ major) + 1.0
    width = np.ptp(pts @ minor) + 1.0
    return SherdRegion(mask, int(m["m00"]), float(length), float(width), float(np.degrees(angle)))


def _pick(cand: np.ndarray, hint_px) -> Optional[np.ndarray]:
    """The largest region of `cand` (or the one nearest `hint_px`), as a 0/255 mask."""
    n, labels, stats, cents = cv2.connectedComponentsWithStats(cand, connectivity=8)
    best, best_score = None, None
    for i in range(1, n):
        area = stats[i, cv2.CC_STAT_AREA]
        if area < MIN_SHERD_PX:
            continue
        score = -area
        if hint_px is not None:
            score = np.hypot(*(cents[i] - np.asarray(hint_px))) - 0.001 * area
        if best_score is None or score < best_score:
            best, best_score = i, score
    if best is None:
        return None
    return (labels == best).astype(np.uint8) * 255


def mm_per_px(px_per_cm: float, camera_height_m: float = 0.0, object_height_m: float = 0.0):
    """mm per photo pixel at the height of the sherd's outline: the bar lies on the table, the
    outline is `object_height_m` higher, so nearer a camera `camera_height_m` above the table."""
    s = 10.0 / px_per_cm
    if camera_height_m > 0 and 0 < object_height_m < camera_height_m:
        s *= (camera_height_m - object_height_m) / camera_height_m
    return s


PAINT_SEPARATION = 12.0  # [L*a*b*] two colour clusters this far apart: body and paint


def _body_colour(px: np.ndarray) -> np.ndarray:
    """The pixels of the sherd's body colour: of two clusters (k-means in L*a*b*) far apart,
    the larger (painted decoration, a slip band, dirt left out)."""
    srgb = np.clip(px, 0, 1) ** (1 / 2.2)  # perceptual enough to cluster in
    lab = cv2.cvtColor(srgb.astype(np.float32).reshape(-1, 1, 3), cv2.COLOR_RGB2Lab).reshape(-1, 3)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 20, 0.5)
    cv2.setRNGSeed(1)
    _, labels, centres = cv2.kmeans(lab, 2, None, crit, 2, cv2.KMEANS_PP_CENTERS)
    labels = labels.ravel()
    if np.linalg.norm(centres[0] - centres[1]) < PAINT_SEPARATION:
        return px
    big = int(np.sum(labels == 1) > np.sum(labels == 0))
    return px[labels == big]


def robust_colour(linear: np.ndarray, raw8: np.ndarray, mask: np.ndarray):
    """Median linear RGB of the sherd's face: the mask eroded by a tenth of its radius (its
    border), clipped pixels, highlights and shadows left out. (rgb or None, pixel count, why
    None)."""
    area = int(np.count_nonzero(mask))
    r = max(2, int(0.1 * np.sqrt(area / np.pi)))
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
    inner = cv2.erode(mask, k) > 0
    px = linear[inner]
    raw = raw8[inner]
    # clipped: any channel at the top, or every channel at the bottom (a dark saturated colour
    # has a channel near 0 and is kept)
    ok = np.all(raw < 253, axis=1) & np.any(raw > 2, axis=1)
    # most of the face clipped: what is left is decoration or shadow, not the body's colour
    if len(px) >= MIN_COLOUR_PX and (ok.sum() < MIN_COLOUR_PX or ok.mean() < 0.5):
        return (
            None,
            int(ok.sum()),
            "overexposed (%d %% of its pixels clipped)" % (100 - 100 * ok.sum() // len(px)),
        )
    px = px[ok]
    if len(px) < MIN_COLOUR_PX:
        return None, len(px), "sherd region too small (%d px)" % len(px)
    px = _body_colour(px)
    y = px @ np.array([0.2126, 0.7152, 0.0722])
    lo, hi = np.percentile(y, [SHADOW_PCT, HIGHLIGHT_PCT])
    px = px[(y >= lo) & (y <= hi)]
    if len(px) < MIN_COLOUR_PX:
        return None, len(px), "sherd region too small (%d px)" % len(px)
    return np.median(px, axis=0), len(px), ""
