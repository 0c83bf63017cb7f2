"""Helpers shared by the catalogue tests (imported by name; not a conftest)."""

import os

PYTHON = "/usr/bin/python3"


def subprocess_env():
    """Environment for a child /usr/bin/python3 that must import rascal_tasks."""
    import rascal_tasks

    src = os.path.dirname(os.path.dirname(os.path.abspath(rascal_tasks.__file__)))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
    env["PYTHONUNBUFFERED"] = "1"
    return env


class FakeClock:
    """Deterministic wall clock for record timestamps: +1.25 s per reading."""

    def __init__(self, start=1_790_000_000.0):
        self.t = start

    def __call__(self):
        self.t += 1.25
        return self.t
