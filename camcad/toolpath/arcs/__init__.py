"""Arc paths fitted to an exact plane curve within a measured tolerance.

- :mod:`~camcad.toolpath.arcs.biarc`: pieces (arcs and lines), biarcs,
  chords and the two-way deviation measurement;
- :mod:`~camcad.toolpath.arcs.search`: the layered search for short arc splines;
- :mod:`~camcad.toolpath.arcs.refine`: the minimax refit that drops arcs from a closed loop;
- :mod:`~camcad.toolpath.arcs.march`: the greedy biarc march (fallback, and G1 chords);
- :mod:`~camcad.toolpath.arcs.spline`: :func:`fit_arc_spline`, which uses them.
"""

from camcad.toolpath.arcs.biarc import CurveFn, Pieces, biarc_pieces, chord_pieces, measure_deviation
from camcad.toolpath.arcs.spline import fit_arc_spline

__all__ = ["CurveFn", "Pieces", "biarc_pieces", "chord_pieces", "fit_arc_spline", "measure_deviation"]
