"""The fit stage's options."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FitSpec"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FitSpec:
    """NURBS fit settings. ``tolerance`` mm."""

    tolerance: float = 1e-3
    max_control_points: int | None = None  # None: automatic (as many as the fit's samples allow)
