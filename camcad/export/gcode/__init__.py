"""G-code for the cam plate: biarc toolpaths, passes, leads, tabs, dialects, a reader and a proof.

- :func:`plan_toolpath` fits the exact tool-centre path ``cam.offset(φ, r)``
  with biarcs, lays out roughing and finishing passes, leads, tabs and the
  bore, and raises :class:`~camcad.errors.GougeError` when the tool does not fit.
- :func:`render_gcode` writes it in a dialect (``linuxcnc``, ``grbl``,
  ``generic``); :meth:`Toolpath.summary` gives the figures for summary.json.
- :func:`parse_gcode` and :func:`parse_canon` (LinuxCNC ``rs274`` output)
  read programs back, and :func:`check_toolpath` proves them against the cam.

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
>>> toolpath = plan_toolpath(cam, design.gcode, name="demo", thickness=design.cam.thickness)
>>> toolpath.max_deviation <= design.gcode.tolerance
True
>>> render_gcode(toolpath).splitlines()[0]
'(camcad G-code: demo)'
"""

from camcad.export.gcode.arcspline import fit_curve
from camcad.export.gcode.biarc import Pieces, biarc_pieces, measure_deviation
from camcad.export.gcode.dialects import DIALECTS, DialectRules, dialect_rules
from camcad.export.gcode.moves import Move, MoveKind
from camcad.export.gcode.parse import GcodeSyntaxError, parse_canon, parse_gcode
from camcad.export.gcode.toolpath import Toolpath, check_gouge, plan_toolpath
from camcad.export.gcode.verify import ToolpathCheck, check_toolpath
from camcad.export.gcode.writer import GcodeSummary, count_blocks, render_gcode, write_gcode

__all__ = [
    "DIALECTS",
    "DialectRules",
    "GcodeSummary",
    "GcodeSyntaxError",
    "Move",
    "MoveKind",
    "Pieces",
    "Toolpath",
    "ToolpathCheck",
    "biarc_pieces",
    "check_gouge",
    "check_toolpath",
    "count_blocks",
    "dialect_rules",
    "fit_curve",
    "measure_deviation",
    "parse_canon",
    "parse_gcode",
    "plan_toolpath",
    "render_gcode",
    "write_gcode",
]
