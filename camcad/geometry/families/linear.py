"""The linear cam: a bar translating along x, its top edge the cam; a spring holds the follower on.

The plate-cam core with a translation instead of a rotation
(:mod:`camcad.geometry.linear`): the family's one part is the designed cam
with ``stroke_length`` set (:attr:`camcad.geometry.cam.Cam.stroke_length`),
so every later stage (pressure angle, curvature, undercut, dynamics, the
fit) runs the same code on it, and a :class:`~camcad.geometry.families.base.Bar`
that the writers cut: the open edge from x0 to x0 + L, closed by the bar's
two ends and its bottom ``bar_height`` below the base line.

The motion's angle maps to the bar's travel x = Lφ/2π; one cycle of the
motion program is one bar length. Time enters only through the dynamics:
``[linear] speed_mm_s`` v sets the cycle time L/v (the design file turns it
into the cycle rate, ``cam.speed_rpm`` cycles per minute), and the energy
method's drive torque T [N·mm per radian of motion] is the force F = T/c
[N] that pushes the bar, c = L/2π (the work T dφ = F dx).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from camcad.angles import TWO_PI
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families.base import Bar, Drive, FamilyOptions, Part, PartResults
from camcad.geometry.followers import FOLLOWER_TYPES
from camcad.geometry.spec import Rotation

__all__ = ["LINEAR", "LinearFamily"]

BAR_SAMPLES = 3601
"""Edge samples per cycle for the bar's floor check (a margin check, not an extreme: 0.1° apart)."""


class LinearFamily:
    """A linear cam: the bar under the follower is the one part."""

    name = "linear"
    table = "linear"
    own_keys: frozenset[str] = frozenset()  # its keys are the [linear] table's
    needs_roller = False  # a curved (mushroom) face works too; a flat face is refused in check_cam
    one_plate = False  # no rotary machine
    plates = False  # a bar, not a disc: no FE check of a plate

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """A linear cam needs its stroke length; it has no blank round it."""
        if options.outer_radius is not None:
            raise DesignError("cam.outer_radius", "applies to groove cams (cam.style = 'groove') only")
        if not options.linear.stroke_length > 0.0:
            raise DesignError(
                "linear.stroke_length",
                "is required for a linear cam: the bar's travel per cycle of the motion (mm > 0)",
            )
        if options.hole_radius > 0.0:
            raise DesignError("cam.bore", "a linear cam's bar has no bore (allowed: 0)")

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """A contact circle (roller, curved face), a bar that slides one way, a floor below the edge."""
        bar_cam = replace(cam(), stroke_length=options.linear.stroke_length)
        if bar_cam.rotation is not Rotation.CCW:
            raise DesignError(
                "cam.rotation",
                "a linear cam's bar moves towards −x under the follower; 'cw' applies to disc cams "
                "(allowed: ccw)",
            )
        if not bar_cam.roller_radius > 0.0:
            rollers = " or ".join(sorted(t.word for t in FOLLOWER_TYPES.values() if t.two_sided))
            raise DesignError(
                "follower.type",
                f"{bar_cam.follower_spec.kind.word}: a flat face has no envelope on a linear cam (it does "
                f"not turn relative to the bar); allowed: {rollers} or a curved face",
            )
        bar = _bar(bar_cam, options)
        phi = np.linspace(0.0, TWO_PI, BAR_SAMPLES)
        low = float(np.min(bar_cam.profile(phi).point[:, 1]))
        if low <= bar.bottom:
            raise DesignError(
                "linear.bar_height",
                f"{options.linear.bar_height:g} mm puts the bar's bottom at y = {bar.bottom:g} mm, above "
                f"the edge's lowest point y = {low:.3f} mm; allowed: > {bar_cam.base_radius - low:.3f} mm",
            )

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """The bar: the cam translating by ``stroke_length`` per cycle, cut along its edge."""
        bar_cam = replace(cam, stroke_length=options.linear.stroke_length)
        return (Part(cam=bar_cam, bar=_bar(bar_cam, options)),)

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """A spring holds the follower on the bar."""
        return Drive(positive_drive=False, clearance=0.0, flank_offsets=None)

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """The ``linear`` section: the bar, its speed and the force that pushes it (F = T/c)."""
        (result,) = results
        part = result.part
        bar = part.bar
        assert bar is not None and part.cam.travel_rate is not None  # parts() made it
        c = part.cam.travel_rate  # mm of travel per radian of motion
        dyn = result.dynamics
        out: dict[str, Any] = {
            "stroke_length_mm": bar.length,
            "bar_x0_mm": bar.x0,
            "bar_bottom_mm": bar.bottom,
            "travel_per_rad_mm": c,
        }
        geo = result.geometry
        for name in ("pressure_angle_max", "curvature_radius_min", "concave_radius_min"):
            where = getattr(geo, name)
            if where is not None:  # where along the bar the geometry's extremes lie: x = cφ
                out[f"{name}_x_mm"] = c * float(where.phi)
        for key, ext in (("drive_force_min_N", dyn.torque_min), ("drive_force_max_N", dyn.torque_max)):
            if ext is not None:  # F = T/c: the work T dφ = F dx with dx = c dφ (c > 0 keeps the extremes)
                out[key] = float(ext.value) / c
        return {"linear": out}

    def caption(self, parts: Sequence[Part]) -> str:
        """The bar slides under the follower."""
        return " One cycle of the motion is one stroke length of the bar."


def _bar(cam: Cam, options: FamilyOptions) -> Bar:
    """The bar under ``cam``'s edge: from the edge's start at φ = 0, its bottom below the base line."""
    x0 = float(cam.profile(np.array([0.0])).point[0, 0])
    return Bar(
        x0=x0,
        length=options.linear.stroke_length,
        bottom=cam.base_radius - options.linear.bar_height,
    )


LINEAR = LinearFamily()
