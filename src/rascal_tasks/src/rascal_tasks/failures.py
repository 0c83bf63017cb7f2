"""What a failure stops: this sherd, or the whole batch. The rule is `classify`; the states only
apply it (`batch.BatchState`). No ROS here.
"""

from rascal_tasks.rig import RigError

# Arm codes that refuse a goal before the arm moves: the goal is wrong, not the rig
# (rascal_control.results: UNREACHABLE, COLLISION, INVALID_GOAL; NO_IK for an IK that found none).
ARM_REFUSALS = frozenset({"UNREACHABLE", "NO_IK", "COLLISION", "INVALID_GOAL"})
# Codes that say the rig itself is not what the batch believes: the arm driver restarted (the
# controller refuses goals until the next run acknowledges it), or the arm left its planned
# path. Never about one sherd, even on a grasp target: park, stop, exit FAULT.
UNSAFE = frozenset({"DRIVER_RESTARTED", "TRACKING_ERROR"})

LOSE_SHERD = "lose_sherd"  # record this sherd lost with the reason, go on with the next one
STOP = "stop"  # park the arm and end the batch 'aborted'; the sherd stays unfinished


class SherdFailure(Exception):
    """This sherd cannot go on, while the rig can: the arm refused a grasp target computed from
    its detection, or a station plug-in said 'failed' for it. `station` is where the sherd is
    left lying; `observation` is the detection whose grasp was refused (if any)."""

    def __init__(self, reason: str, station, observation=None):
        super().__init__(reason)
        self.reason = reason
        self.station = station
        self.observation = observation


def about_this_sherd(error: Exception, sherd_target: bool = False) -> bool:
    """Part 1 of the rule (see `classify`): whether `error` is about the sherd, not the rig."""
    if isinstance(error, SherdFailure):
        return True
    if isinstance(error, RigError) and error.code in UNSAFE:
        return False
    return isinstance(error, RigError) and sherd_target and error.code in ARM_REFUSALS


def classify(error: Exception, sherd_target: bool = False, left_in_the_way: bool = False) -> str:
    """LOSE_SHERD or STOP for an error raised while a sherd was being handled.

    LOSE_SHERD only when both hold:
    1. The error is about this sherd: a SherdFailure (a station plug-in said 'failed' for it),
       or a RigError coded UNREACHABLE, NO_IK, COLLISION or INVALID_GOAL from an arm move whose
       target was computed from this sherd's detection (`sherd_target`: the approach and descent
       of a grasp, made with the gripper open and empty; the controller refuses such a goal
       before moving).
    2. The sherd is not left in the way (`left_in_the_way`: lying on a station where the next
       sherd is placed, the scale or the camera): the next sherd would land on it. Stopping
       there keeps it unfinished, so a restart resumes it once a person has looked.
    A sherd is never in the fingers when LOSE_SHERD applies: every move made while it is held
    (travel, placing, lifting) stops the batch when refused.

    STOP for everything else: DRIVER_RESTARTED and TRACKING_ERROR (UNSAFE: the rig is not what
    the batch believes), TIMEOUT (an arm or scale that did not answer in time), PREEMPTED,
    MISSING nodes, any gripper, perception, scale or camera error, any code not listed above,
    database errors, and any other exception. Anything raised by park ends the batch anyway.
    """
    if about_this_sherd(error, sherd_target) and not left_in_the_way:
        return LOSE_SHERD
    return STOP
