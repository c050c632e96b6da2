"""Cam families, one module each, and the registry from the TOML ``cam.style`` to its family.

See :mod:`camcad.geometry.families.base` for what a family yields.
"""

from __future__ import annotations

from camcad.geometry.families.barrel import BARREL, BARREL_RIB
from camcad.geometry.families.base import (
    Bar,
    Barrel,
    BarrelSpec,
    CamFamily,
    Drive,
    FamilyOptions,
    Flank,
    Part,
    PartCheck,
    PartResults,
    Pocket,
)
from camcad.geometry.families.conjugate import CONJUGATE
from camcad.geometry.families.groove import GROOVE
from camcad.geometry.families.linear import LINEAR
from camcad.geometry.families.plate import PLATE
from camcad.geometry.spec import CamStyle

__all__ = [
    "FAMILIES",
    "Bar",
    "Barrel",
    "BarrelSpec",
    "CamFamily",
    "Drive",
    "FamilyOptions",
    "Flank",
    "Part",
    "PartCheck",
    "PartResults",
    "Pocket",
    "family_of",
]

FAMILIES: dict[CamStyle, CamFamily] = {
    CamStyle.PLATE: PLATE,
    CamStyle.GROOVE: GROOVE,
    CamStyle.CONJUGATE: CONJUGATE,
    CamStyle.LINEAR: LINEAR,
    CamStyle.BARREL: BARREL,
    CamStyle.BARREL_RIB: BARREL_RIB,
}
"""Each ``cam.style`` and its family."""


def family_of(style: CamStyle) -> CamFamily:
    """The cam family of a ``cam.style``."""
    return FAMILIES[style]
