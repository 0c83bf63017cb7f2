"""Userdata: the container-scoped key/value store and the per-state view of it.

``UserData`` keeps smach's observable behaviour (attribute and item access, KeyError for a
missing key, ``_data`` as the storage dict) but guards it with one lock per instance instead
of one lock per key, so a userdata that was touched by attribute can still be pickled or
deep-copied (upstream raises TypeError: cannot pickle '_thread.lock').
"""

import copy
import sys
import threading

__all__ = ["UserData", "Remapper", "Const", "get_const"]


def _smach():
    return sys.modules[__package__]


class UserData:
    """A dict-like store that also allows ``ud.key`` access."""

    def __init__(self):
        object.__setattr__(self, "_data", {})
        object.__setattr__(self, "_lock", threading.RLock())

    # --- pickling / copying: the lock is not state ---
    def __getstate__(self):
        return {"_data": self._data}

    def __setstate__(self, state):
        object.__setattr__(self, "_data", state["_data"])
        object.__setattr__(self, "_lock", threading.RLock())

    # --- dict-like API ---
    def keys(self):
        with self._lock:
            return list(self._data.keys())

    def __contains__(self, key):
        with self._lock:
            return key in self._data

    def __getitem__(self, key):
        with self._lock:
            if key not in self._data:
                _smach().logerr(
                    "Userdata key '%s' not available. Available keys are: %s"
                    % (key, list(self._data.keys()))
                )
                raise KeyError(key)
            return self._data[key]

    def __setitem__(self, key, item):
        with self._lock:
            self._data[key] = item

    def update(self, other_userdata):
        """Merge another UserData (its values win) into this one."""
        data = other_userdata._data if isinstance(other_userdata, UserData) else other_userdata
        with self._lock:
            self._data.update(data)

    def extract(self, keys, remapping):
        """A new UserData holding shallow copies of ``keys``, under their remapped names."""
        ud = UserData()
        reverse = {v: k for k, v in (remapping or {}).items()}
        for k in keys:
            ud[reverse.get(k, k)] = copy.copy(self[k])
        return ud

    def merge(self, ud, keys, remapping):
        """Copy ``keys`` of ``ud`` into this one under their remapped names."""
        for k in keys:
            self[(remapping or {}).get(k, k)] = copy.copy(ud[k])

    # --- attribute access ---
    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name]

    def __setattr__(self, name, value):
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __repr__(self):
        return "UserData(%r)" % (self._data,)


class Remapper:
    """The view of a container's userdata that one child sees while it executes.

    Only declared input keys can be read and only declared output keys can be written;
    ``remapping`` maps the state's local name to the container's key.
    """

    def __init__(self, ud, input_keys=(), output_keys=(), remapping=None):
        object.__setattr__(self, "_ud", ud)
        object.__setattr__(self, "_input", set(input_keys or ()))
        object.__setattr__(self, "_output", set(output_keys or ()))
        # smach_ros passes a list ([]) as the remapping; accept any empty value
        object.__setattr__(self, "_map", dict(remapping) if remapping else {})

    def _remap(self, key):
        return self._map.get(key, key)

    def __getitem__(self, key):
        if key not in self._input:
            raise _smach().InvalidUserCodeError(
                "Reading from SMACH userdata key '%s' but the only keys that were declared as "
                "input to this state were: %s. This key needs to be declared as input to this "
                "state." % (key, sorted(self._input))
            )
        value = self._ud[self._remap(key)]
        if key not in self._output:
            return get_const(value)
        return value

    def __setitem__(self, key, item):
        if key not in self._output:
            _smach().logerr(
                "Writing to SMACH userdata key '%s' but the only keys that were declared as "
                "output from this state were: %s. The write is ignored."
                % (key, sorted(self._output))
            )
            return
        self._ud[self._remap(key)] = item

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name]

    def __setattr__(self, name, value):
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __contains__(self, key):
        return key in self._input and self._remap(key) in self._ud

    def keys(self):
        """The state-local names of the declared input keys that are present.

        (smach 2.5.2 filters on the container's names and returns remapped ones, which is
        wrong whenever a remapping is used.)
        """
        return [k for k in self._input if self._remap(k) in self._ud]

    def update(self, other_userdata):
        self._ud.update(other_userdata)

    def __repr__(self):
        return "Remapper(in=%s, out=%s, map=%s)" % (
            sorted(self._input),
            sorted(self._output),
            self._map,
        )


def get_const(obj):
    """Wrap objects with attributes in ``Const``; plain values pass through unchanged."""
    if hasattr(obj, "__dict__") and not callable(obj) and not isinstance(obj, Const):
        return Const(obj)
    return obj


class Const:
    """A read-only view of an object read through an input-only key.

    Reads pass through (sub-objects are wrapped in turn); writes and deletes raise TypeError.
    smach 2.5.2 means to do the same but a name-mangling typo lets attribute writes land on
    the wrapper silently. Lists, dicts and objects with ``__slots__`` (ROS messages) are not
    wrapped, exactly as upstream.
    """

    def __init__(self, obj):
        object.__setattr__(self, "_Const__obj", obj)

    def __getattr__(self, name):
        return get_const(getattr(self.__obj, name))

    def __getitem__(self, key):
        return get_const(self.__obj[key])

    def __setattr__(self, name, value):
        raise TypeError(
            "'%s' is an input-only userdata value: it cannot be changed (attribute "
            "'%s'); declare the key as output or io to modify it"
            % (type(self.__obj).__name__, name)
        )

    def __delattr__(self, name):
        raise TypeError(
            "'%s' is an input-only userdata value: attribute '%s' cannot be "
            "deleted" % (type(self.__obj).__name__, name)
        )

    def __setitem__(self, key, value):
        raise TypeError("input-only userdata value: item %r cannot be changed" % (key,))

    def __delitem__(self, key):
        raise TypeError("input-only userdata value: item %r cannot be deleted" % (key,))

    def __eq__(self, other):
        if isinstance(other, Const):
            other = other._Const__obj
        return self.__obj == other

    def __hash__(self):
        return hash(self.__obj)

    def __repr__(self):
        return "Const(%r)" % (self.__obj,)
