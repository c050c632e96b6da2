"""``profile.dxf`` of a barrel cam: the groove developed (unrolled) at the roller's pitch station.

In the developed plane (:mod:`camcad.geometry.barrel_limits`) x = u = t_p·φ
(+ the axis's offset y for an arm) along the barrel's circumference and
y = w = z along its axis, both walls and the pitch line are fitted as open
cubic B-splines (:func:`camcad.fit.fit_points`, within ``tolerance`` [mm] of
the exact points every 0.1°) and written as SPLINE entities on the layers
``WALL_UPPER``, ``WALL_LOWER`` and ``PITCH``; two LINEs mark the developed
barrel's ends (φ = 0 and 2π). A rib's faces
(:func:`~camcad.geometry.barrel.face_rollers`) go on the same two wall
layers, the follower's pitch line (between its rollers) on ``PITCH``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from camcad.export._ezdxf import import_ezdxf, save_reproducible
from camcad.fit import fit_points
from camcad.fit.result import ProfileFit
from camcad.geometry.barrel import BarrelFollower, BarrelOptions, WallSide, face_rollers
from camcad.geometry.barrel_limits import developed_walls
from camcad.motion.program import MotionProgram

__all__ = ["DevelopedGroove", "developed_groove", "write_developed_dxf"]


@dataclass(frozen=True, slots=True, kw_only=True)
class DevelopedGroove:
    """The fitted developed curves at ``station`` t_p [mm]: pitch line and both walls."""

    station: float
    pitch: ProfileFit
    upper: ProfileFit
    lower: ProfileFit


def developed_groove(
    program: MotionProgram,
    follower: BarrelFollower,
    options: BarrelOptions,
    *,
    tolerance: float = 0.005,
    step: float = math.radians(0.1),
) -> DevelopedGroove:
    """Fit the developed pitch line and walls (a rib's faces) at the pitch station within ``tolerance``."""
    n = math.ceil(math.tau / step)
    phi = np.linspace(0.0, math.tau, n + 1)
    motion = program.evaluate(phi)
    tp = options.pitch_station
    pitch = developed_walls(motion, follower, options, tp).pitch.point
    faces = []
    for roller, side in face_rollers(follower, options):
        walls = developed_walls(motion, roller, options, tp)
        faces.append((walls.upper if side is WallSide.UPPER else walls.lower).point)
    fits = [fit_points(np.asarray(c), closed=False, tolerance=tolerance) for c in (pitch, *faces)]
    return DevelopedGroove(station=options.pitch_station, pitch=fits[0], upper=fits[1], lower=fits[2])


def write_developed_dxf(groove: DevelopedGroove, path: str | os.PathLike[str], *, length: float) -> None:
    """Write the developed groove as DXF R2010 (mm); ``length`` [mm]: the barrel's, for the end lines."""
    ezdxf = import_ezdxf()
    doc = ezdxf.new("R2010", units=4)  # 4: millimetres
    msp = doc.modelspace()
    for layer, fit in (("PITCH", groove.pitch), ("WALL_UPPER", groove.upper), ("WALL_LOWER", groove.lower)):
        doc.layers.add(layer)
        curve = fit.clamped
        spline = msp.add_spline(dxfattribs={"layer": layer})
        spline.dxf.degree = curve.degree
        spline.control_points = [(float(x), float(y), 0.0) for x, y in curve.control_points]
        spline.knots = [float(k) for k in curve.knots]
    doc.layers.add("BARREL_ENDS")
    span = math.tau * groove.station
    for x in (0.0, span):
        msp.add_line((x, 0.0), (x, length), dxfattribs={"layer": "BARREL_ENDS"})
    save_reproducible(doc, path)
