"""A linear cam's bar: its closed outline as one B-spline, for the DXF, STEP and mesh writers.

The bar's outline is the certified clamped B-spline of the open edge (the
cam, from x0 at φ = 0 to x0 + L at φ = 2π) followed by three straight sides:
down the end at x0 + L to the bottom, back along the bottom, up the end at
x0 to the edge's start (:class:`~camcad.geometry.families.Bar`). The sides
are written as cubic Bézier pieces with collinear, evenly spaced poles
(exact straight lines) joined to the edge by triple knots (C⁰ corners), so
the whole outline is one closed clamped cubic B-spline: the STEP writer
(:mod:`camcad.export._step_brep`) extrudes it as it does a plate's profile,
and the mesh is its flattened polygon extruded by manifold3d.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import ExportError
from camcad.fit.curve import BSplineCurve

if TYPE_CHECKING:
    from camcad.fit.result import ProfileFit
    from camcad.geometry.families import Bar

__all__ = ["bar_outline"]


def _line_piece(a: FloatArray, b: FloatArray, degree: int) -> FloatArray:
    """Poles (p + 1, 2) of the straight segment a–b as a Bézier curve of degree p (evenly spaced: exact)."""
    t = np.linspace(0.0, 1.0, degree + 1)[:, None]
    out: FloatArray = (1.0 - t) * a + t * b
    return out


def bar_outline(fit: ProfileFit, bar: Bar) -> BSplineCurve:
    """The bar's closed outline as one clamped B-spline: the edge, then its three straight sides.

    The edge is ``fit.clamped`` on its domain [0, 1]; the sides take the
    parameters [1, 2], [2, 3], [3, 4]. The first and last poles are the
    edge's start, so the curve closes there (a corner).
    """
    edge = fit.clamped
    if edge.periodic or not math.isclose(edge.domain[0], 0.0) or not math.isclose(edge.domain[1], 1.0):
        raise ExportError("a bar's outline needs the clamped open edge of a linear cam on [0, 1]")
    p = edge.degree
    ctrl = np.asarray(edge.control_points, dtype=float)
    start, end = ctrl[0], ctrl[-1]
    corners = [end, np.array([end[0], bar.bottom]), np.array([start[0], bar.bottom]), start]
    poles = [ctrl]
    knots = [np.asarray(edge.knots, dtype=float)[:-1]]  # the edge's end knot keeps p copies: C⁰ there
    for k in range(3):
        poles.append(_line_piece(corners[k], corners[k + 1], p)[1:])
        knots.append(np.full(p, float(k + 2)))
    knots.append(np.array([4.0]))
    out = BSplineCurve(degree=p, knots=np.concatenate(knots), control_points=np.vstack(poles), periodic=False)
    readonly(out.knots, out.control_points)
    return out
