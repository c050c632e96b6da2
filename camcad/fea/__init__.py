"""The finite-element check of the cam plate: mesh (gmsh), solve (scikit-fem), stresses.

Optional: needs the extra ``camcad[fea]`` (gmsh is GPL-licensed; scikit-fem BSD).
Pure computation: :func:`analyse_fea` returns a :class:`FeaResult`; the
fields are written by :mod:`camcad.export.stress`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camcad._lazy import lazy_names

if TYPE_CHECKING:
    from camcad.fea.model import analyse_fea, load_cases, mesh_plate, plane_model
    from camcad.fea.results import FeaResult, LoadCase, Peak, StressCase
    from camcad.fea.spec import FeaSpec, PlaneModel

_HOME = {
    "FeaResult": "camcad.fea.results",
    "FeaSpec": "camcad.fea.spec",
    "LoadCase": "camcad.fea.results",
    "Peak": "camcad.fea.results",
    "PlaneModel": "camcad.fea.spec",
    "StressCase": "camcad.fea.results",
    "analyse_fea": "camcad.fea.model",
    "load_cases": "camcad.fea.model",
    "mesh_plate": "camcad.fea.model",
    "plane_model": "camcad.fea.model",
}
"""Where each public name lives: loaded on first use, so ``camcad.fea.spec`` (read by
``camcad.design`` for every design) does not load the solver and its libraries."""


__getattr__ = lazy_names(__name__, _HOME)

__all__ = [
    "FeaResult",
    "FeaSpec",
    "LoadCase",
    "Peak",
    "PlaneModel",
    "StressCase",
    "analyse_fea",
    "load_cases",
    "mesh_plate",
    "plane_model",
]
