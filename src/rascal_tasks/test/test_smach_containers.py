"""Sequence, Iterator and CBState behaviour of the SMACH-compatible core."""

import threading

import pytest
from smach_helpers import Raises, Returns, Waiter

from rascal_tasks import smach

pytestmark = pytest.mark.timeout(30)


def test_sequence_links_states_in_order_and_last_falls_through(logs):
    order = []
    seq = smach.Sequence(outcomes=["done", "failed"], connector_outcome="done")
    with seq:
        for name in "ABC":
            smach.Sequence.add(name, Returns("done", ("done", "failed"), order, name))
    assert seq.execute() == "done"
    assert order == ["A", "B", "C"]
    assert ("done", "A", "B") in seq.get_internal_edges()


def test_sequence_explicit_transition_overrides_the_link(logs):
    order = []
    seq = smach.Sequence(outcomes=["done", "skipped"], connector_outcome="done")
    with seq:
        smach.Sequence.add("A", Returns("done", ("done",), order, "A"), transitions={"done": "C"})
        smach.Sequence.add("B", Returns("done", ("done",), order, "B"))
        smach.Sequence.add("C", Returns("done", ("done",), order, "C"))
    assert seq.execute() == "done"
    assert order == ["A", "C"]


def test_sequence_exception_stops_later_states(logs):
    later = Returns()
    seq = smach.Sequence(outcomes=["done"], connector_outcome="done")
    with seq:
        smach.Sequence.add("BAD", Raises())
        smach.Sequence.add("LATER", later)
    with pytest.raises(smach.InvalidUserCodeError):
        seq.execute()
    assert later.runs == 0 and not seq.is_running()


def test_sequence_has_no_constants_argument(logs):
    seq = smach.Sequence(outcomes=["done"], connector_outcome="done")
    with pytest.raises(TypeError):
        with seq:
            smach.Sequence.add("A", Returns(), constants={"k": 1})


class Collect(smach.State):
    def __init__(self, stop_at=None):
        smach.State.__init__(
            self, outcomes=["next", "stop"], input_keys=["item"], output_keys=["got"]
        )
        self.stop_at = stop_at

    def execute(self, ud):
        got = ud.got if "got" in ud else []
        ud.got = got + [ud.item]
        return "stop" if ud.item == self.stop_at else "next"


def make_iterator(items, stop_at=None, **kw):
    it = smach.Iterator(
        outcomes=["stopped"],
        input_keys=[],
        output_keys=["got"],
        it=items,
        it_label="item",
        exhausted_outcome="all_done",
    )
    with it:
        smach.Iterator.set_contained_state("COLLECT", Collect(stop_at), **kw)
    return it


def test_iterator_runs_once_per_item_then_exhausted(logs):
    it = make_iterator([1, 2, 3], loop_outcomes=["next"])
    parent = smach.UserData()
    assert it.execute(parent) == "all_done"
    assert parent.got == [1, 2, 3]
    assert "all_done" in it.get_registered_outcomes()


def test_iterator_break_outcome_ends_loop_with_mapped_outcome(logs):
    it = make_iterator(
        [1, 2, 3], stop_at=2, break_outcomes=["stop"], final_outcome_map={"stop": "stopped"}
    )
    parent = smach.UserData()
    assert it.execute(parent) == "stopped"
    assert parent.got == [1, 2]


def test_iterator_callable_items_are_fresh_each_execution(logs):
    calls = []

    def items():
        calls.append(1)
        return iter([len(calls)])

    it = make_iterator(items, loop_outcomes=["next"])
    it.userdata.got = []
    it.execute(smach.UserData())
    it.execute(smach.UserData())
    assert it.userdata.got == [1, 2]


def test_iterator_preempt_breaks_the_loop_and_is_serviced(logs):
    started = threading.Event()
    waiter = Waiter(service=True, started=started)
    it = smach.Iterator(outcomes=[], input_keys=[], output_keys=[], it=range(100))
    with it:
        smach.Iterator.set_contained_state("WAIT", waiter, loop_outcomes=["done", "preempted"])
    threading.Thread(target=lambda: (started.wait(5), it.request_preempt()), daemon=True).start()
    assert it.execute(smach.UserData()) == "preempted"
    assert not it.preempt_requested()


def test_iterator_termination_cb_gets_the_label_string(logs):
    got = []
    it = make_iterator([1], loop_outcomes=["next"])
    it.register_termination_cb(lambda ud, label, outcome: got.append((label, outcome)))
    it.execute(smach.UserData())
    assert got == [("COLLECT", "all_done")]


def test_cbstate_passes_args_and_merges_cb_interface(logs):
    @smach.cb_interface(outcomes=["odd", "even"], input_keys=["n"], output_keys=["half"])
    def classify(ud, divisor, label=""):
        ud.half = ud.n / divisor
        return "even" if ud.n % 2 == 0 else "odd"

    state = smach.CBState(classify, cb_args=[2], cb_kwargs={"label": "x"}, outcomes=["extra"])
    assert set(state.get_registered_outcomes()) == {"odd", "even", "extra"}
    sm = smach.StateMachine(outcomes=["odd", "even", "extra"])
    sm.userdata.n = 4
    with sm:
        smach.StateMachine.add("C", state)
    assert sm.execute() == "even"
    assert sm.userdata.half == 2


def test_cb_interface_io_keys_are_honoured(logs):
    wrapped = smach.CBInterface(lambda ud: "done", outcomes=["done"], io_keys=["k"])
    assert wrapped.get_registered_input_keys() == ("k",)
    assert wrapped.get_registered_output_keys() == ("k",)
    assert smach.has_smach_interface(wrapped) and not smach.has_smach_interface(len)
