"""Read G-code, or LinuxCNC's canonical machining calls, back into moves.

Two independent readers of what a program does:

- :func:`parse_gcode` tokenises the G-code subset camcad writes (and a bit
  more): G0–G3 in the XY plane, G20/G21, G90/G91, G90.1/G91.1, F, comments
  in parentheses or after ``;``.
- :func:`parse_canon` reads the canonical output of LinuxCNC's standalone
  interpreter ``rs274 -g FILE OUT`` (``STRAIGHT_TRAVERSE``, ``STRAIGHT_FEED``,
  ``ARC_FEED``, ``SET_FEED_RATE``).

Both start the machine at (0, 0, 0), as ``rs274`` does.
"""

from __future__ import annotations

import re

from camcad.export.gcode.moves import Move, MoveKind

__all__ = ["GcodeSyntaxError", "parse_canon", "parse_gcode"]

_INCH = 25.4
_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\([^)]*\)")
_CALL = re.compile(r"([A-Z_]+)\((.*)\)\s*$")


class GcodeSyntaxError(ValueError):
    """A G-code line the reader does not understand."""

    def __init__(self, line_no: int, line: str, why: str) -> None:
        super().__init__(f"line {line_no}: {why}: {line.strip()!r}")
        self.line_no = line_no


def _words(line: str) -> list[tuple[str, float, str]]:
    code = _COMMENT.sub(" ", line.split(";", 1)[0]).upper()
    if "(" in code or ")" in code:
        raise ValueError("unbalanced comment")
    rest = _WORD.sub(" ", code).strip()
    if rest and rest != "%":
        raise ValueError(f"cannot read {rest!r}")
    return [(m.group(1), float(m.group(2)), m.group(2)) for m in _WORD.finditer(code)]


def parse_gcode(text: str) -> tuple[Move, ...]:
    """Moves of a G-code program, in mm, absolute.

    Parameters
    ----------
    text
        The program.

    Returns
    -------
    tuple[Move, ...]
        One move per motion block; arcs carry their absolute centre. Notes
        are empty; ``feed`` is the modal feed [mm/min].

    Raises
    ------
    GcodeSyntaxError
        For unreadable words, a plane other than G17, R-format arcs, or a
        feed move before any feed rate.
    """
    pos = (0.0, 0.0, 0.0)
    mode: MoveKind | None = None
    scale = 1.0
    absolute = True
    ij_absolute = False
    feed = 0.0
    out: list[Move] = []
    for no, line in enumerate(text.splitlines(), start=1):
        try:
            words = _words(line)
        except ValueError as err:
            raise GcodeSyntaxError(no, line, str(err)) from None
        axes: dict[str, float] = {}
        motion = None
        for letter, value, raw in words:
            if letter == "G":
                if raw in ("0", "00"):
                    motion = MoveKind.RAPID
                elif raw in ("1", "01"):
                    motion = MoveKind.LINE
                elif raw in ("2", "02"):
                    motion = MoveKind.CW
                elif raw in ("3", "03"):
                    motion = MoveKind.CCW
                elif value == 20:
                    scale = _INCH
                elif value == 21:
                    scale = 1.0
                elif raw == "90":
                    absolute = True
                elif raw == "91":
                    absolute = False
                elif raw == "90.1":
                    ij_absolute = True
                elif raw == "91.1":
                    ij_absolute = False
                elif value in (18, 19):
                    raise GcodeSyntaxError(no, line, "only the XY plane (G17) is supported")
            elif letter in "XYZIJ":
                axes[letter] = value
            elif letter == "R":
                raise GcodeSyntaxError(no, line, "R-format arcs are not supported")
            elif letter == "F":
                feed = value * scale
        if motion is not None:
            mode = motion
        if not any(a in axes for a in "XYZ"):
            continue
        if mode is None:
            raise GcodeSyntaxError(no, line, "coordinates without a motion mode")
        end = list(pos)
        for k, a in enumerate("XYZ"):
            if a in axes:
                end[k] = axes[a] * scale if absolute else pos[k] + axes[a] * scale
        end_t = (end[0], end[1], end[2])
        if mode is not MoveKind.RAPID and feed <= 0.0:
            raise GcodeSyntaxError(no, line, "feed move with zero feed rate")
        center = None
        if mode.is_arc:
            if "I" not in axes and "J" not in axes:
                raise GcodeSyntaxError(no, line, "arc without I or J")
            i, j = axes.get("I", 0.0) * scale, axes.get("J", 0.0) * scale
            center = (i, j) if ij_absolute else (pos[0] + i, pos[1] + j)
        out.append(
            Move(
                kind=mode,
                start=pos,
                end=end_t,
                center=center,
                feed=0.0 if mode is MoveKind.RAPID else feed,
            )
        )
        pos = end_t
    return tuple(out)


def _floats(args: str) -> list[float]:
    return [float(a) for a in args.replace(" ", ",").split(",") if a]


def parse_canon(text: str) -> tuple[Move, ...]:
    """Moves from the canonical output of LinuxCNC's ``rs274 -g``.

    Parameters
    ----------
    text
        Lines like ``  25 N..... STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, …)``.

    Returns
    -------
    tuple[Move, ...]
        Rapids, lines and arcs in mm. ``ARC_FEED(x, y, cx, cy, rotation, z, …)``
        gives an arc about (cx, cy): counter-clockwise for rotation > 0,
        with |rotation| − 1 extra full turns.

    Raises
    ------
    ValueError
        If the program selects a plane other than XY or inch units.
    """
    pos = (0.0, 0.0, 0.0)
    feed = 0.0
    out: list[Move] = []
    for line in text.splitlines():
        body = line.split("N.....", 1)[-1].strip()
        m = _CALL.match(body)
        if not m:
            continue
        name, args = m.group(1), m.group(2)
        if name == "USE_LENGTH_UNITS" and "MM" not in args:
            raise ValueError(f"canonical output in {args}, expected CANON_UNITS_MM")
        if name == "SELECT_PLANE" and "XY" not in args:
            raise ValueError(f"canonical output selects {args}, expected CANON_PLANE_XY")
        if name == "SET_FEED_RATE":
            feed = _floats(args)[0]
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            v = _floats(args)
            end = (v[0], v[1], v[2])
            rapid = name == "STRAIGHT_TRAVERSE"
            kind = MoveKind.RAPID if rapid else MoveKind.LINE
            out.append(Move(kind=kind, start=pos, end=end, feed=0.0 if rapid else feed))
            pos = end
        elif name == "ARC_FEED":
            v = _floats(args)
            end = (v[0], v[1], v[5])
            rotation = int(v[4])
            kind = MoveKind.CCW if rotation > 0 else MoveKind.CW
            turns = abs(rotation) - 1  # a closed arc is one full turn already
            out.append(Move(kind=kind, start=pos, end=end, center=(v[2], v[3]), turns=turns, feed=feed))
            pos = end
    return tuple(out)
