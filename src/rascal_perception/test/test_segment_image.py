"""`segment_image` on the real photos (test/data/photos, hand truth in photos_truth.json), run as
a user runs it. Each photo is its own test: the count within the hand range, px/cm within 2 %
of the hand reading where the truth has one. Photos the segmentation still gets wrong are listed
in KNOWN_FAILURES with why; they are expected to fail (strict: one that starts passing fails)."""

import functools
import json
import os
import subprocess

import cv2
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
TOOL = os.path.join(WORKSPACE, "devel", "lib", "rascal_perception", "segment_image")
PHOTOS = os.path.join(HERE, "data", "photos")
with open(os.path.join(PHOTOS, "photos_truth.json")) as f:
    TRUTH = json.load(f)

# Also in PhotoSegmenterTest.cpp (kKnownFailures), with the same reasons.
KNOWN_FAILURES = {
    "img129SG101853_orig.jpg": "crowded small sherds merge (118 of 119-123)",
}


def segment(*args, cwd=None):
    return subprocess.run(
        [TOOL, *args], capture_output=True, text=True, timeout=60, cwd=cwd, check=False
    )


@functools.lru_cache(maxsize=None)
def photo_result(photo):
    """The tool's report (JSON object) for one photo of the data set (run once per photo)."""
    return result(photo)[0]


def result(photo, *args, cwd=None):
    r = segment(photo, "--report", "-", "--no-overlay", *args, cwd=cwd)
    assert r.returncode in (0, 1), r.stderr
    return json.loads(r.stdout), r


@pytest.fixture(scope="module", autouse=True)
def built():
    if not os.access(TOOL, os.X_OK):
        pytest.fail(
            "segment_image is not built: run `make -C build rascal_perception_segment_image`"
        )


def _params():
    for name in sorted(TRUTH):
        marks = []
        if name in KNOWN_FAILURES:
            marks.append(pytest.mark.xfail(reason=KNOWN_FAILURES[name], strict=True))
        yield pytest.param(name, marks=marks, id=name)


@pytest.mark.parametrize("name", list(_params()))
def test_count_within_the_hand_range(name):
    d = photo_result(os.path.join(PHOTOS, name))
    lo, hi = TRUTH[name]["count_range"]
    assert lo <= len(d["sherds"]) <= hi, "%d sherds, hand range [%d, %d]" % (
        len(d["sherds"]),
        lo,
        hi,
    )


@pytest.mark.parametrize("name", sorted(n for n in TRUTH if TRUTH[n].get("px_per_cm")))
def test_scale_within_two_percent_of_the_hand_reading(name):
    d = photo_result(os.path.join(PHOTOS, name))
    truth = TRUTH[name]["px_per_cm"]
    assert d["px_per_cm"] is not None, "no scale bar found"
    assert abs(d["px_per_cm"] / truth - 1) < 0.02, (d["px_per_cm"], truth)
    for s in d["sherds"]:
        assert s["length_mm"] >= s["width_mm"] > 0


def test_options_before_or_after_the_photo_give_the_same_result(tmp_path):
    photo = os.path.join(PHOTOS, "img114SG101831.jpg")
    a = segment("--json", str(tmp_path / "a.json"), "--format", "table", "--no-overlay", photo)
    b = segment(photo, "--no-overlay", "--format", "table", "--json", str(tmp_path / "b.json"))
    assert a.returncode == b.returncode and a.stdout == b.stdout
    assert json.loads((tmp_path / "a.json").read_text()) == json.loads(
        (tmp_path / "b.json").read_text()
    )
    assert "length mm" in a.stdout.splitlines()[0]


@pytest.mark.parametrize(
    "args",
    [
        ["{p}", "--json"],
        ["--json", "{p}"],
        ["--format", "json", "{p}"],
        ["{p}", "--json", "-"],
        ["-j", "{p}"],
        ["{p}"],  # stdout is a pipe here: a program reads it, so JSON by default
    ],
    ids=["json-last", "json-first", "format-json", "json-dash", "j", "piped"],
)
def test_json_on_stdout_is_one_line_with_the_sherds_and_px_per_cm_however_asked(tmp_path, args):
    photo = os.path.join(PHOTOS, "img040DSC02176.jpg")
    r = segment(*[a.format(p=photo) for a in args], "--no-overlay", cwd=tmp_path)
    assert r.returncode in (0, 1), r.stderr
    d = json.loads(r.stdout)  # nothing but the JSON
    assert r.stdout.count("\n") == 1  # one line: line readers take it too
    sherds = d["sherds"]
    assert isinstance(sherds, list) and len(sherds) == photo_result(photo)["sherd_count"] >= 1
    assert d["sherd_count"] == len(sherds) and d["px_per_cm"] == photo_result(photo)["px_per_cm"]
    assert d["scale"] == "%.2f px/cm" % d["px_per_cm"]
    assert d["summary"] == photo_result(photo)["summary"]
    # the list stands between the first '[' and the last ']' (readers that cut a list out)
    assert json.loads(r.stdout[r.stdout.index("[") : r.stdout.rindex("]") + 1]) == sherds
    # the summary line a person reads, on stderr apart from the JSON
    assert r.stderr == "segment_image: %s\n" % photo_result(photo)["summary"]
    assert "%.2f px/cm" % photo_result(photo)["px_per_cm"] in r.stderr
    for s in sherds:
        assert s["px_per_cm"] == photo_result(photo)["px_per_cm"]
        assert s["scale"] == "%.2f px/cm" % s["px_per_cm"]
        assert s["length_mm"] >= s["width_mm"] > 0 and isinstance(s["flags"], list)
    assert not list(tmp_path.iterdir())  # the photo's name was not taken for a JSON file


def test_json_with_stderr_merged_into_stdout_still_parses(tmp_path):
    photo = os.path.join(PHOTOS, "img040DSC02176.jpg")
    r = subprocess.run(
        [TOOL, photo, "--json", "--no-overlay"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=60,
        cwd=tmp_path,
        check=False,
    )
    assert r.returncode in (0, 1)
    assert len(json.loads(r.stdout)["sherds"]) == photo_result(photo)["sherd_count"]  # no summary


def test_report_on_stdout_is_one_object_with_the_photo_wide_findings(tmp_path):
    photo = os.path.join(PHOTOS, "img040DSC02176.jpg")
    for args in (["--report", photo], ["--format", "report", photo], [photo, "--report", "-"]):
        r = segment(*args, "--no-overlay", cwd=tmp_path)
        d = json.loads(r.stdout)
        assert r.stderr == "" and d["sherd_count"] == len(d["sherds"]) >= 1
        assert d["summary"].startswith("%d sherds" % len(d["sherds"]))
    assert not list(tmp_path.iterdir())


def test_a_read_only_folder_only_warns_about_the_default_overlay(tmp_path):
    photo = os.path.join(PHOTOS, "img040DSC02176.jpg")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        r = segment(photo, "--format", "table", cwd=ro)
        quiet = segment(photo, "--json", cwd=ro)  # JSON for a program: no warning
    finally:
        ro.chmod(0o755)
    if os.geteuid() == 0:  # root writes anyway: the overlay is simply there
        assert (ro / "img040DSC02176_segmented.jpg").exists()
    else:
        assert "warning: cannot write the overlay" in r.stderr
    assert r.returncode in (0, 1) and "length mm" in r.stdout
    assert quiet.returncode in (0, 1) and json.loads(quiet.stdout)
    assert "warning" not in quiet.stderr and len(quiet.stderr.splitlines()) == 1  # the summary


def test_overlay_is_written_where_asked_and_by_default_beside(tmp_path):
    photo = os.path.join(PHOTOS, "img040DSC02176.jpg")
    r = segment(photo, cwd=tmp_path)
    assert r.returncode in (0, 1), r.stderr
    default = tmp_path / "img040DSC02176_segmented.jpg"
    assert cv2.imread(str(default)).shape == cv2.imread(photo).shape
    segment(photo, "--overlay", str(tmp_path / "o.png"))
    assert cv2.imread(str(tmp_path / "o.png")) is not None


def test_help_names_every_option_and_the_exit_codes():
    r = segment("--help")
    assert r.returncode == 0
    for option in (
        "--json",
        "--report",
        "--format",
        "--overlay",
        "--no-overlay",
        "--mask",
        "--background",
        "--bar-length",
        "--clusters",
    ):
        assert option in r.stdout
    assert "exit codes" in r.stdout and "probably_several" in r.stdout


@pytest.mark.parametrize(
    "args, says",
    [
        (["--bogus", "x.jpg"], "unknown option --bogus"),
        (["--bar-length", "abc", "x.jpg"], "--bar-length"),
        (["--format", "xml", "x.jpg"], "--format"),
        (["--json", "-", "--report", "-", "x.jpg"], "cannot both go to stdout"),
        ([], "no photo given"),
        (["/nonexistent/photo.jpg"], "does not exist"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args, says):
    r = segment(*args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], r.stderr


def test_a_photo_without_a_scale_bar_is_doubtful_and_says_so(tmp_path):
    # img005 with its bar (truth notes: x 406-634, y 705-750) cropped away
    img = cv2.imread(os.path.join(PHOTOS, "img005DSC02101.jpg"))[:690]
    path = tmp_path / "nobar.jpg"
    cv2.imwrite(str(path), img)
    d, r = result(str(path))
    assert r.returncode == 1
    assert d["px_per_cm"] is None and any("no scale bar" in x for x in d["doubts"])
    assert all("no_scale" in s["flags"] for s in d["sherds"])
    assert "no scale bar" in d["summary"] and r.stderr == ""  # on stdout the JSON says it all


def test_json_round_trip_matches_the_table(tmp_path):
    photo = os.path.join(PHOTOS, "img005DSC02101.jpg")
    r = segment(photo, "--json", str(tmp_path / "r.json"), "--format", "table", "--no-overlay")
    sherds = json.loads((tmp_path / "r.json").read_text())["sherds"]
    rows = r.stdout.strip().splitlines()[1:]
    assert len(rows) == len(sherds)
    for row, s in zip(rows, sherds, strict=True):
        cols = row.split()
        assert int(cols[0]) == s["id"]
        assert abs(float(cols[1]) - s["length_mm"]) < 0.051


def test_several_photos_give_a_json_line_each_and_the_worst_exit_code(tmp_path):
    first, second = (os.path.join(PHOTOS, n) for n in ("img040DSC02176.jpg", "img114SG101831.jpg"))
    missing = str(tmp_path / "missing.jpg")
    r = segment(first, missing, "--json", second, cwd=tmp_path)
    assert r.returncode == 2  # the missing photo; the two others are still segmented
    lines = [json.loads(line) for line in r.stdout.splitlines()]
    assert [d["photo"] for d in lines] == [first, second]
    for d in lines:  # each as the photo alone gives it
        assert d["sherd_count"] == photo_result(d["photo"])["sherd_count"]
        assert d["px_per_cm"] == photo_result(d["photo"])["px_per_cm"]
    assert "missing.jpg' does not exist" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "img040DSC02176_segmented.jpg",
        "img114SG101831_segmented.jpg",
    ]


def test_several_photos_as_tables_are_titled_each(tmp_path):
    photos = [os.path.join(PHOTOS, n) for n in ("img040DSC02176.jpg", "img048DSC02186.jpg")]
    r = segment(*photos, "--format", "table", "--no-overlay")
    assert r.returncode == max(segment(p, "--json", "-", "--no-overlay").returncode for p in photos)
    out = r.stdout.splitlines()
    assert [line for line in out if line.endswith(".jpg")] == photos
    for p in photos:
        head = out.index(p)
        assert out[head + 1].split()[:2] == ["id", "length"]
        assert photo_result(p)["summary"] in r.stderr


@pytest.mark.parametrize(
    "args",
    [["--mask", "m.png"], ["--labels", "l.png"], ["--overlay", "o.jpg"], ["--json", "r.json"]],
)
def test_a_file_option_with_several_photos_is_one_line_and_exit_2(tmp_path, args):
    photos = [os.path.join(PHOTOS, n) for n in ("img040DSC02176.jpg", "img114SG101831.jpg")]
    r = segment(*photos, *args, cwd=tmp_path)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "is one photo's" in lines[0], r.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written
