"""camcad: disc cams from motion specification to DXF, STL and G-code.

>>> import camcad
>>> design = camcad.load("samples/quintero_vap_b01.toml")  # doctest: +SKIP
>>> result = camcad.analyse(design)  # doctest: +SKIP
>>> result.build("out/")  # doctest: +SKIP

The Python API (:mod:`camcad.api`): ``load``, ``analyse``, ``Design``,
``Result``, ``optimize``, ``sweep``.
"""

from camcad._version import __version__
from camcad.design import load_design, parse_design
from camcad.errors import CamcadError, DesignError, DesignLimitError, OutputError, UsageError
from camcad.geometry.cam import Cam
from camcad.motion.laws import LAWS, make_law
from camcad.motion.program import Motion, MotionProgram

_PIPELINE = ("Analysis", "BuildResult", "Project", "build")
_API = ("Design", "Quantity", "Result", "analyse", "load", "optimize", "sweep")


def __getattr__(name: str) -> object:
    """Import the pipeline and the API on first use, so ``camcad --version`` stays light."""
    if name in _API:
        from camcad import api

        return getattr(api, name)
    if name in _PIPELINE:
        from camcad import pipeline

        return getattr(pipeline, name)
    raise AttributeError(f"module 'camcad' has no attribute {name!r}")


__all__ = [
    "LAWS",
    "Analysis",
    "BuildResult",
    "Cam",
    "CamcadError",
    "Design",
    "DesignError",
    "DesignLimitError",
    "Motion",
    "MotionProgram",
    "OutputError",
    "Project",
    "Quantity",
    "Result",
    "UsageError",
    "__version__",
    "analyse",
    "build",
    "load",
    "load_design",
    "make_law",
    "optimize",
    "parse_design",
    "sweep",
]
