"""What a lab scale says on its serial line, in two dialects: requests and parsed replies.

MT-SICS (Mettler Toledo; Reference Manual "MT-SICS", level 0/1 commands): `SI` weight now,
`S` stable weight, `T` tare, `Z` zero, each CR LF terminated; replies `S S <value> <unit>`
(stable), `S D ...` (dynamic, not settled), `S I` (not executable now: busy, or no stable value
in time), `S +` / `S -` (overload / underload), `T S <tare> <unit>`, `T I`, `T +`, `T -`,
`Z A`, `Z I`, `Z +`, `Z -`, and the command-level errors `ES` (syntax: not understood), `ET`
(transmission error), `EL` (logical error).

A&D standard format (A&D GX-A/GF-A communication manual, "A&D standard format"): `Q` weight
now, `S` stable weight, `T` tare, `R` re-zero; a weight is 15 characters
`ST,+00123.45  g` (header ST stable, US unstable, QT counting, OL out of range), tare and
re-zero are acknowledged with ACK (06h), and errors are `EC,Exx` (E01 undefined command,
E11 stability error ...).

Every reply becomes a `Reading` (mass in kg, the scale's own stable flag) or a `ScaleReplyError`
whose text is one line. No ROS here.
"""

from dataclasses import dataclass

UNITS = {"g": 1e-3, "kg": 1.0, "mg": 1e-6}


@dataclass
class Reading:
    mass: float  # [kg]
    stable: bool


class ScaleReplyError(Exception):
    """A reply that is not a weight. `kind`: busy, overload, underload, syntax, transmission,
    logical, garbage; `retry` when asking again may help."""

    def __init__(self, kind: str, text: str, retry: bool):
        super().__init__(text)
        self.kind = kind
        self.retry = retry


def _mass(value: str, unit: str, reply: str) -> float:
    if unit not in UNITS:
        raise ScaleReplyError("garbage", "unexpected unit %r in %r" % (unit, reply), True)
    try:
        return float(value) * UNITS[unit]
    except ValueError:
        raise ScaleReplyError("garbage", "unreadable weight in %r" % reply, True) from None


class MtSics:
    name = "mt_sics"
    weigh = b"SI\r\n"  # immediately, with the stable/dynamic flag, at the poll rate
    tare = b"T\r\n"

    def _common(self, reply: str) -> None:
        if reply == "ES":
            raise ScaleReplyError(
                "syntax",
                "the scale does not understand MT-SICS (ES); is drivers.scale.protocol right?",
                False,
            )
        if reply == "ET":
            raise ScaleReplyError("transmission", "transmission error (ET); asking again", True)
        if reply == "EL":
            raise ScaleReplyError("logical", "logical error (EL)", True)

    def parse_weight(self, reply: str) -> Reading:
        self._common(reply)
        parts = reply.split()
        if parts[:2] == ["S", "I"]:
            raise ScaleReplyError("busy", "scale busy (S I)", True)
        if parts[:2] == ["S", "+"]:
            raise ScaleReplyError("overload", "scale overloaded (S +): take the load off", True)
        if parts[:2] == ["S", "-"]:
            raise ScaleReplyError(
                "underload", "scale underloaded (S -): is the weighing pan on?", True
            )
        if len(parts) == 4 and parts[0] == "S" and parts[1] in ("S", "D"):
            return Reading(_mass(parts[2], parts[3], reply), parts[1] == "S")
        if reply[:3] in ("ST,", "US,", "OL,", "EC,"):
            raise ScaleReplyError(
                "syntax",
                "the scale answers in the A&D format (%r); set drivers.scale.protocol: a_and_d"
                % reply,
                False,
            )
        raise ScaleReplyError("garbage", "unexpected reply %r to SI" % reply, True)

    def parse_tare(self, reply: str) -> str:
        """'' when tared, else why not (one line)."""
        self._common(reply)
        parts = reply.split()
        if len(parts) == 4 and parts[:2] == ["T", "S"]:
            return ""
        if parts[:2] == ["T", "I"]:
            return "the scale could not tare now (T I: busy or not stable); try again"
        if parts[:2] == ["T", "+"]:
            return "tare refused (T +): above the taring range; take the load off"
        if parts[:2] == ["T", "-"]:
            return "tare refused (T -): below the taring range; is the weighing pan on?"
        raise ScaleReplyError("garbage", "unexpected reply %r to T" % reply, True)


class AandD:
    name = "a_and_d"
    weigh = b"Q\r\n"
    tare = b"T\r\n"
    ERRORS = {"E00": "communication error", "E01": "undefined command", "E11": "stability error"}

    def _error(self, reply: str) -> None:
        if reply.startswith("EC,"):
            code = reply[3:].strip()
            if code == "E01":
                raise ScaleReplyError(
                    "syntax",
                    "the scale does not understand A&D commands (EC,E01); is "
                    "drivers.scale.protocol right?",
                    False,
                )
            raise ScaleReplyError(
                "transmission", "scale error %s (%s)" % (code, self.ERRORS.get(code, "?")), True
            )

    def parse_weight(self, reply: str) -> Reading:
        self._error(reply)
        if reply == "ES" or reply[:4] in ("S S ", "S D ", "S I"):
            raise ScaleReplyError(
                "syntax",
                "the scale answers in MT-SICS (%r); set drivers.scale.protocol: mt_sics" % reply,
                False,
            )
        if reply.startswith("OL,"):  # out of range: only the sign of the data matters
            if reply[3:].strip().startswith("-"):
                raise ScaleReplyError(
                    "underload", "scale underloaded (OL, -): is the weighing pan on?", True
                )
            raise ScaleReplyError("overload", "scale overloaded (OL): take the load off", True)
        if len(reply) < 15 or reply[2] != ",":
            raise ScaleReplyError("garbage", "unexpected reply %r to Q" % reply, True)
        header, value, unit = reply[:2], reply[3:12], reply[12:15].strip()
        if header not in ("ST", "US"):
            raise ScaleReplyError("garbage", "unexpected header %r in %r" % (header, reply), True)
        return Reading(_mass(value, unit, reply), header == "ST")

    def parse_tare(self, reply: str) -> str:
        if reply == "\x06":
            return ""
        if reply.startswith("EC,E11"):
            return "the scale could not tare now (EC,E11: not stable); try again"
        self._error(reply)
        raise ScaleReplyError("garbage", "unexpected reply %r to T" % reply, True)


PROTOCOLS = {"mt_sics": MtSics, "a_and_d": AandD}
