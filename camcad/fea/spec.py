"""What the user states in ``[fea]``: the finite-element check's options."""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["FeaSpec", "PlaneModel"]

PLANE_STRAIN_RATIO = 0.5
"""``plane = "auto"``: plane strain when thickness ≥ this × the plate's outer diameter, else plane stress."""


class PlaneModel(enum.Enum):
    """The 2-D hypothesis of the plate model."""

    AUTO = "auto"  # by thickness / outer diameter (PLANE_STRAIN_RATIO)
    STRESS = "stress"  # thin plate: σ_zz = 0
    STRAIN = "strain"  # thick plate: ε_zz = 0, σ_zz = ν(σ_xx + σ_yy)


@dataclass(frozen=True, slots=True, kw_only=True)
class FeaSpec:
    """The ``[fea]`` table. Lengths mm, stresses MPa, ``angles`` rad.

    Attributes
    ----------
    angles
        Cam angles [rad] to load besides those found automatically (peak
        contact force, peak |input torque|, peak Hertz stress).
    plane
        Plane stress, plane strain, or chosen by thickness / outer diameter.
    allowable_stress
        Limit on the peak von Mises stress [MPa] (a soft limit, like the
        Hertz one); ``None``: no limit.
    mesh_size
        Largest element edge [mm]; ``None``: the outer radius / 10.
    contact_divisions
        Element edges across the Hertz contact strip 2b (the contact's
        refinement; the mesh grows from b·2/contact_divisions away from it).
    growth
        How fast the element size grows away from a refined spot [mm/mm].
    keyway_fillet
        Radius of the fillets at the keyway's two inner corners [mm]; a sharp
        corner has infinite stress in linear elasticity. ``None``: 5 % of the
        keyway width.
    """

    angles: tuple[float, ...] = ()
    plane: PlaneModel = PlaneModel.AUTO
    allowable_stress: float | None = None
    mesh_size: float | None = None
    contact_divisions: int = 10
    growth: float = 0.3
    keyway_fillet: float | None = None
