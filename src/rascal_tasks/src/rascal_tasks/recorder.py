"""Writes what the workflow measures to the catalogue, one commit per measurement.

Binds the catalogue (PostgreSQL) and the image archive to one context and speaks in the
workflow's units (kg, m, s); the catalogue keeps the archaeologists' units (g, mm). No ROS here.
"""

import os
import threading
import time
from typing import List, Optional, Tuple

from rascal_tasks.catalogue import ArchiveError, Catalogue, ImageArchive, repair_archive
from rascal_tasks.catalogue.archive import make_dirs, owner_tag
from rascal_tasks.catalogue.context_id import context_folder
from rascal_tasks.catalogue.errors import FieldError
from rascal_tasks.sorting import SherdValues, choose_bin

DEFAULT_MIN_FREE_MB = 1000  # archive.min_free_mb's default in the parameter schema
ANALYSIS_WAIT = 120.0  # [s] longest wait for a photo's analysis when the sherd is done
UNSTABLE_NOTE = "scale reading not stable"  # the note of a sherd recorded mass_unstable
FINAL_STATUSES = ("done", "lost")


def _analysed(row) -> bool:
    """Whether a sherd's archival photo was analysed: values or an `archival:` note."""
    notes = row.get("notes") or ""
    return bool(row.get("colour_munsell") or row.get("px_per_cm")) or any(
        line.startswith("archival: ") for line in notes.splitlines()
    )


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
        self._wrist = {}  # seq -> (length mm, width mm, height m) as the wrist camera saw it
        self._pending = {}  # seq -> (thread, its result) of a photo's analysis under way
        self.archival_geometry = None  # rascal_tasks.archival.Geometry (use_archival_station)
        self.analyse_photos = True  # colour and size from each archival photo
        self._unfinished = None  # read once, at start-up
        archive.check(min_free_mb * 1000 * 1000)
        self.opened = catalogue.open_context(context, site)
        self.repaired = repair_archive(catalogue, archive, context, log=self.log)

    def _id(self, seq: int) -> int:
        if seq not in self._ids:
            rows = self.catalogue.sherds(self.context)
            self._ids.update({r["seq"]: r["sherd_id"] for r in rows})
        return self._ids[seq]

    def new_sherd(self, pickup_xy, attempts: int = 1, seconds: float = None) -> int:
        """Number the sherd just picked; `seconds` it took to find and pick it (t_pick_s)."""
        rec = self.catalogue.new_sherd(
            self.context, pickup_xy=list(pickup_xy), grasp_attempts=attempts, t_pick_s=seconds
        )
        self._ids[rec["seq"]] = rec["sherd_id"]
        return rec["seq"]

    def dimensions(self, seq, length, width, thickness, height=None, diameter=(0.0, 0.0)):
        """The wrist camera's length, width, wall thickness (0: not measured, recorded empty),
        height as the sherd lies [m] (the archival analysis's parallax; default thickness) and
        the vessel's diameter with its 1-sigma uncertainty [m] ((0, 0): not told, empty)."""
        self._wrist[seq] = (length * 1000.0, width * 1000.0, height or thickness)
        told = diameter[0] > 0 and diameter[1] > 0
        self.catalogue.record_dimensions(
            self._id(seq),
            length * 1000.0,
            width * 1000.0,
            thickness * 1000.0 if thickness > 0 else None,
            vessel_diameter_mm=(diameter[0] * 1000.0, diameter[1] * 1000.0) if told else None,
        )

    def mass(self, seq, kg: float, stable: bool = True, seconds: float = None):
        """A settled mass [kg]; an unstable reading is never recorded as a mass (mass_unstable)."""
        if not stable:
            raise ValueError(
                "Recorder.mass: sherd %d: an unstable reading (%.1f g) is not a mass; use "
                "Recorder.mass_unstable" % (seq, kg * 1000.0)
            )
        self.catalogue.record_mass(self._id(seq), kg * 1000.0, t_weigh_s=seconds)

    def mass_by_difference(self, seq, kg: float, weighed: float):
        """Its own mass [kg]: the `weighed` row less a sherd that stayed on the pan."""
        self.catalogue.record_mass_by_difference(self._id(seq), kg * 1000.0, weighed * 1000.0)

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

    def use_archival_station(self, station, lies_on=None):
        """The camera station's targets (chart and bar sizes, camera height; config.Station):
        what the photo analysis may know. Where the targets lie is found in each photo; where
        they and the placing spot lie on the table says where the sherd was put in it (a
        sherd of the table's colour is looked for there). `lies_on`: the station the sherd
        lies on in the photo, when not the camera's (the scale under it): only that is
        looked at, and it lies higher than the targets."""
        from rascal_tasks.archival.analysis import Geometry, Placement, Support
        from rascal_tasks.archival.chart import BarSpec, ChartSpec

        cc, sb = station.colour_chart, station.scale_bar
        placement = None
        if cc is not None and sb is not None:
            placement = Placement(
                tuple(cc.area.center), tuple(sb.area.center), tuple(station.place_at)
            )
        self.archival_geometry = Geometry(
            ChartSpec(cc.area.size[0] * 1000.0, cc.area.size[1] * 1000.0)
            if cc is not None
            else ChartSpec(),
            BarSpec(sb.area.size[0] * 1000.0, sb.area.size[1] * 1000.0)
            if sb is not None
            else BarSpec(),
            camera_height_m=station.camera_height,
            placement=placement,
            support=None
            if lies_on is None or lies_on is station
            else Support(
                tuple(lies_on.area.center),
                tuple(lies_on.area.size),
                lies_on.surface_z - station.surface_z,
                lies_on.area.yaw,
            ),
        )

    def wrist_size(self, seq) -> Optional[Tuple[float, float]]:
        """(length, width) in m the wrist camera measured for sherd `seq`, or None."""
        wrist = self._wrist_size(seq)
        return None if wrist is None else (wrist[0] / 1000.0, wrist[1] / 1000.0)

    def _wrist_size(self, seq):
        """(length mm, width mm, height m) the wrist camera measured, or None."""
        wrist = self._wrist.get(seq)
        if wrist is None:  # a resumed sherd: what the catalogue holds
            row = self.catalogue.get(self._id(seq))
            if row.get("length_mm") and row.get("width_mm"):  # its height was not kept: the wall
                wrist = (row["length_mm"], row["width_mm"], (row.get("thickness_mm") or 0) / 1e3)
        return wrist

    def _analyse(self, image_path, wrist):
        """The archival analysis of an archived photo: (catalogue fields, note). Never raises:
        any failure leaves the fields empty and says so in the note. No database access (it
        runs beside the batch, in its own thread); the corrected copy is written here."""
        try:
            from rascal_tasks.archival import analyse, corrected_path, save_corrected

            kwargs = {}
            if self.archival_geometry is not None:
                kwargs["geometry"] = self.archival_geometry
            if wrist is not None:
                kwargs["wrist_size_mm"] = wrist[:2]
                # the outline seen from above is the sherd's top edge: its height as it lies
                kwargs["object_height_m"] = wrist[2] or 0.0
            r = analyse(image_path, **kwargs)
        except Exception as e:  # noqa: BLE001  (the record must never be lost to the analysis)
            line = str(e).splitlines()[0] if str(e) else type(e).__name__
            return {}, "archival analysis failed: %s" % line
        note = r.note()
        try:
            save_corrected(
                r, corrected_path(image_path), self.archive.file_mode, self.archive.dir_mode
            )
        except (OSError, ValueError) as e:
            note = "; ".join(filter(None, [note, "corrected image not saved: %s" % e]))
        size = None
        if r.length_mm is not None and not any(
            f.startswith(("size disagrees", "size uncertain", "scale bar fit")) for f in r.flags
        ):
            size = (r.length_mm, r.width_mm)
        fields = {
            "size_mm": size,
            "colour_munsell": r.munsell,
            "colour_lab": list(r.lab_d50) if r.lab_d50 is not None else None,
            "chart_delta_e00": r.chart_de00,
            "px_per_cm": r.px_per_cm,
        }
        return {k: v for k, v in fields.items() if v is not None}, note

    def photo(self, seq, image_path: str, seconds: float = None) -> str:
        """Archive the captured file atomically, then record its path and SHA-256. The photo's
        analysis (colour, Munsell chip, the chart's CIEDE2000, px/cm, a colour-corrected copy in
        `corrected/` beside it; the archived original is only read) runs beside the batch and
        is recorded when it has finished (`collect_analyses`), after the sherd is done if need
        be: the arm never waits for it."""
        self.collect_analyses()
        rec = self.catalogue.archive_photo(
            self._id(seq), self.archive, image_path, t_photo_s=seconds
        )
        try:
            os.unlink(image_path)
        except OSError:
            pass
        archived = self.archive.path(self.catalogue.get(rec["sherd_id"])["image_path"])
        if self.analyse_photos:
            wrist = self._wrist_size(seq)
            out = {}
            worker = threading.Thread(
                target=lambda: out.update(result=self._analyse(archived, wrist)),
                name="archival-%d" % seq,
                daemon=True,
            )
            worker.start()
            self._pending[seq] = (worker, out)
        return archived

    def collect_analyses(self, wait: float = 0.0):
        """Record every photo analysis that has finished; with `wait` > 0, wait up to `wait` s
        in all for those still running (the end of a batch), and look for this rig's done sherds
        of the context whose photo was never analysed (a run that stopped in between): they are
        analysed now, as long as the deadline lasts. What did not finish in time is noted,
        never lost silently."""
        deadline = time.monotonic() + wait
        for seq in sorted(self._pending):
            worker, out = self._pending[seq]
            if wait > 0:
                worker.join(max(0.0, deadline - time.monotonic()))
            if worker.is_alive() and wait <= 0:
                continue
            del self._pending[seq]
            fields, note = out.get("result") or ({}, "archival analysis did not finish in time")
            self._write_analysis(seq, fields, note)
        if wait > 0 and self.analyse_photos:
            # this rig's own photos only, and only while the deadline lasts (a context recorded
            # before photos were analysed is caught up over the next batches, not at once)
            for row in self.catalogue.sherds(self.context, ("done",)):
                if time.monotonic() >= deadline:
                    break
                if row.get("rig") != self.catalogue.rig or not row.get("image_path"):
                    continue
                if not _analysed(row):
                    self._ids[row["seq"]] = row["sherd_id"]
                    fields, note = self._analyse(
                        self.archive.path(row["image_path"]), self._wrist_size(row["seq"])
                    )
                    self._write_analysis(row["seq"], fields, note)

    def finish_analysis(self, seq, wait: float = ANALYSIS_WAIT):
        """Record sherd `seq`'s photo analysis now, waiting for it up to `wait` s (a sherd lost
        after its photo; a photographed sherd a stopped run left, analysed now)."""
        if not self.analyse_photos:
            return
        pending = self._pending.pop(seq, None)
        if pending is None:
            row = self.catalogue.get(self._id(seq))
            if not row.get("image_path") or _analysed(row):
                return
            fields, note = self._analyse(
                self.archive.path(row["image_path"]), self._wrist_size(seq)
            )
        else:
            worker, out = pending
            worker.join(wait)
            fields, note = out.get("result") or ({}, "archival analysis did not finish in time")
        self._write_analysis(seq, fields, note)

    def _write_analysis(self, seq, fields: dict, note: str):
        """The analysis's columns, its archival size where it agreed with the wrist camera's
        (the photo's scale, ~0.13 mm a pixel; the note keeps both), and its note; then the
        image's sidecar. A value the catalogue refuses costs only that value."""
        fields = dict(fields)
        row = self.catalogue.get(self._id(seq))
        size = fields.get("size_mm")
        if size is not None and row.get("length_mm"):
            note += "; wrist camera L %.1f mm, W %.1f mm" % (row["length_mm"], row["width_mm"])
        if fields:
            try:
                self.catalogue.record_archival(self._id(seq), **fields)
            except FieldError as e:
                note = "; ".join(filter(None, [note, "archival values refused: %s" % e]))
        # "archival:" marks the photo as analysed (see _analysed), even with nothing to say
        self.catalogue.add_note(self._id(seq), "archival: " + (note or "analysed"))
        if note:
            self.log("sherd %d archival: %s" % (seq, note))
        if row["status"] in FINAL_STATUSES:
            self.catalogue.refresh_sidecar(self._id(seq), self.archive)

    def sort(self, seq, bins, default: str, wait_for_photo: bool = False):
        """Choose sherd `seq`'s box (sorting.choose_bin) on what the catalogue holds of it,
        after its photo's analysis when a rule needs its colour (`wait_for_photo`), and record
        the choice and its reason. Returns the sorting.Decision."""
        if wait_for_photo:
            self.finish_analysis(seq)
        values = SherdValues.from_row(self.catalogue.get(self._id(seq)))
        decision = choose_bin(bins, default, values)
        self.catalogue.record_bin(self._id(seq), decision.bin, decision.reason)
        return decision

    def done(self, seq, seconds: float = None, timings: dict = None):
        pending = self._pending.get(seq)
        if pending is not None and not pending[0].is_alive():
            self.finish_analysis(seq)  # finished already: in the row before the sidecar
        self.catalogue.record_done(
            self._id(seq), t_discard_s=seconds, timings=timings, archive=self.archive
        )
        self.collect_analyses()

    def lost(self, seq, reason: str, timings: dict = None):
        if seq in self._pending:  # lost after its photo: the photo's colour is still its own
            self.finish_analysis(seq)
        self.catalogue.record_lost(self._id(seq), reason, timings=timings)
        # a sherd lost after its photo: its sidecar says lost too
        self.catalogue.refresh_sidecar(self._id(seq), self.archive)

    def drop(self, seq, station: str):
        self.catalogue.record_drop(self._id(seq), station)

    def taken_over(self, seq, pickup_xy):
        """Sherd `seq` (two put back apart) is now the sherd picked at `pickup_xy` [m]."""
        self.catalogue.record_taken_over(self._id(seq), list(pickup_xy))

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
