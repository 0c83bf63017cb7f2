"""HTML report of one context: a thumbnail and the measurements of each sherd, and where the
time went (the paper's Fig. 10 breakdown: locomotion, grasping, data collection, perception).

Input is the catalogue's export rows (dicts); output one self-contained folder
`<archive>/<context>/report/` with `index.html` and JPEG thumbnails. No ROS here.
"""

import html
import os

PHASES = (
    ("locomotion", "#4e79a7"),
    ("grasping", "#f28e2b"),
    ("data_collection", "#59a14f"),
    ("perception", "#b07aa1"),
)


def _thumbnail(src: str, dst: str, width: int = 240) -> bool:
    try:
        import cv2
    except ImportError:  # pragma: no cover - python3-opencv is installed by setup.sh
        return False
    img = cv2.imread(src)
    if img is None:
        return False
    h = max(1, round(img.shape[0] * width / img.shape[1]))
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    return cv2.imwrite(dst, cv2.resize(img, (width, h), interpolation=cv2.INTER_AREA))


def _fmt(v, spec="%.1f"):
    return "–" if v is None else spec % v


def _breakdown_svg(rows) -> str:
    """Stacked horizontal bar per sherd plus the mean, in seconds."""
    bars = [(str(r["seq"]), [r.get("t_%s_s" % p) or 0.0 for p, _ in PHASES]) for r in rows]
    if bars:
        mean = [sum(b[1][i] for b in bars) / len(bars) for i in range(len(PHASES))]
        bars.append(("mean", mean))
    longest = max([sum(b[1]) for b in bars] + [1.0])
    scale = 520.0 / longest
    row_h, left = 22, 60
    out = [
        '<svg xmlns="http://www.w3.org/2000/svg" width="720" height="%d" font-size="12" '
        'font-family="sans-serif">' % (row_h * (len(bars) + 2) + 10)
    ]
    for i, (label, parts) in enumerate(bars):
        y = 5 + i * row_h
        out.append(
            '<text x="%d" y="%d" text-anchor="end">%s</text>'
            % (left - 6, y + 14, html.escape(label))
        )
        x = left
        for (phase, colour), secs in zip(PHASES, parts, strict=True):
            w = secs * scale
            out.append(
                '<rect x="%.1f" y="%d" width="%.1f" height="16" fill="%s">'
                "<title>%s %.1f s</title></rect>" % (x, y, w, colour, phase, secs)
            )
            x += w
        out.append('<text x="%.1f" y="%d">%.1f s</text>' % (x + 4, y + 13, sum(parts)))
    y = 10 + len(bars) * row_h
    for i, (phase, colour) in enumerate(PHASES):
        out.append(
            '<rect x="%d" y="%d" width="12" height="12" fill="%s"/>'
            '<text x="%d" y="%d">%s</text>'
            % (left + i * 150, y, colour, left + i * 150 + 16, y + 10, phase.replace("_", " "))
        )
    out.append("</svg>")
    return "".join(out)


def _note(r) -> str:
    """Why a row is incomplete: lost, or weighed without a mass (mass_unstable)."""
    parts = []
    if r.get("mass_missing_reason"):
        parts.append("no mass: %s" % r["mass_missing_reason"])
    if r.get("lost_reason"):
        parts.append(r["lost_reason"])
    return "; ".join(parts)


def write_report(context: str, rows, archive_root: str, summary: dict = None) -> str:
    """Write the report folder for `context`; returns the path of index.html."""
    folder = os.path.join(archive_root, context, "report")
    os.makedirs(folder, exist_ok=True)
    cells = []
    for r in rows:
        thumb = ""
        if r.get("image_path"):
            src = r["image_path"]
            src = src if os.path.isabs(src) else os.path.join(archive_root, src)
            name = "thumb_%d.jpg" % r["seq"]
            if _thumbnail(src, os.path.join(folder, name)):
                thumb = '<img src="%s" alt="sherd %d">' % (name, r["seq"])
        cells.append(
            "<tr><td>%d</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>"
            "<td>%s</td><td>%s</td></tr>"
            % (
                r["seq"],
                html.escape(str(r.get("status", ""))),
                thumb,
                _fmt(r.get("mass_g")),
                _fmt(r.get("length_mm")),
                _fmt(r.get("width_mm")),
                _fmt(r.get("thickness_mm")),
                _fmt(r.get("drops"), "%d"),
                html.escape(_note(r)),
            )
        )
    lines = "".join(
        "<li>%s: %s</li>" % (html.escape(k), html.escape(str(v)))
        for k, v in (summary or {}).items()
    )
    page = """<!DOCTYPE html><html><head><meta charset="utf-8">
<title>RASCAL context %(ctx)s</title>
<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}
td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}img{max-width:240px}</style>
</head><body><h1>Context %(ctx)s</h1><ul>%(summary)s</ul>
<h2>Where the time went (seconds per sherd)</h2>%(svg)s
<h2>Sherds</h2><table><tr><th>#</th><th>status</th><th>archival image</th><th>mass (g)</th>
<th>length (mm)</th><th>width (mm)</th><th>thickness (mm)</th><th>drops</th><th>note</th></tr>
%(rows)s</table></body></html>
""" % {
        "ctx": html.escape(context),
        "summary": lines,
        "svg": _breakdown_svg(rows),
        "rows": "\n".join(cells),
    }
    path = os.path.join(folder, "index.html")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, path)
    return path
