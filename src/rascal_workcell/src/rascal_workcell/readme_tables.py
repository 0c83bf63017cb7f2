"""Parameter tables of the package READMEs, generated from the schema.

A README holds, for each node it documents, the two lines
    <!-- BEGIN parameters <reader> -->
    <!-- END parameters -->
and `update()` writes between them one row per key the schema lists for that reader:
name (type, unit, default, range) and its description. Tests fail when a README is stale
(`rosrun rascal_workcell parameter_tables` rewrites them).
"""

import re
from typing import Optional

from rascal_workcell.schema import Schema, Spec, builtin

MARKER = re.compile(r"(<!-- BEGIN parameters (\w+) -->\n)(.*?)(<!-- END parameters -->)", re.S)


def _default(spec: Spec) -> str:
    if spec.required:
        return "required"
    if spec.default is None:
        return "none"  # optional, nothing in its place (a station without markers)
    return "`%s`" % (
        spec.default if not isinstance(spec.default, bool) else str(spec.default).lower()
    )


def _range(spec: Spec) -> str:
    if spec.type in ("number", "integer"):
        return spec.range_text()
    if spec.type == "enum":
        return " \\| ".join(spec.choices)
    if spec.type in ("vector", "vector_list"):
        text = spec.shape
        if spec.min is not None and not isinstance(spec.min, list):
            text += ", each in " + spec.range_text()
        return text
    if spec.type == "map":
        return "names" + (" incl. " + ", ".join(spec.required_names) if spec.required_names else "")
    return ""


def table(reader: str, schema: Optional[Schema] = None) -> str:
    schema = schema or builtin()
    rows = [
        "| parameter | type | unit | default | range | what it sets |",
        "|---|---|---|---|---|---|",
    ]
    for s in schema.for_reader(reader):
        rows.append(
            "| `%s` | %s | %s | %s | %s | %s |"
            % (
                s.key,
                s.type,
                s.unit or "",
                _default(s),
                _range(s),
                s.description.replace("|", "\\|"),
            )
        )
    return "\n".join(rows) + "\n"


def render(text: str, schema: Optional[Schema] = None) -> str:
    """The README text with every marked table regenerated."""
    return MARKER.sub(lambda m: m.group(1) + table(m.group(2), schema) + m.group(4), text)


def update(path: str, schema: Optional[Schema] = None) -> bool:
    """Rewrite the tables of one README; True when it changed."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    new = render(text, schema)
    if new != text:
        with open(path, "w", encoding="utf-8") as f:
            f.write(new)
    return new != text
