"""The outcome of a dynamic analysis: per-sample arrays and the summary numbers.

No file I/O here: :meth:`DynamicsResult.summary` gives the ``dynamics``
section of ``summary.json`` for the pipeline to write (``dynamics.csv`` is
written from the arrays by :func:`camcad.export.tables.write_dynamics_csv`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import FloatArray
from camcad.dynamics.jump import covering_arc
from camcad.dynamics.spec import DynamicsModel
from camcad.extremes import SIDE_WORDS, Extreme
from camcad.findings import Finding

__all__ = ["FLANK_WORDS", "DynamicsResult"]

FLANK_WORDS = ("inner", "outer")
"""A groove's flanks: the inner drives where the contact force is positive, the outer where negative."""


def _flank(force: Extreme, stress: Extreme) -> dict[str, Any]:
    """One flank's figures where it drives: its largest load and Hertz stress (None if it never drives)."""
    drives = force.value > 0.0
    out: dict[str, Any] = {}
    for key, unit, ext in (("contact_force_max", "N", force), ("hertz_stress_max", "MPa", stress)):
        out[f"{key}_{unit}"] = ext.value if drives else None
        out[f"{key}_angle_deg"] = round(ext.angle_deg, 6) if drives else None
        out[f"{key}_side"] = SIDE_WORDS[ext.side] if drives and ext.side is not None else None
    return out


def _deg(phi: float) -> float:
    """Angle in [0, 360) degrees, rounded to 1e-6° so that summaries diff cleanly."""
    return round(math.degrees(phi) % 360.0, 6)


@dataclass(frozen=True, slots=True, kw_only=True)
class DynamicsResult:
    """Forces, torque and contact stress of the follower over the cam turn.

    Attributes
    ----------
    model
        The dynamic model used.
    phi
        (n,) cam angle φ [rad].
    contact_force
        (n,) contact force [N]: F_C along the common normal (energy method),
        or the normal force N1 on the flat face (guided tappet). Negative
        where the follower would leave the cam.
    torque
        (n,) drive torque on the cam shaft [N·mm], positive when the shaft
        drives the cam in its sense of rotation.
    hertz_stress
        (n,) peak Hertz contact stress σ_max [MPa]; 0 where contact is lost.
    normal_force
        (n,) N1 [N] for the guided tappet (equals ``contact_force``); ``None``
        for the energy method.
    guide_force_near, guide_force_far
        (n,) guide normal forces N2, N3 [N] of the guided tappet, else ``None``.
    margin
        ``[dynamics].min_contact_force`` [N]: contact counts as lost below it.
    jump_ranges
        (first, last) sample angle [rad] of every run where contact is lost;
        first > last for a run through 0°.
    min_preload
        Smallest spring preload [N] that keeps the contact force ≥ margin.
    preload_deflection
        The same as a preload deflection y1 [mm] when the spring is given by
        its coil, else ``None``.
    speed_range_rpm
        (low, high) cam speeds [rpm] that keep the contact force ≥ margin
        (high may be ``inf``); ``None`` if no speed does.
    allowable_stress
        ``[dynamics].allowable_stress`` [MPa] or ``None``.
    findings
        The broken limits (jump, contact stress) and the notes on the
        model's validity (guide forces changing side) as typed findings.
    contact_force_min, contact_force_max, torque_min, torque_max, hertz_stress_max
        True extremes over the turn (one-sided limits at joints included), when
        the analysis had the exact cam; else ``None`` and the summary falls back
        to the samples.
    """

    model: DynamicsModel
    phi: FloatArray
    contact_force: FloatArray
    torque: FloatArray
    hertz_stress: FloatArray
    normal_force: FloatArray | None = None
    guide_force_near: FloatArray | None = None
    guide_force_far: FloatArray | None = None
    margin: float = 0.0
    jump_ranges: tuple[tuple[float, float], ...] = ()
    min_preload: float = 0.0  # in preload_unit
    preload_unit: str = "N"  # "N·mm" for a torsion spring on an arm
    preload_deflection: float | None = None
    speed_range_rpm: tuple[float, float] | None = None
    allowable_stress: float | None = None
    findings: tuple[Finding, ...] = ()
    contact_force_min: Extreme | None = None
    contact_force_max: Extreme | None = None
    torque_min: Extreme | None = None
    torque_max: Extreme | None = None
    hertz_stress_max: Extreme | None = None
    crossovers: tuple[float, ...] = ()  # rad, positive drive: where the driving flank (or roller) changes
    impact_speeds: tuple[float, ...] = ()  # mm/s across the groove's clearance, one per crossover
    positive_drive: bool = False  # a groove or conjugate pair: no spring holds it on, no jump check
    # a groove's inner and outer flank: the largest load [N] and Hertz stress [MPa] where each drives
    flank_force_max: tuple[Extreme, Extreme] | None = None
    flank_stress_max: tuple[Extreme, Extreme] | None = None

    @property
    def jump(self) -> bool:
        """Whether the contact force falls below the margin anywhere."""
        return bool(self.jump_ranges)

    @property
    def jump_range(self) -> tuple[float, float] | None:
        """Shortest arc (start, end) [rad] holding every loss of contact, or ``None``."""
        return covering_arc(self.jump_ranges)

    def summary(self) -> dict[str, Any]:
        """Return the ``dynamics`` section of ``summary.json``.

        Returns
        -------
        dict[str, Any]
            For each of ``torque_max``, ``torque_min``, ``contact_force_max``,
            ``contact_force_min`` and ``hertz_stress_max``: the value
            (``_Nmm``, ``_N``, ``_MPa``), ``_angle_deg`` and ``_side``
            (``"before joint"``/``"after joint"`` for a one-sided limit, else
            ``None``); then ``jump`` (bool), ``jump_range_deg`` ([start, end]
            in degrees, start > end through 0°, or ``None``),
            ``min_preload_N``, ``speed_range_rpm`` ([low, high] or ``None``;
            both left out for positive drive, where no jump check applies).
            A groove adds
            ``hertz_stress_max_flank`` (``"inner"`` or ``"outer"``, the flank
            that carries the peak) and ``flanks``: for each flank the largest
            load it carries where it drives (``contact_force_max_N``) and its
            largest Hertz stress (``hertz_stress_max_MPa``), with angles and
            sides; the signed ``contact_force_*`` are positive where the
            inner flank drives. Plain Python values, JSON-ready.
        """
        arc = self.jump_range
        out: dict[str, Any] = {}
        for key, unit, ext, values, kind in (
            ("torque_max", "Nmm", self.torque_max, self.torque, "max"),
            ("torque_min", "Nmm", self.torque_min, self.torque, "min"),
            ("contact_force_max", "N", self.contact_force_max, self.contact_force, "max"),
            ("contact_force_min", "N", self.contact_force_min, self.contact_force, "min"),
            ("hertz_stress_max", "MPa", self.hertz_stress_max, self.hertz_stress, "max"),
        ):
            if ext is None:
                i = int(np.argmax(values) if kind == "max" else np.argmin(values))
                ext = Extreme(value=float(values[i]), phi=float(self.phi[i]))
            out[f"{key}_{unit}"] = ext.value
            out[f"{key}_angle_deg"] = round(ext.angle_deg, 6)
            out[f"{key}_side"] = None if ext.side is None else SIDE_WORDS[ext.side]
        out |= {"jump": self.jump, "jump_range_deg": None if arc is None else [_deg(arc[0]), _deg(arc[1])]}
        if not self.positive_drive:  # the spring's preload and the speed range keep a spring-held follower on
            out |= {
                ("min_preload_N" if self.preload_unit == "N" else "min_preload_N_mm"): self.min_preload,
                "speed_range_rpm": None if self.speed_range_rpm is None else list(self.speed_range_rpm),
            }
        if self.flank_force_max is not None and self.flank_stress_max is not None:
            out["hertz_stress_max_flank"] = self.hertz_stress_flank
            out["flanks"] = {
                name: _flank(force, peak)
                for name, force, peak in zip(
                    FLANK_WORDS, self.flank_force_max, self.flank_stress_max, strict=True
                )
            }
        if self.crossovers:
            out["crossover_angles_deg"] = [_deg(p) for p in self.crossovers]
            # a massless follower has no free flight (NaN): no figure
            out["impact_speed_max_mm_per_s"] = max(
                (v for v in self.impact_speeds if math.isfinite(v)), default=None
            )
        return out

    @property
    def hertz_stress_flank(self) -> str | None:
        """A groove's flank that carries the peak Hertz stress (``"inner"``/``"outer"``), else None."""
        if self.flank_stress_max is None:
            return None
        return FLANK_WORDS[0 if self.flank_stress_max[0].value >= self.flank_stress_max[1].value else 1]
