"""The text ``camcad check`` prints: one row (name, value) per figure of the summary."""

from __future__ import annotations

import math
from typing import Any


def _fmt(value: Any, unit: str = "", digits: int = 3) -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value}{unit}"
    return f"{value:.{digits}f}{unit}"


def _at(section: dict[str, Any], key: str) -> str:
    """`` at 90.0° (just before the joint)`` for an extreme of ``section``, or ``""``."""
    angle = section.get(f"{key}_angle_deg")
    if angle is None:
        return ""
    side = section.get(f"{key}_side")
    return f" at {angle:.1f}°" + (f" (just {side.replace(' joint', ' the joint')})" if side else "")


def _lift_row(motion: dict[str, Any]) -> tuple[str, str]:
    """The nominal lift (or swing), with the true stroke beside it where the travel exceeds it."""
    name, u, shown = ("lift", "mm", " mm") if "lift_mm" in motion else ("arm swing", "deg", "°")
    text = _fmt(motion[f"lift_{u}"], shown)
    stroke = motion.get(f"stroke_{u}")
    if stroke is not None and round(stroke, 3) != round(motion[f"lift_{u}"], 3):
        low, high = (round(motion[f"travel_{e}_{u}"], 3) + 0.0 for e in ("min", "max"))  # no "-0.000"
        top = f"{_fmt(low, shown)} to {_fmt(high, shown)}"
        text += f" (true stroke {_fmt(stroke, shown)}: {top} at {motion['travel_max_angle_deg']:.1f}°)"
    return name, text


def _check_rows(summary: dict[str, Any], design: Any, *, positive_drive: bool) -> list[tuple[str, str]]:
    """The common rows of ``camcad check``; ``positive_drive``: the family drives the follower both ways."""
    geo, dyn = summary["geometry"], summary["dynamics"]
    fit = summary.get("fit") or {}
    limit = math.degrees(design.cam.max_pressure_angle)
    return [
        _lift_row(summary["motion"]),
        (
            "max pressure angle",
            _fmt(geo["pressure_angle_max_deg"], "°", 2)
            + _at(geo, "pressure_angle_max")
            + f" (limit {limit:g}°"
            + (
                f"; {flank} flank drives)"
                if (flank := summary.get("groove", {}).get("pressure_angle_max_flank"))
                else ")"
            ),
        ),
        (
            "min curvature radius",
            _fmt(geo["curvature_radius_min_mm"], " mm") + _at(geo, "curvature_radius_min"),
        ),
        ("min concave radius", _fmt(geo["concave_radius_min_mm"], " mm") + _at(geo, "concave_radius_min")),
        ("undercut", _fmt(geo["undercut"])),
        ("max torque", _fmt(dyn.get("torque_max_Nmm"), " N·mm", 1) + _at(dyn, "torque_max")),
        ("max contact force", _fmt(dyn.get("contact_force_max_N"), " N", 2) + _at(dyn, "contact_force_max")),
        ("min contact force", _fmt(dyn.get("contact_force_min_N"), " N", 2) + _at(dyn, "contact_force_min")),
        (
            "max contact stress",
            _fmt(dyn.get("hertz_stress_max_MPa"), " MPa", 1)
            + _at(dyn, "hertz_stress_max")
            + (f" ({dyn['hertz_stress_max_flank']} flank)" if dyn.get("hertz_stress_max_flank") else ""),
        ),
        (
            "follower jump",
            "none (positive drive)" if positive_drive else _fmt(dyn.get("jump")),
        ),
        (
            "fit control points",
            f"{fit['control_points']} (max error {fit['max_error_mm'] * 1000:.3f} µm)" if fit else "—",
        ),
    ]


def _duty_rows(summary: dict[str, Any], prefix: str = "") -> list[tuple[str, str]]:
    """The rows ``[life]``, ``[lubrication]`` and ``[drive]`` add to ``camcad check`` (issue 35).

    ``summary`` is ``summary.json`` or a later part's own sections (its duty's
    summary), whose rows start with ``prefix``: the same rows for every part.
    """
    rows: list[tuple[str, str]] = []
    life, film, drive = summary.get("life"), summary.get("lubrication"), summary.get("drive")
    if life is not None and "sliding_speed_max_mm_per_s" in life:
        rows.append(
            (
                f"{prefix}rolling life",
                f"n/a: the face slides (max {life['sliding_speed_max_mm_per_s']:.1f} mm/s)",
            )
        )
    if life is not None and "roller_life_h" in life:
        hours = life["roller_life_h"]
        rows.append(
            (
                f"{prefix}roller L10 life",
                ("unloaded" if hours is None else f"{hours:.4g} h")
                + f" (P {life['roller_equivalent_load_N']:.1f} N,"
                + f" {life['roller_turns_per_cam_turn']:.3f} roller turns a turn)",
            )
        )
    if life is not None and "track_life_h" in life:
        hours = life["track_life_h"]
        flank = life.get("track_load_stress_factor_flank")  # a groove: the flank that fails first
        rows.append(
            (
                f"{prefix}track life",
                ("unloaded" if hours is None else f"{hours:.4g} h") + (f" ({flank} flank)" if flank else ""),
            )
        )
    if film is not None:
        flank = film.get("min_film_ratio_flank")
        rows.append(
            (
                f"{prefix}min film ratio λ",
                _fmt(film["min_film_ratio"], "", 2)
                + _at(film, "min_film_ratio")
                + (f", {flank} flank" if flank else "")
                + f" (limit {film['film_ratio_limit']:g})",
            )
        )
    if drive is not None:
        for line in drive["checks"]:
            verdict = "" if line["ok"] is None else (" ok" if line["ok"] else " FAILS")
            limit = "" if line["limit"] is None else f" (limit {line['limit']:g})"
            unit = "" if line["unit"] == "1" else f" {line['unit']}"
            rows.append((f"motor {line['name']}", f"{line['value']:.4g}{unit}{limit}{verdict}"))
    return rows


def _vibration_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows ``[vibration]`` adds to ``camcad check`` (issue 34): the elastic train at the design speed."""
    vib = summary.get("vibration")
    if vib is None:
        return []
    unit = "mm" if "error_peak_mm" in vib else "deg"
    shown = " mm" if unit == "mm" else "°"
    force = " N" if unit == "mm" else " N·mm"
    at = f" at {vib['speed_rpm']:g} rpm"
    rows = [
        ("natural frequency", ", ".join(f"{f:.4g} Hz" for f in vib["natural_frequencies_hz"])),
        (
            "peak dynamic error",
            f"{vib[f'error_peak_{unit}']:.4g}{shown} at {vib['error_peak_angle_deg']:.1f}°{at}",
        ),
        (
            "min dynamic contact force",
            f"{vib['contact_force_min']:.4g}{force} at {vib['contact_force_min_angle_deg']:.1f}°{at}",
        ),
    ]
    for k, value in enumerate(vib[f"residual_{unit}"], start=1):
        rows.append((f"residual in dwell {k}", f"{value:.4g}{shown}"))
    flights = vib["flights"]
    leaves = "no"
    if vib["leaves_cam"]:
        leaves = "yes" + (f", at {flights[0]['leave_deg']:.1f}°" if flights else "")
    rows.append(("leaves the cam", leaves))
    if "compensate_rpm" in vib:
        rows.append(
            (
                "polydyne lift correction",
                f"max |c − s| {vib[f'lift_correction_max_{unit}']:.4g}{shown}"
                f" (tuned for {vib['compensate_rpm']:g} rpm)",
            )
        )
    return rows


def _barrel_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows a barrel cam adds to ``camcad check`` (issue 36): pressure angles, groove, slip, walls."""
    barrel = summary.get("barrel")
    if barrel is None:
        return []
    rows: list[tuple[str, str]] = []
    for where in ("bottom", "pitch", "top"):
        ext = barrel["pressure_angle_max"][where]
        radius = barrel["stations_mm"][where]
        rows.append(
            (
                f"pressure angle at {where}",
                f"{ext['value_deg']:.2f}° at {ext['angle_deg']:.1f}° (radius {radius:g} mm)",
            )
        )
    z = barrel["groove_z_mm"]
    rows.append(
        (
            f"{'rib' if 'rib' in barrel else 'groove'} along the axis",
            f"{z['lowest']:.3f} to {z['highest']:.3f} mm (of {barrel['length_mm']:g})",
        )
    )
    rib = barrel.get("rib")
    if rib is not None:  # a rib's least width between its exact faces, at its root and its top
        for where, label in (("bottom", "root"), ("top", "top")):
            ext = rib["thickness_min"][where]
            rows.append(
                (
                    f"rib thickness at {label}",
                    f"{ext['value_mm']:.3f} mm least at {ext['angle_deg']:.1f}° "
                    f"(radius {barrel['stations_mm'][where]:g} mm; width {rib['width_mm']:g} mm as designed)",
                )
            )
    slip = barrel["slip"]
    rows.append(
        (
            "roller slip",
            f"{slip['across_max']['value_mm_per_rad']:.3f} mm/rad round it, "
            f"{slip['along_max']['value_mm_per_rad']:.3f} mm/rad along it (× ω for mm/s)",
        )
    )
    return rows


def _positive_rows(summary: dict[str, Any], *, positive_drive: bool) -> list[tuple[str, str]]:
    """The rows a groove or a conjugate pair adds to ``camcad check``: flanks, second plate, crossovers."""
    rows: list[tuple[str, str]] = []
    groove, second = summary.get("groove"), summary.get("second_plate")
    if groove is not None:
        rows += [
            ("groove width", _fmt(groove["width_mm"], " mm")),
            ("largest cutter radius", _fmt(groove["tool_radius_max_mm"], " mm")),
            ("outer flank reach", _fmt(groove["outer_flank_reach_mm"], " mm")),
        ]
        for name, flank in summary["dynamics"].get("flanks", {}).items():  # where each flank drives
            load = "does not drive"
            if flank["contact_force_max_N"] is not None:
                load = (
                    _fmt(flank["contact_force_max_N"], " N", 2)
                    + _at(flank, "contact_force_max")
                    + ", stress "
                    + _fmt(flank["hertz_stress_max_MPa"], " MPa", 1)
                    + _at(flank, "hertz_stress_max")
                )
            rows.append((f"{name} flank max load", load))
    if second is not None:
        geo = second["geometry"]
        rows += [
            (
                "2nd plate pressure angle",
                _fmt(geo["pressure_angle_max_deg"], "°", 2) + _at(geo, "pressure_angle_max"),
            ),
            (
                "2nd plate min curvature",
                _fmt(geo["curvature_radius_min_mm"], " mm") + _at(geo, "curvature_radius_min"),
            ),
        ]
        dyn2 = second["dynamics"]  # the second plate's own roller and contact
        rows += [
            (
                "2nd plate max force",
                _fmt(dyn2.get("contact_force_max_N"), " N", 2) + _at(dyn2, "contact_force_max"),
            ),
            (
                "2nd plate max stress",
                _fmt(dyn2.get("hertz_stress_max_MPa"), " MPa", 1) + _at(dyn2, "hertz_stress_max"),
            ),
        ]
    if positive_drive:
        dyn = summary["dynamics"]
        crossings = ", ".join(f"{a:.1f}°" for a in dyn.get("crossover_angles_deg", [])) or "none"
        rows.append(("crossovers", crossings))
        if dyn.get("impact_speed_max_mm_per_s") is not None:
            rows.append(("max impact speed", _fmt(dyn["impact_speed_max_mm_per_s"], " mm/s", 1)))
    return rows


def _fea_rows(fea: dict[str, Any], prefix: str = "") -> list[tuple[str, str]]:
    """The finite-element check's rows of ``camcad check``: the peak von Mises stress, then each case.

    ``prefix`` names a later plate's rows ("second plate "): the same rows for every plate.
    """
    limit = fea.get("allowable_stress_MPa")
    peak = _fmt(fea.get("von_mises_max_MPa"), " MPa", 1)
    if fea.get("von_mises_max_angle_deg") is not None:
        peak += f" at {fea['von_mises_max_angle_deg']:.1f}°, {fea['von_mises_max_where']}"
    rows = [(f"{prefix}FE max von Mises", peak + (f" (limit {limit:g} MPa)" if limit is not None else ""))]
    for case in fea.get("cases", []):
        rows.append(
            (
                f"  {prefix}FE case {case['case']}",
                f"{case['label']} at {case['angle_deg']:.1f}°: von Mises {case['von_mises_max_MPa']:.1f} MPa "
                f"(Hertz {case['hertz_stress_MPa']:.1f} MPa)",
            )
        )
    return rows
