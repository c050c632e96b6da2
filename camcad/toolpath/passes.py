"""Assemble passes: approach, plunge, tangent leads, contour with tabs, retract; the bore helix.

Safe-height rule: rapids run only at or above the safe height. The tool
reaches cutting depth by a plunge at the plunge feed, off the part, and
leaves it by a feed move up to the safe height.
"""

from __future__ import annotations

import math
from typing import Any

from camcad.errors import DesignError
from camcad.knobs import Knob
from camcad.toolpath.contour import Contour, round_mm, round_point
from camcad.toolpath.moves import Move, MoveKind
from camcad.toolpath.spec import Direction, GcodeSpec

__all__ = ["Program", "check_bore", "cut_contour", "lead_points", "mill_bore"]

TWO_PI = 2.0 * math.pi
_HELIX_RAMP = math.radians(3.0)  # bore helix ramp angle
_MIN_PITCH = 0.1  # × tool diameter: the finest helix pitch per turn


class Program:
    """Accumulates moves from a known position."""

    def __init__(self, z: float) -> None:
        self.moves: list[Move] = []
        self.pos: tuple[float, float, float] = (0.0, 0.0, z)
        self.note = ""

    def comment(self, text: str) -> None:
        """Attach ``text`` to the next move as its comment."""
        self.note = text if not self.note else f"{self.note}\n{text}"

    def _add(self, kind: MoveKind, end: tuple[float, float, float], **kw: Any) -> None:
        if end == self.pos and kind is not MoveKind.CW and kind is not MoveKind.CCW:
            return
        self.moves.append(Move(kind=kind, start=self.pos, end=end, note=self.note, **kw))
        self.note = ""
        self.pos = end

    def rapid(self, x: float | None = None, y: float | None = None, z: float | None = None) -> None:
        """Rapid move to (x, y, z) [mm]; an axis left out keeps its position."""
        px, py, pz = self.pos
        self._add(MoveKind.RAPID, (px if x is None else x, py if y is None else y, pz if z is None else z))

    def line(
        self, x: float | None = None, y: float | None = None, z: float | None = None, *, feed: float
    ) -> None:
        """Straight feed move to (x, y, z) [mm] at ``feed`` [mm/min]; an axis left out keeps its position."""
        px, py, pz = self.pos
        end = (px if x is None else x, py if y is None else y, pz if z is None else round_mm(z))
        self._add(MoveKind.LINE, end, feed=feed)

    def arc(
        self, kind: MoveKind, x: float, y: float, center: tuple[float, float], *,
        feed: float, z: float | None = None,
    ) -> None:  # fmt: skip
        """Arc move of ``kind`` (CW or CCW) to (x, y) about ``center`` [mm], optionally helical to z."""
        end = (x, y, self.pos[2] if z is None else round_mm(z))
        self._add(kind, end, center=center, feed=feed)


def lead_points(contour: Contour, radius: float, samples: int = 24) -> list[tuple[float, float]]:
    """Points [mm] along both quarter-circle leads of ``contour`` for a lead radius [mm]."""
    out = []
    for tangent, entering in ((contour.start_tangent, True), (contour.end_tangent, False)):
        far, c, _ = _lead_arc(contour.start, tangent, contour.normal, radius, entering=entering)
        a0 = math.atan2(contour.start[1] - c[1], contour.start[0] - c[0])
        a1 = math.atan2(far[1] - c[1], far[0] - c[0])
        turn = (a1 - a0 + math.pi) % TWO_PI - math.pi  # a quarter turn either way
        for k in range(1, samples + 1):
            a = a0 + turn * k / samples
            out.append((c[0] + radius * math.cos(a), c[1] + radius * math.sin(a)))
    return out


def _lead_arc(
    point: tuple[float, float], tangent: tuple[float, float], normal: tuple[float, float],
    radius: float, *, entering: bool,
) -> tuple[tuple[float, float], tuple[float, float], MoveKind]:  # fmt: skip
    """Quarter-circle lead tangent to the contour at ``point``, on the outward side.

    Returns the far end of the lead [mm], its centre and its turning direction.
    """
    c = (point[0] + radius * normal[0], point[1] + radius * normal[1])
    s = -1.0 if entering else 1.0
    far = (c[0] + s * radius * tangent[0], c[1] + s * radius * tangent[1])
    a, b = (far, point) if entering else (point, far)
    cross = (a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0])
    return round_point(far), c, MoveKind.CCW if cross > 0.0 else MoveKind.CW


def cut_contour(
    prog: Program, contour: Contour, spec: GcodeSpec, z: float, tab_top: float | None,
    lead_radius: float, label: str,
) -> None:  # fmt: skip
    """One pass: approach, plunge off the part, lead in, contour (with tabs), lead out, retract."""
    start = contour.start
    lead_in, c_in, k_in = _lead_arc(start, contour.start_tangent, contour.normal, lead_radius, entering=True)
    lead_out, c_out, k_out = _lead_arc(
        start, contour.end_tangent, contour.normal, lead_radius, entering=False
    )
    prog.comment(label)
    prog.rapid(*lead_in)
    prog.rapid(z=spec.safe_height)
    prog.line(z=z, feed=spec.plunge_feed)
    ij = round_point((c_in[0] - lead_in[0], c_in[1] - lead_in[1]))
    prog.arc(k_in, *start, (lead_in[0] + ij[0], lead_in[1] + ij[1]), feed=spec.feed)
    tabs = tab_top is not None and z < tab_top
    riding = False
    for st in contour.tabbed_steps() if tabs else contour.steps:
        if tabs and st.tab and not riding:
            prog.line(z=tab_top, feed=spec.feed)
            riding = True
        elif tabs and not st.tab and riding:
            prog.line(z=z, feed=spec.plunge_feed)
            riding = False
        if st.center is None:
            prog.line(*st.end, feed=spec.feed)
        else:
            prog.arc(st.kind, *st.end, st.center, feed=spec.feed)
    if riding:
        prog.line(z=z, feed=spec.plunge_feed)
    ij = round_point((c_out[0] - start[0], c_out[1] - start[1]))
    prog.arc(k_out, *lead_out, (start[0] + ij[0], start[1] + ij[1]), feed=spec.feed)
    prog.line(z=spec.safe_height, feed=spec.feed)


def check_bore(spec: GcodeSpec, bore: float) -> None:
    """Raise unless the bore [mm] can be helix-milled with the tool.

    Raises
    ------
    DesignError
        When there is no bore, or it is not larger than the tool.
    """
    if bore <= 0.0:
        raise DesignError(Knob.MILL_BORE, "the cam has no bore (bore = 0); set mill_bore = false")
    if bore <= spec.tool_diameter:
        raise DesignError(
            Knob.MILL_BORE,
            f"the bore Ø{bore:g} mm is not larger than the tool Ø{spec.tool_diameter:g} mm, "
            "so it cannot be helix-milled; use a smaller tool or drill the bore",
        )


def mill_bore(prog: Program, spec: GcodeSpec, bore: float, depth: float) -> None:
    """Helical interpolation down the bore, then a full circle at the finished radius."""
    check_bore(spec, bore)
    r = spec.tool_radius
    finish = bore / 2.0 - r
    rough = finish - spec.stock_to_leave if finish - spec.stock_to_leave > 0.1 * r else finish
    climb = spec.direction is Direction.CLIMB
    kind = MoveKind.CCW if climb else MoveKind.CW  # inside: climb runs counter-clockwise
    # a gentle ramp, but no endless helix when the tool nearly fills the bore
    pitch = min(spec.step_down, max(TWO_PI * rough * math.tan(_HELIX_RAMP), _MIN_PITCH * spec.tool_diameter))
    turns = max(1, math.ceil(depth / pitch - 1e-9))
    x0 = round_mm(rough)
    prog.comment(
        f"bore D{bore:.3f}: helix of {turns} turns at r{rough:.4f}"
        + (f", finish at r{finish:.4f}" if rough != finish else "")
    )
    prog.rapid(x0, 0.0)
    prog.rapid(z=spec.safe_height)
    prog.line(z=0.0, feed=spec.plunge_feed)
    for t in range(1, turns + 1):
        prog.arc(kind, x0, 0.0, (0.0, 0.0), feed=spec.feed, z=-depth * t / turns)
    prog.arc(kind, x0, 0.0, (0.0, 0.0), feed=spec.feed)  # level full turn at the bottom
    if rough != finish:
        xf = round_mm(finish)
        prog.line(xf, 0.0, feed=spec.feed)
        prog.arc(kind, xf, 0.0, (0.0, 0.0), feed=spec.feed)
        prog.line(x0, 0.0, feed=spec.feed)
    prog.line(z=spec.safe_height, feed=spec.feed)
