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
from dataclasses import dataclass

from camcad.errors import GcodeSyntaxError
from camcad.toolpath.moves import Move, MoveKind

__all__ = ["parse_canon", "parse_gcode"]

_INCH = 25.4
_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\([^)]*\)")
_CALL = re.compile(r"([A-Z_]+)\((.*)\)\s*$")


class _LineError(Exception):
    """Why one line cannot be read (turned into a :class:`GcodeSyntaxError` with its line)."""


_MOTION = {
    "0": MoveKind.RAPID, "00": MoveKind.RAPID, "1": MoveKind.LINE, "01": MoveKind.LINE,
    "2": MoveKind.CW, "02": MoveKind.CW, "3": MoveKind.CCW, "03": MoveKind.CCW,
}  # fmt: skip


@dataclass(slots=True)
class _Modal:
    """The reader's machine state: position [mm] and the modal words in force."""

    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mode: MoveKind | None = None
    scale: float = 1.0  # mm per program unit (G20: 25.4)
    absolute: bool = True  # G90 / G91
    ij_absolute: bool = False  # G90.1 / G91.1
    feed: float = 0.0  # mm/min


def _words(line: str) -> list[tuple[str, float, str]]:
    code = _COMMENT.sub(" ", line.split(";", 1)[0]).upper()
    if "(" in code or ")" in code:
        raise _LineError("unbalanced comment")
    rest = _WORD.sub(" ", code).strip()
    if rest and rest != "%":
        raise _LineError(f"cannot read {rest!r}")
    return [(m.group(1), float(m.group(2)), m.group(2)) for m in _WORD.finditer(code)]


def _g_word(state: _Modal, raw: str, value: float) -> MoveKind | None:
    """Apply one G word to the modal state; return the motion mode it selects, if any."""
    if raw in _MOTION:
        return _MOTION[raw]
    if value == 20:
        state.scale = _INCH
    elif value == 21:
        state.scale = 1.0
    elif raw in ("90", "91"):
        state.absolute = raw == "90"
    elif raw in ("90.1", "91.1"):
        state.ij_absolute = raw == "90.1"
    elif value in (18, 19):
        raise _LineError("only the XY plane (G17) is supported")
    return None


def _read_words(
    state: _Modal, words: list[tuple[str, float, str]]
) -> tuple[MoveKind | None, dict[str, float]]:
    """Apply a line's words in order; return the motion mode it selects and its axis words."""
    axes: dict[str, float] = {}
    motion = None
    for letter, value, raw in words:
        if letter == "G":
            kind = _g_word(state, raw, value)
            motion = kind if kind is not None else motion
        elif letter in "XYZIJ":
            axes[letter] = value
        elif letter == "R":
            raise _LineError("R-format arcs are not supported")
        elif letter == "F":
            state.feed = value * state.scale
    return motion, axes


def _move(state: _Modal, axes: dict[str, float]) -> Move:
    """The motion block of a line with axis words, in the current mode; advances the position."""
    mode = state.mode
    if mode is None:
        raise _LineError("coordinates without a motion mode")
    pos = state.pos
    end = list(pos)
    for k, a in enumerate("XYZ"):
        if a in axes:
            end[k] = axes[a] * state.scale if state.absolute else pos[k] + axes[a] * state.scale
    end_t = (end[0], end[1], end[2])
    if mode is not MoveKind.RAPID and state.feed <= 0.0:
        raise _LineError("feed move with zero feed rate")
    center = None
    if mode.is_arc:
        if "I" not in axes and "J" not in axes:
            raise _LineError("arc without I or J")
        i, j = axes.get("I", 0.0) * state.scale, axes.get("J", 0.0) * state.scale
        center = (i, j) if state.ij_absolute else (pos[0] + i, pos[1] + j)
    state.pos = end_t
    feed = 0.0 if mode is MoveKind.RAPID else state.feed
    return Move(kind=mode, start=pos, end=end_t, center=center, feed=feed)


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
    state = _Modal()
    out: list[Move] = []
    for no, line in enumerate(text.splitlines(), start=1):
        try:
            motion, axes = _read_words(state, _words(line))
            if motion is not None:
                state.mode = motion
            if any(a in axes for a in "XYZ"):
                out.append(_move(state, axes))
        except _LineError as err:
            raise GcodeSyntaxError(no, line, str(err)) from None
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
