"""One lab scale on a serial line: poll a weight, tare, and notice when it goes away.

The serial port is injected (pyserial's Serial, opened with timeout = reply_timeout), so the
core runs against the emulator's pty and a real scale alike. Every request waits at most
reply_timeout; a scale that gives no valid reply for disconnect_timeout (or whose line
disappears) is reported disconnected in one line. A dialect the scale does not speak (ES,
EC,E01) is reported at once: polling on would only repeat it. No ROS here.
"""

import threading
import time
from typing import Optional, Tuple

from rascal_drivers.scale_protocols import Reading, ScaleReplyError


class ScaleFault(RuntimeError):
    """Fatal for the driver: disconnected, or the wrong protocol. str() is one line."""


class ScaleLink:
    def __init__(
        self, port, protocol, device: str, disconnect_timeout: float, clock=time.monotonic
    ):
        self.port = port
        self.protocol = protocol
        self.device = device
        self.disconnect_timeout = disconnect_timeout
        self.clock = clock
        self.lock = threading.Lock()  # the poll loop and the tare service share the line
        self.last_valid = clock()

    def _ask(self, request: bytes) -> Optional[str]:
        try:
            with self.lock:
                self.port.reset_input_buffer()  # a late reply to the last request is stale
                self.port.write(request)
                line = self.port.read_until(b"\n")
        except Exception as e:  # pyserial's SerialException, OSError: the line is gone
            raise ScaleFault(
                "scale on %s lost (%s); check its cable and power, then start scale_driver again"
                % (self.device, e)
            ) from e
        if not line.endswith(b"\n"):
            return None
        return line.decode("ascii", errors="replace").rstrip("\r\n")

    def _silence(self) -> None:
        silent = self.clock() - self.last_valid
        if silent > self.disconnect_timeout:
            raise ScaleFault(
                "no valid reply from the scale on %s for %.1f s (drivers.scale.disconnect_timeout);"
                " check its cable, power, drivers.scale.baud and drivers.scale.protocol"
                % (self.device, silent)
            )

    def poll(self) -> Tuple[Optional[Reading], str]:
        """(reading, '') or (None, why not this time); raises ScaleFault."""
        reply = self._ask(self.protocol.weigh)
        if reply is None:
            self._silence()
            return None, "no reply within drivers.scale.reply_timeout"
        try:
            reading = self.protocol.parse_weight(reply)
        except ScaleReplyError as e:
            if not e.retry:
                raise ScaleFault(str(e)) from e
            if e.kind != "garbage":
                self.last_valid = self.clock()  # the scale answered, it just cannot weigh
            else:
                self._silence()
            return None, str(e)
        self.last_valid = self.clock()
        return reading, ""

    def tare(self) -> Tuple[bool, str]:
        reply = self._ask(self.protocol.tare)
        if reply is None:
            return False, "the scale did not answer the tare within drivers.scale.reply_timeout"
        try:
            why = self.protocol.parse_tare(reply)
        except ScaleReplyError as e:
            return False, str(e)
        self.last_valid = self.clock()
        return (False, why) if why else (True, "tared")
