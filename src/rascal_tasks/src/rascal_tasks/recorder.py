"""Writes what the workflow measures to the catalogue, one commit per measurement.

Binds the catalogue (PostgreSQL) and the image archive to one context and speaks in the
workflow's units (kg, m, s); the catalogue keeps the archaeologists' units (g, mm). No ROS here.
"""

import os
from typing import List, Tuple

from rascal_tasks.catalogue import Catalogue, ImageArchive


class Recorder:
    def __init__(
        self, catalogue: Catalogue, archive: ImageArchive, context: str, site: str, log=None
    ):
        self.catalogue = catalogue
        self.archive = archive
        self.context = context
        self.log = log or (lambda msg: None)
        self._ids = {}  # seq -> sherd_id
        self._unfinished = None  # read once, at start-up
        self.opened = catalogue.open_context(context, site)

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

    def mass(self, seq, kg: float, stable: bool, seconds: float = None):
        self.catalogue.record_mass(self._id(seq), kg * 1000.0, t_weigh_s=seconds)
        if not stable:
            self.catalogue.add_note(
                self._id(seq), "scale reading not stable: %.1f g" % (kg * 1000.0)
            )

    def spool_path(self, seq: int) -> str:
        """Where the archival camera writes before the archive takes the file over."""
        spool = os.path.join(self.archive.root, ".spool")
        os.makedirs(spool, exist_ok=True)
        return os.path.join(spool, "%s-%d.png" % (self.context, seq))

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
