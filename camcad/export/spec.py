"""The writers' options: DXF, mesh and table settings."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

__all__ = ["DriveLayout", "DxfSpec", "MeshSpec", "TablesSpec"]


class DriveLayout(enum.Enum):
    """Column layouts of ``cam_table.csv``, the electronic-cam table for a servo drive.

    ``FULL``: master angle, slave position, velocity and acceleration per
    master degree. ``MASTER_SLAVE``: master/slave position pairs (the n×2
    position table of TwinCAT's MC_TABLETYPE_NONEQUIDISTANT). ``EQUIDISTANT``:
    slave positions only, at equal master steps from 0° to 360° (TwinCAT's
    MC_TABLETYPE_EQUIDISTANT, CODESYS SoftMotion's SMC_CAMTable_LREAL_n_1).
    """

    FULL = "full"
    MASTER_SLAVE = "master-slave"
    EQUIDISTANT = "equidistant"


@dataclass(frozen=True, slots=True, kw_only=True)
class DxfSpec:
    """DXF settings. ``chord_tolerance`` mm, for the polyline DXF."""

    pitch_curve: bool = True
    chord_tolerance: float = 0.005
    annotate: bool = True


@dataclass(frozen=True, slots=True, kw_only=True)
class MeshSpec:
    """Solid settings. ``chord_tolerance`` mm."""

    formats: tuple[str, ...] = ("stl",)
    chord_tolerance: float = 0.005


@dataclass(frozen=True, slots=True, kw_only=True)
class TablesSpec:
    """Resolution of ``points.csv``, ``lift.csv`` and ``polar.txt``; ``step`` and ``polar_step`` rad.

    ``wheel_radius`` [mm] asks for ``polar.txt``, the tool-centre radius per
    angle for a grinding wheel (or tool) of that radius, at ``polar_step``
    (None: ``step``) with ``polar_decimals`` decimals.
    """

    step: float = math.radians(1.0)
    wheel_radius: float | None = None
    polar_step: float | None = None
    polar_decimals: int = 4
    cam_table_points: int | None = None  # cam_table.csv for a servo drive: master steps per turn (None: none)
    cam_table_layout: DriveLayout = DriveLayout.FULL
