"""A barrel cam's files from its part: ``profile.dxf`` (developed groove), ``cam.stl``, ``cam.step``.

Each writer takes the part's :class:`~camcad.geometry.families.Barrel` (its
shape as data): the developed groove at the pitch station
(:mod:`camcad.export.barrel_dxf`), the watertight mesh from the exact walls
(:mod:`camcad.export.barrel_mesh`), and the exact solid whose walls are the
certified surfaces (:mod:`camcad.export.barrel_step`, through OpenCASCADE:
the ``step`` extra).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from camcad.errors import UsageError
from camcad.export.atomic import atomic_write, atomic_write_bytes
from camcad.export.barrel_dxf import developed_groove, write_developed_dxf
from camcad.export.barrel_mesh import BarrelMeshOptions, barrel_mesh, barrel_stl_bytes
from camcad.geometry.families import Barrel, Part

if TYPE_CHECKING:
    from camcad.fit.surface import BarrelWallFit

__all__ = ["write_barrel_dxf", "write_barrel_step", "write_barrel_stl"]


def _barrel(part: Part) -> Barrel:
    if part.barrel is None:
        raise ValueError("not a barrel part")
    return part.barrel


def write_barrel_dxf(folder: str | os.PathLike[str], part: Part, *, tolerance: float) -> Path:
    """``profile{suffix}.dxf``: the developed pitch line and walls, fitted within ``tolerance`` [mm]."""
    b = _barrel(part)
    groove = developed_groove(b.program, b.follower, b.options, tolerance=tolerance)
    path = Path(folder) / f"profile{part.suffix}.dxf"
    return atomic_write(path, lambda tmp: write_developed_dxf(groove, tmp, length=b.options.length))


def write_barrel_stl(folder: str | os.PathLike[str], part: Part, *, chord: float) -> Path:
    """``cam{suffix}.stl``: the barrel less its groove, watertight, polygons within ``chord`` [mm]."""
    b = _barrel(part)
    mesh = barrel_mesh(b.program, b.follower, b.options, BarrelMeshOptions(chord=chord))
    return atomic_write_bytes(Path(folder) / f"cam{part.suffix}.stl", barrel_stl_bytes(mesh))


def write_barrel_step(folder: str | os.PathLike[str], part: Part, *, fit: BarrelWallFit, name: str) -> Path:
    """``cam{suffix}.step``: the exact barrel, its walls the certified surfaces ``fit``.

    Raises
    ------
    UsageError
        OpenCASCADE (``pip install camcad[step]``) is missing: exit 2, naming ``--only``.
    ExportError
        Its solid is not one valid solid.
    """
    b = _barrel(part)
    try:
        import OCP  # noqa: F401  # the step extra; barrel_step imports its parts where it uses them

        from camcad.export.barrel_step import barrel_shape, barrel_step_bytes
    except ImportError as err:
        raise UsageError(
            "--only",
            "a barrel's cam.step needs OpenCASCADE, which is not installed: pip install 'camcad[step]', "
            "or leave the STEP file out (--only tables,dxf,stl,gcode,report)",
        ) from err
    solid = barrel_shape(fit, b.options)
    return atomic_write_bytes(Path(folder) / f"cam{part.suffix}.step", barrel_step_bytes(solid, name=name))
