"""The text of a CMM export: points x, y [mm] or polar angle [°] and radius [mm], by its header.

The first line that is not blank and not a comment (``#``) is the header; it
names the columns, separated by commas, semicolons, tabs or spaces, in any
letter case, with an optional unit (``x_mm``, ``X [mm]``, ``angle_deg``,
``A(deg)``):

- ``x`` and ``y``: Cartesian points [mm] in any frame;
- ``angle`` (or ``a``, ``theta``) and ``radius`` (or ``r``): polar points,
  angle in degrees, radius in mm, about any centre.

Other columns (``z``, ``i``, ``j``, ``k``, a point name) are ignored. A unit
other than mm and degrees (``x_in``, ``[inch]``, ``rad``) is refused: convert
the file. Each following line is one point; every error names the line
(1-based). Nothing here reads a file: :func:`camcad.design.table_file.read_table_file`
does, by the point tables' rules.
"""

from __future__ import annotations

import math
import re

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignError
from camcad.inspect.measure import points_from_polar

__all__ = ["MAX_MEASURED_POINTS", "MeasuredPoints", "parse_measured"]

MAX_MEASURED_POINTS = 200_000
"""Most points read from one file (a dense scan of a large cam holds tens of thousands)."""

_DELIMITED = re.compile(r"\s*[,;\t]\s*")
_SPACED = re.compile(r"\s+")
_NAME = re.compile(r"^\s*([A-Za-z]+)\s*(?:[_\s]*[\[(]?\s*([A-Za-z°]*)\s*[\])]?)?\s*$")
_ROLES = {
    "x": "x",
    "y": "y",
    "angle": "angle",
    "a": "angle",
    "theta": "angle",
    "radius": "radius",
    "r": "radius",
}
_UNITS = {
    "x": ("", "mm"),
    "y": ("", "mm"),
    "angle": ("", "deg", "°", "degree", "degrees"),
    "radius": ("", "mm"),
}


class MeasuredPoints:
    """Points (m, 2) [mm], the 1-based file line of each, and the layout read (``"x, y"`` or ``"polar"``)."""

    __slots__ = ("layout", "lines", "points")

    def __init__(self, points: FloatArray, lines: list[int], layout: str) -> None:
        self.points, self.lines, self.layout = points, lines, layout


def _bad(where: str, line: int, message: str) -> DesignError:
    return DesignError(where, f"line {line}: {message}")


def _roles(header: list[str], where: str, line: int) -> dict[str, int]:
    found: dict[str, int] = {}
    for i, cell in enumerate(header):
        m = _NAME.match(cell)
        if m is None:
            continue
        role = _ROLES.get(m[1].lower())
        if role is None:
            continue
        unit = (m[2] or "").lower()
        if unit not in _UNITS[role]:
            wanted = "degrees" if role == "angle" else "mm"
            raise _bad(
                where, line, f"column {cell.strip()!r} is in {unit!r}; allowed: {wanted} (convert the file)"
            )
        if role in found:
            raise _bad(where, line, f"two columns name {role}; allowed: one each")
        found[role] = i
    if {"x", "y"} <= set(found):
        return {"x": found["x"], "y": found["y"]}
    if {"angle", "radius"} <= set(found):
        return {"angle": found["angle"], "radius": found["radius"]}
    shown = ", ".join(c.strip() for c in header)[:120]
    raise _bad(
        where,
        line,
        f"header {shown!r} names no point columns; allowed: x, y (mm) or angle (degrees), radius (mm)",
    )


def parse_measured(text: str, *, where: str) -> MeasuredPoints:
    """The points of a CMM export's text (see the module notes); ``where`` names the file in errors.

    Raises
    ------
    DesignError
        Naming ``where`` and the line: no header, unknown or non-mm units, a
        cell that is not a finite number, a short line, too many points.
    """
    rows: list[tuple[float, float]] = []
    lines: list[int] = []
    roles: dict[str, int] | None = None
    split = _SPACED
    for number, raw in enumerate(text.splitlines(), start=1):
        body = raw.split("#", 1)[0].strip()
        if not body:
            continue
        if roles is None:
            split = _DELIMITED if re.search(r"[,;\t]", body) else _SPACED  # the header's separator
            roles = _roles(split.split(body), where, number)
            continue
        cells = split.split(body)
        idx = list(roles.values())
        if len(cells) <= max(idx):
            raise _bad(
                where, number, f"{len(cells)} values; allowed: at least {max(idx) + 1} as in the header"
            )
        values = []
        for name, i in roles.items():
            try:
                v = float(cells[i])
            except ValueError:
                raise _bad(where, number, f"{name} {cells[i][:40]!r} is not a number") from None
            if not math.isfinite(v):
                raise _bad(where, number, f"{name} {cells[i][:40]!r} is not finite; allowed: numbers")
            values.append(v)
        rows.append((values[0], values[1]))
        lines.append(number)
        if len(rows) > MAX_MEASURED_POINTS:
            raise _bad(where, number, f"more than {MAX_MEASURED_POINTS} points; allowed: at most that many")
    if roles is None:
        raise DesignError(
            where, "no header line; allowed: a header naming x, y or angle, radius, then one point a line"
        )
    arr = np.array(rows, dtype=float).reshape(-1, 2)
    if "angle" in roles:
        return MeasuredPoints(points_from_polar(arr[:, 0], arr[:, 1]), lines, "polar")
    return MeasuredPoints(arr, lines, "x, y")
