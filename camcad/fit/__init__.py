"""Certified B-spline fit of the cam profile for CAD export.

The profile is fitted by a periodic cubic B-spline by least squares over
chord-length parameters (Quang & Hung 2015, eqs. 6–10), with knots at the
motion breakpoints and the fewest control points whose certified distance to
the exact profile is below the tolerance. The periodic curve converts exactly
to a clamped closed curve, opened inside the longest stretch between motion
breakpoints so its seam adds no tangent or curvature jump, and to a ``geomdl``
curve for export.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camcad._lazy import lazy_names

if TYPE_CHECKING:
    from camcad.fit._profile import fit_points, fit_profile
    from camcad.fit.bspline import clamped_from_periodic, to_geomdl
    from camcad.fit.cam import fit_cam_profile
    from camcad.fit.curve import BSplineCurve
    from camcad.fit.result import ProfileFit

_HOME = {
    "BSplineCurve": "camcad.fit.curve",
    "ProfileFit": "camcad.fit.result",
    "clamped_from_periodic": "camcad.fit.bspline",
    "fit_cam_profile": "camcad.fit.cam",
    "fit_points": "camcad.fit._profile",
    "fit_profile": "camcad.fit._profile",
    "to_geomdl": "camcad.fit.bspline",
}
"""Where each public name lives: loaded on first use, so ``camcad.fit.spec`` (read by
``camcad.design``) does not load SciPy."""


__getattr__ = lazy_names(__name__, _HOME)

__all__ = [
    "BSplineCurve",
    "ProfileFit",
    "clamped_from_periodic",
    "fit_cam_profile",
    "fit_points",
    "fit_profile",
    "to_geomdl",
]
