"""The writers' options: DXF, mesh and table settings."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["DxfSpec", "MeshSpec", "TablesSpec"]


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
    """Resolution of ``points.csv`` and ``lift.csv``; ``step`` rad."""

    step: float = math.radians(1.0)
