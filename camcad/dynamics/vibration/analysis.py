"""One entry point for the pipeline: the ``[vibration]`` analysis of a design, its findings and tables.

No file I/O: :meth:`VibrationResult.summary` is the ``vibration`` entry of
``summary.json``, :meth:`VibrationResult.response_rows` the rows of
``vibration.csv`` and :meth:`VibrationResult.speed_map_rows` those of
``speed_map.csv``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad.dynamics.vibration.harmonics import acceleration_harmonics, resonances
from camcad.dynamics.vibration.polydyne import CompensatedMotion, compensate
from camcad.dynamics.vibration.response import SpeedMap, TrainResponse, speed_map, train_response
from camcad.dynamics.vibration.train import train_from_specs
from camcad.errors import DesignError
from camcad.findings import Finding, Severity
from camcad.knobs import Knob

if TYPE_CHECKING:
    from camcad._typing import FloatArray
    from camcad.dynamics.spec import DynamicsSpec
    from camcad.dynamics.vibration.spec import VibrationSpec
    from camcad.extremes import Side
    from camcad.motion.program import MotionProgram

__all__ = ["VibrationResult", "analyse_vibration", "correction_max"]


@dataclass(frozen=True, slots=True, kw_only=True)
class VibrationResult:
    """The ``[vibration]`` analysis: response at the design speed, speed map, harmonics, findings."""

    response: TrainResponse
    speed_map: SpeedMap
    harmonics: tuple[FloatArray, FloatArray]
    findings: tuple[Finding, ...]
    compensated: CompensatedMotion | None = None
    unit: str = "mm"

    def summary(self) -> dict[str, Any]:
        """The ``vibration`` entry of ``summary.json`` (plain JSON values)."""
        r = self.response
        peak = r.error_peak
        out: dict[str, Any] = {
            "speed_rpm": r.speed_rpm,
            "natural_frequencies_hz": [round(float(w) / (2 * math.pi), 9) for w in r.natural_frequencies],
            f"error_peak_{self.unit}": peak.value,
            "error_peak_angle_deg": round(peak.angle_deg, 6),
            "contact_force_min": r.contact_force_min.value,
            "contact_force_min_angle_deg": round(r.contact_force_min.angle_deg, 6),
            f"residual_{self.unit}": list(r.residuals),
            "leaves_cam": r.leaves,
            "flights": [
                {
                    "leave_deg": round(math.degrees(f.leave), 6),
                    "land_deg": None if math.isnan(f.land) else round(math.degrees(f.land), 6),
                    f"impact_speed_{self.unit}_per_s": f.impact_speed,
                }
                for f in r.flights
            ],
            "periodic": r.periodic,
            "acceleration_harmonics": [
                [float(a), float(b)] for a, b in zip(self.harmonics[0], self.harmonics[1], strict=True)
            ],
        }
        if self.compensated is not None:
            value, where = correction_max(self.compensated)
            out["compensate_rpm"] = self.compensated.speed_rpm
            out[f"lift_correction_max_{self.unit}"] = value
            out["lift_correction_max_angle_deg"] = round(math.degrees(where), 6)
        return out

    def response_rows(self) -> list[tuple[str, ...]]:
        """``vibration.csv``: φ, s, x, x − y, contact force at the design speed, fixed format."""
        r = self.response
        rows: list[tuple[str, ...]] = [
            ("angle_deg", f"s_{self.unit}", f"x_{self.unit}", f"error_{self.unit}", "contact_force")
        ]
        for p, s, x, e, f in zip(np.degrees(r.phi), r.s, r.x, r.error, r.contact_force, strict=True):
            rows.append((f"{p:.6f}", f"{s:.9f}", f"{x:.9f}", f"{e:.9f}", f"{f:.6f}"))
        return rows

    def speed_map_rows(self) -> list[tuple[str, ...]]:
        """``speed_map.csv``: one row per speed (residual per dwell, peak error, minimum force, leaves)."""
        m = self.speed_map
        head = ["speed_rpm"] + [f"residual_dwell{k + 1}_{self.unit}" for k in range(len(m.dwells))]
        head += [f"error_peak_{self.unit}", "contact_force_min", "leaves_cam"]
        rows: list[tuple[str, ...]] = [tuple(head)]
        for k, rpm in enumerate(m.speeds_rpm):
            rows.append(
                (
                    f"{rpm:.6f}",
                    *(f"{v:.9f}" for v in m.residuals[k]),
                    f"{m.error_peak[k]:.9f}",
                    f"{m.contact_force_min[k]:.6f}",
                    "1" if m.leaves[k] else "0",
                )
            )
        return rows


def correction_max(cam: CompensatedMotion) -> tuple[float, float]:
    """The true largest |c − y| [lift unit] and its angle [rad]: a 0.1° grid with the joints, then Newton.

    Newton's steps on (c − y)′ = 0 use the exact (c − y)″; the joints' one-sided
    values are candidates too, so the figure is the true extreme, not a sample's.
    """
    joints = np.mod(np.asarray(cam.program.pieces, dtype=float), 2.0 * math.pi)
    phi = np.union1d(np.linspace(0.0, 2.0 * math.pi, 3600, endpoint=False), joints)

    def diff(p: FloatArray, side: Side = "right") -> tuple[FloatArray, FloatArray, FloatArray]:
        c, y = cam.evaluate(p, side=side), cam.program.evaluate(p, side=side)
        return c.s - y.s, c.v - y.v, c.a - y.a

    e, _, _ = diff(phi)
    k = int(np.argmax(np.abs(e)))
    best, where = abs(float(e[k])), float(phi[k])
    x, half = float(phi[k]), 2.0 * math.pi / 3600
    for _ in range(8):
        _, d1, d2 = diff(np.array([x]))
        if d2[0] == 0.0:
            break
        x = min(max(x - float(d1[0] / d2[0]), float(phi[k]) - half), float(phi[k]) + half)
        value = abs(float(diff(np.array([x]))[0][0]))
        if value > best:
            best, where = value, x
    for side in ("left", "right"):
        ej, _, _ = diff(joints, side)  # type: ignore[arg-type]
        if ej.size and float(np.max(np.abs(ej))) > best:
            i = int(np.argmax(np.abs(ej)))
            best, where = float(abs(ej[i])), float(joints[i])
    return best, where % (2.0 * math.pi)


def analyse_vibration(
    program: MotionProgram,
    vib: VibrationSpec,
    dyn: DynamicsSpec,
    *,
    speed_rpm: float,
    arm_angle: float | None = None,
    spring_loaded: bool = True,
) -> VibrationResult:
    """Run the ``[vibration]`` analysis of a design.

    Parameters
    ----------
    program
        The motion program (the output's motion; with ``compensate_rpm`` the
        cam is made from the polydyne lift c instead).
    vib, dyn
        The ``[vibration]`` and ``[dynamics]`` tables.
    speed_rpm
        The design speed ``cam.speed_rpm``.
    arm_angle
        An oscillating follower's arm direction at ψ = 0 [rad]; ``None`` for a slide.
    spring_loaded
        False for a groove or conjugate cam (positive drive).

    Raises
    ------
    DesignError
        A bad ``[vibration]`` field, ``compensate_rpm`` on a positive-drive cam,
        or a law not smooth enough for it (exit 2).
    """
    train = train_from_specs(vib, dyn, arm_angle=arm_angle)
    unit = "deg" if arm_angle is not None else "mm"
    cam: CompensatedMotion | None = None
    if vib.compensate_rpm is not None:
        if not spring_loaded:
            raise DesignError(
                Knob.COMPENSATE_RPM, "a groove or conjugate cam cannot be compensated here; remove it"
            )
        cam = compensate(program, train, speed_rpm=vib.compensate_rpm)
    lift = program if cam is None else cam
    response = train_response(lift, train, speed_rpm=speed_rpm, spring_loaded=spring_loaded, target=program)
    lo = vib.speed_min_rpm if vib.speed_min_rpm is not None else 0.5 * speed_rpm
    hi = vib.speed_max_rpm if vib.speed_max_rpm is not None else 1.5 * speed_rpm
    if not lo < hi:
        raise DesignError(Knob.VIBRATION_SPEED_MAX, f"{hi!r} must exceed speed_min_rpm = {lo!r}")
    speeds = np.linspace(lo, hi, vib.speed_points) if vib.speed_points > 1 else np.array([lo])
    smap = speed_map(lift, train, speeds_rpm=speeds, spring_loaded=spring_loaded, target=program)
    harmonics = acceleration_harmonics(program)
    findings = list(resonances(response.natural_frequencies, harmonics, speed_rpm=speed_rpm))
    if response.leaves:
        first = response.flights[0].leave if response.flights else response.contact_force_min.phi
        field = Knob.SPRING_PRELOAD_TORSIONAL if arm_angle is not None else Knob.SPRING_PRELOAD
        findings.append(
            Finding(
                kind="leaves the cam",
                severity=Severity.HARD,
                field=field,
                message=(
                    f"the elastic follower train leaves the cam at {math.degrees(first):.2f}° "
                    f"at {speed_rpm:g} rpm "
                    f"(contact force would reach {response.contact_force_min.value:.4g} "
                    f"{'N·mm' if arm_angle is not None else 'N'}): raise the spring "
                    "preload or rate, stiffen the train, or lower the speed"
                ),
                angle=first,
                value=response.contact_force_min.value,
                limit=0.0,
                unit="N·mm" if arm_angle is not None else "N",
            )
        )
    if vib.max_residual is not None and response.residuals:
        worst = int(np.argmax(response.residuals))
        value = response.residuals[worst]
        if value > vib.max_residual:
            findings.append(
                Finding(
                    kind="residual vibration",
                    severity=Severity.SOFT,
                    field=Knob.MAX_RESIDUAL,
                    message=(
                        f"residual vibration of {value:.4g} {unit} in dwell {worst + 1} "
                        f"at {speed_rpm:g} rpm exceeds "
                        f"max_residual = {vib.max_residual:g} {unit}: choose a smoother law, a longer rise, "
                        "a stiffer train or a polydyne cam (compensate_rpm)"
                    ),
                    value=value,
                    limit=vib.max_residual,
                    unit=unit,
                )
            )
    return VibrationResult(
        response=response,
        speed_map=smap,
        harmonics=harmonics,
        findings=tuple(findings),
        compensated=cam,
        unit=unit,
    )
