"""One archival photo in, the sherd's colour, Munsell chip and size out (issue 15, items 2-5).

`analyse(path)` finds the chart and the bar (chart.py), corrects the colours (colour.py), finds
the sherd (size.py), measures it and names its chip (munsell.py). Every problem becomes a flag
(one line), never an exception: a value that cannot be trusted is left None. The photo file is
only read; `save_corrected` writes the corrected image to another path. No ROS here.
"""

import os
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import cv2
import numpy as np

from rascal_tasks.archival import chart as ch
from rascal_tasks.archival import colour as col
from rascal_tasks.archival import size as sz
from rascal_tasks.archival.munsell import soil_chart
from rascal_tasks.planar import placed

MAX_CHART_DE00 = 3.0  # mean CIEDE2000 of the chart above this: the colour is flagged
MAX_CHIP_DE00 = 6.0  # the nearest soil-chart chip farther than this: flagged (glaze, paint)
MAX_REPROJECTION_PX = 2.0  # a chart or bar fit worse than this is flagged
SHADOW_LIGHTNESS_WEIGHT = 0.3  # second segmentation: lightness differences count this much
# a region under this share of the area the wrist camera's size expects is looked for again as a
# faint sherd (size.find_faint_sherd) around it, within the sherd's length and this much play
FAINT_AREA = 0.5
PLACE_PLAY_MM = 10.0
SIZE_TOLERANCE_MM = 2.0  # archival and wrist length/width may differ by this ...
SIZE_TOLERANCE_FRAC = 0.05  # ... or this share of the length, whichever is larger
BAR_CHART_AGREEMENT = 0.04  # bar and chart scales may differ by this share (chart: 1 px edges)
# the chart and the bar as far apart in the photo as the configuration says, within this share
# of the bar's px/cm: else where the sherd was put is not taken from the configuration
PLACEMENT_SCALE = 0.1
# a platform the sherd lies on in the photo (the scale under the camera) is looked at this far
# inside its configured outline: its rim and the housing stay out, and the similarity's error
# (0.3-1.9 mm on the bench photos) and the platform's nearness to the lens (it looks ~5 % larger
# than the chart's plane) only move the edge further in
SUPPORT_INSET = 0.012  # m


@dataclass
class Placement:
    """Where on the table (station configuration, m, base_link) the chart's and the bar's
    centres lie and the sherd is put: with the chart and the bar found in a photo, where the
    sherd was put in it."""

    chart_xy: Tuple[float, float]
    bar_xy: Tuple[float, float]
    place_xy: Tuple[float, float]

    def in_photo(
        self, chart_px, bar_px, px_per_cm: float, xy=None
    ) -> Optional[Tuple[float, float]]:
        """The placing spot (or the table point `xy`) in photo pixels, through the similarity
        that takes the chart's and the bar's centres to where the photo shows them (mirrored:
        a camera looking down sees the table's y against its image rows, whichever way it is
        turned). None when its scale is not the bar's within PLACEMENT_SCALE (the targets do
        not lie as configured)."""

        def table(p):
            return complex(p[0], -p[1])

        apart = table(self.chart_xy) - table(self.bar_xy)
        if abs(apart) < 1e-3:
            return None
        a = (complex(*chart_px) - complex(*bar_px)) / apart  # px per m, and the turn
        if abs(abs(a) / (px_per_cm * 100.0) - 1.0) > PLACEMENT_SCALE:
            return None
        xy = self.place_xy if xy is None else xy
        z = complex(*chart_px) + a * (table(xy) - table(self.chart_xy))
        return z.real, z.imag


@dataclass
class Support:
    """What the sherd lies on when it is not the table around the targets: the scale's
    platform under the camera (`over_scale`), its outline on the table (m, base_link; turned
    by its station's yaw) and its top above the chart's and bar's plane."""

    center: Tuple[float, float]
    size: Tuple[float, float]
    height_m: float
    yaw: float = 0.0

    def outline(self, inset: float) -> List[Tuple[float, float]]:
        hx, hy = self.size[0] / 2 - inset, self.size[1] / 2 - inset
        corners = ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))
        return [placed(self.center, self.yaw, c) for c in corners]


@dataclass
class Geometry:
    """What the station's configuration says (optional): sizes of the targets, the camera's
    height and where the sherd is put (`placement`: only to look for a sherd that nothing of
    stood out from the whole photo), and what it lies on when that is not the table
    (`support`: the sherd is looked for only on it; needs `placement`)."""

    chart: ch.ChartSpec = ch.ChartSpec()
    bar: ch.BarSpec = ch.BarSpec()
    camera_height_m: float = 0.0  # lens above the table (parallax of the sherd's outline)
    placement: Optional[Placement] = None
    support: Optional[Support] = None


@dataclass
class ArchivalResult:
    munsell: Optional[str] = None  # nearest soil-chart chip, e.g. '5YR 6/4'
    munsell_de00: Optional[float] = None  # distance to that chip
    lab_d50: Optional[Tuple[float, float, float]] = None
    chart_de00: Optional[float] = None  # mean CIEDE2000 of the 24 patches after correction
    px_per_cm: Optional[float] = None
    length_mm: Optional[float] = None
    width_mm: Optional[float] = None
    chart_reprojection_px: Optional[float] = None
    bar_reprojection_px: Optional[float] = None
    colour_px: int = 0  # pixels the colour was taken from
    flags: List[str] = field(default_factory=list)
    corrected: Optional[np.ndarray] = None  # corrected RGB image (not stored in the catalogue)
    mask: Optional[np.ndarray] = None

    def note(self) -> str:
        """One line for the catalogue's notes: the flags, and the archival size."""
        parts = []
        if self.length_mm is not None:
            parts.append(
                "archival photo: L %.1f mm, W %.1f mm at %.1f px/cm"
                % (self.length_mm, self.width_mm, self.px_per_cm)
            )
        parts.extend(self.flags)
        return "; ".join(parts)


def _support_mask(shape, geometry: Geometry, chart, bar, px_per_cm) -> Optional[np.ndarray]:
    """uint8 0/255: the support's outline (SUPPORT_INSET inside its edge) in the photo, placed
    through the chart and the bar; None when they were not found as configured."""
    if geometry.placement is None or chart is None or bar is None or px_per_cm is None:
        return None
    chart_px, bar_px = chart.corners().mean(axis=0), bar.corners().mean(axis=0)
    corners = [
        geometry.placement.in_photo(chart_px, bar_px, px_per_cm, xy)
        for xy in geometry.support.outline(SUPPORT_INSET)
    ]
    if any(c is None for c in corners):
        return None
    mask = np.zeros(shape[:2], np.uint8)
    cv2.fillConvexPoly(mask, np.round(np.array(corners)).astype(np.int32), 255)
    return mask


def read_rgb(path: str) -> np.ndarray:
    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError("cannot read image %s" % path)
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def analyse_rgb(
    rgb: np.ndarray,
    geometry: Optional[Geometry] = None,
    wrist_size_mm: Optional[Tuple[float, float]] = None,
    object_height_m: float = 0.0,
    hint_px: Optional[Tuple[float, float]] = None,
    tone_curve: str = "full",
) -> ArchivalResult:
    """`tone_curve`: colour.fit's (a comparison's choice; the rig's is "full")."""
    geometry = geometry if geometry is not None else Geometry()
    r = ArchivalResult()
    feats = ch.photo_features(rgb)
    chart, corr = chart_correction(rgb, feats, geometry.chart, r, tone_curve)
    if corr is not None:
        r.corrected = col.correct_image(rgb, corr)
    bar = locate_bar(rgb, feats, geometry, chart, r)
    if bar is not None:
        r.bar_reprojection_px = bar.reprojection_px
        r.px_per_cm = ch.bar_px_per_cm(bar, geometry.bar)
        if bar.reprojection_px > MAX_REPROJECTION_PX:
            r.flags.append("scale bar fit %.1f px RMS" % bar.reprojection_px)

    exclude = np.zeros(rgb.shape[:2], np.uint8)
    for loc in (chart, bar):
        if loc is not None:
            exclude |= loc.polygon_mask(rgb.shape, grow_px=max(4, rgb.shape[1] // 200))
    on_support = None
    if geometry.support is not None:
        on_support = _support_mask(rgb.shape, geometry, chart, bar, r.px_per_cm)
        if on_support is None:
            r.flags.append(
                "the platform the sherd lies on could not be placed in the photo (chart or bar "
                "not found, or not where the configuration has them)"
            )
        else:
            exclude |= 255 - on_support
        object_height_m += geometry.support.height_m
    # segmented in the corrected photo: a colour cast no longer hides a sherd near the table's
    seg = r.corrected if r.corrected is not None else rgb
    sherd = sz.find_sherd(seg, exclude, hint_px)
    expected = None
    if wrist_size_mm is not None and r.px_per_cm is not None and all(wrist_size_mm):
        # what the wrist camera saw only chooses between two segmentations, never the size
        expected = 0.75 * wrist_size_mm[0] * wrist_size_mm[1] * (r.px_per_cm / 10.0) ** 2
    if expected is not None and (sherd is None or sherd.area_px > 1.8 * expected):
        # a region far larger than the sherd: a shadow across the table joined it? Again,
        # with lightness counting less than colour
        other = sz.find_sherd(seg, exclude, hint_px, lightness_weight=SHADOW_LIGHTNESS_WEIGHT)
        sherd = _nearer_in_area(sherd, other, expected)
    near = hint_px if hint_px is not None else _centre(sherd.mask) if sherd is not None else None
    if near is None and geometry.placement is not None and chart is not None and bar is not None:
        # nothing of it stood out: where the station's configuration says it was put
        near = geometry.placement.in_photo(
            chart.corners().mean(axis=0), bar.corners().mean(axis=0), r.px_per_cm
        )
    if (
        expected is not None
        and near is not None
        and (sherd is None or sherd.area_px < FAINT_AREA * expected)
    ):
        # a region far smaller than the sherd: one near the table's colour, of which only an
        # edge or a painted band stood out? Again, against the table around that region (or
        # where it was put), within the sherd's length and the placing's play
        px_per_mm = r.px_per_cm / 10.0
        radius = (max(wrist_size_mm) + PLACE_PLAY_MM) * px_per_mm
        sherd = _nearer_in_area(sherd, sz.find_faint_sherd(seg, exclude, near, radius), expected)
    if sherd is None:
        r.flags.append("sherd not found in the archival photo")
    else:
        r.mask = sherd.mask
        if (
            on_support is not None
            and (cv2.dilate(sherd.mask, np.ones((5, 5), np.uint8)) & ~on_support).any()
        ):
            r.flags.append(
                "the sherd reaches the edge of the platform it lies on: its size may be cut"
            )

    if corr is not None and sherd is not None:
        colour_of(rgb, corr, sherd.mask, r)

    if sherd is not None and r.px_per_cm is not None:
        s = sz.mm_per_px(r.px_per_cm, geometry.camera_height_m, object_height_m)
        r.length_mm, r.width_mm = sherd.length_px * s, sherd.width_px * s
        if wrist_size_mm is not None and all(v and v > 0 for v in wrist_size_mm):
            tol = max(SIZE_TOLERANCE_MM, SIZE_TOLERANCE_FRAC * max(wrist_size_mm[0], r.length_mm))
            dl, dw = r.length_mm - wrist_size_mm[0], r.width_mm - wrist_size_mm[1]
            if abs(dl) > tol or abs(dw) > tol:
                r.flags.append(
                    "size disagrees: archival L/W %.1f/%.1f mm, wrist camera %.1f/%.1f mm "
                    "(tolerance %.1f mm)"
                    % (r.length_mm, r.width_mm, wrist_size_mm[0], wrist_size_mm[1], tol)
                )
    return r


def chart_correction(
    rgb: np.ndarray, feats, spec: ch.ChartSpec, r: ArchivalResult, tone_curve: str = "full"
):
    """(the chart located, the colour correction fitted from it), either None where it failed;
    what went wrong or is doubtful is flagged in `r`, with the chart's reprojection error and
    CIEDE2000 after correction."""
    try:
        chart = ch.locate("chart", feats, spec)
    except ch.TargetNotFound as e:
        r.flags.append("no colour: %s" % e)
        return None, None
    r.chart_reprojection_px = chart.reprojection_px
    if chart.reprojection_px > MAX_REPROJECTION_PX:
        r.flags.append("colour chart fit %.1f px RMS" % chart.reprojection_px)
    try:
        patches, clipped = ch.sample_patches(rgb, chart, spec)
        corr = col.fit(patches, clipped, tone_curve)
    except (ValueError, np.linalg.LinAlgError) as e:
        r.flags.append("no colour: %s" % e)
        return chart, None
    r.chart_de00 = corr.mean_delta_e00
    if r.chart_de00 > MAX_CHART_DE00:
        r.flags.append(
            "colour uncertain: chart CIEDE2000 %.1f after correction (> %.1f)"
            % (r.chart_de00, MAX_CHART_DE00)
        )
    return chart, corr


def colour_of(rgb: np.ndarray, corr: col.Correction, mask: np.ndarray, r: ArchivalResult):
    """The robust colour of the sherd under `mask` (uint8) in the photo `rgb`, corrected by the
    chart's `corr`, into `r`: Munsell chip, its distance, L*a*b* (D50), or a flag."""
    lut = col.decode(np.arange(256))
    full = np.zeros(rgb.shape, np.float64)
    full[mask > 0] = corr.apply(lut[rgb[mask > 0]])
    rgb_lin, n, why = sz.robust_colour(full, rgb, mask)
    r.colour_px = n
    if rgb_lin is None:
        r.flags.append("no colour: %s" % why)
        return
    chip, de = soil_chart().nearest(rgb_lin)
    r.munsell, r.munsell_de00 = chip.notation, de
    if de > MAX_CHIP_DE00:
        r.flags.append("colour off the soil chart: CIEDE2000 %.1f to %s" % (de, chip.notation))
    lab = col.linear_to_lab_d50(rgb_lin)
    r.lab_d50 = tuple(float(v) for v in np.clip(lab, [0, -200, -200], [100, 200, 200]))


def chart_px_per_cm(chart: ch.Located, spec: ch.ChartSpec) -> float:
    c = chart.corners()
    w = (np.linalg.norm(c[1] - c[0]) + np.linalg.norm(c[2] - c[3])) / 2 / (spec.width_mm / 10)
    h = (np.linalg.norm(c[3] - c[0]) + np.linalg.norm(c[2] - c[1])) / 2 / (spec.height_mm / 10)
    return float((w + h) / 2)


def locate_bar(rgb, feats, geometry: Geometry, chart, r: ArchivalResult):
    """The bar by features (the seed's method), then refined by its outline: the one
    black-and-white rectangle of its proportions near where the features put it (sub-pixel
    edges over its whole length, where a few feature points leave ~0.5 % of scale error). With
    too few features, the outline alone, searched over the whole photo (chart left out). Where
    features and outline disagree, the one nearer the chart's scale (else the features). A bar
    whose scale disagrees with the chart's by more than BAR_CHART_AGREEMENT is flagged."""
    why = []
    feat = None
    try:
        feat = ch.locate("bar", feats, geometry.bar)
    except ch.TargetNotFound as e:
        why.append(str(e))
    exclude = np.zeros(rgb.shape[:2], np.uint8)
    if chart is not None:
        exclude |= chart.polygon_mask(rgb.shape, grow_px=6)
    if feat is not None:
        grow = int(0.15 * ch.bar_px_per_cm(feat, geometry.bar) * geometry.bar.length_mm / 10)
        exclude |= 255 - feat.polygon_mask(rgb.shape, grow_px=max(8, grow))
    outline = None
    try:
        outline = ch.locate_bar_outline(rgb, geometry.bar, exclude)
    except ch.TargetNotFound as e:
        why.append(str(e))
    bar = outline
    if feat is not None:
        if outline is None or abs(_scale(outline, geometry) / _scale(feat, geometry) - 1) > 0.03:
            bar = feat
            if outline is not None and chart is not None:
                # two readings of the bar that disagree: the one the chart bears out (a
                # darker exposure's features fitted the bar 9 % long, its outline exactly)
                ref = chart_px_per_cm(chart, geometry.chart)
                bar = min((feat, outline), key=lambda b: abs(_scale(b, geometry) / ref - 1))
    if bar is None:
        r.flags.append("no size: %s" % "; ".join(why))
        return None
    if chart is not None:
        ref = chart_px_per_cm(chart, geometry.chart)
        if abs(_scale(bar, geometry) / ref - 1) > BAR_CHART_AGREEMENT:
            r.flags.append(
                "size uncertain: the scale bar says %.1f px/cm, the colour chart %.1f px/cm"
                % (_scale(bar, geometry), ref)
            )
    return bar


def _scale(loc, geometry):
    return ch.bar_px_per_cm(loc, geometry.bar)


def _nearer_in_area(sherd, other, expected: float):
    """Of two segmentations (size.SherdRegion or None), the one whose area is nearer, as a
    ratio, the `expected` area in pixels: what the wrist camera saw chooses, never sizes."""
    if other is None or (
        sherd is not None
        and abs(np.log(other.area_px / expected)) >= abs(np.log(sherd.area_px / expected))
    ):
        return sherd
    return other


def _centre(mask: np.ndarray) -> Tuple[float, float]:
    m = cv2.moments(mask, binaryImage=True)
    return m["m10"] / m["m00"], m["m01"] / m["m00"]


def analyse(path: str, **kwargs) -> ArchivalResult:
    """analyse_rgb on an image file (only read)."""
    return analyse_rgb(read_rgb(path), **kwargs)


def corrected_path(image_path: str) -> str:
    """Where the corrected copy of an archived image goes: a `corrected/` folder beside it,
    same file name (the archive's own files and `rascal verify` leave subfolders alone)."""
    folder, name = os.path.split(image_path)
    return os.path.join(folder, "corrected", name)


def save_corrected(
    result: ArchivalResult, path: str, file_mode: int = 0o644, dir_mode: int = 0o755
) -> Optional[str]:
    """Write the corrected image to `path` (PNG, atomically); None when there is none."""
    if result.corrected is None:
        return None
    folder = os.path.dirname(path)
    if not os.path.isdir(folder):
        os.makedirs(folder, exist_ok=True)
        os.chmod(folder, dir_mode)
    tmp = path + ".tmp.png"
    if not cv2.imwrite(tmp, cv2.cvtColor(result.corrected, cv2.COLOR_RGB2BGR)):
        raise OSError("cannot write %s" % tmp)
    os.chmod(tmp, file_mode)
    os.replace(tmp, path)
    return path
