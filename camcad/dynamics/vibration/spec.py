"""What the user states about the follower train's elasticity: the ``[vibration]`` options."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from camcad.errors import DesignError
from camcad.knobs import Knob, TableKey

__all__ = ["TrainModel", "VibrationSpec"]


class TrainModel(enum.Enum):
    """Lumped models of the follower train (Rothbart 2004, ch. 13; Norton 2009, §15.3)."""

    SINGLE_MASS = "single-mass"
    TWO_MASS = "two-mass"


@dataclass(frozen=True, slots=True, kw_only=True)
class VibrationSpec:
    """The ``[vibration]`` table: train stiffness, damping, masses and the speed map.

    Attributes
    ----------
    model
        Single mass (the follower mass on the train stiffness) or two masses.
    stiffness
        k_f [N/mm]: the train between the cam contact and the (first) mass.
    stiffness_torsional
        k_f of an oscillating follower [N·mm/rad] about the pivot.
    damping_ratio
        ζ [1], 0 ≤ ζ < 1: c = 2ζ√(k_f·m) for the train (and c₂ = 2ζ√(k₂·m₂)).
    mass_1, mass_2
        Two-mass model: the mass at the contact and at the output [kg].
    stiffness_2
        Two-mass model: the stiffness between them [N/mm].
    speed_min_rpm, speed_max_rpm, speed_points
        The speed map's range [rpm] and number of speeds; ``None``: 0.5 and
        1.5 times the design speed.
    compensate_rpm
        Make the polydyne cam for this speed [rpm] (``None``: no compensation).
    max_residual
        Largest residual vibration amplitude in a dwell [mm, or degrees of
        swing for an arm] before a finding; ``None``: no limit.
    """

    model: TrainModel = TrainModel.SINGLE_MASS
    stiffness: float | None = None  # N/mm
    stiffness_torsional: float | None = None  # N·mm/rad
    damping_ratio: float = 0.05
    mass_1: float | None = None  # kg
    mass_2: float | None = None  # kg
    stiffness_2: float | None = None  # N/mm
    speed_min_rpm: float | None = None
    speed_max_rpm: float | None = None
    speed_points: int = 200
    compensate_rpm: float | None = None
    max_residual: float | None = None

    def validate(self, *, arm: bool) -> None:
        """Check the table; raise :class:`DesignError` naming the field (exit 2).

        Parameters
        ----------
        arm
            True for an oscillating follower (``stiffness_torsional`` needed).
        """
        key = "stiffness_torsional" if arm else "stiffness"
        rate = self.stiffness_torsional if arm else self.stiffness
        if rate is None:
            raise DesignError(TableKey(Knob.VIBRATION_TABLE, key), "is required (the train's stiffness)")
        _positive(key, rate)
        if not (0.0 <= self.damping_ratio < 1.0) or not math.isfinite(self.damping_ratio):
            raise DesignError(Knob.VIBRATION_DAMPING, f"{self.damping_ratio!r} is outside [0, 1)")
        if self.model is TrainModel.TWO_MASS:
            if arm:
                raise DesignError(
                    Knob.VIBRATION_MODEL, "'two-mass' is for translating followers; use 'single-mass'"
                )
            for name in ("mass_1", "mass_2", "stiffness_2"):
                value = getattr(self, name)
                if value is None:
                    raise DesignError(
                        TableKey(Knob.VIBRATION_TABLE, name), "is required by model = 'two-mass'"
                    )
                _positive(name, value)
        lo, hi = self.speed_min_rpm, self.speed_max_rpm
        for name, value in (
            ("speed_min_rpm", lo),
            ("speed_max_rpm", hi),
            ("compensate_rpm", self.compensate_rpm),
        ):
            if value is not None:
                _positive(name, value)
        if lo is not None and hi is not None and not lo < hi:
            raise DesignError(Knob.VIBRATION_SPEED_MAX, f"{hi!r} must exceed speed_min_rpm = {lo!r}")
        if (
            isinstance(self.speed_points, bool)
            or not isinstance(self.speed_points, int)
            or self.speed_points < 1
        ):
            raise DesignError(Knob.VIBRATION_SPEED_POINTS, f"{self.speed_points!r} is not an integer ≥ 1")
        if self.speed_points > 10000:
            raise DesignError(Knob.VIBRATION_SPEED_POINTS, f"{self.speed_points!r} exceeds 10000")
        if self.max_residual is not None:
            _positive("max_residual", self.max_residual)


def _positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0.0):
        raise DesignError(TableKey(Knob.VIBRATION_TABLE, name), f"{value!r} must be a finite number > 0")
