"""Concurrence behaviour of the SMACH-compatible core (2.5.2 semantics, hangs fixed)."""

import threading

import pytest
from smach_helpers import Raises, Returns, Setter, Waiter

from rascal_tasks import smach

pytestmark = pytest.mark.timeout(30)


class Meet(smach.State):
    """Waits at a barrier: only passes if its siblings really run at the same time."""

    def __init__(self, barrier, outcome="done"):
        smach.State.__init__(self, outcomes=["done", "failed"])
        self.barrier, self.outcome = barrier, outcome

    def execute(self, ud):
        self.barrier.wait(5.0)
        return self.outcome


def concurrence(children, **kw):
    kw.setdefault("outcomes", ["succeeded", "aborted", "stopped"])
    kw.setdefault("default_outcome", "aborted")
    cc = smach.Concurrence(**kw)
    with cc:
        for label, state in children.items():
            smach.Concurrence.add(label, state)
    return cc


def test_children_run_at_the_same_time_and_default_outcome_applies(logs):
    barrier = threading.Barrier(2)
    cc = concurrence({"A": Meet(barrier), "B": Meet(barrier)})
    assert cc.execute() == "aborted"
    assert not barrier.broken


def test_outcome_map_most_specific_entry_wins(logs):
    cc = concurrence(
        {"A": Returns("done", ("done", "failed")), "B": Returns("failed", ("done", "failed"))},
        outcome_map={"stopped": {"B": "failed"}, "succeeded": {"A": "done", "B": "failed"}},
    )
    assert cc.execute() == "succeeded"


def test_outcome_map_tie_goes_to_the_first_entry(logs):
    cc = concurrence(
        {"A": Returns(), "B": Returns()},
        outcome_map={"stopped": {"A": "done"}, "succeeded": {"B": "done"}},
    )
    assert cc.execute() == "stopped"


def test_outcome_map_unsatisfied_keeps_default(logs):
    cc = concurrence({"A": Returns()}, outcome_map={"succeeded": {"A": "failed"}})
    assert cc.execute() == "aborted"


def test_outcome_cb_overrides_outcome_map_and_gets_child_outcomes(logs):
    seen = []

    def cb(outcomes):
        seen.append(dict(outcomes))
        return "stopped"

    cc = concurrence(
        {"A": Returns(), "B": Returns()}, outcome_map={"succeeded": {"A": "done"}}, outcome_cb=cb
    )
    assert cc.execute() == "stopped"
    assert seen == [{"A": "done", "B": "done"}]


@pytest.mark.parametrize("returned", [None, 42])
def test_outcome_cb_without_a_string_keeps_the_current_choice(logs, returned):
    cc = concurrence(
        {"A": Returns()}, outcome_map={"succeeded": {"A": "done"}}, outcome_cb=lambda o: returned
    )
    assert cc.execute() == "succeeded"


def test_outcome_cb_exception_raises_invalid_user_code(logs):
    def cb(outcomes):
        raise KeyError("oops")

    cc = concurrence({"A": Returns()}, outcome_cb=cb)
    with pytest.raises(smach.InvalidUserCodeError, match="outcome callback"):
        cc.execute()


def test_child_termination_cb_true_preempts_running_siblings(logs):
    slow = Waiter(service=True, timeout=10.0)
    cc = concurrence(
        {"FAST": Returns(), "SLOW": slow},
        child_termination_cb=lambda outcomes: outcomes["FAST"] == "done",
        outcome_map={"succeeded": {"FAST": "done", "SLOW": "preempted"}},
    )
    assert cc.execute() == "succeeded"
    assert slow.saw_preempt


def test_child_termination_cb_false_waits_for_every_child(logs):
    calls = []
    slow = Waiter(service=True, timeout=0.3)

    def cb(outcomes):
        calls.append(dict(outcomes))
        return False

    cc = concurrence(
        {"FAST": Returns(), "SLOW": slow},
        child_termination_cb=cb,
        outcome_map={"succeeded": {"FAST": "done", "SLOW": "done"}},
    )
    assert cc.execute() == "succeeded"
    assert not slow.saw_preempt
    assert calls[-1] == {"FAST": "done", "SLOW": "done"} and len(calls) == 2


def test_child_exception_raises_invalid_state_and_preempts_siblings(logs):
    slow = Waiter(service=True, timeout=10.0)
    cc = concurrence({"BAD": Raises(ValueError("camera gone")), "SLOW": slow})
    with pytest.raises(smach.InvalidStateError, match="camera gone"):
        cc.execute()
    assert slow.saw_preempt


def test_child_exception_inside_a_machine_is_invalid_user_code(logs):
    cc = concurrence({"BAD": Raises()})
    sm = smach.StateMachine(outcomes=["succeeded", "aborted", "stopped"])
    with sm:
        smach.StateMachine.add("CC", cc)
    with pytest.raises(smach.InvalidUserCodeError):
        sm.execute()


def test_child_returning_none_fails_instead_of_hanging(logs):
    slow = Waiter(service=True, timeout=10.0)
    cc = concurrence({"NONE": Returns(None), "SLOW": slow})
    with pytest.raises(smach.InvalidStateError, match="returned None"):
        cc.execute()
    assert slow.saw_preempt


def test_child_termination_cb_exception_fails_instead_of_hanging(logs):
    def cb(outcomes):
        raise RuntimeError("cb broke")

    cc = concurrence(
        {"A": Returns(), "SLOW": Waiter(service=True, timeout=10.0)}, child_termination_cb=cb
    )
    with pytest.raises(smach.InvalidUserCodeError, match="cb broke"):
        cc.execute()


def test_empty_concurrence_raises(logs):
    cc = smach.Concurrence(outcomes=["done"], default_outcome="done")
    with pytest.raises(smach.InvalidStateError, match="No states"):
        cc.execute()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"default_outcome": "not_registered"},
        {"default_outcome": None},
        {"default_outcome": "done", "outcome_map": {"unknown": {"A": "done"}}},
        {"default_outcome": "done", "outcome_cb": "not callable"},
        {"default_outcome": "done", "child_termination_cb": 3},
    ],
)
def test_constructor_rejects_bad_policies(logs, kwargs):
    with pytest.raises(smach.InvalidStateError):
        smach.Concurrence(outcomes=["done"], **kwargs)


def test_children_share_the_concurrence_userdata(logs):
    class Wait4(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done"], input_keys=["x"])
            self.seen = None

        def execute(self, ud):
            for _ in range(500):
                if "x" in ud:
                    self.seen = ud.x
                    break
                threading.Event().wait(0.005)
            return "done"

    reader = Wait4()
    cc = concurrence({"W": Setter("x", "shared"), "R": reader}, output_keys=["x"])
    parent = smach.UserData()
    cc.execute(parent)
    assert reader.seen == "shared"
    assert parent.x == "shared"


def test_preempt_serviced_by_all_children_uses_outcome_selection(logs):
    a, b = Waiter(service=True), Waiter(service=True)
    cc = concurrence(
        {"A": a, "B": b}, outcome_map={"stopped": {"A": "preempted", "B": "preempted"}}
    )
    threading.Thread(
        target=lambda: (a.started.wait(5), b.started.wait(5), cc.request_preempt()), daemon=True
    ).start()
    assert cc.execute() == "stopped"  # 2.5.2: map/default, not the literal 'preempted'
    assert not cc.preempt_requested()


def test_preempt_not_serviced_by_a_child_is_recalled_and_stays_set(logs):
    a, b = Waiter(service=True), Waiter(service=False)
    cc = concurrence({"A": a, "B": b})
    threading.Thread(
        target=lambda: (a.started.wait(5), b.started.wait(5), cc.request_preempt()), daemon=True
    ).start()
    assert cc.execute() == "aborted"
    assert cc.preempt_requested()
    assert not b.preempt_requested()  # recalled
    assert any("did not service" in m for m in logs.lines("warn"))


def test_callbacks_signatures_and_two_transition_calls_per_child(logs):
    calls = []
    lock = threading.Lock()

    def record(*item):
        with lock:
            calls.append(item)

    cc = concurrence({"A": Returns(), "B": Returns()})
    cc.register_start_cb(lambda ud, init: record("start", sorted(init)))
    cc.register_transition_cb(lambda ud, active: record("transition"))
    cc.register_termination_cb(lambda ud, term, out: record("term", sorted(term), out))
    cc.execute()
    assert calls[0] == ("start", ["A", "B"])
    assert calls[-1] == ("term", ["A", "B"], "aborted")
    assert calls.count(("transition",)) == 4


def test_introspection_of_concurrence(logs):
    cc = concurrence(
        {"A": Returns(), "B": Returns()}, outcome_map={"succeeded": {"A": "done", "B": "done"}}
    )
    assert sorted(cc.get_initial_states()) == ["A", "B"]
    assert cc.get_active_states() == []
    assert sorted(cc.get_internal_edges()) == [
        ("done", "A", "succeeded"),
        ("done", "B", "succeeded"),
    ]
    ud = smach.UserData()
    ud.k = 1
    cc.set_initial_state(["A"], ud)  # upstream raises TypeError on Python 3
    assert cc.userdata.k == 1
    with pytest.raises(KeyError):
        cc["C"]


def test_concurrence_nested_in_machine_routes_its_outcome(logs):
    cc = concurrence({"A": Returns()}, outcome_map={"succeeded": {"A": "done"}})
    after = Returns()
    sm = smach.StateMachine(outcomes=["end", "failed"])
    with sm:
        smach.StateMachine.add(
            "CC", cc, transitions={"succeeded": "AFTER", "aborted": "failed", "stopped": "failed"}
        )
        smach.StateMachine.add("AFTER", after, transitions={"done": "end"})
    assert sm.execute() == "end"
    assert after.runs == 1
