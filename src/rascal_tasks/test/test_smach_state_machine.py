"""StateMachine behaviour of the SMACH-compatible core (no ROS master)."""

import pickle
import threading

import pytest
from smach_helpers import Getter, Raises, Returns, Setter, Waiter

from rascal_tasks import smach

pytestmark = pytest.mark.timeout(30)


def test_public_names_and_module_layout_match_smach():
    for name in [
        "CBInterface",
        "CBState",
        "Concurrence",
        "Container",
        "InvalidConstructionError",
        "InvalidStateError",
        "InvalidTransitionError",
        "InvalidUserCodeError",
        "Iterator",
        "Remapper",
        "Sequence",
        "State",
        "StateMachine",
        "UserData",
        "cb_interface",
        "has_smach_interface",
        "is_shutdown",
        "set_shutdown_check",
        "set_loggers",
        "loginfo",
        "logwarn",
        "logerr",
        "logdebug",
    ]:
        assert hasattr(smach, name), name
    assert smach.container.Container is smach.Container
    assert smach.state_machine.StateMachine is smach.StateMachine
    assert smach.state.__all__ == ["State", "CBState"]
    assert issubclass(smach.Sequence, smach.StateMachine)
    assert not hasattr(smach, "SmachError")
    for exc in (
        smach.InvalidStateError,
        smach.InvalidTransitionError,
        smach.InvalidUserCodeError,
        smach.InvalidConstructionError,
    ):
        assert issubclass(exc, smach.exceptions.SmachError)


def test_userdata_flows_from_output_to_next_input(logs):
    sm = smach.StateMachine(outcomes=["end"])
    getter = Getter("x")
    with sm:
        smach.StateMachine.add("SET", Setter("x", 42), transitions={"done": "GET"})
        smach.StateMachine.add("GET", getter, transitions={"done": "end"})
    assert sm.execute() == "end"
    assert getter.seen == [42]
    assert sm.userdata.x == 42


def test_remapping_maps_local_names_to_container_keys(logs):
    sm = smach.StateMachine(outcomes=["end"])
    getter = Getter("inp")
    with sm:
        smach.StateMachine.add(
            "SET", Setter("out", "v"), transitions={"done": "GET"}, remapping={"out": "shared"}
        )
        smach.StateMachine.add(
            "GET", getter, transitions={"done": "end"}, remapping={"inp": "shared"}
        )
    assert sm.execute() == "end"
    assert getter.seen == ["v"]
    assert sm.userdata.keys() == ["shared"]


def test_transitions_follow_the_returned_outcome(logs):
    order = []
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add(
            "A", Returns("right", ("left", "right")), transitions={"left": "L", "right": "R"}
        )
        smach.StateMachine.add("L", Returns(log=order, name="L"), transitions={"done": "end"})
        smach.StateMachine.add("R", Returns(log=order, name="R"), transitions={"done": "end"})
    assert sm.execute() == "end"
    assert order == ["R"]


def test_outcome_without_transition_falls_through_as_machine_outcome(logs):
    sm = smach.StateMachine(outcomes=["done", "other"])
    with sm:
        smach.StateMachine.add("A", Returns("done"))
    assert sm.execute() == "done"


def test_target_that_is_both_label_and_outcome_goes_to_the_state(logs):
    b = Returns("done")
    sm = smach.StateMachine(outcomes=["B", "done"])
    with sm:
        smach.StateMachine.add("A", Returns("next", ("next",)), transitions={"next": "B"})
        smach.StateMachine.add("B", b)
    assert sm.execute() == "done"
    assert b.runs == 1


@pytest.mark.parametrize("bad", ["nope", None])
def test_unregistered_outcome_at_run_time_raises_invalid_transition(logs, bad):
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Returns(bad, ("done",)))
    with pytest.raises(smach.InvalidTransitionError, match="registered outcomes"):
        sm.execute()
    assert not sm.is_running()


def test_add_with_transition_for_unknown_outcome_raises(logs):
    sm = smach.StateMachine(outcomes=["end"])
    with pytest.raises(smach.InvalidTransitionError, match="'oops'"):
        with sm:
            smach.StateMachine.add("A", Returns(), transitions={"oops": "end"})


def test_duplicate_label_raises_invalid_state(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(smach.InvalidStateError, match="'A'"):
        with sm:
            smach.StateMachine.add("A", Returns())
            smach.StateMachine.add("A", Returns())


def test_exception_in_execute_becomes_invalid_user_code_error(logs):
    parent = smach.UserData()
    sm = smach.StateMachine(outcomes=["done"], output_keys=["x"])
    with sm:
        smach.StateMachine.add(
            "SET", Setter("x", 1, outcome="next", outcomes=("next",)), transitions={"next": "BAD"}
        )
        smach.StateMachine.add("BAD", Raises(ValueError("sherd fell")))
    with pytest.raises(smach.InvalidUserCodeError) as err:
        sm.execute(parent)
    assert "'BAD'" in str(err.value) and "sherd fell" in str(err.value)
    assert not sm.is_running()
    assert "x" not in parent  # outputs are not copied after an error


def test_invalid_user_code_error_from_child_propagates_unchanged(logs):
    original = smach.InvalidUserCodeError("mine")
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Raises(original))
    with pytest.raises(smach.InvalidUserCodeError) as err:
        sm.execute()
    assert err.value is original


def test_transition_to_unknown_label_fails_consistency_and_returns_none(logs):
    a = Returns("done")
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("A", a, transitions={"done": "MISSING"})
    assert sm.execute() is None
    assert a.runs == 0
    assert any("consistency" in m for m in logs.lines("error"))


def test_unmapped_outcome_that_is_not_a_machine_outcome_returns_none(logs):
    a = Returns("done", ("done", "failed"))
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", a)
    assert sm.execute() is None
    assert a.runs == 0


def test_empty_machine_returns_none(logs):
    assert smach.StateMachine(outcomes=["done"]).execute() is None


def test_first_state_is_initial_and_set_initial_state_overrides(logs):
    order = []
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Returns(log=order, name="A"), transitions={"done": "B"})
        smach.StateMachine.add("B", Returns(log=order, name="B"))
    assert sm.get_initial_states() == ["A"]
    ud = smach.UserData()
    ud.injected = 7
    sm.set_initial_state(["B"], ud)
    assert sm.execute() == "done"
    assert order == ["B"]
    assert sm.userdata.injected == 7


def test_nested_machine_copies_declared_keys_only(logs):
    inner = smach.StateMachine(outcomes=["done"], input_keys=["a"], output_keys=["b"])
    inner_getter = Getter("a")
    with inner:
        smach.StateMachine.add("GET", inner_getter, transitions={"done": "SETB"})
        smach.StateMachine.add("SETB", Setter("b", "out"), transitions={"done": "SETC"})
        smach.StateMachine.add("SETC", Setter("c", "private"))
    outer = smach.StateMachine(outcomes=["done"])
    outer.userdata.a = "in"
    with outer:
        smach.StateMachine.add("INNER", inner)
    assert outer.execute() == "done"
    assert inner_getter.seen == ["in"]
    assert outer.userdata.b == "out"
    assert "c" not in outer.userdata and inner.userdata.c == "private"


def test_add_auto_connects_and_overrides_explicit_transition(logs):
    order = []
    sm = smach.StateMachine(outcomes=["done", "elsewhere"])
    with sm:
        smach.StateMachine.add_auto(
            "A", Returns("ok", ("ok",), order, "A"), ["ok"], transitions={"ok": "elsewhere"}
        )
        smach.StateMachine.add("B", Returns(log=order, name="B"))
    assert sm.execute() == "done"
    assert order == ["A", "B"]


def test_add_auto_with_unknown_connector_raises(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(smach.InvalidStateError, match="auto-connect"):
        with sm:
            smach.StateMachine.add_auto("A", Returns(), ["nope"])


def test_add_without_an_open_container_raises(logs):
    with pytest.raises(smach.InvalidStateError, match="no container"):
        smach.StateMachine.add("A", Returns())


def test_with_binds_none_and_opened_yields_the_container(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with sm as bound:
        assert bound is None
        smach.StateMachine.add("A", Returns())
    sm2 = smach.StateMachine(outcomes=["done"])
    with sm2.opened() as bound2:
        assert bound2 is sm2
        sm2.add("A", Returns())
    assert sm2.execute() == "done"


def test_exception_in_with_block_releases_the_construction_lock(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(RuntimeError):
        with sm:
            raise RuntimeError("typo in construction")
    assert not sm.is_opened()
    built = threading.Event()

    def other_thread():
        other = smach.StateMachine(outcomes=["done"])
        with other:
            smach.StateMachine.add("A", Returns())
        built.set()

    t = threading.Thread(target=other_thread, daemon=True)
    t.start()
    t.join(5.0)
    assert built.is_set(), "another thread blocked opening a container (upstream deadlock)"


def test_callbacks_receive_documented_arguments_in_order(logs):
    calls = []
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("A", Returns(), transitions={"done": "B"})
        smach.StateMachine.add("B", Returns(), transitions={"done": "end"})
    sm.register_start_cb(lambda ud, init, tag: calls.append(("start", init, tag)), ["s"])
    sm.register_transition_cb(lambda ud, active: calls.append(("transition", active)))
    sm.register_termination_cb(lambda ud, term, out: calls.append(("term", term, out)))
    assert sm.execute() == "end"
    assert calls == [("start", ["A"], "s"), ("transition", ["B"]), ("term", ["B"], "end")]


def test_failing_callback_is_logged_and_skips_the_rest_of_its_list(logs):
    calls = []

    def bad(ud, init):
        raise RuntimeError("cb failed")

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Returns())
    sm.register_start_cb(bad)
    sm.register_start_cb(lambda ud, init: calls.append("second start"))
    sm.register_termination_cb(lambda ud, t, o: calls.append("term"))
    assert sm.execute() == "done"
    assert calls == ["term"]
    assert any("cb failed" in m for m in logs.lines("error"))


def test_active_states_and_internal_edges(logs):
    seen = []

    class Peek(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done"])

        def execute(self, ud):
            seen.append((sm.get_active_states(), sm.is_running()))
            return "done"

    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("P", Peek(), transitions={"done": "end"})
    assert sm.get_active_states() == ["None"]
    assert sm.execute() == "end"
    assert seen == [(["P"], True)]
    assert sm.get_active_states() == ["None"] and not sm.is_running()
    assert sm.get_internal_edges() == [("done", "P", "end")]
    assert sm["P"] is sm.get_children()["P"]
    with pytest.raises(KeyError):
        sm["missing"]


def test_serviced_preempt_ends_machine_and_clears_flag(logs):
    waiter = Waiter(service=True)
    after = Returns()
    sm = smach.StateMachine(outcomes=["preempted", "end"])
    with sm:
        smach.StateMachine.add("WAIT", waiter, transitions={"done": "AFTER"})
        smach.StateMachine.add("AFTER", after, transitions={"done": "end"})
    threading.Thread(
        target=lambda: (waiter.started.wait(5), sm.request_preempt()), daemon=True
    ).start()
    assert sm.execute() == "preempted"
    assert after.runs == 0
    assert not sm.preempt_requested()


def test_serviced_preempt_with_transition_to_a_state_carries_on(logs):
    waiter = Waiter(service=True)
    after = Returns()
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("WAIT", waiter, transitions={"done": "end", "preempted": "AFTER"})
        smach.StateMachine.add("AFTER", after, transitions={"done": "end"})
    threading.Thread(
        target=lambda: (waiter.started.wait(5), sm.request_preempt()), daemon=True
    ).start()
    assert sm.execute() == "end"
    assert after.runs == 1
    assert not after.preempt_requested() and not sm.preempt_requested()


def test_unserviced_preempt_preempts_next_state_and_stays_set(logs):
    waiter = Waiter(service=False)
    nxt = Waiter(service=True, timeout=0.5)
    sm = smach.StateMachine(outcomes=["end", "preempted"])
    with sm:
        smach.StateMachine.add("WAIT", waiter, transitions={"done": "NEXT"})
        smach.StateMachine.add("NEXT", nxt, transitions={"done": "end"})
    threading.Thread(
        target=lambda: (waiter.started.wait(5), sm.request_preempt()), daemon=True
    ).start()
    assert sm.execute() == "preempted"
    assert waiter.saw_preempt and nxt.saw_preempt


def test_preempt_requested_before_execute_preempts_initial_state_and_is_sticky(logs):
    first = Waiter(service=False, timeout=0.2)
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    with sm:
        smach.StateMachine.add("A", first)
    sm.request_preempt()
    assert sm.execute() == "done"
    assert first.saw_preempt
    assert sm.preempt_requested()  # nobody serviced it: sticky, as in smach
    first.saw_preempt = False
    first.recall_preempt()
    assert sm.execute() == "done"
    assert first.saw_preempt


def test_request_preempt_from_own_callback_does_not_deadlock(logs):
    waiter = Waiter(service=True, timeout=3.0)
    sm = smach.StateMachine(outcomes=["end", "preempted"])
    with sm:
        smach.StateMachine.add("A", Returns(), transitions={"done": "WAIT"})
        smach.StateMachine.add("WAIT", waiter, transitions={"done": "end"})
    sm.register_transition_cb(lambda ud, active: sm.request_preempt())
    result = []
    t = threading.Thread(target=lambda: result.append(sm.execute()), daemon=True)
    t.start()
    t.join(10.0)
    assert result == ["preempted"], "request_preempt from a callback deadlocked (upstream bug)"


def test_preempt_propagates_into_nested_machine(logs):
    waiter = Waiter(service=True)
    inner = smach.StateMachine(outcomes=["preempted", "done"])
    with inner:
        smach.StateMachine.add("WAIT", waiter)
    outer = smach.StateMachine(outcomes=["stopped", "done"])
    with outer:
        smach.StateMachine.add("INNER", inner, transitions={"preempted": "stopped"})
    threading.Thread(
        target=lambda: (waiter.started.wait(5), outer.request_preempt()), daemon=True
    ).start()
    assert outer.execute() == "stopped"
    assert waiter.saw_preempt
    assert not outer.preempt_requested() and not inner.preempt_requested()


def test_shutdown_check_stops_the_machine_with_none(logs):
    order = []
    flag = []
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("A", Returns(log=order, name="A"), transitions={"done": "B"})
        smach.StateMachine.add("B", Returns(log=order, name="B"), transitions={"done": "end"})
    sm.register_transition_cb(lambda ud, active: flag.append(True))
    smach.set_shutdown_check(lambda: bool(flag))
    assert sm.execute() is None
    assert order == ["A"]


def test_set_loggers_routes_messages_and_errors_log_when_constructed(logs):
    smach.loginfo("hello")
    smach.InvalidStateError("bad state")
    assert "hello" in logs.lines("info")
    assert "InvalidStateError: bad state" in logs.lines("error")


def test_constants_are_written_before_the_state_runs(logs):
    getter = Getter("speed")
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("GET", getter, constants={"speed": 0.5})
    assert sm.execute() == "done"
    assert getter.seen == [0.5]


def test_machine_and_touched_userdata_can_be_pickled(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Setter("x", [1, 2]))
    sm.execute()
    sm.userdata.y = 3  # attribute access made per-key locks upstream (unpicklable)
    clone = pickle.loads(pickle.dumps(sm))
    assert clone.userdata.x == [1, 2] and clone.userdata.y == 3
    assert clone.execute() == "done"


def test_star_import_gives_smachs_names_and_submodules():
    namespace = {}
    exec("from rascal_tasks.smach import *", namespace)
    for name in (
        "StateMachine",
        "Concurrence",
        "UserData",
        "cb_interface",
        "state",
        "user_data",
        "InvalidUserCodeError",
        "set_shutdown_check",
    ):
        assert name in namespace, name
    assert "SmachError" not in namespace


def test_cores_import_without_ros():
    import subprocess

    from catalogue_helpers import PYTHON, subprocess_env

    code = (
        "import sys; import rascal_tasks.smach, rascal_tasks.catalogue, rascal_tasks.cli; "
        'bad = [m for m in sys.modules if m.split(".")[0] in ("rospy", "roslib", "genpy")]; '
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run(
        [PYTHON, "-c", code], capture_output=True, text=True, env=subprocess_env(), timeout=60
    )
    assert r.returncode == 0, r.stdout + r.stderr


def test_preempting_a_machine_preempts_its_running_concurrence(logs):
    a, b = Waiter(service=True), Waiter(service=True)
    cc = smach.Concurrence(
        outcomes=["ok", "stopped"],
        default_outcome="ok",
        outcome_map={"stopped": {"A": "preempted", "B": "preempted"}},
    )
    with cc:
        smach.Concurrence.add("A", a)
        smach.Concurrence.add("B", b)
    sm = smach.StateMachine(outcomes=["ok", "halted"])
    with sm:
        smach.StateMachine.add("CC", cc, transitions={"stopped": "halted"})
    threading.Thread(
        target=lambda: (a.started.wait(5), b.started.wait(5), sm.request_preempt()), daemon=True
    ).start()
    assert sm.execute() == "halted"
    assert a.saw_preempt and b.saw_preempt
    assert not sm.preempt_requested()


def test_iterator_nested_in_machine_reads_parent_keys(logs):
    seen = []

    class Use(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["next"])

        def execute(self, ud):
            seen.append((ud.it_data, ud.factor))
            return "next"

    it = smach.Iterator(
        outcomes=["all_done"],
        input_keys=["factor"],
        output_keys=[],
        it=[1, 2],
        exhausted_outcome="all_done",
    )
    with it:
        smach.Iterator.set_contained_state("USE", Use(), loop_outcomes=["next"])
    sm = smach.StateMachine(outcomes=["all_done"])
    sm.userdata.factor = 3
    with sm:
        smach.StateMachine.add("IT", it)
    assert sm.execute() == "all_done"
    assert seen == [(1, 3), (2, 3)]
