"""Design exploration: constrained optimization, sweeps of the design space and Pareto fronts.

It sits above :mod:`camcad.pipeline` (each design is analysed as ``camcad
check`` does) and below :mod:`camcad.cli` (``camcad optimize``, ``camcad
sweep``). Variables are keys of the design file (:mod:`.space`), objectives
and limits are true extremes of the analysis (:mod:`.measures`). A sweep
into a folder is :func:`camcad.explore.sweep.sweep` (the module and the
function share the name, so the function is not re-exported here).
"""

from __future__ import annotations

from camcad.explore.measures import MEASURES, Limit, Measure, parse_limit
from camcad.explore.pareto import pareto_mask
from camcad.explore.space import Variable, design_with, grid_points, lhs_points, parse_variable
from camcad.explore.sweep import SweepPlan, SweepResult, run_sweep

__all__ = [
    "MEASURES",
    "Limit",
    "Measure",
    "SweepPlan",
    "SweepResult",
    "Variable",
    "design_with",
    "grid_points",
    "lhs_points",
    "pareto_mask",
    "parse_limit",
    "parse_variable",
    "run_sweep",
]
