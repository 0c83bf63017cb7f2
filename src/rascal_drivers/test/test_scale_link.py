"""Core tests (no master): both scale dialects' replies, and the scale link against the scale
emulator on a pseudo-terminal through pyserial (settling, tare, overload, underload, garbage,
silence, unplugging)."""

import time

import pytest

from rascal_drivers.scale_emulator import ScaleEmulator
from rascal_drivers.scale_link import ScaleFault, ScaleLink
from rascal_drivers.scale_protocols import AandD, MtSics, Reading, ScaleReplyError

serial = pytest.importorskip("serial")


@pytest.mark.parametrize(
    "reply,reading",
    [
        ("S S      25.2 g", Reading(0.0252, True)),
        ("S D     -0.3 g", Reading(-0.0003, False)),
        ("S S  0.0252 kg", Reading(0.0252, True)),
    ],
)
def test_mt_sics_weights(reply, reading):
    got = MtSics().parse_weight(reply)
    assert got.stable == reading.stable and got.mass == pytest.approx(reading.mass)


@pytest.mark.parametrize(
    "reply,kind,retry",
    [
        ("S I", "busy", True),
        ("S +", "overload", True),
        ("S -", "underload", True),
        ("ES", "syntax", False),
        ("ET", "transmission", True),
        ("S S 12,3 g", "garbage", True),
        ("ST,+000025.2  g", "syntax", False),  # an A&D scale set up as MT-SICS
    ],
)
def test_mt_sics_errors(reply, kind, retry):
    with pytest.raises(ScaleReplyError) as e:
        MtSics().parse_weight(reply)
    assert (e.value.kind, e.value.retry) == (kind, retry)
    assert "\n" not in str(e.value)


def test_a_and_d_replies():
    p = AandD()
    assert p.parse_weight("ST,+000025.2  g") == Reading(pytest.approx(0.0252), True)
    assert p.parse_weight("US,-000000.4  g").stable is False
    for reply, kind in (("OL,+9999999 g", "overload"), ("OL,-9999999 g", "underload")):
        with pytest.raises(ScaleReplyError, match=kind):
            p.parse_weight(reply)
    with pytest.raises(ScaleReplyError, match="drivers.scale.protocol"):
        p.parse_weight("EC,E01")
    assert p.parse_tare("\x06") == ""
    assert "not stable" in p.parse_tare("EC,E11")
    assert MtSics().parse_tare("T S      25.2 g") == ""
    assert "busy or not stable" in MtSics().parse_tare("T I")


@pytest.fixture(params=["mt_sics", "a_and_d"])
def scale(request):
    emu = ScaleEmulator(request.param, settle_time=0.05, stable_after=0.1).start()
    port = serial.Serial(emu.device, 9600, timeout=0.3)
    protocol = MtSics() if request.param == "mt_sics" else AandD()
    yield emu, ScaleLink(port, protocol, emu.device, disconnect_timeout=0.8)
    port.close()
    emu.stop()


def settled(link, deadline=3.0):
    end = time.monotonic() + deadline
    while time.monotonic() < end:
        reading, _ = link.poll()
        if reading is not None and reading.stable:
            return reading
        time.sleep(0.02)
    return None


def test_a_load_settles_then_tares_to_zero(scale):
    emu, link = scale
    emu.put(0.0521)
    first, _ = link.poll()
    assert first is not None and not first.stable  # still swinging right after the load
    reading = settled(link)
    assert reading is not None and reading.mass == pytest.approx(0.0521, abs=2e-4)
    assert link.tare() == (True, "tared")
    assert settled(link).mass == pytest.approx(0.0, abs=2e-4)


def test_overload_underload_and_garbage_are_reported_not_published(scale):
    emu, link = scale
    emu.put(1.0)  # above the 620 g capacity
    time.sleep(0.3)
    reading, why = link.poll()
    assert reading is None and "overloaded" in why
    emu.put(0.0)
    emu.pan_on = False
    time.sleep(0.4)
    reading, why = link.poll()
    assert reading is None and "underloaded" in why
    emu.pan_on = True
    assert settled(link) is not None
    emu.garbage_next = 2
    assert link.poll()[0] is None and link.poll()[0] is None
    assert link.poll()[0] is not None  # back in step after the noise


def test_silence_and_unplugging_raise_one_line(scale):
    emu, link = scale
    assert settled(link) is not None
    emu.silent = True
    with pytest.raises(ScaleFault, match="no valid reply from the scale"):
        for _ in range(20):
            link.poll()
    emu.silent = False
    link.last_valid = time.monotonic()
    emu.unplug()
    with pytest.raises(ScaleFault, match="lost"):
        for _ in range(5):
            link.poll()
