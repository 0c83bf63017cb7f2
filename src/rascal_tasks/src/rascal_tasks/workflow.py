"""The station workflow: one bag's sherds, each picked, carried through the stations and recorded.

    HOME -> CALIBRATE -> RESUME -> SURVEY -> PICKUP -> [TRANSLATE -> PLACE -> <station> -> REPICK]*
         -> SURVEY_NEXT ... -> PARK (when the pickup area stays empty)

This module only connects the states (`build_machine`). One file per stage of a sherd's life:

    batch.py           Batch (what the states share) and BatchState (failures -> outcomes)
    failures.py        the rule: which failure loses only this sherd, which stops the batch
    resume.py          HOME, CALIBRATE, RESUME: start, and carrying on after a killed run
    survey.py          SURVEY, SURVEY_NEXT: the lawnmower over the pickup area, views merged
    selection.py       the selection policy: which sherd of the survey is picked next
    pickup.py          PICKUP: grasped from the pickup area, then numbered
    manipulation.py    grasp, its retries, the finger opening
    station_states.py  TRANSLATE, PLACE, STATION (the plug-ins of stations.py), REPICK
    recovery.py        RECOVER: a dropped sherd looked for and picked up again, or lost
    sherd_record.py    SherdRecord: the sherd in progress and its catalogue writes (done, lost)

Every measurement is written when taken, and the row's status moves picked -> weighed ->
photographed -> done | lost, so a restart of the same context resumes the sherd that was in
progress instead of numbering it again. No ROS here: the rig, recorder and progress callback
are injected.
"""

from rascal_tasks.batch import Batch, BatchState, smach
from rascal_tasks.pickup import Pickup
from rascal_tasks.recovery import Recover
from rascal_tasks.resume import Calibrate, Home, Resume
from rascal_tasks.rig import RigError
from rascal_tasks.station_states import AtStation, Place, PutBack, Repick, Translate
from rascal_tasks.survey import NextSherd, Survey

__all__ = ["Batch", "Park", "build_machine", "park", "smach"]


class Park(BatchState):
    def __init__(self, batch):
        super().__init__(batch, ["done"])

    def execute(self, userdata):  # parks even when preempted
        try:
            park(self.batch)
        except RigError as e:
            self.batch.event(None, "park_failed", str(e))
            return "aborted"
        return "done"


def park(b: Batch):
    # the fingers may still be low around a sherd they let go of (Batch.lift_later): straight
    # up first, so the way to the sleep pose does not sweep it away
    for x, y, z, yaw, linear in b.take_lift():
        try:
            b.rig.arm.move_down(x, y, z, yaw, linear=linear)
        except RigError as e:
            b.log("parking: the lift before it failed: %s" % e)
    b.rig.arm.go("sleep")


def build_machine(batch: Batch):
    """The state machine for one batch; outcomes: finished, preempted, aborted.

    States are numbered by the station's place in the config (TRANSLATE_0 goes to the first
    station after pickup); any state that is preempted or aborts goes through a PARK state."""
    sm = smach.StateMachine(outcomes=["finished", "preempted", "aborted"])
    n = len(batch.plugins)
    fail = {"preempted": "PARK_PREEMPTED", "aborted": "PARK_ABORTED"}

    def add(label, state, **transitions):
        smach.StateMachine.add(
            label, state, {**transitions, **fail} if not label.startswith("PARK") else transitions
        )

    with sm:
        add("HOME", Home(batch), done="CALIBRATE")
        add("CALIBRATE", Calibrate(batch), done="RESUME")
        resume = Resume(batch)
        add("RESUME", resume, **{o: o for o in resume.get_registered_outcomes() if o not in fail})
        add("SURVEY", Survey(batch), found="PICKUP", empty="PARK")
        add("PICKUP", Pickup(batch), held="TRANSLATE_0", missed="SURVEY")
        for i in range(n):
            last = i == n - 1
            # a camera over the scale shoots the sherd where it was weighed: no repick, no carry
            after = "STATION_%d" % (i + 1) if batch.next_stays(i) else None
            add(
                "TRANSLATE_%d" % i,
                Translate(batch, i),
                arrived="PLACE_%d" % i,
                dropped="RECOVER_%d" % i,
            )
            add("PLACE_%d" % i, Place(batch, i), placed="STATION_%d" % i)
            add(
                "STATION_%d" % i,
                AtStation(batch, i),
                done="SURVEY_NEXT" if last else after or "REPICK_%d" % i,
                dropped="RECOVER_%d" % i,
                lost="SURVEY_NEXT",
                double="PUT_BACK_%d" % i,
            )
            add("PUT_BACK_%d" % i, PutBack(batch, i), surveyed="SURVEY", lost="SURVEY_NEXT")
            if not last:
                add(
                    "REPICK_%d" % i,
                    Repick(batch, i),
                    held="TRANSLATE_%d" % (i + 1),
                    lost="SURVEY_NEXT",
                )
            add(
                "RECOVER_%d" % i,
                Recover(batch),
                held="TRANSLATE_%d" % i,
                lost="SURVEY_NEXT",
                returned="SURVEY",
                done="SURVEY_NEXT",
            )
        add("SURVEY_NEXT", NextSherd(batch), pickup="PICKUP", survey="SURVEY")
        add("PARK", Park(batch), done="finished", aborted="aborted", preempted="preempted")
        add(
            "PARK_PREEMPTED",
            Park(batch),
            done="preempted",
            aborted="aborted",
            preempted="preempted",
        )
        add("PARK_ABORTED", Park(batch), done="aborted", aborted="aborted", preempted="aborted")
    return sm
