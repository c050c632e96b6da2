"""Machine moves: the toolpath's vocabulary, shared by the planner, writer and parser.

A move is one block of motion: a rapid, a straight feed, or a clockwise or
counter-clockwise arc (possibly helical) about a centre. Coordinates are in
the program frame (G54 on the cam axis, Z0 on top of the stock) in mm.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

__all__ = ["Move", "MoveKind", "arc_sweep", "move_length", "path_length"]

Point3 = tuple[float, float, float]

_FULL_TURN_EPS = 1e-9  # mm: an arc whose end meets its start is a full turn


class MoveKind(enum.Enum):
    """Kinds of motion block, valued by their G word."""

    RAPID = "G0"
    LINE = "G1"
    CW = "G2"
    CCW = "G3"

    @property
    def is_arc(self) -> bool:
        """Whether the move is a circular or helical arc."""
        return self in (MoveKind.CW, MoveKind.CCW)


@dataclass(frozen=True, slots=True, kw_only=True)
class Move:
    """One motion block.

    Attributes
    ----------
    kind
        Rapid, line or arc.
    start, end
        (x, y, z) where the move starts and ends [mm].
    center
        Arc centre (x, y) [mm]; None for rapids and lines.
    turns
        Extra full turns of an arc beyond the first sweep (helices).
    feed
        Feed rate [mm/min]; 0 for rapids.
    note
        A comment written on its own line before the block ("" for none).
    """

    kind: MoveKind
    start: Point3
    end: Point3
    center: tuple[float, float] | None = None
    turns: int = 0
    feed: float = 0.0
    note: str = ""

    @property
    def sweep(self) -> float:
        """Signed swept angle of an arc [rad] (+ counter-clockwise); 0 otherwise."""
        return arc_sweep(self) if self.kind.is_arc else 0.0

    @property
    def radii(self) -> tuple[float, float]:
        """Distance from the centre to the start and to the end [mm] (arcs only)."""
        if self.center is None:
            return (0.0, 0.0)
        cx, cy = self.center
        return (
            math.hypot(self.start[0] - cx, self.start[1] - cy),
            math.hypot(self.end[0] - cx, self.end[1] - cy),
        )

    @property
    def length(self) -> float:
        """Path length of the move [mm]."""
        return move_length(self)


def arc_sweep(move: Move) -> float:
    """Signed sweep [rad] of an arc move; a closed arc is a full turn, plus ``turns`` more."""
    assert move.center is not None
    cx, cy = move.center
    a0 = math.atan2(move.start[1] - cy, move.start[0] - cx)
    a1 = math.atan2(move.end[1] - cy, move.end[0] - cx)
    closed = math.hypot(move.end[0] - move.start[0], move.end[1] - move.start[1]) <= _FULL_TURN_EPS
    turn = 2.0 * math.pi if closed else (a1 - a0) % (2.0 * math.pi)
    if move.kind is MoveKind.CW:
        turn = 2.0 * math.pi if closed else 2.0 * math.pi - turn
    turn += 2.0 * math.pi * move.turns
    return turn if move.kind is MoveKind.CCW else -turn


def move_length(move: Move) -> float:
    """Length [mm] of a line, rapid or (helical) arc."""
    dz = move.end[2] - move.start[2]
    if not move.kind.is_arc:
        return math.dist(move.start, move.end)
    r0, r1 = move.radii
    planar = abs(arc_sweep(move)) * 0.5 * (r0 + r1)
    return math.hypot(planar, dz)


def path_length(moves: Iterable[Move], kinds: Sequence[MoveKind] | None = None) -> float:
    """Total length [mm] of the moves (of the given kinds only, when given)."""
    return sum(m.length for m in moves if kinds is None or m.kind in kinds)
