r"""What a design is judged by: objectives, limits, and one table row per analysed design.

The measures are true extremes from the analysis (``summary.json``'s
figures, see :mod:`camcad.extremes`), in the units of the report:

========================  ====  =================================================
name                      unit  figure
========================  ====  =================================================
``base_radius``           mm    ``cam.base_radius`` (the cam's size)
``pressure_angle``        deg   peak \|α\| over the turn, on every plate
``contact_stress``        MPa   peak Hertz stress, on every plate and flank
``torque``                N·mm  peak \|input torque\|
``contact_force``         N     peak contact force, on every plate and flank
``contact_force_min``     N     smallest contact force (follower jump below 0)
``curvature_radius``      mm    smallest convex profile radius, on every plate
``roller_life_h``         h     track roller's L10 life (``[life]``; issue 35)
``min_film_ratio``        1     smallest film ratio λ (``[lubrication]``)
``motor_rms_torque``      N·m   motor's RMS torque (``[drive]``)
``vibration_residual_mm`` mm    largest residual vibration in a dwell at the
                                design speed (``[vibration]``; issue 34;
                                degrees of swing on an arm)
``min_dynamic_contact_``  N     smallest contact force of the elastic train at
``force``                       the design speed (``[vibration]``; N·mm on an arm)
========================  ====  =================================================

The last five are empty (None) for a design without their table.

Every part is held to a limit (issue 31): a conjugate pair's figures are the
worse of its two plates' (the second plate with its own roller, the
``second_plate`` section of ``summary.json``), a groove's the worse of its
two flanks' where each drives (``dynamics.flanks``: the outer flank's load is
the negative contact force's size). ``roller_life_h`` and ``min_film_ratio``
are the smallest over the parts (a pair's second roller and plate; a groove's
figures already cover both flanks). ``contact_force_min`` stays the signed
figure of the first plate (positive where the first roller or the inner
flank drives): a positive drive has no jump to keep.

A limit is ``name<=value`` or ``name>=value`` in those units (``--limit
contact_stress<=800``).
"""

from __future__ import annotations

import json
import math
import operator
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from camcad.analysis import Analysis
from camcad.errors import CamcadError, DesignError, UsageError

__all__ = [
    "MEASURES",
    "Limit",
    "Measure",
    "analysis_row",
    "failed_row",
    "measure",
    "measure_values",
    "parse_limit",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class Measure:
    """One figure a design is judged by: its name, unit, column and what it is."""

    name: str
    unit: str
    column: str  # the row's column, e.g. "pressure_angle_deg"
    text: str

    def of(self, row: Mapping[str, Any]) -> float | None:
        """The measure's value in a table row (None for a design that was not analysed)."""
        value = row.get(self.column)
        return None if value is None else float(value)


def _torque(summary: Mapping[str, Any]) -> float | None:
    dyn = summary["dynamics"]
    values = [abs(v) for v in (dyn.get("torque_max_Nmm"), dyn.get("torque_min_Nmm")) if v is not None]
    return max(values) if values else None


def _residual(summary: Mapping[str, Any]) -> float | None:
    """The largest residual vibration over the dwells at the design speed [mm, or deg on an arm]."""
    vib = summary.get("vibration")
    if vib is None:
        return None
    values = vib.get("residual_mm", vib.get("residual_deg", []))
    return max(values) if values else None


def _sections(summary: Mapping[str, Any], name: str) -> list[Mapping[str, Any]]:
    """The ``geometry`` or ``dynamics`` section of every plate: the first's, a conjugate pair's second's."""
    out = [summary[name]]
    second = summary.get("second_plate")
    if second is not None and name in second:
        out.append(second[name])
    return out


def _parts_of(summary: Mapping[str, Any], name: str) -> list[Mapping[str, Any]]:
    """The ``life`` or ``lubrication`` section of every part that has it (a pair's second plate's too)."""
    return [x[name] for x in (summary, summary.get("second_plate") or {}) if name in x]


def _worst(values: Sequence[Any], pick: Callable[[Sequence[float]], float]) -> float | None:
    known = [float(v) for v in values if v is not None]
    return pick(known) if known else None


def _per_part(summary: Mapping[str, Any], key: str) -> list[Any]:
    """``key`` of every plate's dynamics and of each flank of a groove where it drives."""
    out = [dyn.get(key) for dyn in _sections(summary, "dynamics")]
    for flank in summary["dynamics"].get("flanks", {}).values():
        out.append(flank.get(key))  # None where the flank never drives
    return out


def _contact_force(summary: Mapping[str, Any]) -> float | None:
    """The largest load any part carries [N]: a groove's flanks' (each positive where it drives)."""
    flanks = summary["dynamics"].get("flanks")
    if flanks is not None:
        found = _worst([f.get("contact_force_max_N") for f in flanks.values()], max)
        if found is not None:
            return found
    return _worst([dyn.get("contact_force_max_N") for dyn in _sections(summary, "dynamics")], max)


_FIGURES: dict[str, Callable[[Analysis, Mapping[str, Any]], float | None]] = {
    "base_radius": lambda a, s: a.design.cam.base_radius,
    "pressure_angle": lambda a, s: _worst(
        [g["pressure_angle_max_deg"] for g in _sections(s, "geometry")], max
    ),
    "contact_stress": lambda a, s: _worst(_per_part(s, "hertz_stress_max_MPa"), max),
    "torque": lambda a, s: _torque(s),
    "contact_force": lambda a, s: _contact_force(s),
    "contact_force_min": lambda a, s: s["dynamics"].get("contact_force_min_N"),
    "curvature_radius": lambda a, s: _worst(
        [g["curvature_radius_min_mm"] for g in _sections(s, "geometry")], min
    ),
    # issue 35: life, film and drive, when the design has their tables
    "roller_life_h": lambda a, s: _worst([x.get("roller_life_h") for x in _parts_of(s, "life")], min),
    "min_film_ratio": lambda a, s: _worst(
        [x.get("min_film_ratio") for x in _parts_of(s, "lubrication")], min
    ),
    "motor_rms_torque": lambda a, s: s.get("drive", {}).get("motor_rms_torque_Nm"),
    # issue 34: the elastic follower train at the design speed, when the design has [vibration]
    "vibration_residual_mm": lambda a, s: _residual(s),
    "min_dynamic_contact_force": lambda a, s: s.get("vibration", {}).get("contact_force_min"),
}

MEASURES: dict[str, Measure] = {
    m.name: m
    for m in (
        Measure(name="base_radius", unit="mm", column="base_radius_mm", text="base radius (cam size)"),
        Measure(name="pressure_angle", unit="deg", column="pressure_angle_deg", text="peak |pressure angle|"),
        Measure(name="contact_stress", unit="MPa", column="contact_stress_MPa", text="peak Hertz stress"),
        Measure(name="torque", unit="N·mm", column="torque_Nmm", text="peak |input torque|"),
        Measure(name="contact_force", unit="N", column="contact_force_N", text="peak contact force"),
        Measure(
            name="contact_force_min", unit="N", column="contact_force_min_N", text="smallest contact force"
        ),
        Measure(
            name="curvature_radius",
            unit="mm",
            column="curvature_radius_mm",
            text="smallest convex profile radius",
        ),
        Measure(name="roller_life_h", unit="h", column="roller_life_h", text="track roller L10 life"),
        Measure(
            name="min_film_ratio", unit="1", column="min_film_ratio", text="smallest lubricant film ratio"
        ),
        Measure(name="motor_rms_torque", unit="N·m", column="motor_rms_torque_Nm", text="motor RMS torque"),
        Measure(
            name="vibration_residual_mm",
            unit="mm",
            column="vibration_residual_mm",
            text="largest residual vibration in a dwell",
        ),
        Measure(
            name="min_dynamic_contact_force",
            unit="N",
            column="min_dynamic_contact_force_N",
            text="smallest contact force of the elastic train",
        ),
    )
}
"""The objectives and limit quantities by name."""


def measure(name: str, flag: str) -> Measure:
    """The measure called ``name`` or a UsageError naming ``flag`` and listing them."""
    if name not in MEASURES:
        raise UsageError(flag, f"unknown quantity {name!r} (allowed: {', '.join(MEASURES)})")
    return MEASURES[name]


_OPS: dict[str, Callable[[float, float], bool]] = {"<=": operator.le, ">=": operator.ge}


@dataclass(frozen=True, slots=True, kw_only=True)
class Limit:
    """``measure op value``: a constraint on a measure (value in the measure's unit)."""

    measure: Measure
    op: str  # "<=" or ">="
    value: float

    @property
    def text(self) -> str:
        """``contact_stress<=800``."""
        return f"{self.measure.name}{self.op}{self.value:g}"

    def margin(self, value: float | None) -> float:
        """How far ``value`` is inside the limit (≥ 0 holds), in the measure's unit; −inf when unknown."""
        if value is None or not math.isfinite(value):
            return -math.inf
        return self.value - value if self.op == "<=" else value - self.value

    def holds(self, row: Mapping[str, Any]) -> bool:
        """The limit holds for a table row (False for a design that was not analysed)."""
        return self.margin(self.measure.of(row)) >= 0.0


def parse_limit(text: str, *, flag: str = "--limit") -> Limit:
    """Read ``name<=value`` or ``name>=value``.

    Raises
    ------
    UsageError
        Naming ``flag`` and the text when the form, the name or the number is wrong.
    """
    match = re.fullmatch(r"\s*([a-z_]+)\s*(<=|>=)\s*([^\s]+)\s*", text)
    if match is None:
        raise UsageError(
            flag, f"{text!r}: write quantity<=value or quantity>=value, e.g. contact_stress<=800"
        )
    try:
        value = float(match[3])
    except ValueError:
        raise UsageError(flag, f"{text!r}: {match[3]!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(flag, f"{text!r}: the limit must be a finite number")
    return Limit(measure=measure(match[1], flag), op=match[2], value=value)


def measure_values(analysis: Analysis, summary: Mapping[str, Any] | None = None) -> dict[str, float | None]:
    """Every measure of an analysed design, by column name."""
    s = analysis.summary() if summary is None else summary
    out: dict[str, float | None] = {}
    for name, m in MEASURES.items():
        value = _FIGURES[name](analysis, s)
        out[m.column] = None if value is None else float(value)
    return out


def _flat(prefix: str, section: Mapping[str, Any], out: dict[str, Any]) -> None:
    """Scalars of a summary section as ``prefix.key``; lists as JSON text; joints left out."""
    for key, value in section.items():
        if key == "joints":
            continue
        name = f"{prefix}.{key}"
        if isinstance(value, Mapping):
            _flat(name, value, out)
        elif isinstance(value, (list, tuple)):
            out[name] = json.dumps(value, separators=(",", ":"))
        elif isinstance(value, bool) or value is None or isinstance(value, str):
            out[name] = value
        else:
            out[name] = float(value)


def analysis_row(analysis: Analysis, limits: Sequence[Limit]) -> dict[str, Any]:
    """The verdicts, measures and every summary figure of one analysed design.

    Columns: ``status`` (``ok`` no limit broken, ``limit`` a hard or soft
    limit of the design broken), ``feasible`` (status ok and every
    ``limits`` holds), ``violations`` (the broken limits' kinds, ``;``
    separated), ``reason`` (the first broken limit's message), one
    ``limit:<text>`` column per extra limit, the measures
    (:data:`MEASURES`), then ``motion.*``, ``geometry.*``, ``dynamics.*``
    from ``summary.json``.
    """
    summary = analysis.summary()
    findings = [f for f in analysis.findings if not f.note]  # the broken limits; a note breaks none
    row: dict[str, Any] = {
        "status": "limit" if findings else "ok",
        "feasible": False,
        "violations": "; ".join(dict.fromkeys(f.kind for f in findings)),
        "reason": findings[0].message if findings else None,
    }
    values = measure_values(analysis, summary)
    verdicts = {f"limit:{lim.text}": lim.holds(values) for lim in limits}
    row.update(verdicts)
    row["feasible"] = not findings and all(verdicts.values())
    row.update(values)
    for section in ("motion", "geometry", "dynamics"):
        _flat(section, summary[section], row)
    return row


def failed_row(err: CamcadError, limits: Sequence[Limit]) -> dict[str, Any]:
    """The row of a design that could not be analysed: ``invalid`` with the error as the reason."""
    row: dict[str, Any] = {
        "status": "invalid" if isinstance(err, DesignError) else "limit",
        "feasible": False,
        "violations": "invalid" if isinstance(err, DesignError) else type(err).__name__,
        "reason": str(err),
    }
    row.update({f"limit:{lim.text}": False for lim in limits})
    return row
