"""`archival_photo`: the archival analysis offline, on any photo of sherds with the colour chart
(and a scale bar) in view: per sherd its Munsell chip, L*a*b* and length/width in mm.

The sherds are found by `segment_image` (rascal_perception: the segmentation tested on real
photos, its 10 cm chequer bar) and measured here: the chart by features + homography, the
colours corrected from its 24 patches, each sherd's robust colour named on the soil chart.
Sizes are the extents along and across each sherd's principal axis, through the scale of
segment_image's bar or, without one, of the archival scale bar when found.
No ROS here (segment_image is found on CMAKE_PREFIX_PATH, as `rosrun` would).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from typing import List, Optional

import cv2
import numpy as np

from rascal_tasks.archival import chart as ch
from rascal_tasks.archival import colour as col
from rascal_tasks.archival import size as sz
from rascal_tasks.archival.analysis import (
    ArchivalResult,
    Geometry,
    locate_bar,
    chart_correction,
    colour_of,
    read_rgb,
)

OK, DOUBTFUL, BAD_INPUT = 0, 1, 2
# a segmented region lying this much on the chart or a bar is part of the target, not a sherd
ON_TARGET_SHARE = 0.3


def segment_image_tool() -> str:
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        path = os.path.join(prefix, "lib", "rascal_perception", "segment_image")
        if prefix and os.access(path, os.X_OK):
            return path
    raise FileNotFoundError(
        "segment_image not found on CMAKE_PREFIX_PATH; build the workspace and "
        "`source devel/setup.bash`"
    )


def segment(photo: str):
    """(segment_image's JSON, its label image) for `photo`."""
    with tempfile.TemporaryDirectory(prefix="archival_photo_") as tmp:
        labels_path = os.path.join(tmp, "labels.png")
        r = subprocess.run(
            [segment_image_tool(), photo, "--report", "-", "--no-overlay", "--labels", labels_path],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        if r.returncode not in (0, 1):
            raise ValueError(r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed")
        labels = cv2.imread(labels_path, cv2.IMREAD_UNCHANGED)
    return json.loads(r.stdout), labels


def refined(rgb: np.ndarray, mask: np.ndarray, others: np.ndarray) -> np.ndarray:
    """The sherd's outline put where the archival analysis puts it (half its contrast against
    the cloth around it: size.find_sherd on a crop around it, the other sherds and the targets
    left out), so sizes follow the catalogue's definition; segment_image's outline (drawn a
    little outside the edge) where that finds nothing like it."""
    x, y, w, h = cv2.boundingRect(mask)
    m = max(w, h) // 3 + 10
    x0, y0 = max(0, x - m), max(0, y - m)
    x1, y1 = min(rgb.shape[1], x + w + m), min(rgb.shape[0], y + h + m)
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (9, 9))
    exclude = cv2.dilate(others[y0:y1, x0:x1].astype(np.uint8) * 255, k)
    own = mask[y0:y1, x0:x1]
    centre = np.argwhere(own > 0).mean(axis=0)[::-1]
    region = sz.find_sherd(rgb[y0:y1, x0:x1], exclude, hint_px=tuple(centre))
    if region is None:
        return mask
    a, b = region.mask > 0, own > 0
    if (a & b).sum() < 0.7 * (a | b).sum():  # not the same piece: keep segment_image's
        return mask
    out = np.zeros_like(mask)
    out[y0:y1, x0:x1] = region.mask
    return out


def analyse_photo(photo: str) -> dict:
    """Every sherd of the photo with its colour and size, and the photo's doubts."""
    rgb = read_rgb(photo)
    seg, labels = segment(photo)
    geometry = Geometry()
    photo_r = ArchivalResult()
    feats = ch.photo_features(rgb)
    chart, corr = chart_correction(rgb, feats, geometry.chart, photo_r)
    bar = None
    if seg.get("px_per_cm") is None:  # the archival station's bar, when segment_image saw none
        bar = locate_bar(rgb, feats, geometry, chart, photo_r)
        if bar is not None:
            photo_r.px_per_cm = ch.bar_px_per_cm(bar, geometry.bar)
    targets = np.zeros(rgb.shape[:2], np.uint8)
    for loc in (chart, bar):
        if loc is not None:
            targets |= loc.polygon_mask(rgb.shape, grow_px=max(4, rgb.shape[1] // 200))
    px_per_cm = seg.get("px_per_cm") or photo_r.px_per_cm
    corrected = col.correct_image(rgb, corr) if corr is not None else rgb
    sherds: List[dict] = []
    for s in seg["sherds"]:
        mask = ((labels == s["id"]) * 255).astype(np.uint8)
        if not mask.any() or (targets[mask > 0] > 0).mean() > ON_TARGET_SHARE:
            continue  # a piece of the chart or bar
        mask = refined(corrected, mask, (labels > 0) & (labels != s["id"]) | (targets > 0))
        r = ArchivalResult()
        if corr is not None:
            colour_of(rgb, corr, mask, r)
        # extents along and across the principal axis (the archival analysis's and the
        # catalogue's definition), through the bar's scale
        length = width = None
        if px_per_cm:
            region = sz.region_of(mask)
            mm = sz.mm_per_px(px_per_cm)
            length, width = region.length_px * mm, region.width_px * mm
        sherds.append(
            {
                "id": len(sherds) + 1,
                "segment_image_id": s["id"],
                "centre_px": s["centre_px"],
                "length_mm": _round(length),
                "width_mm": _round(width),
                "munsell": r.munsell,
                "munsell_de00": _round(r.munsell_de00, 2),
                "lab_d50": [round(v, 2) for v in r.lab_d50] if r.lab_d50 else None,
                "flags": s["flags"] + r.flags,
            }
        )
    doubts = list(photo_r.flags) + list(seg.get("doubts", []))
    if px_per_cm is None:
        doubts.append("no scale bar: sizes not measured")
    return {
        "image": photo,
        "px_per_cm": _round(px_per_cm, 2),
        "chart_delta_e00": _round(photo_r.chart_de00, 2),
        "chart_reprojection_px": _round(photo_r.chart_reprojection_px, 2),
        "doubts": doubts,
        "sherds": sherds,
    }


def _round(v: Optional[float], digits: int = 1):
    return None if v is None else round(float(v), digits)


def table(result: dict) -> str:
    lines = [
        "%4s %9s %9s  %-10s %20s  %s"
        % ("id", "length mm", "width mm", "Munsell", "L*a*b*", "flags")
    ]
    for s in result["sherds"]:
        lab = "%.1f %.1f %.1f" % tuple(s["lab_d50"]) if s["lab_d50"] else "-"
        lines.append(
            "%4d %9s %9s  %-10s %20s  %s"
            % (
                s["id"],
                "-" if s["length_mm"] is None else "%.1f" % s["length_mm"],
                "-" if s["width_mm"] is None else "%.1f" % s["width_mm"],
                s["munsell"] or "-",
                lab,
                ", ".join(s["flags"]),
            )
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        prog="archival_photo",
        description="Munsell colour (soil chart, illuminant C), L*a*b* (D50) and length/width "
        "in mm of every sherd in a photo with the colour chart and a scale bar in view.",
        epilog="exit codes: 0 every sherd measured; 1 doubtful (no chart, no bar, a sherd "
        "flagged: the summary says which); 2 bad usage or an unreadable photo.",
    )
    p.add_argument("photo")
    p.add_argument("--json", action="store_true", help="JSON on stdout instead of the table")
    args = p.parse_args(argv)
    if not os.path.isfile(args.photo):
        print(
            "archival_photo: photo '%s' does not exist; check the path" % args.photo,
            file=sys.stderr,
        )
        return BAD_INPUT
    try:
        result = analyse_photo(args.photo)
    except (ValueError, OSError) as e:
        print("archival_photo: %s" % str(e).splitlines()[0], file=sys.stderr)
        return BAD_INPUT
    doubtful = bool(result["doubts"]) or any(s["flags"] for s in result["sherds"])
    if args.json:
        print(json.dumps(result, indent=1))
    else:
        print(table(result))
        summary = "%d sherds, %s, chart %s" % (
            len(result["sherds"]),
            "%.2f px/cm" % result["px_per_cm"] if result["px_per_cm"] else "no scale bar",
            "CIEDE2000 %.2f" % result["chart_delta_e00"]
            if result["chart_delta_e00"] is not None
            else "not found",
        )
        if result["doubts"]:
            summary += "; " + "; ".join(result["doubts"])
        print(
            "archival_photo: %s%s" % (summary, " (doubtful: exit 1)" if doubtful else ""),
            file=sys.stderr,
        )
    return DOUBTFUL if doubtful else OK


if __name__ == "__main__":
    sys.exit(main())
