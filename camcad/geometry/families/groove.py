"""The groove (face) cam: one blank with a groove whose two flanks drive the roller both ways.

The part is the designed cam with a :class:`~camcad.geometry.families.base.Pocket`
between its inner and outer flank (:mod:`camcad.geometry.groove`: the pitch
curve offset by ∓(r_f + c/2), Rothbart 2004, §8.2), checked for loops, the
blank's rim, the bore and the largest cutter.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families.base import Drive, FamilyOptions, Flank, Part, PartResults, Pocket
from camcad.geometry.groove import analyse_groove, roller_flank_offsets

__all__ = ["GROOVE", "GrooveFamily", "flank_at"]


class GrooveFamily:
    """A groove cam: one part, the blank with the groove's two flanks."""

    name = "groove"
    table = "groove"
    own_keys: frozenset[str] = frozenset()
    needs_roller = True
    one_plate = False
    plates = False  # a blank with a pocket

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """A groove needs its blank, room for the groove in it, and a depth less than its thickness."""
        outer, depth = options.outer_radius, options.groove.depth
        if outer is None:
            raise DesignError("cam.outer_radius", "is required for a groove cam (mm, the blank's radius)")
        if outer <= base_radius + 2.0 * roller_radius:
            raise DesignError(
                "cam.outer_radius",
                f"{outer:g} mm leaves no room for the groove; allowed: > base_radius + 2 × "
                f"roller_radius = {base_radius + 2.0 * roller_radius:g} mm",
            )
        if depth >= thickness:
            raise DesignError(
                "groove.depth", f"{depth:g} mm must be less than the blank's thickness {thickness:g} mm"
            )

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """The blank with its groove, checked (:func:`camcad.geometry.groove.analyse_groove`)."""
        groove = analyse_groove(
            cam,
            clearance=options.groove.clearance,
            outer_radius=options.outer_radius,
            hole_radius=options.hole_radius,
        )
        assert options.outer_radius is not None  # the schema requires it for a groove cam
        pocket = Pocket(
            outer_radius=options.outer_radius,
            depth=options.groove.depth,
            clearance=options.groove.clearance,
            width=groove.width,
            flanks=(
                Flank(name="inner_flank", layer="GROOVE_INNER", offset=groove.inner_offset),
                Flank(name="outer_flank", layer="GROOVE_OUTER", offset=groove.outer_offset),
            ),
        )
        return (Part(cam=cam, pocket=pocket, checks=(groove,)),)

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """The groove's two flanks drive the roller both ways, with the groove's radial play."""
        clearance = options.groove.clearance
        offsets = roller_flank_offsets(roller_radius, clearance)
        return Drive(positive_drive=True, clearance=clearance, flank_offsets=offsets)

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """Nothing to check on the cam itself."""

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """The ``groove`` section: flank checks, flank fits, the flank at the largest pressure angle."""
        (result,) = results
        (groove,) = result.part.checks
        out: dict[str, Any] = groove.summary()
        if result.flank_fits:
            out["fit"] = {
                f.name: fit.summary() for f, fit in zip(result.part.flanks, result.flank_fits, strict=True)
            }
        # the pressure angle is the same on both flanks; say which one drives there
        out["pressure_angle_max_flank"] = flank_at(result.dynamics, result.geometry.pressure_angle_max.phi)
        return {"groove": out}

    def caption(self, parts: Sequence[Part]) -> str:
        """The roller runs in the groove."""
        return " The roller runs in the groove milled into the blank's face."


def flank_at(dynamics: Any, phi: float) -> str | None:
    """The groove flank that drives at cam angle φ [rad]: the sign of the nearest sample's contact force."""
    d = np.angle(np.exp(1j * (np.asarray(dynamics.phi) - phi)))  # wrapped distance [rad]
    force = float(dynamics.contact_force[int(np.argmin(np.abs(d)))])
    if force == 0.0:
        return None  # a rest: neither flank drives
    return "inner" if force > 0.0 else "outer"


GROOVE = GrooveFamily()
