"""G-code for a planned toolpath: the writer in three dialects, and two readers.

The toolpath itself is planned by :mod:`camcad.toolpath`; this package only
turns it into text and reads programs back.

- :func:`render_gcode` writes a :class:`~camcad.toolpath.Toolpath` in a
  dialect (``linuxcnc``, ``grbl``, ``generic``); :func:`render_program` also
  counts the figures for summary.json on the text it rendered.
- :func:`render_rotary` writes a rotary program (``machine = "rotary"``:
  X and A or C words in G93 inverse time) of a
  :class:`~camcad.toolpath.rotary.RotaryToolpath`; :func:`render_rotary_program`
  also counts its figures.
- :func:`parse_gcode` and :func:`parse_canon` (LinuxCNC ``rs274`` output)
  read programs back into :class:`~camcad.toolpath.Move` s, for
  :func:`camcad.toolpath.check_toolpath` to prove.

>>> from camcad.design import parse_design
>>> from camcad.geometry.cam import Cam
>>> from camcad.toolpath import plan_toolpath
>>> design = parse_design({
...     "cam": {"base_radius": 40, "thickness": 8},
...     "follower": {"type": "translating-roller", "roller_radius": 10},
...     "motion": [
...         {"kind": "rise", "angle": 180, "lift": 10, "law": "cycloidal"},
...         {"kind": "return", "angle": 180, "lift": 10, "law": "cycloidal"},
...     ],
... })
>>> toolpath = plan_toolpath(Cam.from_design(design), design.gcode, name="demo", thickness=8.0)
>>> render_gcode(toolpath).splitlines()[0]
'(camcad G-code: demo)'
"""

from camcad.export.gcode.dialects import DIALECTS, DialectRules, dialect_rules
from camcad.export.gcode.parse import parse_canon, parse_gcode
from camcad.export.gcode.rotary import render_rotary, render_rotary_program
from camcad.export.gcode.writer import (
    GcodeProgram,
    GcodeSummary,
    count_blocks,
    render_gcode,
    render_program,
    summarize,
)

__all__ = [
    "DIALECTS",
    "DialectRules",
    "GcodeProgram",
    "GcodeSummary",
    "count_blocks",
    "dialect_rules",
    "parse_canon",
    "parse_gcode",
    "render_gcode",
    "render_program",
    "render_rotary",
    "render_rotary_program",
    "summarize",
]
