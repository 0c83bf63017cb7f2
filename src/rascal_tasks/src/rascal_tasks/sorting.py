"""Sorting: which box a recorded sherd goes into.

A site adds sorting bins as stations of `type: bin`, each with a `rule` on the sherd's recorded
values; the discard station is the default bin. Bins are tried in the config's order and the
first whose rule holds takes the sherd. A rule is one line an archaeologist can write:

    length >= 60 mm
    mass < 5 g or flag mass_unstable
    munsell_hue in [2.5YR, 5YR] and munsell_value <= 5

    rule      := clause ("or" clause)*
    clause    := condition ("and" condition)*
    condition := QUANTITY OP NUMBER [UNIT]      length width thickness diameter (m, cm, mm);
                                                mass (kg, g); munsell_value munsell_chroma
               | "munsell_hue" ("=" HUE | "in" "[" HUE ("," HUE)* "]")
               | "flag" FLAG                    see FLAGS

`and` binds tighter than `or`. A value the sherd does not have (no trustworthy mass, no colour)
makes its conditions false, never true: such a sherd falls through to a later bin or the
default, and the reason recorded with it says so. No ROS here.
"""

import re
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

# quantity -> (unit of the recorded value, the units a rule may write it in with their factor)
QUANTITIES: Dict[str, Tuple[str, Dict[str, float]]] = {
    "length": ("m", {"m": 1.0, "cm": 0.01, "mm": 0.001}),
    "width": ("m", {"m": 1.0, "cm": 0.01, "mm": 0.001}),
    "thickness": ("m", {"m": 1.0, "cm": 0.01, "mm": 0.001}),
    "diameter": ("m", {"m": 1.0, "cm": 0.01, "mm": 0.001}),
    "mass": ("kg", {"kg": 1.0, "g": 0.001}),
    "munsell_value": ("", {}),
    "munsell_chroma": ("", {}),
}
FLAGS = {
    "mass_unstable": "the scale gave no trustworthy mass",
    "dropped": "it slipped from the gripper at least once",
    "no_colour": "the archival photo gave no Munsell colour",
    "no_thickness": "the wrist camera could not tell its wall thickness",
    "no_diameter": "its curvature told no vessel diameter",
}
# Munsell hue pages: 2.5, 5, 7.5, 10 of each hue family (soil charts), and N for neutrals
HUE_FAMILIES = ("R", "YR", "Y", "GY", "G", "BG", "B", "PB", "P", "RP")
_HUE = re.compile(r"^(\d+(?:\.\d+)?)(%s)$" % "|".join(sorted(HUE_FAMILIES, key=len, reverse=True)))
_TOKEN = re.compile(r"\s*(<=|>=|==|=|<|>|\[|\]|,|[A-Za-z_][A-Za-z0-9_]*|\d+(?:\.\d+)?[A-Za-z]*|\S)")
_EPS = 1e-9  # 18 mm written is 0.018000000000000002 m: a boundary is not decided by rounding
_OPS = {
    "<": lambda a, b: a < b - _EPS,
    "<=": lambda a, b: a <= b + _EPS,
    ">": lambda a, b: a > b + _EPS,
    ">=": lambda a, b: a >= b - _EPS,
    "=": lambda a, b: abs(a - b) <= _EPS,
    "==": lambda a, b: abs(a - b) <= _EPS,
}


class RuleError(ValueError):
    """A rule does not follow the grammar; str() says where and what is expected."""


@dataclass(frozen=True)
class SherdValues:
    """What the catalogue holds of a sherd when it is sorted (SI units; None: not measured)."""

    length: Optional[float] = None
    width: Optional[float] = None
    thickness: Optional[float] = None
    diameter: Optional[float] = None
    mass: Optional[float] = None
    munsell: Optional[str] = None  # "5YR 6/4", "N5"
    flags: frozenset = frozenset()

    @classmethod
    def from_row(cls, row: dict) -> "SherdValues":
        """From a catalogue row (mm, g as the catalogue keeps them)."""

        def si(column, factor):
            v = row.get(column)
            return None if v is None else float(v) * factor

        flags = set()
        if row.get("mass_g") is None:
            flags.add("mass_unstable")
        if row.get("drops"):
            flags.add("dropped")
        if not row.get("colour_munsell"):
            flags.add("no_colour")
        if row.get("thickness_mm") is None:
            flags.add("no_thickness")
        if row.get("vessel_diameter_mm") is None:
            flags.add("no_diameter")
        return cls(
            length=si("length_mm", 1e-3),
            width=si("width_mm", 1e-3),
            thickness=si("thickness_mm", 1e-3),
            diameter=si("vessel_diameter_mm", 1e-3),
            mass=si("mass_g", 1e-3),
            munsell=row.get("colour_munsell") or None,
            flags=frozenset(flags),
        )

    def munsell_parts(self) -> Tuple[Optional[str], Optional[float], Optional[float]]:
        """(hue page, value, chroma) of the Munsell notation; Nones when there is none."""
        if not self.munsell:
            return None, None, None
        m = re.match(r"^\s*N\s*(\d+(?:\.\d+)?)", self.munsell)
        if m:
            return "N", float(m.group(1)), 0.0
        m = re.match(r"^\s*(\S+)\s+(\d+(?:\.\d+)?)\s*/\s*(\d+(?:\.\d+)?)", self.munsell)
        if not m:
            return None, None, None
        return m.group(1), float(m.group(2)), float(m.group(3))

    def get(self, quantity: str) -> Optional[float]:
        if quantity == "munsell_value":
            return self.munsell_parts()[1]
        if quantity == "munsell_chroma":
            return self.munsell_parts()[2]
        return getattr(self, quantity)


@dataclass(frozen=True)
class Condition:
    text: str  # as written, for the reason recorded with the sherd
    quantity: str = ""  # a comparison: quantity op threshold (SI)
    op: str = ""
    threshold: float = 0.0
    hues: Tuple[str, ...] = ()  # munsell_hue is one of these
    flag: str = ""

    @property
    def needs_colour(self) -> bool:
        return bool(self.hues) or self.quantity.startswith("munsell") or self.flag == "no_colour"

    def holds(self, v: SherdValues) -> Tuple[bool, str]:
        """(whether it holds, why in words)."""
        if self.flag:
            return self.flag in v.flags, self.text
        if self.hues:
            hue = v.munsell_parts()[0]
            if hue is None:
                return False, "%s: no Munsell colour" % self.text
            return hue in self.hues, "%s (%s)" % (self.text, v.munsell)
        x = v.get(self.quantity)
        if x is None:
            return False, "%s: %s not measured" % (self.text, self.quantity)
        unit = QUANTITIES[self.quantity][0]
        shown = {"m": (1000.0, "mm"), "kg": (1000.0, "g")}.get(unit, (1.0, ""))
        return _OPS[self.op](x, self.threshold), "%s (%g%s)" % (
            self.text,
            round(x * shown[0], 1),
            (" " + shown[1]) if shown[1] else "",
        )


@dataclass(frozen=True)
class Rule:
    text: str
    clauses: Tuple[Tuple[Condition, ...], ...]  # or of ands

    @property
    def needs_colour(self) -> bool:
        return any(c.needs_colour for clause in self.clauses for c in clause)

    def holds(self, v: SherdValues) -> Tuple[bool, str]:
        """(whether the rule holds, the words of the clause that decided it)."""
        reasons = []
        for clause in self.clauses:
            results = [c.holds(v) for c in clause]
            if all(ok for ok, _ in results):
                return True, " and ".join(why for _, why in results)
            reasons.append(next(why for ok, why in results if not ok))
        return False, "; ".join("not %s" % r for r in reasons)


def normalise_hue(text: str) -> str:
    """'5yr' -> '5YR', '10.0YR' -> '10YR'; RuleError for what is not a hue page or N."""
    t = text.strip().upper()
    if t == "N":
        return "N"
    m = _HUE.match(t)
    if not m or not 0 < float(m.group(1)) <= 10:
        raise RuleError("%r is not a Munsell hue (e.g. 2.5YR, 10YR, N)" % text)
    return "%g%s" % (float(m.group(1)), m.group(2))


def parse_rule(text: str) -> Rule:
    """The rule as written in a bin's `rule`; RuleError (one line) when it cannot be read."""
    tokens = _TOKEN.findall(text or "")
    if not tokens:
        raise RuleError("empty; write e.g. \"length >= 60 mm\"")
    pos = 0

    def peek():
        return tokens[pos] if pos < len(tokens) else None

    def take(what):
        nonlocal pos
        t = peek()
        if t is None:
            raise RuleError("ends where %s is expected" % what)
        pos += 1
        return t

    def condition() -> Condition:
        start = pos
        word = take("a quantity, munsell_hue or flag")
        if word == "flag":
            name = take("a flag name (%s)" % ", ".join(FLAGS))
            if name not in FLAGS:
                raise RuleError("unknown flag %r (one of %s)" % (name, ", ".join(FLAGS)))
            return Condition("flag " + name, flag=name)
        if word == "munsell_hue":
            op = take("= or in")
            if op in ("=", "=="):
                hues = (normalise_hue(take("a Munsell hue")),)
            elif op == "in":
                if take("[") != "[":
                    raise RuleError("munsell_hue in: expected a list like [2.5YR, 5YR]")
                hues = []
                while True:
                    hues.append(normalise_hue(take("a Munsell hue")))
                    sep = take(", or ]")
                    if sep == "]":
                        break
                    if sep != ",":
                        raise RuleError("munsell_hue in [...]: expected , or ], got %r" % sep)
                hues = tuple(hues)
            else:
                raise RuleError("munsell_hue: expected = or in, got %r" % op)
            return Condition(" ".join(tokens[start:pos]), hues=hues)
        if word not in QUANTITIES:
            raise RuleError(
                "unknown quantity %r (one of %s, munsell_hue, flag)" % (word, ", ".join(QUANTITIES))
            )
        op = take("a comparison (<, <=, >, >=, =)")
        if op not in _OPS:
            raise RuleError("%s: expected <, <=, >, >= or =, got %r" % (word, op))
        number = take("a number")
        m = re.match(r"^(\d+(?:\.\d+)?)([A-Za-z]*)$", number)
        if not m:
            raise RuleError("%s %s: expected a number, got %r" % (word, op, number))
        value, unit = float(m.group(1)), m.group(2)
        units = QUANTITIES[word][1]
        if not unit and peek() not in (None, "and", "or") and peek().isalpha():
            unit = take("a unit")
        if unit:
            if unit not in units:
                raise RuleError(
                    "%s: unit %r not known (%s)"
                    % (word, unit, ", ".join(units) if units else "it has no unit")
                )
            value *= units[unit]
        return Condition(" ".join(tokens[start:pos]), quantity=word, op=op, threshold=value)

    clauses: List[Tuple[Condition, ...]] = []
    current: List[Condition] = [condition()]
    while pos < len(tokens):
        joiner = take("and or or")
        if joiner not in ("and", "or"):
            raise RuleError("expected and / or after %r, got %r" % (current[-1].text, joiner))
        if joiner == "or":
            clauses.append(tuple(current))
            current = []
        current.append(condition())
    clauses.append(tuple(current))
    return Rule(text.strip(), tuple(clauses))


@dataclass(frozen=True)
class Decision:
    bin: str  # the station's name
    reason: str  # one line: the rule that took it, or why none did


def choose_bin(bins: Sequence[Tuple[str, Rule]], default: str, values: SherdValues) -> Decision:
    """The first bin (name, rule), in order, whose rule holds for `values`; else `default`."""
    misses = []
    for name, rule in bins:
        ok, why = rule.holds(values)
        if ok:
            return Decision(name, "%s: %s" % (name, why))
        misses.append("%s: %s" % (name, why))
    return Decision(default, "%s (no bin's rule held: %s)" % (default, " | ".join(misses)))
