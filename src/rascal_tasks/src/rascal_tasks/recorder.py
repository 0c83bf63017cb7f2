"""Writes what the workflow measures to the catalogue, one commit per measurement.

Binds the catalogue (PostgreSQL) and the image archive to one context and speaks in the
workflow's units (kg, m, s); the catalogue keeps the archaeologists' units (g, mm). No ROS here.
"""

import os
from typing import List, Tuple

from rascal_tasks.catalogue import ArchiveError, Catalogue, ImageArchive, repair_archive
from rascal_tasks.catalogue.archive import make_dirs, owner_tag
from rascal_tasks.catalogue.context_id import context_folder

DEFAULT_MIN_FREE_MB = 1000  # archive.min_free_mb's default in the parameter schema
UNSTABLE_NOTE = "scale reading not stable"  # the note of a sherd recorded mass_unstable


class Recorder:
    def __init__(
        self,
        catalogue: Catalogue,
        archive: ImageArchive,
        context: str,
        site: str,
        log=None,
        min_free_mb: float = DEFAULT_MIN_FREE_MB,
    ):
        """Before the first pick: checks the archive folder (``ImageArchive.check``: exists or
        can be created, a probe file really written and removed, more than ``min_free_mb``
        (archive.min_free_mb) MB free, kept to by every later image), opens the context, then
        repairs the context's archive after a crash (``repair_archive``: leftover temporary
        files removed, stale sidecars rewritten from the catalogue; one log line if it did).
        Raises ArchiveError or CatalogueError, one line naming the key and the fix."""
        self.catalogue = catalogue
        self.archive = archive
        self.context = context
        self.log = log or (lambda msg: None)
        self._ids = {}  # seq -> sherd_id
        self._unfinished = None  # read once, at start-up
        archive.check(min_free_mb * 1000 * 1000)
        self.opened = catalogue.open_context(context, site)
        self.repaired = repair_archive(catalogue, archive, context, log=self.log)

    def _id(self, seq: int) -> int:
        if seq not in self._ids:
            rows = self.catalogue.sherds(self.context)
            self._ids.update({r["seq"]: r["sherd_id"] for r in rows})
        return self._ids[seq]

    def new_sherd(self, pickup_xy, attempts: int = 1) -> int:
        rec = self.catalogue.new_sherd(
            self.context, pickup_xy=list(pickup_xy), grasp_attempts=attempts
        )
        self._ids[rec["seq"]] = rec["sherd_id"]
        return rec["seq"]

    def dimensions(self, seq, length, width, thickness):
        self.catalogue.record_dimensions(
            self._id(seq),
            length * 1000.0,
            width * 1000.0,
            thickness * 1000.0 if thickness > 0 else None,
        )

    def mass(self, seq, kg: float, stable: bool = True, seconds: float = None):
        """A settled mass [kg]; an unstable reading is never recorded as a mass (mass_unstable)."""
        if not stable:
            raise ValueError(
                "Recorder.mass: sherd %d: an unstable reading (%.1f g) is not a mass; use "
                "Recorder.mass_unstable" % (seq, kg * 1000.0)
            )
        self.catalogue.record_mass(self._id(seq), kg * 1000.0, t_weigh_s=seconds)

    def mass_unstable(self, seq, reason: str, seconds: float = None):
        """No trustworthy mass: status mass_unstable, no mass, `reason` in mass_missing_reason
        and a note (UNSTABLE_NOTE, which `rascal run`'s summary counts)."""
        self.catalogue.record_mass_unstable(self._id(seq), reason, t_weigh_s=seconds)
        note = "%s: no mass recorded (%s)" % (UNSTABLE_NOTE, reason)
        self.catalogue.add_note(self._id(seq), note)

    def spool_path(self, seq: int) -> str:
        """Where the archival camera writes before the archive takes the file over."""
        spool = os.path.join(self.archive.root, ".spool")
        try:
            make_dirs(spool, self.archive.dir_mode)
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: cannot create %s (%s); make the folder writable"
                % (self.archive.root, spool, e.strerror)
            ) from None
        # named for this catalogue too: two catalogues sharing an archive never share a capture
        tag = owner_tag(self.catalogue.identity())
        return os.path.join(spool, "%s-%d-%s.png" % (context_folder(self.context), seq, tag))

    def photo(self, seq, image_path: str, seconds: float = None) -> str:
        """Archive the captured file atomically, then record its path and SHA-256."""
        rec = self.catalogue.archive_photo(
            self._id(seq), self.archive, image_path, t_photo_s=seconds
        )
        try:
            os.unlink(image_path)
        except OSError:
            pass
        return self.archive.path(self.catalogue.get(rec["sherd_id"])["image_path"])

    def done(self, seq, seconds: float = None, timings: dict = None):
        self.catalogue.record_done(
            self._id(seq), t_discard_s=seconds, timings=timings, archive=self.archive
        )

    def lost(self, seq, reason: str, timings: dict = None):
        self.catalogue.record_lost(self._id(seq), reason, timings=timings)
        # a sherd lost after its photo: its sidecar says lost too
        self.catalogue.refresh_sidecar(self._id(seq), self.archive)

    def drop(self, seq, station: str):
        self.catalogue.record_drop(self._id(seq), station)

    def grasp_attempt(self, seq, station: str):
        self.catalogue.record_grasp_attempt(self._id(seq), station)

    def note(self, seq, text: str):
        self.catalogue.add_note(self._id(seq), text)

    def unfinished(self) -> List[Tuple[int, str, Tuple[float, float]]]:
        """(seq, status, pickup (x, y) in m) of this rig's sherds that a killed run left
        unfinished, oldest first, as they were at start-up."""
        if self._unfinished is None:  # the catalogue logs a resume once per run
            rows = self.catalogue.resume(self.context)
            self._ids.update({r["seq"]: r["sherd_id"] for r in rows})
            self._unfinished = [
                (r["seq"], r["status"], (r["pickup_x_m"], r["pickup_y_m"])) for r in rows
            ]
        return self._unfinished

    def rows(self):
        return self.catalogue.sherds(self.context)
