"""A device on a pseudo-terminal, for the emulators the drivers are tested against: the line a
driver opens (`device`, optionally behind a symlink `link` as udev would make it), a thread that
serves it (`_run`, the subclass's device), and unplugging (the line disappears under the
driver). No ROS here.
"""

import os
import threading
import tty
from typing import Optional


class PtyDevice:
    def __init__(self, link: Optional[str] = None):
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # kept open: the line stays up between driver sessions
        self.device = os.ttyname(self._slave)
        self.link = link
        if link:
            if os.path.lexists(link):
                os.unlink(link)
            os.symlink(self.device, link)
        self.lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        raise NotImplementedError

    def start(self):
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop serving and take the line away (its link too)."""
        self._stop.set()
        self._thread.join(timeout=2.0)
        for fd in (self.master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass
        if self.link and os.path.islink(self.link):
            os.unlink(self.link)

    def unplug(self) -> None:
        """The cable pulled out: the line goes away under the driver."""
        self.stop()
