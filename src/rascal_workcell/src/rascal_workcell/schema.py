"""The parameter schema (schema/parameters.yaml) and a validator that follows it.

The same file is compiled into the C++ nodes (rascal_workcell::Parameters); this module is the
Python reading of it: `validate(data)` checks every key of a loaded config/rascal.yaml at every
depth (type, unit, range, required, unknown keys with the nearest known one) and returns a copy
with the defaults filled in. Layout rules that relate several stations (reach, overlap) live in
rascal_tasks.config, on top of this. No ROS here.
"""

import copy
import difflib
import math
import os
from dataclasses import dataclass, field
from typing import Any, List, Optional

import yaml

SCHEMA_PATH = os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "schema", "parameters.yaml"
)
UNIT_WORDS = {"m": "metres", "s": "seconds", "rad": "radians", "px": "pixels"}
READERS = ("rascal", "sim", "arm_controller", "sherd_detector")


class SchemaError(ValueError):
    """A value does not follow the schema; str() is one line: `key: expected ..., got ...`."""

    def __init__(self, key: str, message: str):
        super().__init__("%s: %s" % (key, message))
        self.key = key


@dataclass
class Spec:
    key: str
    type: str
    unit: str = ""
    description: str = ""
    min: Any = None
    max: Any = None
    exclusive_min: bool = False
    length: int = 0
    inner_length: int = 0
    max_length: int = 0
    shape: str = ""
    choices: List[str] = field(default_factory=list)
    station_types: List[str] = field(default_factory=list)
    required_names: List[str] = field(default_factory=list)
    readers: List[str] = field(default_factory=list)
    required: bool = False
    default: Any = None

    def matches(self, key: str) -> bool:
        a, b = self.key.split("."), key.split(".")
        return len(a) == len(b) and all(p in ("*", k) for p, k in zip(a, b, strict=True))

    def range_text(self) -> str:
        def show(b, inf):
            if b is None:
                return inf
            if isinstance(b, list):
                return "[%s]" % ", ".join("%g" % v for v in b)
            return b if isinstance(b, str) else "%g" % b

        return "%s%s, %s]" % (
            "(" if self.exclusive_min else "[",
            show(self.min, "-inf"),
            show(self.max, "inf"),
        )

    def expectation(self) -> str:
        in_unit = " in " + UNIT_WORDS.get(self.unit, self.unit) if self.unit else ""
        if self.type == "number":
            return "a number%s in %s" % (in_unit, self.range_text())
        if self.type == "integer":
            return "an integer%s in %s" % (in_unit, self.range_text())
        if self.type == "bool":
            return "true or false"
        if self.type == "string":
            return "a non-empty one-line string"
        if self.type == "enum":
            return "one of " + ", ".join(self.choices)
        if self.type in ("vector", "vector_list"):
            return self.shape + in_unit
        return "a mapping of names"


class Schema:
    def __init__(self, specs: List[Spec]):
        self.specs = specs

    @classmethod
    def load(cls, path: str = SCHEMA_PATH) -> "Schema":
        with open(path, encoding="utf-8") as f:
            raw = yaml.safe_load(f)
        specs = []
        for key, fields in raw.items():
            spec = Spec(key=key, **fields)
            if spec.required == ("default" in fields):
                raise ValueError("%s: %s needs either required: true or a default" % (path, key))
            specs.append(spec)
        return cls(specs)

    def find(self, key: str) -> Optional[Spec]:
        return next((s for s in self.specs if s.matches(key)), None)

    def for_reader(self, reader: str) -> List[Spec]:
        return [s for s in self.specs if reader in s.readers]

    def sections(self, prefix: str) -> List[str]:
        """Names the schema knows directly under a section (`*` for a site-chosen name)."""
        depth = len(prefix.split(".")) if prefix else 0
        out = []
        for s in self.specs:
            parts = s.key.split(".")
            if len(parts) > depth and _prefix_matches(parts[:depth], prefix):
                if parts[depth] not in out:
                    out.append(parts[depth])
        return out


def _prefix_matches(parts: List[str], prefix: str) -> bool:
    want = prefix.split(".") if prefix else []
    return len(parts) == len(want) and all(p in ("*", k) for p, k in zip(parts, want, strict=True))


_SCHEMA: Optional[Schema] = None


def builtin() -> Schema:
    global _SCHEMA
    if _SCHEMA is None:
        _SCHEMA = Schema.load()
    return _SCHEMA


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


class _Validator:
    def __init__(self, schema: Schema, data: dict):
        self.schema = schema
        self.data = data

    def fail(self, key, spec: Spec, got):
        raise SchemaError(key, "expected %s, got %r" % (spec.expectation(), got))

    def value_of(self, key: str):
        node = self.data
        for part in key.split("."):
            if not isinstance(node, dict) or node.get(part) is None:
                return None
            node = node[part]
        return node

    def bound(self, spec: Spec, which: str, index: int = 0):
        b = getattr(spec, which)
        if isinstance(b, list):
            return b[index]
        if isinstance(b, str):  # another key's value
            other = self.value_of(b)
            if other is None:
                other = self.schema.find(b).default
            return other if _is_number(other) else None
        return b

    def check_number(self, key, spec: Spec, v, integer=False):
        if not _is_number(v) or (integer and not isinstance(v, int)):
            self.fail(key, spec, v)
        lo, hi = self.bound(spec, "min"), self.bound(spec, "max")
        if (lo is not None and (v < lo or (spec.exclusive_min and v == lo))) or (
            hi is not None and v > hi
        ):
            shown = copy.copy(spec)
            for which, b in (("min", lo), ("max", hi)):
                if isinstance(getattr(spec, which), str):
                    setattr(shown, which, "%s = %g" % (getattr(spec, which), b))
            self.fail(key, shown, v)

    def check_leaf(self, key: str, spec: Spec, v):
        t = spec.type
        if t in ("number", "integer"):
            self.check_number(key, spec, v, integer=t == "integer")
        elif t == "bool":
            if not isinstance(v, bool):
                self.fail(key, spec, v)
        elif t == "enum":
            if v not in spec.choices:
                self.fail(key, spec, v)
        elif t == "string":
            if (
                not isinstance(v, str)
                or not v.strip()
                or any(ord(c) < 32 for c in v)
                or (spec.max_length and len(v) > spec.max_length)
            ):
                self.fail(key, spec, v)
        elif t == "vector":
            if not isinstance(v, list) or len(v) != spec.length:
                self.fail(key, spec, v)
            for i, e in enumerate(v):
                lo, hi = self.bound(spec, "min", i), self.bound(spec, "max", i)
                if not _is_number(e) or (lo is not None and e < lo) or (hi is not None and e > hi):
                    self.fail(key, spec, v)
        elif t == "vector_list":
            if not isinstance(v, list) or len(v) != spec.length:
                self.fail(key, spec, v)
            lo, hi = self.bound(spec, "min"), self.bound(spec, "max")
            for inner in v:
                if (
                    not isinstance(inner, list)
                    or len(inner) != spec.inner_length
                    or not all(_is_number(e) and lo <= e <= hi for e in inner)
                ):
                    self.fail(key, spec, v)

    def unknown(self, key: str, section: str, known: List[str]):
        name = key.rsplit(".", 1)[-1]
        near = difflib.get_close_matches(name, [k for k in known if k != "*"], n=1, cutoff=0.0)
        hint = (
            "did you mean %s?" % ((section + "." if section else "") + near[0])
            if near
            else "known keys here: %s" % ", ".join(k for k in known if k != "*")
        )
        raise SchemaError(key, "unknown key (a typo? %s)" % hint)

    def walk(self, node, prefix: str, station_type: Optional[str] = None) -> dict:
        """Checks one mapping of the file against the schema; returns it with defaults."""
        out = {}
        known = self.schema.sections(prefix)
        if not isinstance(node, dict):
            raise SchemaError(
                prefix or "(top level)", "expected a mapping of keys, got %r" % (node,)
            )
        for name, value in node.items():
            key = "%s.%s" % (prefix, name) if prefix else str(name)
            if not isinstance(name, str) or (name not in known and "*" not in known):
                self.unknown(key, prefix, known)
            if name not in known and not name.replace("_", "").isalnum():
                raise SchemaError(key, "names chosen by the site are snake_case words")
            spec = self.schema.find(key)
            if spec is not None and spec.station_types and station_type not in spec.station_types:
                raise SchemaError(
                    key,
                    "not a key of a %s station (only of %s)"
                    % (station_type, ", ".join(spec.station_types)),
                )
            if spec is not None and spec.type != "map":
                if value is None:
                    if spec.required:
                        raise SchemaError(
                            key, "missing; add it (see the shipped " "config/rascal.yaml)"
                        )
                    value = copy.deepcopy(spec.default)
                self.check_leaf(key, spec, value)
                out[name] = value
                continue
            if spec is not None and spec.type == "map":
                if not isinstance(value, dict) or not value:
                    raise SchemaError(key, "expected %s, got %r" % (spec.expectation(), value))
                for req in spec.required_names:
                    if req not in value:
                        raise SchemaError(
                            key + "." + req,
                            "missing; add it (see the shipped " "config/rascal.yaml)",
                        )
            st = station_type
            if prefix == "stations":
                st = value.get("type") if isinstance(value, dict) else None
            out[name] = self.walk(value, key, st)
        # what is not in the file: defaults, or an error naming the first required key
        for name in known:
            if name == "*" or name in out:
                continue
            key = "%s.%s" % (prefix, name) if prefix else name
            spec = self.schema.find(key)
            if spec is not None and spec.station_types and station_type not in spec.station_types:
                continue
            if spec is not None and spec.type != "map":
                if spec.required:
                    raise SchemaError(key, "missing; add it (see the shipped config/rascal.yaml)")
                out[name] = copy.deepcopy(spec.default)
            elif self._needs(key, station_type):
                raise SchemaError(key, "missing; add it (see the shipped config/rascal.yaml)")
            elif station_type is None:  # a section of defaults only
                out[name] = self.walk({}, key, station_type)
        return out

    def _needs(self, prefix: str, station_type: Optional[str]) -> bool:
        """Whether a section holds a required key (then it must be in the file)."""
        depth = len(prefix.split("."))
        for s in self.schema.specs:
            parts = s.key.split(".")
            if s.type == "map" and s.matches(prefix):
                return s.required
            if (
                len(parts) > depth
                and _prefix_matches(parts[:depth], prefix)
                and s.required
                and (not s.station_types or station_type in s.station_types)
            ):
                return True
        return False


def validate(data, schema: Optional[Schema] = None) -> dict:
    """The configuration checked against the schema, with defaults filled in.
    Raises SchemaError naming the first wrong key."""
    return _Validator(schema or builtin(), data).walk(data, "")
