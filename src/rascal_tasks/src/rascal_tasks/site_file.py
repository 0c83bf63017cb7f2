"""Edits of the site file's text that keep it the site's own: every other line, comment and key
order stays as the person wrote it (a YAML dump would lose them). Used by `rascal calibrate`
(stations moved) and `rascal teach` (a taught place stored). No ROS here.

Only block-style mappings are followed (the shipped file's style); a station written in flow
style (`scale: {type: scale, ...}`) is left alone, and the caller's check of the written file
then finds the value unchanged.
"""

import math
import re
from typing import Dict, Iterator, List, Sequence, Tuple

from rascal_tasks.planar import local_of, placed

# Keys under a station whose first two numbers are a place on the table that moves with it.
MOVING = {
    ("position",),
    ("place_at",),
    ("colour_chart", "position"),
    ("scale_bar", "position"),
    ("stand", "position"),
    ("taught_place",),
}
_LINE = re.compile(r"^(?P<indent> *)(?P<key>[A-Za-z_][A-Za-z0-9_]*):(?P<rest>.*)$")
_LIST = re.compile(r"\[(?P<items>[-+0-9.eE,\s]+)\]")


def _walk(text: str) -> Iterator[Tuple[str, str, List[str], int]]:
    """(line without its end, the end, the key path of the line or [], its indent)."""
    path: List[Tuple[int, str]] = []
    for line in text.splitlines(keepends=True):
        body = line.rstrip("\r\n")
        end = line[len(body) :]
        m = _LINE.match(body)
        if not m or body.lstrip().startswith("#"):
            yield body, end, [], -1
            continue
        indent = len(m.group("indent"))
        while path and path[-1][0] >= indent:
            path.pop()
        path.append((indent, m.group("key")))
        yield body, end, [k for _, k in path], indent


def _split_comment(rest: str) -> Tuple[str, str]:
    value, sep, comment = rest.partition("#")
    return value, sep + comment


def _numbers(values) -> str:
    """`[a, b]` of a sequence, or one number."""
    if isinstance(values, (int, float)):
        return "%.4f" % values
    return "[%s]" % ", ".join("%.4f" % v for v in values)


def shift_stations(text: str, shifts: Dict[str, Tuple[float, float]]) -> str:
    """Every place of each shifted station (MOVING) moved by its (dx, dy) [m]."""
    return move_stations(text, {n: ((0.0, 0.0), d, 0.0) for n, d in shifts.items()})


def move_stations(text: str, moves: Dict[str, Tuple[Tuple[float, float], Tuple, float]]) -> str:
    """Every place of each moved station (MOVING) turned by its dyaw [rad] about `old`, its
    centre, and carried to `new` (moves: station -> (old, new, dyaw)); a taught place's yaw
    turns with it."""
    out = []
    for body, end, keys, _ in _walk(text):
        if len(keys) >= 3 and keys[0] == "stations" and keys[1] in moves:
            if tuple(keys[2:]) in MOVING:
                head, rest = body.split(":", 1)
                value, comment = _split_comment(rest)
                m = _LIST.search(value)
                if m:
                    old, new, dyaw = moves[keys[1]]
                    items = [float(v) for v in m.group("items").split(",")]
                    items[:2] = placed(new, dyaw, local_of(old, 0.0, items[:2]))
                    if keys[2:] == ["taught_place"] and len(items) > 2:
                        items[2] = math.remainder(items[2] + dyaw, 2 * math.pi)
                    value = value[: m.start()] + _numbers(items) + value[m.end() :]
                    body = "%s:%s%s" % (head, value, comment)
        out.append(body + end)
    return "".join(out)


def set_station_value(text: str, station: str, key: str, values: Sequence[float]) -> str:
    """`stations.<station>.<key>: [values]` replaced where it is, or added as the station's
    first key; ValueError when the file has no block-style station of that name."""
    lines = list(_walk(text))
    header = child_indent = None
    for i, (body, _, keys, indent) in enumerate(lines):
        if keys == ["stations", station]:
            header = i
        elif header is not None and len(keys) > 2 and keys[:2] == ["stations", station]:
            if child_indent is None:
                child_indent = indent
            if keys[2:] == [key]:
                head, rest = body.split(":", 1)
                _, comment = _split_comment(rest)
                lines[i] = (
                    "%s: %s%s" % (head, _numbers(values), "  " + comment if comment else ""),
                ) + lines[i][1:]
                return "".join(b + e for b, e, _, _ in lines)
    if header is None or child_indent is None:
        raise ValueError("stations.%s: no such station written in block style" % station)
    end = lines[header][1] or "\n"
    new = (" " * child_indent + "%s: %s" % (key, _numbers(values)), end, [], -1)
    lines.insert(header + 1, new)
    return "".join(b + e for b, e, _, _ in lines)
