"""camcad: disc cams from motion specification to DXF, STL and G-code.

>>> import camcad
>>> project = camcad.load("samples/quintero_vap_b01.toml")  # doctest: +SKIP
>>> analysis = project.analyse()  # doctest: +SKIP
>>> project.build("out/")  # doctest: +SKIP
"""

from camcad._version import __version__
from camcad.design import Design, load_design, parse_design
from camcad.errors import CamcadError, DesignError, DesignLimitError, OutputError, UsageError
from camcad.geometry.cam import Cam
from camcad.motion.laws import LAWS, make_law
from camcad.motion.program import Motion, MotionProgram

_PIPELINE = ("Analysis", "BuildResult", "Project", "analyse", "build", "load")


def __getattr__(name: str) -> object:
    """Import the pipeline on first use, so ``camcad --version`` stays light."""
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
    "UsageError",
    "__version__",
    "analyse",
    "build",
    "load",
    "load_design",
    "make_law",
    "parse_design",
]
