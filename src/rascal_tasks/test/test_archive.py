"""ImageArchive tests: atomic writes, sidecars, hashes, refusal of bad input."""

import hashlib
import json
import os

import pytest

from rascal_tasks.catalogue import ContextIdError, FieldError, ImageArchive

PNG = b"\x89PNG\r\n\x1a\n" + os.urandom(0) + bytes(range(256)) * 16


def test_store_writes_image_and_sidecar_under_context_and_seq(tmp_path):
    arch = ImageArchive(str(tmp_path))
    rel, sha = arch.store("TR1-1023", 7, PNG, {"mass_g": 25.3, "seq": 7})
    assert rel == "TR1-1023/7.png"
    assert sha == hashlib.sha256(PNG).hexdigest()
    assert (tmp_path / "TR1-1023" / "7.png").read_bytes() == PNG
    side = json.loads((tmp_path / "TR1-1023" / "7.json").read_text())
    assert side["mass_g"] == 25.3 and side["image_sha256"] == sha and side["image_path"] == rel
    assert arch.verify(rel, sha) and not arch.verify(rel, "0" * 64)
    assert sorted(os.listdir(tmp_path / "TR1-1023")) == ["7.json", "7.png"]  # no temp files


def test_store_copies_from_a_file_path(tmp_path):
    src = tmp_path / "capture.png"
    src.write_bytes(PNG * 300)  # several chunks
    arch = ImageArchive(str(tmp_path / "arch"))
    rel, sha = arch.store("C1", 1, str(src))
    assert sha == hashlib.sha256(PNG * 300).hexdigest()
    assert arch.verify(rel, sha)


def test_failed_rename_leaves_neither_a_partial_image_nor_a_temp_file(tmp_path, monkeypatch):
    arch = ImageArchive(str(tmp_path))
    arch.store("C1", 1, PNG)

    def crash(src, dst):
        raise OSError("disk pulled")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError):
        arch.store("C1", 2, PNG)
    assert sorted(os.listdir(tmp_path / "C1")) == ["1.json", "1.png"]


def test_rewrite_replaces_the_old_image_atomically(tmp_path):
    arch = ImageArchive(str(tmp_path))
    arch.store("C1", 1, PNG)
    new = PNG + b"reshoot"
    rel, sha = arch.store("C1", 1, new)
    assert (tmp_path / "C1" / "1.png").read_bytes() == new
    assert arch.verify(rel, sha)


@pytest.mark.parametrize(
    "image, why",
    [
        (b"GIF89a....", "not a PNG"),
        (b"", "empty"),
        (12345, "must be PNG bytes"),
        ("/nonexistent/capture.png", "cannot be read"),
    ],
)
def test_bad_images_are_refused_and_nothing_is_left(tmp_path, image, why):
    arch = ImageArchive(str(tmp_path))
    with pytest.raises(FieldError, match=why):
        arch.store("C1", 1, image)
    assert os.listdir(tmp_path / "C1") == []


@pytest.mark.parametrize("seq", [0, -1, 1.5, "1", True])
def test_bad_sequence_numbers_are_refused(tmp_path, seq):
    with pytest.raises(FieldError, match="^seq"):
        ImageArchive(str(tmp_path)).store("C1", seq, PNG)


def test_paths_cannot_leave_the_archive(tmp_path):
    arch = ImageArchive(str(tmp_path / "a"))
    with pytest.raises(ContextIdError):
        arch.store("..", 1, PNG)
    with pytest.raises(FieldError, match="outside the archive"):
        arch.path("../../etc/passwd")
    assert not (tmp_path / "etc").exists()
