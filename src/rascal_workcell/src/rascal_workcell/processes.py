"""Starting and stopping the rig's processes, shared by the simulated rig (rascal_tasks.sim_rig)
and the field rig's one start command (rascal_drivers.rig): where the workspace is, a free port
for a master, and stopping a process group. No ROS here.
"""

import os
import signal
import socket
import subprocess


def workspace() -> str:
    """The workspace root (the folder holding config/rascal.yaml), from the source tree or the
    devel space; else the current folder."""
    here = os.path.dirname(os.path.abspath(__file__))
    for up in range(2, 6):
        root = os.path.abspath(os.path.join(here, *([".."] * up)))
        if os.path.isfile(os.path.join(root, "config", "rascal.yaml")):
            return root
    return os.getcwd()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def stop(proc: subprocess.Popen, timeout: float = 10.0) -> None:
    """Ctrl-C to the process group, then SIGKILL what is left."""
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(timeout=timeout)
    except (subprocess.TimeoutExpired, ProcessLookupError):
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
