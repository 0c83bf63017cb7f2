"""Dynamixel Protocol 2.0 framing: CRC-16, byte stuffing, instruction and status packets.

The emulators speak the wire protocol with this module; the arm driver itself uses ROBOTIS's
dynamixel_sdk, so the two sides of every test are independent implementations of the same
framing. Packet layout (ROBOTIS e-manual, "Protocol 2.0"):
    FF FF FD 00 | ID | LEN_L LEN_H | INST | PARAMS... | CRC_L CRC_H
LEN counts INST + PARAMS + CRC; status packets have INST 0x55 followed by an ERROR byte.
No ROS here.
"""

import struct
from dataclasses import dataclass
from typing import List, Optional, Tuple

HEADER = b"\xff\xff\xfd\x00"
BROADCAST_ID = 0xFE

PING, READ, WRITE, REG_WRITE, ACTION, REBOOT = 0x01, 0x02, 0x03, 0x04, 0x05, 0x08
STATUS, SYNC_READ, SYNC_WRITE = 0x55, 0x82, 0x83

# status ERROR byte values (low 7 bits) and the alert flag (bit 7: Hardware Error Status != 0)
ERR_RESULT_FAIL, ERR_INSTRUCTION, ERR_CRC, ERR_DATA_RANGE = 1, 2, 3, 4
ERR_DATA_LENGTH, ERR_DATA_LIMIT, ERR_ACCESS = 5, 6, 7
ERR_ALERT = 0x80


def _crc_table() -> List[int]:
    # CRC-16 with polynomial 0x8005, initial value 0, not reflected (the e-manual's update_crc)
    table = []
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
        table.append(crc & 0xFFFF)
    return table


_TABLE = _crc_table()


def crc16(data: bytes) -> int:
    crc = 0
    for b in data:
        crc = ((crc << 8) ^ _TABLE[((crc >> 8) ^ b) & 0xFF]) & 0xFFFF
    return crc


def stuff(payload: bytes) -> bytes:
    """Inserts 0xFD after every FF FF FD inside instruction + parameters (not the header)."""
    out = bytearray()
    for b in payload:
        out.append(b)
        if len(out) >= 3 and out[-3:] == b"\xff\xff\xfd":
            out.append(0xFD)
    return bytes(out)


def unstuff(payload: bytes) -> bytes:
    out = bytearray()
    i = 0
    while i < len(payload):
        out.append(payload[i])
        if len(out) >= 3 and out[-3:] == b"\xff\xff\xfd" and i + 1 < len(payload):
            if payload[i + 1] == 0xFD:
                i += 1  # the stuffed byte
        i += 1
    return bytes(out)


def encode(dxl_id: int, instruction: int, params: bytes = b"") -> bytes:
    body = stuff(bytes([instruction]) + bytes(params))
    head = HEADER + bytes([dxl_id]) + struct.pack("<H", len(body) + 2)
    frame = head + body
    return frame + struct.pack("<H", crc16(frame))


def status(dxl_id: int, error: int, params: bytes = b"") -> bytes:
    return encode(dxl_id, STATUS, bytes([error]) + bytes(params))


@dataclass
class Packet:
    dxl_id: int
    instruction: int
    params: bytes
    crc_ok: bool


def take_packet(buffer: bytearray) -> Tuple[Optional[Packet], bool]:
    """Removes the first complete packet from `buffer`.

    Returns (packet, need_more): bytes before a header are dropped (garbage on the line); a packet
    whose CRC does not match comes back with crc_ok False so the device can answer CRC error.
    """
    start = buffer.find(HEADER)
    if start < 0:
        # keep a possible partial header at the end
        del buffer[: max(0, len(buffer) - 3)]
        return None, True
    del buffer[:start]
    if len(buffer) < 7:
        return None, True
    length = struct.unpack_from("<H", buffer, 5)[0]
    if length < 3 or length > 1024:
        del buffer[:1]  # not a real header: resynchronise
        return None, False
    total = 7 + length
    if len(buffer) < total:
        return None, True
    frame = bytes(buffer[:total])
    del buffer[:total]
    crc_ok = crc16(frame[:-2]) == struct.unpack_from("<H", frame, total - 2)[0]
    body = unstuff(frame[7:-2])
    return Packet(frame[4], body[0], body[1:], crc_ok), False
