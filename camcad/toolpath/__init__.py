"""The toolpath stage: plan the milling of the cam plate on the exact offset curve, and prove it.

- :func:`plan_toolpath` fits the exact tool-centre path ``cam.offset_curve(φ, r)``
  with arc splines (:mod:`camcad.toolpath.arcs`), lays out roughing and
  finishing passes, leads, tabs and the bore, and raises
  :class:`~camcad.errors.GougeError` when the tool does not fit
  (:func:`camcad.geometry.tool.check_tool`).
- :func:`check_toolpath` proves a program's moves (planned, or read back by
  :mod:`camcad.export.gcode.parse`) against the cam.
- :class:`Move` and :class:`MoveKind` are the vocabulary shared with the
  G-code writer and readers in :mod:`camcad.export.gcode`.

Planning is a stage like the fit: it writes nothing; :mod:`camcad.export.gcode`
turns a :class:`Toolpath` into G-code text.

>>> from camcad.design import parse_design
>>> from camcad.geometry.cam import Cam
>>> design = parse_design({
...     "cam": {"base_radius": 40, "thickness": 8},
...     "follower": {"type": "translating-roller", "roller_radius": 10},
...     "motion": [
...         {"kind": "rise", "angle": 180, "lift": 10, "law": "cycloidal"},
...         {"kind": "return", "angle": 180, "lift": 10, "law": "cycloidal"},
...     ],
... })
>>> cam = Cam.from_design(design)
>>> from camcad.toolpath import plan_toolpath
>>> toolpath = plan_toolpath(cam, design.gcode, name="demo", thickness=design.cam.thickness)
>>> toolpath.max_deviation <= design.gcode.tolerance
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camcad._lazy import lazy_names

if TYPE_CHECKING:
    from camcad.toolpath.arcs import Pieces, biarc_pieces, fit_arc_spline, measure_deviation
    from camcad.toolpath.moves import Move, MoveKind
    from camcad.toolpath.plan import RAPID_RATE, Toolpath, plan_toolpath
    from camcad.toolpath.verify import ToolpathCheck, check_toolpath

_HOME = {
    "Pieces": "camcad.toolpath.arcs",
    "biarc_pieces": "camcad.toolpath.arcs",
    "fit_arc_spline": "camcad.toolpath.arcs",
    "measure_deviation": "camcad.toolpath.arcs",
    "Move": "camcad.toolpath.moves",
    "MoveKind": "camcad.toolpath.moves",
    "RAPID_RATE": "camcad.toolpath.plan",
    "Toolpath": "camcad.toolpath.plan",
    "plan_toolpath": "camcad.toolpath.plan",
    "ToolpathCheck": "camcad.toolpath.verify",
    "check_toolpath": "camcad.toolpath.verify",
}
"""Where each public name lives: loaded on first use, so ``camcad.toolpath.spec`` (read by
``camcad.design`` for every design) loads neither the planner nor the verifier (SciPy)."""


__getattr__ = lazy_names(__name__, _HOME)

__all__ = [
    "RAPID_RATE",
    "Move",
    "MoveKind",
    "Pieces",
    "Toolpath",
    "ToolpathCheck",
    "biarc_pieces",
    "check_toolpath",
    "fit_arc_spline",
    "measure_deviation",
    "plan_toolpath",
]
