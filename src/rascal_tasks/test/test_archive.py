"""ImageArchive tests: atomic writes, sidecars, hashes, refusal of bad input, the folder check
before the first pick, names per catalogue, leftover temporary files."""

import hashlib
import json
import os
import time

import pytest

from rascal_tasks.catalogue import ArchiveError, ContextIdError, FieldError, ImageArchive

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
    with pytest.raises(
        ArchiveError, match=r"archive.root .*: cannot write C1/2.png \(disk pulled\)"
    ):
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


# --- the folder checked before the first pick ---
def test_check_creates_a_missing_root_and_leaves_no_probe(tmp_path):
    arch = ImageArchive(str(tmp_path / "new" / "archive"))
    free = arch.check(1_000_000)
    assert free > 1_000_000 and os.listdir(arch.root) == []
    assert arch.min_free_bytes == 1_000_000


@pytest.mark.parametrize(
    "make, why",
    [
        (lambda p: p.write_text("x"), "exists but is not a folder"),
        (lambda p: (p.parent / "file").write_text("x"), "does not exist and cannot be created"),
    ],
)
def test_check_refuses_a_root_that_is_no_folder_with_one_line(tmp_path, make, why):
    root = tmp_path / "archive"
    make(root)
    target = root if why.startswith("exists") else tmp_path / "file" / "archive"
    with pytest.raises(ArchiveError) as refused:
        ImageArchive(str(target)).check()
    text = str(refused.value)
    assert text.startswith("archive.root %s: %s" % (target, why)) and "\n" not in text
    assert "archive.root in config/rascal.yaml" in text


def test_check_refuses_too_little_free_space_and_store_keeps_to_the_floor(tmp_path):
    arch = ImageArchive(str(tmp_path))
    with pytest.raises(ArchiveError, match=r"MB free, below archive.min_free_mb \(\d+ MB\); free"):
        arch.check(10**18)
    arch.check(5_000_000)
    arch.free_bytes = lambda: 4_999_999
    with pytest.raises(ArchiveError, match=r": 4 MB free, below archive.min_free_mb \(5 MB\)"):
        arch.store("C1", 1, PNG)
    assert not os.path.exists(tmp_path / "C1" / "1.png")


# --- names per catalogue ---
OWNER_A = "3f9c2a1b-e4d0-4c55-a1b2-c3d4e5f60718"
OWNER_B = "0b7e61aa-5d2c-4f3e-9a10-2b3c4d5e6f70"


def test_files_are_named_for_their_catalogue(tmp_path):
    arch = ImageArchive(str(tmp_path))
    rel_a, sha_a = arch.store("C1", 1, PNG + b"a", {"seq": 1}, owner=OWNER_A)
    rel_b, sha_b = arch.store("C1", 1, PNG + b"b", {"seq": 1}, owner=OWNER_B)
    assert (rel_a, rel_b) == ("C1/1-3f9c2a1be4d0.png", "C1/1-0b7e61aa5d2c.png")
    assert arch.verify(rel_a, sha_a) and arch.verify(rel_b, sha_b)
    assert arch.read_sidecar(rel_a)["catalogue_id"] == OWNER_A
    assert arch.read_sidecar(rel_b)["image_sha256"] == sha_b


def test_a_file_another_catalogue_claims_is_never_replaced(tmp_path):
    arch = ImageArchive(str(tmp_path))
    twin = OWNER_A[:-1] + "9"  # same first 12 hex digits, another catalogue
    rel, sha = arch.store("C1", 1, PNG, owner=twin)
    with pytest.raises(ArchiveError, match="belongs to catalogue %s, not this one" % twin):
        arch.store("C1", 1, PNG + b"other", owner=OWNER_A)
    assert arch.verify(rel, sha)


def test_only_old_temporary_files_count_as_left_over(tmp_path):
    arch = ImageArchive(str(tmp_path))
    arch.store("C1", 1, PNG)
    old, young = tmp_path / "C1" / ".1.png.old123.tmp", tmp_path / "C1" / ".1.json.new456.tmp"
    old.write_bytes(b"x")
    young.write_bytes(b"y")
    then = time.time() - 120
    os.utime(old, (then, then))
    assert arch.temp_files() == ["C1/.1.json.new456.tmp", "C1/.1.png.old123.tmp"]
    assert arch.temp_files("C1", older_than=60.0) == ["C1/.1.png.old123.tmp"]
    arch.remove("C1/.1.png.old123.tmp")
    assert not old.exists() and young.exists()
