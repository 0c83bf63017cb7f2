"""UserData, Remapper and Const behaviour of the SMACH-compatible core."""

import copy

import pytest
from smach_helpers import Getter, Returns

from rascal_tasks import smach

pytestmark = pytest.mark.timeout(30)


class Thing:
    def __init__(self):
        self.a = 1


def test_userdata_attribute_and_item_access_share_storage(logs):
    ud = smach.UserData()
    ud.a = 1
    ud["b"] = 2
    assert ud["a"] == 1 and ud.b == 2
    assert sorted(ud.keys()) == ["a", "b"] and "a" in ud and "z" not in ud
    assert ud._data == {"a": 1, "b": 2}


def test_userdata_missing_key_raises_key_error_even_for_getattr_default(logs):
    ud = smach.UserData()
    with pytest.raises(KeyError):
        _ = ud.missing
    with pytest.raises(KeyError):
        getattr(ud, "missing", None)  # smach raises here too, not AttributeError


def test_userdata_update_lets_the_other_win(logs):
    a, b = smach.UserData(), smach.UserData()
    a.k, a.only_a = 1, "a"
    b.k = 2
    a.update(b)
    assert a.k == 2 and a.only_a == "a"


def test_userdata_deepcopies_after_attribute_access(logs):
    ud = smach.UserData()
    ud.items = [1, 2]
    clone = copy.deepcopy(ud)
    clone.items.append(3)
    assert ud.items == [1, 2] and clone.items == [1, 2, 3]


def test_remapper_refuses_to_read_an_undeclared_key(logs):
    ud = smach.UserData()
    ud.secret = 1
    r = smach.Remapper(ud, input_keys=["a"], output_keys=["secret"])
    with pytest.raises(smach.InvalidUserCodeError, match="'secret'"):
        _ = r.secret  # output-only keys cannot be read either


def test_remapper_ignores_and_logs_an_undeclared_write(logs):
    ud = smach.UserData()
    r = smach.Remapper(ud, input_keys=["a"], output_keys=[])
    r.a = 5
    assert "a" not in ud
    assert any("'a'" in m for m in logs.lines("error"))


def test_remapper_contains_and_keys_use_local_names(logs):
    ud = smach.UserData()
    ud.container_key = 1
    r = smach.Remapper(ud, ["local"], ["out"], {"local": "container_key", "out": "o"})
    assert "local" in r and "out" not in r
    assert r.keys() == ["local"]
    assert r.local == 1


def test_remapper_accepts_a_list_as_empty_remapping(logs):
    ud = smach.UserData()
    ud.k = 3
    r = smach.Remapper(ud, ["k"], ["k"], [])  # smach_ros passes []
    assert r.k == 3


def test_input_only_object_is_read_only_but_lists_are_not_wrapped(logs):
    ud = smach.UserData()
    ud.obj = Thing()
    ud.lst = [1]
    r = smach.Remapper(ud, ["obj", "lst"], [])
    with pytest.raises(TypeError, match="input-only"):
        r.obj.a = 2
    assert ud.obj.a == 1 and r.obj.a == 1
    r.lst.append(2)  # as upstream: lists (and ROS messages, __slots__) are not wrapped
    assert ud.lst == [1, 2]
    io = smach.Remapper(ud, ["obj"], ["obj"])
    io.obj.a = 3
    assert ud.obj.a == 3


def test_declared_but_missing_key_surfaces_as_invalid_user_code(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("GET", Getter("never_set"))
    with pytest.raises(smach.InvalidUserCodeError, match="never_set"):
        sm.execute()


def test_io_keys_are_both_readable_and_writable(logs):
    class Inc(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done"], io_keys=["n"])

        def execute(self, ud):
            ud.n = ud.n + 1
            return "done"

    sm = smach.StateMachine(outcomes=["done"])
    sm.userdata.n = 1
    with sm:
        smach.StateMachine.add("INC", Inc())
    assert sm.execute() == "done"
    assert sm.userdata.n == 2


def test_top_level_execute_with_parent_userdata_copies_io(logs):
    parent = smach.UserData()
    parent.a = "from parent"
    getter = Getter("a")
    sm = smach.StateMachine(outcomes=["done"], input_keys=["a"], output_keys=["a"])
    with sm:
        smach.StateMachine.add("GET", getter)
    assert sm.execute(parent) == "done"
    assert getter.seen == ["from parent"]
    assert Returns().get_registered_outcomes() == ("done",)
