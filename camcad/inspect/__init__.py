"""Tolerances and inspection of a made cam (issue 38): Monte Carlo, allocation, CMM points against the design.

Sits between dynamics and fit (see tests/test_architecture.py): it needs the
exact envelope and the motion, and a compensated profile is what the fit and
the tool path will later take. Nothing here reads files or the design schema.
The linear sensitivities and the made cam's re-solved motion, which these
build on, live in :mod:`camcad.geometry.sensitivity` and :mod:`camcad.geometry.made`.
"""

from __future__ import annotations

from camcad.inspect.actual import (
    ActualMotion,
    Compensation,
    FormFit,
    actual_motion,
    compensate,
    smooth_deviation,
)
from camcad.inspect.measure import Inspection, foot_points, inspect_points, points_from_polar
from camcad.inspect.tolerance import (
    Allocation,
    Distribution,
    LinearDwell,
    Method,
    MonteCarlo,
    Tolerance,
    allocate,
    draw,
    dwell_angles,
    linear_dwell,
    monte_carlo,
    variant_figures,
)

__all__ = [
    "ActualMotion",
    "Allocation",
    "Compensation",
    "Distribution",
    "FormFit",
    "Inspection",
    "LinearDwell",
    "Method",
    "MonteCarlo",
    "Tolerance",
    "actual_motion",
    "allocate",
    "compensate",
    "draw",
    "dwell_angles",
    "foot_points",
    "inspect_points",
    "linear_dwell",
    "monte_carlo",
    "points_from_polar",
    "smooth_deviation",
    "variant_figures",
]
