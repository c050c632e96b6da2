"""Where in a TOML text a value the TOML parser cannot read sits: its field path."""

from __future__ import annotations

from collections.abc import Callable

from camcad.design.rules import _key

MAX_NESTING = 100
_MAX_DIGITS = 4300  # sys.get_int_max_str_digits() default


def _nesting(value: str) -> tuple[int, int]:
    """Deepest and final bracket nesting of TOML value text; strings and comments are skipped."""
    depth = deepest = 0
    quote = ""
    i = 0
    while i < len(value):
        c = value[i]
        if quote:
            if c == "\\" and quote == '"':
                i += 1
            elif c == quote:
                quote = ""
        elif c in "\"'":
            quote = c
        elif c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth -= 1
        elif c == "#":
            nl = value.find("\n", i)
            i = len(value) if nl < 0 else nl
        i += 1
    return deepest, depth


def _find_value(text: str, bad: Callable[[str], bool]) -> str:
    """The field path (``cam.name``) of the first value whose text makes ``bad`` true, or ``""``.

    A line-based reading of the TOML structure, good enough to name the field
    in a file that the TOML parser itself cannot read.
    """
    table, motion, key, value = "", -1, "", ""
    for line in text.splitlines():
        stripped = line.strip()
        if key:
            value += "\n" + line
        elif stripped.startswith("["):
            name = stripped.split("#")[0].strip().strip("[]").strip()
            motion += stripped.startswith("[[") and name == "motion"
            table = f"motion[{motion}]" if name == "motion" else name
            continue
        elif "=" in stripped and not stripped.startswith("#"):
            raw, _, value = stripped.partition("=")
            key = _key(raw.strip().strip("\"'"))
        else:
            continue
        if _nesting(value)[1] <= 0:
            if bad(value):
                return f"{table}.{key}" if table else key
            key = ""
    return (f"{table}.{key}" if table else key) if key and bad(value) else ""
