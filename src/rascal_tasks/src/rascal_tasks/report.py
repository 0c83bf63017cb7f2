"""The report of one context for the archaeologist: a page that prints on A4 (and its PDF).

Per sherd: a thumbnail cropped to the sherd (from the colour-corrected image where one lies
next to the archival image, else the archival image itself) that links to the full archival
image; its colour as a swatch with the Munsell notation and CIE L*a*b*, or "not measured"; its
mass and size (length × width × thickness, size class). Then the context's totals (count, total
and mean mass, counts by size class and by colour group, with small inline SVG plots), the lost
sherds with their reasons and, as a last section on a page of its own, the engineer's time
breakdown (the paper's Fig. 10: locomotion, grasping, data collection, perception) when the rows
carry one.

Input is the catalogue's export rows (dicts); output one self-contained folder
``<archive>/<context_folder(context)>/report/`` with ``index.html``, ``thumbs/<seq>.jpg`` and,
with ``print_pdf``, ``<folder>.pdf``: headless Chromium prints the same page (``--pdf``). No ROS
here, and nothing from the network: the page has no external resource.
"""

import datetime
import html
import math
import os
import re
import shutil
import signal
import subprocess
import tempfile
import urllib.parse

from rascal_tasks.catalogue.context_id import context_folder

__all__ = [
    "PHASES",
    "SIZE_CLASSES",
    "CORRECTED_SUFFIXES",
    "write_report",
    "print_pdf",
    "screenshot",
    "find_browser",
    "lab_to_srgb",
    "colour_group",
    "size_class",
    "corrected_image",
    "crop_box",
]

PHASES = (
    ("locomotion", "#4e79a7"),
    ("grasping", "#f28e2b"),
    ("data_collection", "#59a14f"),
    ("perception", "#b07aa1"),
)
# Clist 2004/05 (as in AtlantGIS): the smallest square of this side (mm) the sherd fits in
SIZE_CLASSES = ((30, "< 30 mm"), (70, "30–70 mm"), (120, "70–120 mm"), (200, "120–200 mm"))
LARGEST_CLASS = "≥ 200 mm"
NOT_MEASURED = "not measured"
# the colour-corrected image beside the archival image <folder>/<name>.png: the archival
# stage writes <folder>/corrected/<name>.png (archival.corrected_path); <stem> + one of these
# suffixes is also taken
CORRECTED_FOLDER = "corrected"
CORRECTED_SUFFIXES = (".corrected.png", "-corrected.png", "_corrected.png")
# Munsell hue pages in the order of the hue circle (soil colours first), then the neutrals
_HUE_ORDER = ("10R", "2.5YR", "5YR", "7.5YR", "10YR", "2.5Y", "5Y", "N")
_HUE_RE = re.compile(
    r"^\s*(?:(N)\b|(GLEY\s*\d)|(\d+(?:\.\d+)?)\s*(RP|YR|GY|BG|PB|R|Y|G|B|P)\b)", re.I
)
THUMB_PX = 360  # longest side of a thumbnail: 40 mm printed at about 230 dpi
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


# --- colour ---
def lab_to_srgb(lab):
    """8-bit sRGB (D65) of CIE L*a*b* (D50, as the catalogue stores it; Bradford adapted),
    clipped into the gamut; None for a missing value."""
    if lab is None or any(v is None for v in lab):
        return None
    L, a, b = (float(v) for v in lab)
    fy = (L + 16.0) / 116.0
    fx, fz = fy + a / 500.0, fy - b / 200.0

    def finv(t):
        return t**3 if t**3 > 216.0 / 24389.0 else (116.0 * t - 16.0) / (24389.0 / 27.0)

    xyz50 = (
        0.96422 * finv(fx),
        1.0 * (fy**3 if L > 8.0 else L / (24389.0 / 27.0)),
        0.82521 * finv(fz),
    )
    bradford = (
        (0.9555766, -0.0230393, 0.0631636),
        (-0.0282895, 1.0099416, 0.0210077),
        (0.0122982, -0.0204830, 1.3299098),
    )
    xyz = [sum(m * v for m, v in zip(row, xyz50, strict=True)) for row in bradford]
    to_rgb = (
        (3.2404542, -1.5371385, -0.4985314),
        (-0.9692660, 1.8760108, 0.0415560),
        (0.0556434, -0.2040259, 1.0572252),
    )
    out = []
    for row in to_rgb:
        c = min(1.0, max(0.0, sum(m * v for m, v in zip(row, xyz, strict=True))))
        c = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
        out.append(int(round(255.0 * c)))
    return tuple(out)


def _hex(rgb):
    return "#%02x%02x%02x" % tuple(rgb)


def _lab(row):
    lab = (row.get("colour_l"), row.get("colour_a"), row.get("colour_b"))
    return None if any(v is None for v in lab) else lab


def colour_group(munsell):
    """The Munsell hue page of a notation (``'5YR 6/4'`` → ``'5YR'``, ``'N 5/'`` → ``'N'``,
    ``'GLEY1 5/N'`` → ``'GLEY1'``); ``'not measured'`` when empty, ``'other'`` when unreadable."""
    if not munsell or not str(munsell).strip():
        return NOT_MEASURED
    m = _HUE_RE.match(str(munsell))
    if not m:
        return "other"
    if m.group(1):
        return "N"
    if m.group(2):
        return m.group(2).upper().replace(" ", "")
    number = m.group(3)
    number = number[:-2] if number.endswith(".0") else number
    return number + m.group(4).upper()


def _group_rank(group):
    if group in _HUE_ORDER:
        return (0, _HUE_ORDER.index(group), group)
    if group == NOT_MEASURED:
        return (3, 0, group)
    return (2 if group == "other" else 1, 0, group)


def size_class(row):
    """The sherd's size class (Clist 2004/05) from the larger of length and width."""
    dims = [row.get(k) for k in ("length_mm", "width_mm") if row.get(k) is not None]
    if not dims:
        return NOT_MEASURED
    side = max(dims)
    for limit, label in SIZE_CLASSES:
        if side < limit:
            return label
    return LARGEST_CLASS


# --- images ---
def corrected_image(original):
    """The colour-corrected image beside ``original``: ``corrected/<its name>`` in its folder,
    else ``<stem>`` + one of ``CORRECTED_SUFFIXES``; None when there is none."""
    folder, name = os.path.split(original)
    stem, _ = os.path.splitext(original)
    candidates = [os.path.join(folder, CORRECTED_FOLDER, name)]
    candidates += [stem + suffix for suffix in CORRECTED_SUFFIXES]
    for path in candidates:
        if os.path.isfile(path):
            return path
    return None


def crop_box(img):
    """``(x0, y0, x1, y1)`` of the sherd in an archival frame (BGR), or None where no part of
    the frame looks like one. The background is the frame's border colour; of the regions that
    differ from it, the colour chart and the scale bar are the near-perfect rectangles; the
    sherd is the largest other region not cut by the frame's edge. A margin of 12 % is kept."""
    import cv2
    import numpy as np

    h, w = img.shape[:2]
    scale = 400.0 / max(h, w)
    small = cv2.resize(img, (max(1, round(w * scale)), max(1, round(h * scale))), cv2.INTER_AREA)
    lab = cv2.cvtColor(small, cv2.COLOR_BGR2LAB).astype(np.float32)
    sh, sw = lab.shape[:2]
    border = np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]])
    bg = np.median(border, axis=0)
    spread = np.median(np.linalg.norm(border - bg, axis=1))
    dist = np.linalg.norm(lab - bg, axis=2)
    mask = (dist > max(8.0, 4.0 * spread)).astype(np.uint8)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))
    mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, kernel)
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, kernel)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    best = None
    for i in range(1, n):
        x, y, bw, bh, area = stats[i]
        if area < 0.002 * sh * sw:
            continue
        if x == 0 or y == 0 or x + bw >= sw or y + bh >= sh:
            continue  # cut by the frame's edge: not the sherd placed in view
        contours, _ = cv2.findContours(
            (labels == i).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
        )
        (_, _), (rw, rh), _ = cv2.minAreaRect(max(contours, key=cv2.contourArea))
        if rw * rh > 0 and area / (rw * rh) > 0.9:
            continue  # a rectangle: the colour chart or the scale bar
        if best is None or area > best[4]:
            best = (x, y, bw, bh, area)
    if best is None:
        return None
    x, y, bw, bh, _ = best
    m = 0.12 * max(bw, bh)
    x0, y0 = max(0, int((x - m) / scale)), max(0, int((y - m) / scale))
    x1, y1 = (
        min(w, int(math.ceil((x + bw + m) / scale))),
        min(h, int(math.ceil((y + bh + m) / scale))),
    )
    return x0, y0, x1, y1


def _thumbnail(src, dst, file_mode):
    """Write the cropped thumbnail of ``src`` to ``dst`` (JPEG); ``(written, cropped)``."""
    try:
        import cv2
    except ImportError:  # pragma: no cover - python3-opencv is installed by setup.sh
        return False, False
    img = cv2.imread(src, cv2.IMREAD_COLOR)
    if img is None:
        return False, False
    box = crop_box(img)
    if box is not None:
        x0, y0, x1, y1 = box
        img = img[y0:y1, x0:x1]
    h, w = img.shape[:2]
    f = min(1.0, THUMB_PX / float(max(h, w)))
    if f < 1.0:
        img = cv2.resize(img, (max(1, round(w * f)), max(1, round(h * f))), cv2.INTER_AREA)
    tmp = dst + ".tmp.jpg"
    if not cv2.imwrite(tmp, img, [cv2.IMWRITE_JPEG_QUALITY, 88]):
        return False, False
    os.chmod(tmp, file_mode)
    os.replace(tmp, dst)
    return True, box is not None


# --- formatting ---
def _fmt(v, spec="%.1f"):
    return "–" if v is None else spec % v


def _num(row, column):
    """A measured value as the export writes it (0.1 g, 0.1 mm; half up), or '–'."""
    from rascal_tasks.catalogue.export import rounded

    return _fmt(rounded(column, row.get(column)))


def _esc(v):
    return html.escape("" if v is None else str(v))


def _href(target, start):
    """A relative URL from folder ``start`` to file ``target`` (each part percent-encoded, so
    that an archive folder such as ``TR1%2F1023`` stays one folder)."""
    rel = os.path.relpath(target, start)
    return "/".join(urllib.parse.quote(part) for part in rel.split(os.sep))


def _swatch_svg(rgb, size=34):
    """A colour swatch as SVG (prints without the browser's 'background graphics')."""
    return (
        '<svg class="swatch" width="%d" height="%d" viewBox="0 0 %d %d" role="img" '
        'aria-label="colour swatch %s"><rect width="%d" height="%d" fill="%s" stroke="#333" '
        'stroke-width="1"/></svg>' % (size, size, size, size, _hex(rgb), size, size, _hex(rgb))
    )


def _bar_chart(items, width=300, colours=None):
    """Small horizontal bar chart of ``[(label, count)]`` as inline SVG."""
    row_h, left, right = 18, 96, 34
    top = max([c for _, c in items] + [1])
    height = row_h * len(items) + 6
    out = [
        '<svg class="plot" xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
        'viewBox="0 0 %d %d" font-size="11" font-family="DejaVu Sans, sans-serif">'
        % (width, height, width, height)
    ]
    for i, (label, count) in enumerate(items):
        y = 3 + i * row_h
        bar = (width - left - right) * count / top
        fill = (colours or {}).get(label) or "#7a7a7a"
        out.append(
            '<text x="%d" y="%d" text-anchor="end">%s</text>'
            '<rect x="%d" y="%d" width="%.1f" height="13" fill="%s" stroke="#333" '
            'stroke-width="0.5"/><text x="%.1f" y="%d">%d</text>'
            % (left - 5, y + 11, _esc(label), left, y, bar, fill, left + bar + 4, y + 11, count)
        )
    out.append("</svg>")
    return "".join(out)


def _breakdown_svg(rows) -> str:
    """Stacked horizontal bar per sherd plus the mean, in seconds."""
    bars = [(str(r["seq"]), [r.get("t_%s_s" % p) or 0.0 for p, _ in PHASES]) for r in rows]
    if bars:
        mean = [sum(b[1][i] for b in bars) / len(bars) for i in range(len(PHASES))]
        bars.append(("mean", mean))
    longest = max([sum(b[1]) for b in bars] + [1.0])
    scale = 460.0 / longest
    row_h, left = 20, 60
    height = row_h * (len(bars) + 2) + 10
    out = [
        '<svg xmlns="http://www.w3.org/2000/svg" width="640" height="%d" viewBox="0 0 640 %d" '
        'font-size="11" font-family="DejaVu Sans, sans-serif">' % (height, height)
    ]
    for i, (label, parts) in enumerate(bars):
        y = 5 + i * row_h
        out.append(
            '<text x="%d" y="%d" text-anchor="end">%s</text>' % (left - 6, y + 12, _esc(label))
        )
        x = left
        for (phase, colour), secs in zip(PHASES, parts, strict=True):
            w = secs * scale
            out.append(
                '<rect x="%.1f" y="%d" width="%.1f" height="14" fill="%s">'
                "<title>%s %.1f s</title></rect>" % (x, y, w, colour, phase, secs)
            )
            x += w
        out.append('<text x="%.1f" y="%d">%.1f s</text>' % (x + 4, y + 12, sum(parts)))
    y = 10 + len(bars) * row_h
    for i, (phase, colour) in enumerate(PHASES):
        out.append(
            '<rect x="%d" y="%d" width="12" height="12" fill="%s"/>'
            '<text x="%d" y="%d">%s</text>'
            % (left + i * 140, y, colour, left + i * 140 + 16, y + 10, phase.replace("_", " "))
        )
    out.append("</svg>")
    return "".join(out)


def _note(r) -> str:
    """What a person should know about a row: lost and why, no mass and why, drops, notes."""
    parts = []
    if r.get("status") == "lost":
        parts.append("lost: %s" % (r.get("lost_reason") or "no reason recorded"))
    elif r.get("status") not in (None, "done"):
        parts.append("not finished (%s)" % r.get("status"))
    if r.get("mass_g") is None and r.get("mass_missing_reason"):
        parts.append("no mass: %s" % r["mass_missing_reason"])
    if r.get("drops"):
        parts.append("dropped %d×" % r["drops"])
    if r.get("notes"):
        parts.append(str(r["notes"]))
    return "; ".join(parts)


def _when(ts):
    if ts is None:
        return "–"
    if isinstance(ts, datetime.datetime):
        return ts.astimezone().strftime("%Y-%m-%d %H:%M %Z").strip()
    return str(ts)


def _totals(rows):
    from rascal_tasks.catalogue.export import rounded

    masses = [rounded("mass_g", r["mass_g"]) for r in rows if r.get("mass_g") is not None]
    sizes, groups, labs = {}, {}, {}
    for r in rows:
        sizes[size_class(r)] = sizes.get(size_class(r), 0) + 1
        g = colour_group(r.get("colour_munsell"))
        groups[g] = groups.get(g, 0) + 1
        if _lab(r) is not None:
            labs.setdefault(g, []).append(_lab(r))
    order = [label for _, label in SIZE_CLASSES] + [LARGEST_CLASS, NOT_MEASURED]
    size_items = [(k, sizes[k]) for k in order if k in sizes]
    group_items = sorted(groups.items(), key=lambda kv: _group_rank(kv[0]))
    group_colours = {  # a group's bar in its mean colour (a sherd without notation: grey)
        g: _hex(lab_to_srgb([sum(v[i] for v in ls) / len(ls) for i in range(3)]))
        for g, ls in labs.items()
        if g not in (NOT_MEASURED, "other")
    }
    return {
        "count": len(rows),
        "done": sum(r.get("status") == "done" for r in rows),
        "lost": sum(r.get("status") == "lost" for r in rows),
        "weighed": len(masses),
        "total_mass": sum(masses) if masses else None,
        "mean_mass": sum(masses) / len(masses) if masses else None,
        "sizes": size_items,
        "groups": group_items,
        "group_colours": group_colours,
    }


_CSS = """
@page { size: A4 portrait; margin: 14mm 12mm 16mm 12mm;
  @bottom-left { content: "RASCAL · context %(ctx_css)s"; font: 8pt "DejaVu Sans", sans-serif; }
  @bottom-right { content: "page " counter(page) " of " counter(pages);
                  font: 8pt "DejaVu Sans", sans-serif; } }
* { -webkit-print-color-adjust: exact; print-color-adjust: exact; box-sizing: border-box; }
body { font: 10pt/1.35 "DejaVu Sans", "Liberation Sans", sans-serif; color: #111;
       background: #fff; margin: 0 auto; max-width: 186mm; padding: 4mm 0; }
h1 { font-size: 17pt; margin: 0 0 1mm; } h2 { font-size: 12.5pt; margin: 6mm 0 2mm; }
p.meta { margin: 0 0 3mm; color: #333; }
table { border-collapse: collapse; width: 100%%; }
th, td { border-bottom: 0.3mm solid #bbb; padding: 1.2mm 1.5mm; vertical-align: top;
         text-align: left; }
th { font-size: 8.5pt; color: #333; border-bottom: 0.5mm solid #333; }
td.num, th.num { text-align: right; white-space: nowrap; }
td.find { white-space: nowrap; } td.notes { width: 30mm; }
thead { display: table-header-group; }
tr, .plotbox, .totals { break-inside: avoid; page-break-inside: avoid; }
img.thumb { display: block; width: 38mm; height: 38mm; object-fit: contain;
            background: #f3f3f3; border: 0.2mm solid #999; }
.colour { display: flex; gap: 2mm; align-items: flex-start; }
.colour .munsell { font-weight: bold; white-space: nowrap; }
.small, .lab { font-size: 8pt; color: #444; }
.nm { color: #666; font-style: italic; }
.lost td { background: #fbeaea; }
.totals { display: flex; flex-wrap: wrap; gap: 4mm 8mm; }
.totals dl { margin: 0; display: grid; grid-template-columns: auto auto; gap: 0.5mm 4mm; }
.totals dt { color: #333; } .totals dd { margin: 0; font-weight: bold; text-align: right; }
.plotbox h3 { font-size: 9.5pt; margin: 0 0 1mm; }
section.engineer { break-before: page; page-break-before: always; }
a { color: #0645ad; }
@media print { a { color: inherit; text-decoration: none; } }
"""


def _sherd_row(r, folder, archive_root, file_mode):
    """One table row of the sherd list: ``(html, has_thumbnail)``."""
    thumb = '<span class="nm">no image</span>'
    shown = False
    if r.get("image_path"):
        src = r["image_path"]
        src = src if os.path.isabs(src) else os.path.join(archive_root, src)
        corrected = corrected_image(src)
        name = "%d.jpg" % r["seq"]
        written, cropped = _thumbnail(
            corrected or src, os.path.join(folder, "thumbs", name), file_mode
        )
        kind = "colour-corrected" if corrected else "as photographed"
        if written:
            shown = True
            thumb = (
                '<a href="%s" title="full archival image"><img class="thumb" src="thumbs/%s" '
                'alt="sherd %d (%s%s)"></a><div class="small">%s%s</div>'
                % (
                    _esc(_href(src, folder)),
                    name,
                    r["seq"],
                    kind,
                    "" if cropped else ", whole frame",
                    kind,
                    "" if cropped else ", not cropped",
                )
            )
            if corrected:
                thumb += '<div class="small"><a href="%s">corrected image</a></div>' % _esc(
                    _href(corrected, folder)
                )
        elif os.path.isfile(src):
            thumb = '<span class="nm">image unreadable</span>'
        else:
            thumb = '<span class="nm">image missing from the archive</span>'
    rgb = lab_to_srgb(_lab(r))
    if r.get("colour_munsell") or rgb is not None:
        colour = '<div class="colour">%s<div><div class="munsell">%s</div>%s</div></div>' % (
            _swatch_svg(rgb) if rgb is not None else "",
            _esc(r.get("colour_munsell"))
            if r.get("colour_munsell")
            else '<span class="nm">' "no Munsell notation</span>",
            '<div class="lab">L*a*b* %.1f, %.1f, %.1f</div>' % _lab(r) if rgb is not None else "",
        )
    else:
        colour = '<span class="nm">%s</span>' % NOT_MEASURED
    size = "%s × %s × %s" % (_num(r, "length_mm"), _num(r, "width_mm"), _num(r, "thickness_mm"))
    if r.get("vessel_diameter_mm"):
        size += '<div class="small">vessel Ø %.0f ± %.0f mm</div>' % (
            r["vessel_diameter_mm"],
            r["vessel_diameter_sigma_mm"],
        )
    row = (
        '<tr class="%s"><td class="find"><b>%s</b><div class="small">%s</div></td><td>%s</td>'
        '<td>%s</td><td class="num">%s</td><td class="num">%s<div class="small">%s</div></td>'
        '<td class="small notes">%s</td></tr>'
        % (
            _esc(r.get("status")),
            _esc(r.get("find_id") or r["seq"]),
            _esc(r.get("status")),
            thumb,
            colour,
            _num(r, "mass_g"),
            size,
            _esc(size_class(r)),
            _esc(_note(r)),
        )
    )
    return row, shown


def write_report(
    context: str,
    rows,
    archive_root: str,
    summary: dict = None,
    context_row: dict = None,
    file_mode: int = 0o644,
    dir_mode: int = 0o755,
) -> str:
    """Write the report folder of ``context`` (``<archive_root>/<context_folder>/report``);
    returns the path of its index.html. ``summary``: the engineer's figures (a dict shown as a
    list); ``context_row``: the catalogue's context (site, created_at)."""
    from rascal_tasks.catalogue.archive import make_dirs

    folder = os.path.join(archive_root, context_folder(context), "report")
    make_dirs(os.path.join(folder, "thumbs"), dir_mode)
    rows = sorted(rows, key=lambda r: r["seq"])
    body = []
    for r in rows:
        body.append(_sherd_row(r, folder, archive_root, file_mode)[0])
    t = _totals(rows)
    ctx = context_row or {}
    stamps = [r.get(k) for r in rows for k in ("done_at", "lost_at") if r.get(k) is not None]
    first, last = (min(stamps), max(stamps)) if stamps else (None, None)
    rigs = sorted({str(r["rig"]) for r in rows if r.get("rig")})
    meta = "site %s · %d sherd%s recorded %s – %s%s" % (
        _esc(ctx.get("site_id") or "–"),
        len(rows),
        "" if len(rows) == 1 else "s",
        _esc(_when(first)),
        _esc(_when(last)),
        " · rig %s" % _esc(", ".join(rigs)) if rigs else "",
    )
    totals = (
        '<div class="totals"><dl>'
        "<dt>sherds</dt><dd>%d</dd><dt>recorded (done)</dt><dd>%d</dd><dt>lost</dt><dd>%d</dd>"
        "<dt>weighed</dt><dd>%d</dd><dt>total mass</dt><dd>%s</dd><dt>mean mass</dt><dd>%s</dd>"
        '</dl><div class="plotbox"><h3>by size class (larger of length and width)</h3>%s</div>'
        '<div class="plotbox"><h3>by colour group (Munsell hue page)</h3>%s</div></div>'
        % (
            t["count"],
            t["done"],
            t["lost"],
            t["weighed"],
            "%.1f g" % t["total_mass"] if t["total_mass"] is not None else NOT_MEASURED,
            "%.1f g" % t["mean_mass"] if t["mean_mass"] is not None else NOT_MEASURED,
            _bar_chart(t["sizes"]),
            _bar_chart(t["groups"], colours=t["group_colours"]),
        )
    )
    lost = [r for r in rows if r.get("status") == "lost"]
    if lost:
        lost_html = "<ul>%s</ul>" % "".join(
            "<li><b>%s</b>: %s (%s)</li>"
            % (
                _esc(r.get("find_id") or r["seq"]),
                _esc(r.get("lost_reason") or "no reason recorded"),
                _esc(_when(r.get("lost_at"))),
            )
            for r in lost
        )
    else:
        lost_html = "<p>None: no sherd of this context was lost.</p>"
    timed = [r for r in rows if any(r.get("t_%s_s" % p) is not None for p, _ in PHASES)]
    engineer = ""
    if timed or summary:
        engineer = (
            '<section class="engineer"><h2>For the engineer: where the time went</h2>'
            "<ul>%s</ul>%s</section>"
            % (
                "".join("<li>%s: %s</li>" % (_esc(k), _esc(v)) for k, v in (summary or {}).items()),
                (
                    "<p class=\"small\">seconds per sherd (the paper's Fig. 10 breakdown)</p>"
                    + _breakdown_svg(timed)
                )
                if timed
                else "",
            )
        )
    ctx_css = "".join(  # a CSS string: every character but letters, digits, space escaped
        c if c.isalnum() or c == " " else "\\%06x" % ord(c) for c in context
    )
    page = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Context %(ctx)s – RASCAL sherd report</title>
<style>%(css)s</style>
</head><body>
<header><h1>Context %(ctx)s</h1><p class="meta">%(meta)s</p></header>
<section><h2>Totals</h2>%(totals)s</section>
<section><h2>Sherds</h2>
<table class="sherds"><thead><tr><th>find</th><th>image (links to the archival image)</th>
<th>colour</th><th class="num">mass (g)</th><th class="num">L × W × T (mm)</th><th>notes</th>
</tr></thead><tbody>
%(rows)s
</tbody></table></section>
<section><h2>Lost sherds</h2>%(lost)s</section>
%(engineer)s
<footer class="small"><p>Written by RASCAL on %(now)s. Colour: CIE L*a*b* (D50) shown as
sRGB; Munsell notation of the photographed face. Size classes after Clist 2004/05.</p></footer>
</body></html>
""" % {
        "ctx": html.escape(context),
        "css": _CSS % {"ctx_css": ctx_css},
        "meta": meta,
        "totals": totals,
        "rows": "\n".join(body),
        "lost": lost_html,
        "engineer": engineer,
        "now": _esc(_when(datetime.datetime.now(datetime.timezone.utc))),
    }
    path = os.path.join(folder, "index.html")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.chmod(tmp, file_mode)
    os.replace(tmp, path)
    return path


# --- the headless browser: PDF and screenshot ---
def find_browser():
    """Path of a Chromium to print with (``$RASCAL_CHROMIUM``, else the first on PATH), or a
    RuntimeError saying how to get one."""
    env = os.environ.get("RASCAL_CHROMIUM")
    if env:
        if shutil.which(env):
            return shutil.which(env)
        raise RuntimeError("$RASCAL_CHROMIUM=%s: no such program" % env)
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    raise RuntimeError(
        "the PDF is printed by a headless Chromium and none was found; install it "
        "(apt-get install chromium, as scripts/setup.sh does) or set $RASCAL_CHROMIUM"
    )


def _run_browser(args, out_path, browser=None, timeout=60.0):
    browser = browser or find_browser()
    profile = tempfile.mkdtemp(prefix="rascal-chromium-")
    root, ext = os.path.splitext(out_path)
    tmp = root + ".tmp" + ext  # Chromium picks the screenshot's format by the extension
    cmd = [
        browser,
        "--headless",
        "--no-sandbox",  # as root (the rig's set-up) Chromium refuses to start with it
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--no-first-run",
        "--no-default-browser-check",
        "--disable-extensions",
        "--disable-background-networking",
        "--force-color-profile=srgb",
        "--hide-scrollbars",
        "--user-data-dir=%s" % profile,
    ] + [a.replace("{out}", tmp) for a in args]
    try:
        # its own process group, so that a time-out ends Chromium's helpers too
        proc = subprocess.Popen(
            cmd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        try:
            _, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate(timeout=10)
            raise RuntimeError(
                "%s did not finish within %.0f s writing %s" % (browser, timeout, out_path)
            ) from None
        finally:
            try:  # helpers left behind by a browser that exited
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        if proc.returncode != 0 or not os.path.isfile(tmp) or os.path.getsize(tmp) == 0:
            tail = " ".join((err or "").split()[-30:])
            raise RuntimeError(
                "%s could not write %s (exit %d): %s" % (browser, out_path, proc.returncode, tail)
            )
        os.replace(tmp, out_path)
    finally:
        shutil.rmtree(profile, ignore_errors=True)
        if os.path.exists(tmp):
            os.unlink(tmp)
    return out_path


def print_pdf(html_path, pdf_path=None, browser=None, timeout=90.0, file_mode=0o644):
    """Print the report page to an A4 PDF with headless Chromium (the page's own print CSS,
    no browser header or footer); returns the PDF's path (default: ``<folder>.pdf`` beside
    index.html, named after the context's archive folder)."""
    html_path = os.path.abspath(html_path)
    if pdf_path is None:
        folder = os.path.basename(os.path.dirname(os.path.dirname(html_path)))
        pdf_path = os.path.join(os.path.dirname(html_path), "%s.pdf" % folder)
    _run_browser(
        [
            "--no-pdf-header-footer",
            "--print-to-pdf-no-header",
            "--print-to-pdf={out}",
            "file://" + urllib.parse.quote(html_path),
        ],
        pdf_path,
        browser,
        timeout,
    )
    os.chmod(pdf_path, file_mode)
    return pdf_path


def screenshot(html_path, png_path, width=1000, height=1400, browser=None, timeout=90.0):
    """A PNG of the page as a screen shows it (``width`` × ``height`` CSS px, scale 1)."""
    return _run_browser(
        [
            "--window-size=%d,%d" % (width, height),
            "--force-device-scale-factor=1",
            "--screenshot={out}",
            "file://" + urllib.parse.quote(os.path.abspath(html_path)),
        ],
        png_path,
        browser,
        timeout,
    )
