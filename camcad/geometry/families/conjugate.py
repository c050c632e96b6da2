"""The conjugate pair: two plates on one shaft, each driving its own roller of the follower.

The second plate drives the tied second roller
(:class:`camcad.geometry.followers.tied.TiedRoller`); its roller pushes the
follower back, so its contact force is the generalised force with the sign
turned (``drive_sign`` −1), and its own roller radius sets its Hertz contact
(Johnson 1985, §4.3). A constant-breadth pair (``single_plate``) runs both
rollers on one plate: the second part is analysed, not made.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families.base import Drive, FamilyOptions, Part, PartResults
from camcad.geometry.limits import conjugate_overlap

__all__ = ["CONJUGATE", "ConjugateFamily"]


class ConjugateFamily:
    """A conjugate pair: the designed plate and the second plate with its own roller."""

    name = "conjugate"
    table = "conjugate"
    own_keys: frozenset[str] = frozenset()
    needs_roller = True
    one_plate = False
    plates = True

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """Nothing beyond the roller; a constant-breadth pair's program is the design schema's check."""

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """Plate 1, then plate 2 (``_2``), which drives the second roller."""
        partner = cam.partner(options.conjugate)
        second = Part(
            cam=partner,
            suffix="_2",
            label="second plate",
            drive_sign=-1.0,
            made=not options.conjugate.single_plate,
        )
        return (Part(cam=cam), second)

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """The two plates drive the follower both ways, each through its own roller."""
        return Drive(positive_drive=True, clearance=0.0, flank_offsets=None)

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """The two rollers must clear each other, seen along the shaft (:func:`conjugate_overlap`)."""
        problem = conjugate_overlap(cam().partner(options.conjugate))
        if problem is not None:
            raise DesignError(*problem)

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """The ``second_plate`` section: its geometry, dynamics, fit, FE check, life and film."""
        second = results[1]
        plate: dict[str, Any] = {
            "single_plate": not second.part.made,
            "geometry": second.geometry.summary(),
            "dynamics": second.dynamics.summary(),
        }
        if second.fit is not None:
            plate["fit"] = second.fit.summary()
        if second.fea is not None:
            plate["fea"] = second.fea.summary()  # the FE check of the second plate, its own roller's load
        if second.duty is not None:
            plate |= second.duty.summary()  # its roller's and track's life, its film (its own roller)
        return {"second_plate": plate}

    def caption(self, parts: Sequence[Part]) -> str:
        """What the second plate drives (nothing for a single plate)."""
        second = parts[1]
        return (
            f" The second plate (outline) drives the {second.cam.follower.describe()}." if second.made else ""
        )


CONJUGATE = ConjugateFamily()
