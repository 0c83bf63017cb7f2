"""Station plug-ins: what happens once a sherd is at a station.

A station type is a class registered under the `type` used in config/rascal.yaml; the workflow
builds its states from the config's station list, so a new kind of station (a profile scanner,
a second camera) is a new class here plus a config entry, not an edit of the state machine.
No ROS here: plug-ins use the rig interfaces (`rig.py`) and write through the sherd's record
(`sherd_record.py`).
"""

import math
from typing import Dict, Type

from rascal_tasks.rig import RigError

STATION_PLUGINS: Dict[str, Type["StationPlugin"]] = {}
# The smallest sherd worth recording: 2 x 2 cm, 4 mm wall at 1.8 g/cm^3 is about 2.9 g
# (shared/facts/sherds_and_colour.md §2). A lighter reading means the sherd is not on the scale.
MIN_SHERD_MASS = 0.001  # kg


def station_type(name: str):
    """Class decorator: register a plug-in for stations of config `type: <name>`."""

    def register(cls):
        STATION_PLUGINS[name] = cls
        cls.type_name = name
        return cls

    return register


class StationPlugin:
    """Base class. `status` is the catalogue status a sherd reaches when this station is done."""

    type_name = ""
    status = ""
    # True: the sherd is released from travel height and never picked up again (discard box).
    release_from_above = False
    # True: after placing, the gripper waits just above the sherd (nothing to keep out of view),
    # so picking it up again is a short descent instead of a trip from travel height.
    hover_after_place = False

    def __init__(self, station, batch):
        self.station = station  # rascal_tasks.config.Station
        self.batch = batch  # rascal_tasks.batch.Batch

    def before_place(self, sherd) -> None:
        """Called with the sherd (a SherdRecord) in the gripper above the station (e.g. tare
        the scale)."""

    def after_place(self, sherd) -> str:
        """Called with the sherd placed and the gripper back at travel height; records what it
        measured through `sherd` (SherdRecord). Returns 'done'; 'missing' when the sherd is
        evidently not there (it is searched for like a drop); or 'failed' when the station could
        not do its job for this sherd. A failed sherd that lies where the next sherd is placed
        stops the batch with the arm parked, unfinished, for a person to look (a restart
        resumes it); elsewhere (the discard box) it is recorded lost and the batch goes on
        (`failures.classify`). A RigError raised here stops the batch."""
        raise NotImplementedError


@station_type("scale")
class ScaleStation(StationPlugin):
    status = "weighed"
    hover_after_place = True

    def before_place(self, sherd):
        with self.batch.phase("data_collection"):
            self.batch.rig.scale.tare()

    def after_place(self, sherd):
        cfg = self.batch.config["scale"]
        reading = None
        with self.batch.phase("data_collection"):
            for attempt in range(1 + cfg["rereads"]):
                reading = self.batch.rig.scale.read_stable(cfg["stable_timeout"])
                if reading.stable:
                    break
                self.batch.event(
                    sherd,
                    "scale_unstable",
                    "attempt %d: %.1f g" % (attempt + 1, reading.mass * 1000),
                )
        if reading.mass < MIN_SHERD_MASS:
            # Nothing on the pan: the sherd slipped away unnoticed on the way; look for it.
            self.batch.event(
                sherd, "scale_empty", "reads %.1f g after placing the sherd" % (reading.mass * 1000)
            )
            return "missing"
        # An unstable last reading is still recorded, and flagged in the sherd's notes.
        sherd.record_mass(reading.mass, reading.stable)
        return "done"


@station_type("archival_camera")
class ArchivalCameraStation(StationPlugin):
    status = "photographed"
    CAPTURE_ATTEMPTS = 3

    def after_place(self, sherd):
        b = self.batch
        sx, sy = b.config["arm"]["standby"]
        # Turn the wrist so the wrist camera (mounted ahead of the gripper) faces away from the
        # archival camera's view too.
        cx, cy = self.station.area.center
        b.move_down(sx, sy, b.config["arm"]["travel_z"], math.atan2(sy - cy, sx - cx))
        with b.phase("data_collection"):
            for attempt in range(self.CAPTURE_ATTEMPTS):
                try:
                    capture = b.rig.camera.capture(sherd.spool_path())
                    break
                except RigError as e:
                    b.event(sherd, "capture_failed", "attempt %d: %s" % (attempt + 1, e.reason))
                    b.rig.clock.sleep(1.0)
            else:
                return "failed"  # it lies on the camera's spot: the batch stops
            sherd.record_photo(capture.path)
        return "done"


@station_type("discard")
class DiscardStation(StationPlugin):
    """Nothing to measure: the sherd is done once it is in the box (the last station)."""

    status = "done"
    release_from_above = True

    def after_place(self, sherd):
        return "done"
