"""camcad: disc cams from motion specification to DXF, STL and G-code.

>>> import camcad
>>> design = camcad.load("samples/quintero_vap_b01.toml")  # doctest: +SKIP
>>> result = camcad.analyse(design)  # doctest: +SKIP
>>> result.build("out/")  # doctest: +SKIP

The Python API (:mod:`camcad.api`): ``load``, ``analyse``, ``Design``,
``Result``, ``optimize``, ``sweep``.

Every public name is imported on first use (:func:`__getattr__`), so
``import camcad`` is light: ``camcad --version`` answers at once, and the
command line installs its Ctrl-C handling before NumPy and SciPy load.
"""

import os  # already loaded by Python itself, as sys: nothing here takes time before the handler
import sys


def _exit_interrupted(signum: int, frame: object) -> None:
    """Ctrl-C before the command line runs: one line and exit 130 (``EXIT_INTERRUPTED``), at once."""
    os.write(2, b"camcad: interrupted\n")
    os._exit(130)


# ``python -m camcad`` (argv[0] is "-m" while the package imports) or the ``camcad`` command is
# importing this package: answer Ctrl-C from now on (camcad.cli.main takes over when it runs)
if sys.argv[:1] == ["-m"] or os.path.basename(sys.argv[0] if sys.argv else "") in ("camcad", "camcad.exe"):
    import _signal  # type: ignore[import-not-found]  # the C module: ``signal`` imports ``enum``, itself a window of milliseconds

    _signal.signal(_signal.SIGINT, _exit_interrupted)

from importlib import import_module  # noqa: E402 - after the Ctrl-C handling, on purpose

from camcad._version import __version__  # noqa: E402

# no ``from __future__ import annotations`` here: it is a real import, a window before the handler

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (mypy reads it the same way)

if TYPE_CHECKING:
    from camcad.api import Design, Quantity, Result, analyse, load, optimize, sweep
    from camcad.design import load_design, parse_design
    from camcad.errors import CamcadError, DesignError, DesignLimitError, OutputError, UsageError
    from camcad.geometry.cam import Cam
    from camcad.motion.laws import LAWS, make_law
    from camcad.motion.program import Motion, MotionProgram
    from camcad.pipeline import Analysis, BuildResult, Project, build

_WHERE = {  # public name → the module that defines it
    "Design": "camcad.api",
    "Quantity": "camcad.api",
    "Result": "camcad.api",
    "analyse": "camcad.api",
    "load": "camcad.api",
    "optimize": "camcad.api",
    "sweep": "camcad.api",
    "load_design": "camcad.design",
    "parse_design": "camcad.design",
    "CamcadError": "camcad.errors",
    "DesignError": "camcad.errors",
    "DesignLimitError": "camcad.errors",
    "OutputError": "camcad.errors",
    "UsageError": "camcad.errors",
    "Cam": "camcad.geometry.cam",
    "LAWS": "camcad.motion.laws",
    "make_law": "camcad.motion.laws",
    "Motion": "camcad.motion.program",
    "MotionProgram": "camcad.motion.program",
    "Analysis": "camcad.pipeline",
    "BuildResult": "camcad.pipeline",
    "Project": "camcad.pipeline",
    "build": "camcad.pipeline",
}


def __getattr__(name: str) -> object:
    """Import a public name's module on first use, so ``import camcad`` stays light."""
    if name in _WHERE:
        value = getattr(import_module(_WHERE[name]), name)
        globals()[name] = value  # the next look-up is a plain attribute
        return value
    raise AttributeError(f"module 'camcad' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The public names, those not yet imported included."""
    return sorted({*globals(), *_WHERE})


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
