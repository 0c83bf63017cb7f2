"""The Field Desktop export's image list: ``images/field-image-import.json`` is the body of
Field Desktop's image import (``POST /fileImport``: ``filePaths``, ``category``); the file names
it lists are exactly the files in ``images/`` and exactly the names ``relations.isDepictedIn``
gives (Field makes an image's file name its identifier), for CSV and JSON Lines, also for a
context ID with a slash."""

import csv
import datetime
import io
import json
import os
import stat

import pytest

from rascal_tasks.catalogue.context_id import context_folder
from rascal_tasks.catalogue.field_desktop import IMAGE_LIST, write_export

pytestmark = pytest.mark.timeout(60)
PNG = b"\x89PNG\r\n\x1a\n"


def records(context, archive_root):
    folder = os.path.join(archive_root, context_folder(context))
    os.makedirs(folder, exist_ok=True)
    when = datetime.datetime(2026, 11, 24, 9, 0, tzinfo=datetime.timezone.utc)
    out = []
    for seq, status in ((1, "done"), (2, "done"), (3, "lost"), (4, "lost")):
        image = None
        if seq != 4:  # the fourth was lost before its photo
            image = "%s/%d-abc.png" % (context_folder(context), seq)
            with open(os.path.join(archive_root, image), "wb") as f:
                f.write(PNG + bytes([seq]))
        out.append(
            {
                "find_id": "%s-%d" % (context, seq),
                "seq": seq,
                "status": status,
                "mass_g": 10.0 + seq,
                "mass_missing_reason": None,
                "length_mm": 30.0,
                "width_mm": 20.0,
                "thickness_mm": 6.0,
                "colour_munsell": "5YR 6/4",
                "lost_reason": "dropped off the table" if status == "lost" else None,
                "drops": 0,
                "notes": None,
                "software_version": "1.0",
                "rig": "rig-1",
                "done_at": when if status == "done" else None,
                "lost_at": when if status == "lost" else None,
                "image_path": image,
                "image_sha256": "ab" * 32 if image else None,
            }
        )
    return out


def _depicted_csv(out):
    names = []
    for path in out.glob("*.Pottery.csv"):
        for row in csv.DictReader(io.StringIO(path.read_text("utf-8"))):
            if row.get("relations.isDepictedIn"):
                names += row["relations.isDepictedIn"].split(";")
    return names


def _depicted_jsonl(out):
    names = []
    for path in out.glob("*.Pottery.jsonl"):
        for line in path.read_text("utf-8").splitlines():
            names += json.loads(line)["relations"].get("isDepictedIn", [])
    return names


@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
@pytest.mark.parametrize("context", ["TR1-1023", "TR1/1023"])
def test_image_list_names_exactly_the_exported_images(tmp_path, fmt, context):
    archive = str(tmp_path / "archive")
    out = tmp_path / "export"
    result = write_export(str(out), context, records(context, archive), archive, "SE 1", fmt=fmt)
    listed = out / "images" / IMAGE_LIST
    assert result["image_list"] == str(listed)
    doc = json.loads(listed.read_text("utf-8"))
    assert sorted(doc) == ["category", "filePaths", "readCreatorsFromMetadata"]
    assert doc["category"] == "Photo" and doc["readCreatorsFromMetadata"] is False
    paths = doc["filePaths"]
    assert all(os.path.isabs(p) and os.path.isfile(p) for p in paths), paths
    assert {os.path.dirname(p) for p in paths} == {str(out / "images")}
    names = [os.path.basename(p) for p in paths]
    files = sorted(p.name for p in (out / "images").iterdir() if p.name != IMAGE_LIST)
    depicted = _depicted_csv(out) if fmt == "csv" else _depicted_jsonl(out)
    assert sorted(names) == files == sorted(depicted)
    assert len(names) == 3 and len(set(names)) == 3  # the sherd lost before its photo has none
    assert all("/" not in n for n in names)
    for n, seq in zip(sorted(names), (1, 2, 3), strict=True):
        assert (out / "images" / n).read_bytes() == PNG + bytes([seq])
    assert stat.S_IMODE(listed.stat().st_mode) == 0o644
    assert listed not in [os.path.abspath(f) for f in result["files"]]


def test_no_image_no_list(tmp_path):
    archive = str(tmp_path / "archive")
    recs = [r for r in records("C-1", archive) if r["image_path"] is None]
    result = write_export(str(tmp_path / "export"), "C-1", recs, archive, "C-1")
    assert result["image_list"] is None
    assert not (tmp_path / "export" / "images").exists()
