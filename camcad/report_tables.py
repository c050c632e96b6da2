"""The report's tables in words: human labels, units in the headers, sensible precision.

``summary.json`` keeps machine names (``a_max_abs_mm_per_rad2``); the report
shows the same numbers as "max |a| [mm/rad²]" with the angle where they
occur, and says in words what a jump at a motion joint means for the
machine. :func:`label` turns any summary key into a label with its unit
(keys added later still read well: unknown words are spelled out),
:func:`quantity_rows` pairs every value with its ``…_angle_deg`` and
``…_side`` companions, and :func:`joint_rows` explains each joint.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = [
    "JUMP_BANNER_SHARE",
    "fmt",
    "joint_meaning",
    "joint_rows",
    "label",
    "large_acceleration_jumps",
    "quantity_rows",
    "split_unit",
]

JUMP_BANNER_SHARE = 0.05
"""An acceleration jump of at least this share of the peak |a| goes into the warning banner."""

_DASH = "—"

# unit suffixes of summary keys, longest first: key suffix → shown unit
_UNITS: tuple[tuple[str, str], ...] = (
    ("Nmm_per_rad", "N·mm/rad"),
    ("mm_per_rad3", "mm/rad³"),
    ("mm_per_rad2", "mm/rad²"),
    ("mm_per_rad", "mm/rad"),
    ("deg_per_rad3", "°/rad³"),
    ("deg_per_rad2", "°/rad²"),
    ("deg_per_rad", "°/rad"),
    ("kg_mm2", "kg·mm²"),
    ("N_per_mm", "N/mm"),
    ("Nmm", "N·mm"),
    ("MPa", "MPa"),
    ("rpm", "rpm"),
    ("mm3", "mm³"),
    ("mm2", "mm²"),
    ("mm", "mm"),
    ("deg", "°"),
    ("kg", "kg"),
    ("N", "N"),
    ("s", "s"),
)

# the quantity part of a key (unit suffix removed) → words
_WORDS: dict[str, str] = {
    "lift": "lift",
    "velocity_jumps": "velocity jumps at",
    "v_max_abs": "max |v|",
    "a_max_abs": "max |a|",
    "j_max_abs": "max |j|",
    "pressure_angle_max": "max pressure angle",
    "profile_radius_min": "smallest profile radius",
    "profile_radius_max": "largest profile radius",
    "curvature_radius_min": "smallest convex radius of curvature",
    "concave_radius_min": "smallest concave radius",
    "undercut": "undercut",
    "torque_max": "max input torque",
    "torque_min": "min input torque",
    "contact_force_max": "max contact force",
    "contact_force_min": "min contact force",
    "hertz_stress_max": "max Hertz stress",
    "jump": "follower leaves the cam",
    "jump_range": "where it leaves the cam",
    "min_preload": "smallest spring preload against leaving",
    "speed_range": "speed range without leaving",
    "tolerance": "tolerance",
    "max_error": "certified max error",
    "rms_error": "RMS error at the samples",
    "control_points": "control points",
    "degree": "degree",
    "blocks": "blocks",
    "arcs": "arc moves",
    "cutting_length": "cutting length",
    "cycle_time": "estimated cycle time",
    "max_deviation": "finishing contour deviation",
    "face_width_needed": "face width needed",
}

_SMALL = ("tolerance", "error", "deviation")  # lengths shown in µm when below 0.01 mm


def split_unit(key: str) -> tuple[str, str]:
    """(quantity part, shown unit) of a summary key; unit ``""`` when the key names none."""
    for suffix, unit in _UNITS:
        if key.endswith("_" + suffix):
            return key[: -len(suffix) - 1], unit
    return key, ""


def label(key: str) -> str:
    """A human label with its unit in brackets, e.g. ``a_max_abs_mm_per_rad2`` → ``max |a| [mm/rad²]``."""
    base, unit = split_unit(key)
    words = _WORDS.get(base, base.replace("_", " "))
    return f"{words} [{unit}]" if unit else words


def _sig(value: float, digits: int = 4) -> str:
    """``value`` with ``digits`` significant digits in plain decimal notation (no exponent)."""
    if value == 0.0:
        return "0"
    places = max(0, digits - 1 - math.floor(math.log10(abs(value))))
    text = f"{value:.{places}f}"
    return text.replace("-", "−")


def fmt(value: Any, unit: str = "") -> str:
    """A value for a table: angles to 0.01°, others to 4 significant digits, lists joined, ``—`` for none."""
    if value is None:
        return _DASH
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, (list, tuple)):
        return ", ".join(fmt(v, unit) for v in value) if value else "none"
    if isinstance(value, float):
        if not math.isfinite(value):
            return _DASH
        if unit == "°":
            return f"{value:.2f}".replace("-", "−")
        return _sig(value)
    return str(value)


def quantity_rows(section: Mapping[str, Any], *, skip: Sequence[str] = ()) -> list[tuple[str, str, str]]:
    """(label with unit, value, where) for every entry of a summary section.

    ``X_angle_deg`` and ``X_side`` entries are folded into the "where" of
    their ``X_<unit>``: ``at 240.0° (just after the joint)``. Small lengths
    (tolerances, errors, deviations below 0.01 mm) are shown in µm. Nested
    mappings and lists of records are left to the caller (skipped here).
    """
    rows = []
    for key, value in section.items():
        if key in skip or key.endswith(("_angle_deg", "_side")) or isinstance(value, Mapping):
            continue
        if isinstance(value, (list, tuple)) and value and isinstance(value[0], Mapping):
            continue
        base, unit = split_unit(key)
        where = ""
        angle = section.get(f"{base}_angle_deg")
        if isinstance(angle, (int, float)) and not isinstance(angle, bool):
            where = f"at {angle:.1f}°"
            side = section.get(f"{base}_side")
            if side:
                where += f" (just {side})"
        text = label(key)
        if unit == "mm" and any(w in base for w in _SMALL) and isinstance(value, float) and abs(value) < 0.01:
            value, text = value * 1000.0, text.replace("[mm]", "[µm]")
            unit = "µm"
        rows.append((text, fmt(value, unit), where))
    return rows


def joint_meaning(
    joint: Mapping[str, Any], *, unit: str, mass_kg: float, speed_rpm: float, a_peak: float | None = None
) -> str:
    """What the jump at a joint means for the machine, in words.

    A velocity jump is a blow (infinite acceleration, a corner in the
    profile); an acceleration jump is a step in the inertia force,
    Δf = m Δa ω² on a slide (Norton 2009, §8.3, the "fundamental law of cam
    design"); a jerk jump is a kink in the force (vibration at high speed);
    none is smooth. An acceleration jump below :data:`JUMP_BANNER_SHARE` of
    the peak |a| (``a_peak``, same unit) is called negligible.
    """
    dv = joint.get(f"dv_{unit}_per_rad") or 0.0
    da = joint.get(f"da_{unit}_per_rad2") or 0.0
    dj = joint.get(f"dj_{unit}_per_rad3") or 0.0
    if dv:
        return "the follower is struck: infinite acceleration and a corner in the profile; not runnable"
    if da:
        omega = 2.0 * math.pi * speed_rpm / 60.0  # rad/s
        small = a_peak is not None and abs(da) < JUMP_BANNER_SHARE * a_peak
        if unit == "mm" and mass_kg > 0.0:
            step = mass_kg * abs(da) * 1e-3 * omega**2  # Norton 2009, §8.3: F = m a, a = s″ω²
            if small:
                return f"a negligible step in the inertia force: {_sig(step, 3)} N at {speed_rpm:g} rpm"
            return (
                f"a shock: the inertia force steps by {_sig(step, 3)} N at {speed_rpm:g} rpm "
                "(noise, wear, vibration; grows with speed²)"
            )
        if small:
            return "a negligible step in the inertia load"
        return "a shock: the inertia load steps here (noise, wear, vibration; grows with speed²)"
    if dj:
        return "a kink in the force: smooth enough at low speed, excites vibration at high speed"
    return "smooth: no jump in velocity, acceleration or jerk"


def joint_rows(
    joints: Sequence[Mapping[str, Any]],
    *,
    unit: str,
    mass_kg: float,
    speed_rpm: float,
    a_peak: float | None = None,
) -> tuple[list[str], list[list[str]]]:
    """Header and rows of the joint table: angle, the three jumps with units, and what they mean."""
    u = "°" if unit == "deg" else "mm"
    header = [
        "cam angle [°]",
        f"velocity jump [{u}/rad]",
        f"acceleration jump [{u}/rad²]",
        f"jerk jump [{u}/rad³]",
        "what it means for the machine",
    ]
    rows = []
    for j in joints:
        rows.append(
            [
                fmt(float(j.get("angle_deg", 0.0)), "°"),
                fmt(j.get(f"dv_{unit}_per_rad")),
                fmt(j.get(f"da_{unit}_per_rad2")),
                fmt(j.get(f"dj_{unit}_per_rad3")),
                joint_meaning(j, unit=unit, mass_kg=mass_kg, speed_rpm=speed_rpm, a_peak=a_peak),
            ]
        )
    return header, rows


def large_acceleration_jumps(
    joints: Sequence[Mapping[str, Any]], *, unit: str, a_peak: float | None, mass_kg: float, speed_rpm: float
) -> list[str]:
    """Banner lines for acceleration jumps of at least :data:`JUMP_BANNER_SHARE` of the peak |a|."""
    if not a_peak:
        return []
    u = "°" if unit == "deg" else "mm"
    out = []
    for j in joints:
        da = j.get(f"da_{unit}_per_rad2") or 0.0
        if j.get(f"dv_{unit}_per_rad"):
            continue  # a velocity jump is a hard limit, reported with the findings
        if abs(da) >= JUMP_BANNER_SHARE * a_peak:
            meaning = joint_meaning(j, unit=unit, mass_kg=mass_kg, speed_rpm=speed_rpm)
            out.append(
                f"acceleration jumps by {_sig(da, 3)} {u}/rad² at φ = {float(j['angle_deg']):.1f}° "
                f"({abs(da) / a_peak:.0%} of the peak |a|): {meaning}"
            )
    return out
