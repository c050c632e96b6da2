"""Follower geometry: the exact envelope, pressure angle, curvature, undercut and sizing."""

from camcad.geometry.cam import Cam
from camcad.geometry.curves import CurveSample
from camcad.geometry.limits import GeometryAnalysis, Undercut, analyse_geometry, undercut_error
from camcad.geometry.sizing import SizingResult, min_base_radius, min_pivot_distance

__all__ = [
    "Cam",
    "CurveSample",
    "GeometryAnalysis",
    "SizingResult",
    "Undercut",
    "analyse_geometry",
    "min_base_radius",
    "min_pivot_distance",
    "undercut_error",
]
