"""`rascal report`: the archaeologist's page of one context, checked in a real headless browser
(Debian's chromium, installed by scripts/setup.sh): printed to PDF (pages, A4, text through
pdftotext, the swatch's colour on the printed page through pdftoppm) and shot as a screen
(not blank, each swatch a square of its colour beside its sherd's thumbnail). The thumbnails are
cropped to the sherd (not the chart, not the bar), from the colour-corrected image where one
lies beside the archival image. The catalogue part runs against real PostgreSQL."""

import datetime
import os
import re
import subprocess
import urllib.parse

import cv2
import numpy as np
import pytest
from catalogue_helpers import PYTHON, FakeClock, subprocess_env

from rascal_tasks import report
from rascal_tasks.catalogue import Catalogue, ImageArchive

pytestmark = pytest.mark.timeout(120)

SCRIPT = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "rascal"
)
UTC = datetime.timezone.utc
BACKGROUND = (98, 125, 146)  # BGR of the simulator's camera mat
SHERD_BGR = (120, 170, 215)  # a light clay in the frame
CORRECTED_BGR = (40, 90, 200)  # the same sherd in the colour-corrected image: visibly other
LAB_1 = (60.0, 8.0, 20.0)  # measured colours (D50) of sherds 1 and 2
LAB_2 = (45.0, 25.0, 30.0)


def frame(sherd_bgr=SHERD_BGR, centre=(620, 760)):
    """An archival frame as the simulator renders it (2000 × 1500): the mat, the 24-patch chart
    (top right), the 10 cm bar (bottom right) and one sherd, a hexagon, at ``centre``."""
    img = np.full((1500, 2000, 3), BACKGROUND, np.uint8)
    cv2.rectangle(img, (1270, 190), (1810, 540), (15, 15, 15), -1)
    rng = np.random.default_rng(7)
    for i in range(4):
        for j in range(6):
            colour = tuple(int(c) for c in rng.integers(30, 240, 3))
            x, y = 1280 + j * 90, 200 + i * 85
            cv2.rectangle(img, (x, y), (x + 72, y + 72), colour, -1)
    cv2.rectangle(img, (1080, 1115), (1850, 1230), (230, 240, 250), -1)
    for k in range(4):
        cv2.rectangle(img, (1080 + k * 77, 1115), (1157 + k * 77, 1172), (10, 10, 10), -1)
    cx, cy = centre
    hexagon = np.array(
        [[cx - 160, cy - 10], [cx - 100, cy - 150], [cx + 20, cy - 170], [cx + 150, cy - 60],
         [cx + 140, cy + 90], [cx - 20, cy + 160], [cx - 150, cy + 110]], np.int32
    )  # fmt: skip
    cv2.fillPoly(img, [hexagon], sherd_bgr)
    return img, (cx - 160, cy - 170, cx + 150, cy + 160)


def png(img):
    ok, data = cv2.imencode(".png", img)
    assert ok
    return data.tobytes()


def rows_for(context, archive_root):
    """Three sherds of ``context`` written into an archive: 1 done with colour and a
    colour-corrected image beside its archival image, 2 done without a mass (the scale) and
    without a Munsell notation but with L*a*b*, 3 lost without an image."""
    folder = os.path.join(archive_root, report.context_folder(context))
    os.makedirs(folder, exist_ok=True)
    img, _ = frame()
    cv2.imwrite(os.path.join(folder, "1-abc.png"), img)
    os.makedirs(
        os.path.join(folder, "corrected"), exist_ok=True
    )  # where the archival stage puts it
    cv2.imwrite(os.path.join(folder, "corrected", "1-abc.png"), frame(CORRECTED_BGR)[0])
    cv2.imwrite(os.path.join(folder, "2-abc.png"), frame(centre=(800, 700))[0])
    rel = os.path.basename(folder)
    t0 = datetime.datetime(2026, 11, 24, 9, 0, tzinfo=UTC)
    times = {"t_locomotion_s": 20.0, "t_grasping_s": 9.5, "t_data_collection_s": 30.0}
    one = {
        "seq": 1,
        "find_id": context + "-1",
        "status": "done",
        "image_path": rel + "/1-abc.png",
        "mass_g": 17.94,
        "length_mm": 41.5,
        "width_mm": 30.25,
        "thickness_mm": 6.0,
        "colour_munsell": "5YR 6/4",
        "colour_l": LAB_1[0],
        "colour_a": LAB_1[1],
        "colour_b": LAB_1[2],
        "drops": 1,
        "done_at": t0,
        "rig": "rig-1",
        "t_perception_s": 4.0,
        **times,
    }
    two = {
        "seq": 2,
        "find_id": context + "-2",
        "status": "done",
        "image_path": rel + "/2-abc.png",
        "mass_g": None,
        "mass_missing_reason": "the reading did not hold",
        "length_mm": 22.0,
        "width_mm": 15.0,
        "thickness_mm": 5.0,
        "colour_munsell": None,
        "colour_l": LAB_2[0],
        "colour_a": LAB_2[1],
        "colour_b": LAB_2[2],
        "done_at": t0 + datetime.timedelta(minutes=1),
        "rig": "rig-1",
        "t_perception_s": 3.0,
        **times,
    }
    three = {
        "seq": 3,
        "find_id": context + "-3",
        "status": "lost",
        "lost_reason": "dropped off the table",
        "mass_g": 8.25,
        "lost_at": t0 + datetime.timedelta(minutes=2),
        "rig": "rig-1",
    }
    return [one, two, three]


# --- pieces ---
def test_crop_is_the_sherd_not_the_chart_nor_the_bar():
    img, (x0, y0, x1, y1) = frame()
    box = report.crop_box(img)
    assert box is not None
    bx0, by0, bx1, by1 = box
    assert bx0 <= x0 and by0 <= y0 and bx1 >= x1 and by1 >= y1  # the whole sherd
    assert bx1 < 1270 and by1 < 1115  # neither the chart nor the bar
    assert (bx1 - bx0) * (by1 - by0) < 0.12 * 2000 * 1500  # a crop, not the frame
    empty = np.full((1500, 2000, 3), BACKGROUND, np.uint8)
    assert report.crop_box(empty) is None  # nothing to crop to: the whole frame is shown


def test_crop_of_a_simulated_archival_frame(tmp_path):
    """The simulator's own archival view (render_views, built by catkin): the crop holds the
    sherd and none of the chart's or the bar's black."""
    ws = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(SCRIPT))))
    tool = os.path.join(ws, "devel", "lib", "rascal_sim", "render_views")
    scenario = os.path.join(ws, "config", "scenarios", "small_3.yaml")
    subprocess.run([tool, scenario, str(tmp_path), "1.0"], check=True, timeout=60)
    img = cv2.imread(str(tmp_path / "sim_archival.png"))
    x0, y0, x1, y1 = report.crop_box(img)
    crop = img[y0:y1, x0:x1]
    assert (x1 - x0) * (y1 - y0) < 0.15 * img.shape[0] * img.shape[1]
    assert (crop.max(axis=2) < 40).sum() == 0  # no chart frame, no bar square
    centre = crop[
        crop.shape[0] // 3 : 2 * crop.shape[0] // 3, crop.shape[1] // 3 : 2 * crop.shape[1] // 3
    ]
    border = np.concatenate([img[0], img[-1]])
    assert np.abs(np.median(centre.reshape(-1, 3), 0) - np.median(border, 0)).max() > 10  # sherd


def test_corrected_image_beside_the_original(tmp_path):
    original = tmp_path / "C" / "1-abc.png"
    original.parent.mkdir()
    original.write_bytes(b"x")
    assert report.corrected_image(str(original)) is None
    (tmp_path / "C" / "1-abc-corrected.png").write_bytes(b"y")
    assert report.corrected_image(str(original)) == str(tmp_path / "C" / "1-abc-corrected.png")
    (tmp_path / "C" / "corrected").mkdir()
    (tmp_path / "C" / "corrected" / "1-abc.png").write_bytes(b"z")  # the archival stage's
    assert report.corrected_image(str(original)) == str(tmp_path / "C" / "corrected" / "1-abc.png")


def test_colours_groups_and_size_classes():
    assert report.lab_to_srgb((100.0, 0.0, 0.0)) == (255, 255, 255)
    assert report.lab_to_srgb((0.0, 0.0, 0.0)) == (0, 0, 0)
    grey = report.lab_to_srgb((50.0, 0.0, 0.0))
    assert max(grey) - min(grey) <= 1 and abs(grey[0] - 119) <= 1
    r, g, b = report.lab_to_srgb(LAB_1)  # a light brown clay: red above green above blue
    assert r > g > b
    assert report.lab_to_srgb((None, 1.0, 2.0)) is None
    cases = {"5YR 6/4": "5YR", "7.5YR 5/3": "7.5YR", "10yr 7/3": "10YR", "2.5Y 8/2": "2.5Y",
             "N 5/": "N", "GLEY1 4/N": "GLEY1", "": "not measured", None: "not measured",
             "reddish": "other"}  # fmt: skip
    for notation, group in cases.items():
        assert report.colour_group(notation) == group, notation
    assert report.size_class({"length_mm": 29.9, "width_mm": 10.0}) == "< 30 mm"
    assert report.size_class({"length_mm": 30.0, "width_mm": 10.0}) == "30–70 mm"
    assert report.size_class({"length_mm": 10.0, "width_mm": 130.0}) == "120–200 mm"
    assert report.size_class({"length_mm": 250.0}) == "≥ 200 mm"
    assert report.size_class({}) == "not measured"


def test_page_links_thumbnails_and_one_folder_for_a_slashed_context(tmp_path):
    archive = str(tmp_path / "archive")
    rows = rows_for("TR1/1023", archive)
    path = report.write_report("TR1/1023", rows, archive, {"mean time": "60 s"})
    assert path == os.path.join(archive, "TR1%2F1023", "report", "index.html")
    assert sorted(os.listdir(archive)) == ["TR1%2F1023"]  # no nested TR1/1023 folders
    page = open(path, encoding="utf-8").read()
    assert page.count("<img ") == 2  # the two sherds with an image
    # each thumbnail links to its full archival image, through the %-escaped folder
    hrefs = re.findall(r'<a href="([^"]+)" title="full archival image">', page)
    assert len(hrefs) == 2
    for href, row in zip(hrefs, rows, strict=False):
        target = os.path.normpath(os.path.join(os.path.dirname(path), urllib.parse.unquote(href)))
        assert target == os.path.join(archive, row["image_path"]) and os.path.isfile(target)
    # the thumbnail is the crop of the colour-corrected image (sherd 1), else of the original
    t1 = cv2.imread(os.path.join(os.path.dirname(path), "thumbs", "1.jpg"))
    t2 = cv2.imread(os.path.join(os.path.dirname(path), "thumbs", "2.jpg"))
    assert max(t1.shape[:2]) <= report.THUMB_PX and max(t2.shape[:2]) <= report.THUMB_PX
    centre1 = t1[t1.shape[0] // 2, t1.shape[1] // 2].astype(int)
    centre2 = t2[t2.shape[0] // 2, t2.shape[1] // 2].astype(int)
    assert np.abs(centre1 - CORRECTED_BGR).max() < 12, centre1
    assert np.abs(centre2 - SHERD_BGR).max() < 12, centre2
    assert "colour-corrected" in page and "as photographed" in page
    # colour shown, and "not measured" where it is missing
    assert "5YR 6/4" in page and "no Munsell notation" in page
    assert "#%02x%02x%02x" % report.lab_to_srgb(LAB_1) in page
    # totals: 3 sherds, 2 weighed, 17.9 + 8.3 g (half up, as exported)
    assert "26.2 g" in page and "13.1 g" in page
    assert "dropped off the table" in page and "where the time went" in page
    assert oct(os.stat(path).st_mode & 0o777) == oct(0o644)


# --- in the browser ---
@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """The report of a context written, printed to PDF and shot once for the browser tests."""
    tmp = tmp_path_factory.mktemp("report")
    archive = str(tmp / "archive")
    rows = rows_for("Köln 7", archive)
    path = report.write_report("Köln 7", rows, archive, {"mean time": "60 s"})
    pdf = report.print_pdf(path, timeout=90)
    shot = report.screenshot(path, str(tmp / "shot.png"), width=1000, height=1500, timeout=90)
    return {"html": path, "pdf": pdf, "shot": shot, "tmp": tmp}


def _tool(*cmd):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60, check=True).stdout


def test_pdf_is_a4_with_the_sherds_first_and_the_engineer_page_last(printed):
    pdf = printed["pdf"]
    assert pdf.endswith(os.path.join("Köln%207", "report", "Köln%207.pdf"))
    info = _tool("pdfinfo", pdf)
    assert re.search(r"^Pages:\s+2$", info, re.M), info
    w, h = (float(v) for v in re.search(r"Page size:\s+([\d.]+) x ([\d.]+) pts", info).groups())
    assert abs(w - 595.3) < 2 and abs(h - 841.9) < 2, info  # A4 portrait
    first = " ".join(_tool("pdftotext", "-f", "1", "-l", "1", "-layout", pdf, "-").split())
    last = " ".join(_tool("pdftotext", "-f", "2", "-l", "2", "-layout", pdf, "-").split())
    expected = ["Context Köln 7", "Köln 7-1", "5YR 6/4", "not measured", "17.9", "26.2 g"]
    expected += ["13.1 g", "Köln 7-3: dropped off the table", "Lost sherds", "page 1 of 2"]
    for text in expected:
        assert text in first, (text, first)
    assert "where the time went" in last and "where the time went" not in first
    assert "page 2 of 2" in last
    # the swatch is printed in its colour (SVG: whatever the browser's "background graphics")
    _tool("pdftoppm", "-f", "1", "-l", "1", "-r", "72", "-png", pdf, str(printed["tmp"] / "page"))
    page = cv2.imread(str(printed["tmp"] / "page-1.png"))
    for lab in (LAB_1, LAB_2):
        r, g, b = report.lab_to_srgb(lab)
        near = np.all(np.abs(page.astype(int) - (b, g, r)) <= 3, axis=2)
        assert near.sum() >= 15 * 15, (lab, near.sum())


def _blob(img, bgr, tol):
    """Bounding box and pixel count of the pixels within ``tol`` of ``bgr``."""
    near = np.all(np.abs(img.astype(int) - bgr) <= tol, axis=2)
    ys, xs = np.nonzero(near)
    if not len(xs):
        return None, 0
    return (xs.min(), ys.min(), xs.max(), ys.max()), int(near.sum())


def _squares(img, bgr, side, tol=2):
    """Boxes of the solid squares of ``side`` ± 2 px whose pixels are all within ``tol`` of
    ``bgr`` (a swatch; the bar of the colour-group plot in the same colour is not square)."""
    near = np.all(np.abs(img.astype(int) - bgr) <= tol, axis=2).astype(np.uint8)
    n, _, stats, _ = cv2.connectedComponentsWithStats(near, connectivity=4)
    return [
        (x, y, x + w - 1, y + h - 1)
        for x, y, w, h, area in stats[1:]
        if abs(w - side) <= 2 and abs(h - side) <= 2 and area >= 0.95 * w * h
    ]


def test_screenshot_shows_thumbnails_and_swatches_where_they_belong(printed):
    img = cv2.imread(printed["shot"])
    assert img.shape[:2] == (1500, 1000)
    assert (
        img.std() > 20 and len(np.unique(img[::3, ::3].reshape(-1, 3), axis=0)) > 300
    )  # not blank
    # each swatch: one 32 px square (34 px less its 1 px outline) of exactly its colour
    boxes = []
    for lab in (LAB_1, LAB_2):
        r, g, b = report.lab_to_srgb(lab)
        squares = _squares(img, (b, g, r), 32)
        assert len(squares) == 1, (lab, squares)
        boxes.append(squares[0])
    # the plot of colour groups shows 5YR in sherd 1's colour
    r, g, b = report.lab_to_srgb(LAB_1)
    bar, n = _blob(img, (b, g, r), 2)
    assert bar[1] < boxes[0][1] - 40 and n > 32 * 32 + 500  # the bar above, then the swatch
    assert boxes[1][1] > boxes[0][3]  # sherd 2's row below sherd 1's
    # sherd 1's thumbnail (the corrected colour) to the left of its swatch, in the same row
    thumb, n = _blob(img, CORRECTED_BGR, 14)
    assert thumb is not None and n > 1000, n
    assert thumb[2] < boxes[0][0]
    assert thumb[1] <= boxes[0][3] and thumb[3] >= boxes[0][1]
    # and sherd 2's thumbnail (the original colour) in sherd 2's row
    thumb2, n2 = _blob(img, SHERD_BGR, 14)
    assert thumb2 is not None and n2 > 1000, n2
    assert thumb2[1] <= boxes[1][3] and thumb2[3] >= boxes[1][1]


# --- the command, against the catalogue ---
def test_rascal_report_pdf_from_the_catalogue(migrated_dsn, tmp_path):
    archive_root = tmp_path / "archive"
    cat = Catalogue.connect(migrated_dsn, rig="rig-1", config_hash="abc", clock=FakeClock())
    archive = ImageArchive(str(archive_root))
    try:
        cat.open_context("TR1/1023", "TR1")
        s = cat.new_sherd("TR1/1023", pickup_xy=(0.1, 0.25), t_pick_s=9.0)["sherd_id"]
        cat.record_dimensions(s, 41.5, 30.25, 6.0)
        cat.record_mass(s, 17.94)
        cat.archive_photo(s, archive, png(frame()[0]), colour_munsell="5YR 6/4", colour_lab=LAB_1)
        cat.record_done(s, t_discard_s=3.0, archive=archive)
        s = cat.new_sherd("TR1/1023", pickup_xy=(0.2, 0.25))["sherd_id"]
        cat.record_dimensions(s, 22.0, 15.0, 5.0)
        cat.record_mass(s, 3.0)
        cat.archive_photo(s, archive, png(frame(centre=(800, 700))[0]))  # no colour measured
        cat.record_done(s, archive=archive)
        lost = cat.new_sherd("TR1/1023")["sherd_id"]
        cat.record_lost(lost, "dropped off the table")
    finally:
        cat.close()
    env = subprocess_env()
    env.pop("RASCAL_DSN", None)
    cmd = [PYTHON, SCRIPT, "--dsn", migrated_dsn, "report", "--context", "TR1/1023"]
    cmd += ["--archive", str(archive_root), "--pdf"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=100)
    assert r.returncode == 0, r.stderr
    folder = archive_root / "TR1%2F1023" / "report"
    assert "report: %s" % (folder / "index.html") in r.stdout
    assert "pdf: %s" % (folder / "TR1%2F1023.pdf") in r.stdout
    assert not (archive_root / "TR1").exists()
    text = " ".join(_tool("pdftotext", "-layout", str(folder / "TR1%2F1023.pdf"), "-").split())
    for part in ("Context TR1/1023", "TR1/1023-2", "5YR 6/4", "not measured", "20.9 g",
                 "RASCAL · context TR1/1023",  # the page margin's CSS string, escaped
                 "dropped off the table"):  # fmt: skip
        assert part in text, (part, text)
    page = (folder / "index.html").read_text(encoding="utf-8")
    assert page.count("<img ") == 2 and page.count('class="swatch"') == 1
    # no browser: one line naming the fix, exit 3 (the HTML page is still written)
    env["RASCAL_CHROMIUM"] = str(tmp_path / "no-chromium")
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=60)
    assert r.returncode == 3, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("rascal: error: ") and "RASCAL_CHROMIUM" in line
