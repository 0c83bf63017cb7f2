"""`rascal run --context ID`: one bag's batch on the rig (or the simulator), with a live
progress line. The node wrapper of the workflow core. Before anything moves it checks, each
with a deadline and one line naming what is wrong: the context ID, a ROS master, the
configuration, that no other run holds this rig or this context (`run_lock`), the catalogue,
and the nodes the run needs (`ros_graph`). Then it wires the rig over ROS and runs the machine;
Ctrl-C becomes a preempt that parks the arm. When the database goes away mid-batch the machine
parks the arm; the run waits for the database and carries on with the same context (HOME,
CALIBRATE, RESUME resume the unfinished sherd). Exit codes: `exit_codes.py`.
"""

import os
import signal
import sys
import threading
import time

import psycopg2
import rospy

from rascal_tasks import exit_codes
from rascal_tasks.batch import PUSHED_OFF, SLIPPED_AWAY
from rascal_tasks.catalogue import Catalogue, ConnectionLostError, ImageArchive
from rascal_tasks.catalogue.central import ContextClaimed
from rascal_tasks.catalogue.context_batches import (
    START_RESUME,
    ContextInUse,
    context_state,
    log_batch,
    start_mode,
)
from rascal_tasks.catalogue.context_id import validate_context_id
from rascal_tasks.catalogue.errors import CatalogueError
from rascal_tasks.config import ConfigError, load_config
from rascal_tasks.recorder import ANALYSIS_WAIT, Recorder
from rascal_tasks.rig import Rig, RigError
from rascal_tasks.ros_config import load_for_run
from rascal_tasks.ros_graph import GraphError, check_master, run_needs, wait_for_nodes
from rascal_tasks.run_lock import Busy, ContextLock, RigLock
from rascal_tasks.survey import describe_leftover
from rascal_tasks.workflow import Batch, build_machine, park, smach

MASTER_TIMEOUT = 3.0  # s: a master that does not answer within this is not there


class ProgressLine:
    """`sherd k | state | elapsed | s/sherd` on one terminal line (a plain line per state when
    the output is not a terminal, so logs stay readable)."""

    def __init__(self, out=sys.stdout):
        self.out = out
        self.tty = out.isatty()
        self.batch = None

    def __call__(self, state):
        b = self.batch
        if b is None:
            return
        elapsed = b.rig.clock.now() - b.started
        k = b.sherd.seq if b.sherd else b.completed + b.lost + 1
        per = b.per_sherd()
        line = "sherd %3d | %-22s | %7.1f s | %s" % (
            k,
            state[:22],
            elapsed,
            "%.1f s/sherd" % per if per else "–",
        )
        if self.tty:
            self.out.write("\r" + line + "   ")
        else:
            self.out.write(line + "\n")
        self.out.flush()


def fail(message: str, code: int = exit_codes.BAD_INPUT):
    """One line per problem on stderr; returns `code`."""
    for line in message.splitlines():
        print("error: %s" % line, file=sys.stderr)
    return code


def _first_line(e) -> str:
    return (str(e).strip().splitlines() or [type(e).__name__])[0]


def _smach_error(msg):
    """smach's errors carry a state's traceback: its first line to the terminal, the whole of
    it to the node's log file."""
    lines = str(msg).strip().splitlines() or [""]
    rospy.logerr(lines[0] + (" (RASCAL_DEBUG=1 shows where)" if len(lines) > 1 else ""))
    if len(lines) > 1:
        rospy.logdebug(str(msg))


def _default_database(cfg):
    return cfg["database"]["dsn"], cfg["database"]["connect_timeout"], cfg.source


def run(context: str, config_path: str = None, database=None, append: bool = False) -> int:
    """One batch of `context`. `config_path`: a site config file to use instead of the parameter
    server's (checked against it); `database(cfg)` -> (dsn, connect_timeout, where it came
    from), by default the config's; `append` (--continue): a context whose last batch finished
    complete takes a new bag (`context_batches`). Returns an exit code of exit_codes.py."""
    r = Run(context, config_path, database or _default_database, append)
    try:
        return r.main()
    except KeyboardInterrupt:  # before the handlers are in place: nothing has moved
        return fail("interrupted before the batch started; nothing moved", exit_codes.INTERRUPTED)
    finally:
        r.close()


class _Interrupted(Exception):
    """Ctrl-C while waiting for the database."""


class Run:
    def __init__(self, context, config_path, database, append=False):
        self.context = context
        self.append = append
        self.batch_logged = False  # batch_started written (once the context is open)
        self.config_path = config_path
        self.database = database
        self.cfg = None
        self.stop = threading.Event()  # Ctrl-C or SIGTERM
        self.rig = None
        self.batch = None
        self.machine = None
        self.catalogue = None
        self.rig_lock = None
        self.context_lock = None
        self.stop_reason = None  # why the last batch stopped (Batch.stop_reason, or the database)
        self.park_failed = False  # the last batch could not park the arm

    # --- before anything moves ---
    def main(self) -> int:
        try:
            self.context = validate_context_id(self.context)  # stored NFC-normalised
        except CatalogueError as e:
            return fail(str(e))
        if self.config_path:  # a broken file is said before anything else
            try:
                load_config(self.config_path)
            except ConfigError as e:
                return fail(str(e))
        try:
            uri = check_master(timeout=MASTER_TIMEOUT)
        except GraphError as e:
            return fail(str(e), exit_codes.FAULT)
        # anonymous: a second run must not make the master shut the first one down
        rospy.init_node("rascal", anonymous=True, disable_signals=True)
        signal.signal(signal.SIGINT, self.on_signal)
        signal.signal(signal.SIGTERM, self.on_signal)
        try:
            self.cfg = cfg = load_for_run(self.config_path)
        except ConfigError as e:
            return fail(str(e))
        try:
            self.rig_lock = RigLock(cfg["rig"]["name"], uri, self.context).acquire()
        except Busy as e:
            return fail(str(e), exit_codes.BUSY)
        # The catalogue first: if it is down, nothing may move.
        try:
            from rascal_tasks.cli import UsageError, mask_dsn

            dsn, timeout, source = self.database(cfg)
        except UsageError as e:
            return fail(str(e))
        self.context_lock = ContextLock(self.context, cfg["rig"]["name"])
        try:
            self.catalogue = Catalogue.connect(
                dsn,
                rig=cfg["rig"]["name"],
                config_hash=cfg.hash,
                connect_timeout=timeout,
                application_name=self.context_lock.app_name,  # names this run to a second one
            )
        except CatalogueError as e:
            return fail(
                "database %s (from %s): %s (`rascal db migrate` creates the tables)"
                % (mask_dsn(dsn), source, e),
                exit_codes.FAULT,
            )
        try:
            self.context_lock.acquire(self.catalogue.connection)
        except Busy as e:
            return fail(str(e), exit_codes.BUSY)
        except psycopg2.Error as e:
            return fail("database: cannot lock the context: %s" % _first_line(e), exit_codes.FAULT)
        try:  # under the context's lock: a new bag on a finished context needs --continue
            state = context_state(self.catalogue.connection, self.context)
            if start_mode(state, self.context, self.append) == START_RESUME:
                print(
                    "resuming context %s: %d sherds recorded, %d unfinished; its last run did "
                    "not finish" % (self.context, state["sherds"], state["unfinished"])
                )
        except ContextInUse as e:
            return fail(str(e))
        except psycopg2.Error as e:
            return fail("database: %s" % _first_line(e), exit_codes.FAULT)
        try:
            simulated = bool(rospy.get_param("/use_sim_time", False))
            if not wait_for_nodes(
                run_needs(simulated), cfg["rig"]["node_wait"], uri, stopped=self.stop.is_set
            ):
                return fail(
                    "interrupted before the batch started; nothing moved", exit_codes.INTERRUPTED
                )
            self.rig = make_rig(cfg, self.stop)
        except GraphError as e:
            return fail(str(e), exit_codes.FAULT)
        except RigError as e:
            return fail(str(e), exit_codes.FAULT)
        try:
            archive = ImageArchive(
                cfg.resolve(cfg["archive"]["root"]),
                file_mode=cfg["archive"]["file_mode"],
                dir_mode=cfg["archive"]["dir_mode"],
            )
        except (CatalogueError, OSError) as e:
            return fail("archive.root: %s" % _first_line(e), exit_codes.FAULT)
        return self.batches(archive)

    def on_signal(self, signum, frame):
        if self.stop.is_set():  # second Ctrl-C: stop the arm where it is
            if self.rig is not None:
                self.rig.arm.stop()
            return
        self.stop.set()
        if self.machine is not None:
            print(
                "\nstopping: parking the arm (Ctrl-C again stops it where it is)", file=sys.stderr
            )
            self.batch.stop_requested.set()
            self.machine.request_preempt()

    # --- the batch, again after a database outage ---
    def batches(self, archive) -> int:
        cfg = self.cfg
        progress = ProgressLine()
        # The machine's own chatter (states added, every transition) goes to the node's log; the
        # terminal shows the progress line and what happened to sherds.
        smach.set_loggers(rospy.logdebug, rospy.logwarn, rospy.logdebug, _smach_error)
        wall = time.monotonic()
        done = []  # the batches run so far (one per database outage)
        while True:
            if self.stop.is_set():
                return fail("interrupted; the arm is parked", exit_codes.INTERRUPTED)
            try:
                recorder = Recorder(
                    self.catalogue,
                    archive,
                    self.context,
                    cfg["rig"]["site"],
                    log=rospy.loginfo,
                    min_free_mb=cfg["archive"]["min_free_mb"],
                )
            except ContextClaimed as e:  # another rig records this context: nothing moved
                return fail(str(e), exit_codes.BUSY)
            except CatalogueError as e:
                if not (isinstance(e, ConnectionLostError) or self.database_lost()):
                    return fail("database: %s" % e, exit_codes.FAULT)
                code = self.wait_for_database(_first_line(e))
                if code:
                    return code
                continue
            if not self.batch_logged:  # the context exists now (Recorder opened it)
                try:
                    log_batch(
                        self.catalogue.connection,
                        self.context,
                        cfg["rig"]["name"],
                        "batch_started",
                        {"append": self.append},
                    )
                    self.batch_logged = True
                except psycopg2.Error as e:
                    rospy.logwarn("batch_started not logged: %s", _first_line(e))
            batch = Batch(
                cfg, self.rig, recorder, self.context, progress=progress, log=rospy.loginfo
            )
            if done:  # what the batch before learnt about the mat
                batch.unpickable = done[-1].unpickable
                batch.not_seen_again = done[-1].not_seen_again
                batch.misses = done[-1].misses
                batch.pushed = done[-1].pushed
                batch.pushed_to = done[-1].pushed_to
                batch.put_back_at = done[-1].put_back_at
                batch.two_seen = done[-1].two_seen
                batch.maybe_two = done[-1].maybe_two
                batch.photo_with_another = done[-1].photo_with_another
                batch.left_on_station = done[-1].left_on_station
            progress.batch = batch
            self.batch, self.machine = batch, build_machine(batch)
            if self.stop.is_set():  # Ctrl-C while the machine was being built
                self.machine = None
                continue
            try:
                outcome = self.machine.execute()
            except Exception as e:  # a state's bug: park, then one line (never a traceback)
                return self.crashed(e)
            finally:
                self.machine = None
                self.stop_reason, self.park_failed = batch.stop_reason, batch.park_failed
            done.append(batch)
            print()
            if outcome == "aborted" and not self.stop.is_set() and self.database_lost():
                code = self.wait_for_database(self.stop_reason or "connection lost")
                if code:
                    return code
                continue
            break
        try:
            # the photos' analyses still running (the arm never waited for them) and any done
            # sherd of the context whose photo a stopped run left unanalysed
            recorder.collect_analyses(wait=ANALYSIS_WAIT)
            rows = recorder.rows()
        except CatalogueError as e:
            rows = None
            self.stop_reason = self.stop_reason or "database: %s" % _first_line(e)
            outcome = "aborted"
        print_summary(done, rows, outcome, time.monotonic() - wall)
        code = self.exit_code(outcome, done[-1], rows)
        try:  # exit 0 closes the context (a new bag then needs --continue)
            log_batch(
                self.catalogue.connection,
                self.context,
                cfg["rig"]["name"],
                "batch_ended",
                {
                    "exit": code,
                    "outcome": outcome,
                    # what the person is told to look at stays with the context's history
                    "not_taken": [describe_leftover(lo) for lo in done[-1].leftovers],
                    **{
                        kind: [list(xy) for xy in done[-1].not_seen(kind)]
                        for kind in NOT_SEEN_AGAIN
                    },
                },
            )
        except psycopg2.Error as e:  # not logged: the next run resumes, which loses nothing
            rospy.logwarn("batch_ended not logged: %s", _first_line(e))
        return code

    def exit_code(self, outcome, batch, rows) -> int:
        if outcome == "preempted":
            return fail(
                "interrupted; %s: `rascal run --context %s` resumes the batch"
                % (
                    "the arm could NOT be parked" if self.park_failed else "the arm is parked",
                    self.context,
                ),
                exit_codes.INTERRUPTED,
            )
        if outcome != "finished":
            return fail(
                "the batch stopped: %s; %s and every measurement taken is saved: "
                "once the fault is cleared, `rascal run --context %s` resumes it"
                % (
                    self.stop_reason or "the state machine ended without an outcome",
                    "the arm could NOT be parked (look at it before anything else)"
                    if self.park_failed
                    else "the arm is parked",
                    self.context,
                ),
                exit_codes.FAULT,
            )
        left = what_is_left(batch, rows)
        if not left:
            return exit_codes.COMPLETE
        print(
            "batch %s incomplete: %s; a person must look (`rascal report --context %s` lists the "
            "sherds), then `rascal run --context %s` records what is put back on the mat"
            % (self.context, left, self.context, self.context)
        )
        return exit_codes.INCOMPLETE

    def crashed(self, e: Exception) -> int:
        """A state raised something the workflow does not turn into an outcome: park the arm
        and name the error in one line (smach puts the traceback into the message: its last
        line is the error)."""
        lines = [x.strip() for x in str(e).strip().splitlines() if x.strip()]
        rospy.logdebug("batch: %s", e)  # the node's log file, not the terminal
        if os.environ.get("RASCAL_DEBUG"):
            print(str(e), file=sys.stderr)
        try:
            park(self.batch)
            parked = "the arm is parked"
        except Exception as p:  # whatever the rig says, the line is still printed
            parked = "the arm could NOT be parked (%s)" % _first_line(p)
        return fail(
            "the batch stopped on an unexpected error: %s; %s; a restart resumes the sherd in "
            "progress (RASCAL_DEBUG=1 shows where)"
            % (lines[-1] if lines else type(e).__name__, parked),
            exit_codes.FAULT,
        )

    def database_lost(self) -> bool:
        """Whether the catalogue's connection is gone (a batch stopped on it)."""
        conn = self.catalogue.connection
        if conn.closed:
            return True
        try:
            conn.rollback()
            with conn.cursor() as cur:
                cur.execute("SELECT 1")
            conn.rollback()
        except psycopg2.Error:
            return True
        return False

    def wait_for_database(self, why: str) -> int:
        """Reconnect with the catalogue's backoff for database.retry_for seconds and take the
        context's lock again; 0 when the database is back, else the exit code (the arm is
        parked)."""
        retry_for = self.cfg["database"]["retry_for"]
        print(
            "database lost (%s): the arm is parked; reconnecting for up to %.0f s "
            "(database.retry_for)" % (why, retry_for),
            file=sys.stderr,
        )
        self.context_lock.conn = None  # it went with the connection
        start = time.monotonic()

        def sleep(seconds):
            if self.stop.wait(seconds):
                raise _Interrupted()

        try:
            self.catalogue.reconnect_with_retry(retry_for, log=rospy.logwarn, sleep=sleep)
            self.context_lock.acquire(self.catalogue.connection)
        except _Interrupted:
            return fail("interrupted; the arm is parked", exit_codes.INTERRUPTED)
        except Busy as e:
            return fail(str(e), exit_codes.BUSY)
        except (CatalogueError, psycopg2.Error) as e:
            return fail(
                "%s; the arm is parked and every measurement committed is saved: `rascal run "
                "--context %s` resumes the batch" % (_first_line(e), self.context),
                exit_codes.FAULT,
            )
        print(
            "database back after %.1f s: carrying on with context %s"
            % (time.monotonic() - start, self.context),
            file=sys.stderr,
        )
        return 0

    def close(self):
        if self.context_lock is not None:
            self.context_lock.release()
        if self.catalogue is not None:
            try:
                self.catalogue.close()
            except psycopg2.Error:
                pass
        if self.rig_lock is not None:
            self.rig_lock.release()


def make_rig(cfg, stop=None) -> Rig:
    """The rig over ROS: every wait's deadline from `cfg`'s timings; `stop` (Ctrl-C) ends a
    wait already under way, while a wait begun after it (parking) runs to its deadline."""
    from rascal_tasks.ros_rig import (
        RosArchivalCamera,
        RosArm,
        RosClock,
        RosGripper,
        RosPerception,
        RosScale,
    )

    clock = RosClock(stop=stop)
    return Rig(
        arm=RosArm(config=cfg, stop=stop),
        gripper=RosGripper(config=cfg, stop=stop),
        perception=RosPerception(config=cfg, stop=stop),
        scale=RosScale(clock, config=cfg, stop=stop),
        camera=RosArchivalCamera(config=cfg, stop=stop),
        clock=clock,
    )


# What a person is told of the sherds not seen again (batch.NotSeenAgain), by kind: the count's
# phrase in the closing line, and each one's own line.
NOT_SEEN_AGAIN = {
    SLIPPED_AWAY: (
        "slipped out of the fingers while lifted and not seen again (it may lie beside the "
        "mat: if every sherd of the bag is recorded, it was found again)",
        "slipped out of the fingers while lifted at (%.3f, %.3f) m, not seen again",
    ),
    PUSHED_OFF: (
        "seen near the mat's edge, not picked up and not seen again (a grasp beside it may "
        "have pushed it off the mat, or it came up with another sherd)",
        "seen near the mat's edge at (%.3f, %.3f) m, not picked up, not seen again: look "
        "beside the mat; if it is not there, it may have come up with a sherd recorded after "
        "it was seen (that row would then weigh both)",
    ),
}


def what_is_left(batch, rows) -> str:
    """What a person must see to after a finished batch ('' when the bag is complete): sherds
    left on the mat, objects on it perception does not offer as sherds, rows of the context
    lost, without a mass (the scale gave none that could be trusted: mass_unstable, or done with
    mass_missing_reason) or unfinished, rows weighed with a second sherd seen on the scale
    (stations.LOOK_PUT_BACKS), rows that may be two lying as one (stations.ScaleStation.
    _maybe_two), rows photographed over the scale with another sherd on its pan and sherds left
    on the pan (ScaleStation._left_on_pan)."""
    rows = rows or []
    counts = (
        (len(batch.unpickable), "left on the pickup mat (could not be picked up)"),
        *((len(batch.not_seen(kind)), what) for kind, (what, _) in NOT_SEEN_AGAIN.items()),
        (sum(r["status"] == "lost" for r in rows), "recorded lost"),
        (
            sum(r["status"] not in ("lost", "picked") and r.get("mass_g") is None for r in rows),
            "unweighed (no steady scale reading)",
        ),
        (sum(r["status"] not in ("done", "lost") for r in rows), "unfinished"),
        (len(batch.two_seen), "recorded with a second sherd seen on the scale (`two_seen`)"),
        (len(batch.maybe_two), "recorded as one that may be two lying as one (`maybe_two`)"),
        (
            len(batch.photo_with_another),
            "photographed with another sherd on the scale's pan (`photo_with_another`)",
        ),
        (
            len(batch.left_on_station),
            "left on the scale (came up with another, not taken off there: listed above)",
        ),
    )
    parts = ["%d sherd%s %s" % (n, "" if n == 1 else "s", what) for n, what in counts if n]
    if batch.leftovers:  # perhaps not sherds at all: a chip, a pebble, a label
        n = len(batch.leftovers)
        parts.insert(
            1,
            "%d object%s on the pickup mat not taken as sherds (too small or too large: "
            "listed above)" % (n, "" if n == 1 else "s"),
        )
    return ", ".join(parts)


def print_summary(batches, rows, outcome, wall_seconds):
    first = batches[0]
    completed = sum(b.completed for b in batches)
    lost = sum(b.lost for b in batches)
    sim = first.rig.clock.now() - first.started
    n = completed + lost
    print(
        "batch %s: %s — %d recorded, %d lost, %.1f s (%s), wall %.1f s%s"
        % (
            first.context,
            outcome,
            completed,
            lost,
            sim,
            "%.1f s/sherd" % (sim / n) if n else "no sherds",
            wall_seconds,
            " (%d database outages)" % (len(batches) - 1) if len(batches) > 1 else "",
        )
    )
    for x, y in batches[-1].unpickable:
        print("left in the pickup area (could not be picked up): sherd at (%.3f, %.3f) m" % (x, y))
    for station, kg, seq in batches[-1].left_on_station:
        print(
            "left on the %s (came up with sherd %s, not taken off there): %.1f g; take it to the "
            "pickup mat" % (station, seq, kg * 1000)
        )
    for lo in batches[-1].leftovers:
        print(describe_leftover(lo))
    for u in batches[-1].not_seen_again:
        print(NOT_SEEN_AGAIN[u.kind][1] % (u.x, u.y))
    state_times = {}
    for b in batches:
        for k, v in b.state_times.items():
            state_times[k] = state_times.get(k, 0.0) + v
    if state_times:
        print(
            "time per state (s): "
            + ", ".join("%s %.1f" % kv for kv in sorted(state_times.items(), key=lambda kv: -kv[1]))
        )
    if rows is None:
        print("(the catalogue could not be read for the table)")
        return
    print(
        "%4s  %-13s %9s %9s %9s %9s %6s  %s"
        % ("seq", "status", "mass g", "length mm", "width mm", "thick mm", "drops", "image")
    )
    for r in rows:
        print(
            "%4d  %-13s %9s %9s %9s %9s %6d  %s"
            % (
                r["seq"],
                r["status"],
                _f(r.get("mass_g")),
                _f(r.get("length_mm")),
                _f(r.get("width_mm")),
                _f(r.get("thickness_mm")),
                r.get("drops") or 0,
                r.get("image_path") or r.get("lost_reason") or "",
            )
        )


def _f(v):
    return "–" if v is None else "%.1f" % v
