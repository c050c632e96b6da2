"""The plate cam: one plate, cut along its outline; a spring holds the follower on."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families.base import Drive, FamilyOptions, Part, PartResults

__all__ = ["PLATE", "PlateFamily"]


class PlateFamily:
    """A plate cam: the designed cam is the one part."""

    name = "plate"
    table = None
    own_keys: frozenset[str] = frozenset()
    needs_roller = False
    one_plate = True
    plates = True

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """A plate has no blank round it."""
        if options.outer_radius is not None:
            raise DesignError("cam.outer_radius", "applies to groove cams (cam.style = 'groove') only")

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """The plate."""
        return (Part(cam=cam),)

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """A spring holds the follower on the plate."""
        return Drive(positive_drive=False, clearance=0.0, flank_offsets=None)

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """Nothing to check on the cam itself."""

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """Nothing beyond the common sections."""
        return {}

    def caption(self, parts: Sequence[Part]) -> str:
        """Nothing beyond the common caption."""
        return ""


PLATE = PlateFamily()
