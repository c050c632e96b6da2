"""A design mapping written back as TOML text (the design file of an optimum).

Only what a camcad design file holds is written: tables of strings, booleans,
whole numbers, floats, lists and inline tables, and the array of ``[[motion]]``
tables. Floats are written in Python's shortest round-trip form, so the file
reads back to the very values; strings as TOML basic strings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = ["toml_text"]


_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _string(text: str) -> str:
    """A TOML basic string: quote, backslash and every control character (U+0000–U+001F, U+007F) escaped."""
    out = []
    for c in text:
        if c in _ESCAPES:
            out.append(_ESCAPES[c])
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04X}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"TOML design files hold finite numbers only, got {value!r}")
        return repr(value)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, Mapping):  # an inline table
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"cannot write {type(value).__name__} to a design file")


def _key(key: str) -> str:
    bare = key and all(c.isascii() and (c.isalnum() or c in "_-") for c in key)
    return key if bare else _string(key)


def toml_text(data: Mapping[str, Any], *, header: str = "") -> str:
    """TOML text of a design mapping, tables in the mapping's order, ``[[motion]]`` where it stands.

    Examples
    --------
    >>> data = {"cam": {"base_radius": 23.5, "name": "a"}, "motion": [{"kind": "dwell", "angle": 360.0}]}
    >>> print(toml_text(data))
    [cam]
    base_radius = 23.5
    name = "a"
    <BLANKLINE>
    [[motion]]
    kind = "dwell"
    angle = 360.0
    <BLANKLINE>
    """
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    if lines:
        lines.append("")
    for name, table in data.items():
        if isinstance(table, Mapping):
            lines.append(f"[{_key(name)}]")
            lines += [f"{_key(k)} = {_value(v)}" for k, v in table.items()]
            lines.append("")
        elif isinstance(table, list) and all(isinstance(t, Mapping) for t in table):
            for item in table:
                lines.append(f"[[{_key(name)}]]")
                lines += [f"{_key(k)} = {_value(v)}" for k, v in item.items()]
                lines.append("")
        else:
            raise TypeError(f"top-level key {name!r} of a design file must be a table or an array of tables")
    return "\n".join(lines)
