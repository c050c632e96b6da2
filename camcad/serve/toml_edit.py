"""The design file edited in place: only the keys the form changed, comments and layout kept.

The designer saves by editing the text it loaded with tomlkit (a round-trip
TOML library): a changed value is replaced where it stands (its trailing
comment kept), a key cleared in the form is removed, a key set that the file
did not have is added at the end of its table, a table the design no longer
has is removed and a new one is appended; ``[[motion]]`` tables added or deleted in
the designer are appended or removed at the end of the array. Everything else (comments, blank
lines, key order, the spelling of unchanged numbers) is the file's own text.
:func:`edit_toml` then reads its answer back with tomllib and refuses to
return a text that does not hold exactly the new design.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any

import tomlkit
from tomlkit.exceptions import TOMLKitError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["edit_toml"]


def _same(a: Any, b: Any) -> bool:
    """Equal values (55 and 55.0 alike: the file keeps its own spelling), a bool never equal to a number."""
    return isinstance(a, bool) == isinstance(b, bool) and a == b


def _edit_table(table: Any, old: Mapping[str, Any], new: Mapping[str, Any]) -> None:
    for key in [k for k in old if k not in new]:
        del table[key]
    for key, value in new.items():
        if key not in old or not _same(old[key], value):
            table[key] = value


def edit_toml(text: str, old: Mapping[str, Any], new: Mapping[str, Any]) -> str:
    r"""``text`` (which reads as ``old``) edited to read as ``new``, changing only the keys that differ.

    Parameters
    ----------
    text
        The design file's text as loaded.
    old
        ``tomllib.loads(text)``.
    new
        The design mapping to write. An array of tables is edited table by
        table in order; tables past the old count are appended, those past the
        new count removed (with the comments inside them).

    Raises
    ------
    ValueError
        When the edit cannot be made in place (the result would not read back as ``new``).

    Examples
    --------
    >>> text = '[cam]\nbase_radius = 40.0  # mm\nname = "a"\n'
    >>> old = {"cam": {"base_radius": 40.0, "name": "a"}}
    >>> print(edit_toml(text, old, {"cam": {"base_radius": 52.5, "name": "a"}}))
    [cam]
    base_radius = 52.5  # mm
    name = "a"
    <BLANKLINE>
    """
    try:
        doc = tomlkit.parse(text)
        for name in [k for k in old if k not in new]:
            del doc[name]
        for name, value in new.items():
            if name not in old:
                doc[name] = value
            elif isinstance(value, list) and isinstance(old[name], list):
                tables = doc[name]
                for i, (before, after) in enumerate(zip(old[name], value, strict=False)):
                    _edit_table(tables[i], before, after)
                for _ in range(len(value), len(old[name])):  # segments deleted: drop the last tables
                    del tables[len(value)]
                for after in value[len(old[name]) :]:  # segments added: new tables at the end
                    table = tomlkit.table()
                    table.update(after)
                    table.add(tomlkit.nl())
                    tables.append(table)
            elif isinstance(value, Mapping) and isinstance(old[name], Mapping):
                _edit_table(doc[name], old[name], value)
            elif not _same(old[name], value):
                doc[name] = value
        out = tomlkit.dumps(doc)
        ok = tomllib.loads(out) == new
    except (TOMLKitError, tomllib.TOMLDecodeError, KeyError, TypeError) as err:
        raise ValueError(f"cannot edit the file in place: {err}") from None
    if not ok:
        raise ValueError("cannot edit the file in place: the edited text does not read back as the design")
    return out
