"""The figures of life, lubricant film and drive (issue 35), one per analysis the design asks for.

- life: each part's roller load over the turn with its ISO 281 equivalent
  load P, and its track's load-stress factor K when a K–N line is given;
- film: each part's minimum film thickness and film ratio λ with its limit;
- drive: the motor torque over the turn with the motor's peak and rated
  torque, and the torque–speed plane with the motor's envelope.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._plots._base import COLORS, LIMIT, Plot, closed, figure, svg
from camcad._plots.chart import HLine, Panel, Series, line_chart

if TYPE_CHECKING:
    from camcad.analysis import Analysis
    from camcad.dynamics.duty import DutyResult

__all__ = ["drive_plots", "duty_plots", "film_plot", "life_plot"]


def _bounds(analysis: Analysis) -> list[float]:
    return [math.degrees(b) for b in analysis.cam.program.segment_bounds][1:]


def _series(phi_deg: np.ndarray, values: object, color: str, label: str = "") -> Series:
    x, y = closed(phi_deg, np.asarray(values, dtype=float))
    return Series(x=x, y=y, color=color, label=label)


def _parts(analysis: Analysis) -> list[tuple[str, np.ndarray, DutyResult]]:
    """Every part's curves' label ("plate 2" beside "plate 1"; none for one part), angles [deg] and duty."""
    duties = [(np.degrees(r.dynamics.phi), r.duty) for r in analysis.parts if r.duty is not None]
    if len(duties) == 1:
        return [("", *duties[0])]
    return [(f"plate {i}", phi, d) for i, (phi, d) in enumerate(duties, start=1)]


def _named(label: str, text: str) -> str:
    return f"{label}: {text}" if label else text


def life_plot(analysis: Analysis) -> Plot | None:
    """Each part's roller load over the turn against its equivalent load; its track's K when given."""
    parts = _parts(analysis)
    if not parts or parts[0][2].life is None:
        return None
    panels = []
    notes = []
    rollers = [(label, phi, d) for label, phi, d in parts if d.roller is not None]
    if rollers:
        series = [
            _series(phi, d.load, COLORS[4] if k == 0 else COLORS[1], label or "roller load")
            for k, (label, phi, d) in enumerate(rollers)
        ]
        lines = []
        for k, (label, _, d) in enumerate(rollers):
            assert d.roller is not None
            p = d.roller.equivalent_load
            lines.append(
                HLine(
                    y=p,
                    color=COLORS[1] if k == 0 else COLORS[4],
                    label=_named(label, f"equivalent load P = {p:.1f} N (ISO 281)"),
                )
            )
            notes.append(
                _named(
                    label,
                    f"L10 = (C/P)^p = {d.roller.l10_million_revolutions:.4g} million roller turns, "
                    f"{d.roller.hours:.4g} h at {d.roller.turns_per_cam_turn:.3f} roller turns a cam turn",
                )
            )
        panels.append(
            Panel(
                ylabel="roller load\n[N]",
                series=series,
                lines=lines,
                legend=True,
                height=140.0,
            )
        )
    tracks = [(label, phi, d) for label, phi, d in parts if d.track is not None]
    if tracks:
        series = []
        for k, (label, phi, d) in enumerate(tracks):
            assert d.track is not None
            name = _named(label, "K = (F/L)(1/R₁ + 1/R₂)")
            series.append(_series(phi, d.track.factor, COLORS[6] if k == 0 else COLORS[1], name))
            notes.append(
                _named(
                    label, f"track life {d.track.hours:.4g} h at the largest K ({d.track.factor_max:.4g} MPa)"
                )
            )
        panels.append(Panel(ylabel="load-stress\nfactor K [MPa]", series=series, legend=True, height=140.0))
    if not panels:
        sliding = float(np.max(parts[0][2].contact.sliding_speed))
        return Plot(
            key="life",
            title="Life",
            caption=f"The face slides on the cam (largest sliding speed {sliding:.1f} mm/s): rolling "
            "life does not apply. Give [life] track_slope and track_intercept for the track's life.",
        )
    return Plot(
        key="life",
        title="Roller and track life",
        caption="; ".join(notes) + ".",
        svg=line_chart(panels, bounds_deg=_bounds(analysis), title="Roller and track life"),
    )


def film_plot(analysis: Analysis) -> Plot | None:
    """Each part's minimum film thickness and film ratio λ over the turn, λ's limit dashed."""
    films = [(label, d.film) for label, _, d in _parts(analysis) if d.film is not None]
    if not films:
        return None
    limit = films[0][1].limit
    thickness, ratio, notes = [], [], []
    top = limit
    for k, (label, film) in enumerate(films):
        phi = np.degrees(film.phi)
        shown_h = np.where(np.isfinite(film.thickness_um), film.thickness_um, np.nan)
        shown_l = np.where(np.isfinite(film.ratio), film.ratio, np.nan)
        if np.isfinite(shown_l).any():
            top = max(top, float(np.nanmax(shown_l)))
        thickness.append(_series(phi, shown_h, COLORS[0] if k == 0 else COLORS[1], label))
        ratio.append(
            _series(phi, shown_l, COLORS[2] if k == 0 else COLORS[1], label or "λ = h_min/√(Rq₁² + Rq₂²)")
        )
        where = "" if film.flank is None else f", {film.flank} flank"
        notes.append(
            _named(
                label,
                f"smallest λ {film.min_ratio:.3g} at φ = {math.degrees(film.angle):.1f}°{where} "
                f"(h_min {film.min_thickness_um:.3g} µm)",
            )
        )
    panels = [
        Panel(ylabel="film h_min\n[µm]", series=thickness, legend=len(films) > 1, height=130.0),
        Panel(
            ylabel="film ratio λ",
            series=ratio,
            lines=[HLine(y=limit, label=f"min_film_ratio {limit:g}")],
            ylim=(0.0, top * 1.1),
            legend=True,
            height=130.0,
        ),
    ]
    return Plot(
        key="film",
        title="Lubricant film",
        caption="Dowson–Higginson minimum film thickness of the line contact; "
        + "; ".join(notes)
        + ". Gaps: no contact.",
        svg=line_chart(panels, bounds_deg=_bounds(analysis), title="Lubricant film"),
    )


def drive_plots(analysis: Analysis) -> list[Plot]:
    """Motor torque over the turn, and the torque–speed plane with the motor's envelope."""
    if analysis.drive is None:
        return []
    drive, spec = analysis.drive.drive, analysis.design.drive
    assert spec is not None
    phi = np.degrees(drive.phi)
    lines = [HLine(y=drive.rms_torque, color=COLORS[1], dash="2 3", label=f"RMS {drive.rms_torque:.3g} N·m")]
    if spec.motor_peak_torque_Nm is not None:
        lines += [
            HLine(y=s * spec.motor_peak_torque_Nm, label="peak torque" if s > 0 else "") for s in (1, -1)
        ]
    if spec.motor_rated_torque_Nm is not None:
        rated = spec.motor_rated_torque_Nm
        lines += [HLine(y=s * rated, color="#e08e0b", label="rated torque" if s > 0 else "") for s in (1, -1)]
    panel = Panel(
        ylabel="motor torque\nT_m [N·m]",
        series=[_series(phi, drive.motor_torque, COLORS[5], "motor torque")],
        lines=lines,
        legend=True,
        height=170.0,
    )
    torque = Plot(
        key="drive",
        title="Motor torque",
        caption=f"Torque at the motor ({drive.mode.value}): the load over i·η while the motor drives, "
        f"times η/i while it is driven back; peak {drive.peak_torque:.3g} N·m, "
        f"RMS {drive.rms_torque:.3g} N·m.",
        svg=line_chart([panel], bounds_deg=_bounds(analysis), title="Motor torque"),
    )
    fig = figure()
    ax = fig.add_subplot()
    speed = np.asarray(drive.motor_speed_rpm, dtype=float)
    step = max(1, speed.size // 360)  # about a point a degree: the figure stays small
    keep = np.union1d(np.arange(0, speed.size, step), [int(np.argmax(np.abs(drive.motor_torque)))])
    ax.plot(speed[keep], np.abs(drive.motor_torque[keep]), ".", color=COLORS[5], markersize=2.5,
            label="|T_m| over the cycle")  # fmt: skip
    ax.plot([float(np.max(speed))], [drive.rms_torque], "o", color=COLORS[1], label="RMS at top speed")
    top_speed = spec.motor_max_rpm if spec.motor_max_rpm is not None else float(np.max(speed)) * 1.2
    if spec.motor_peak_torque_Nm is not None:
        ax.plot([0.0, top_speed], [spec.motor_peak_torque_Nm] * 2, **LIMIT, label="peak torque")
    if spec.motor_rated_torque_Nm is not None:
        ax.plot([0.0, top_speed], [spec.motor_rated_torque_Nm] * 2, color="#e08e0b", label="rated torque")
    if spec.motor_max_rpm is not None:
        ax.axvline(spec.motor_max_rpm, **LIMIT)
    ax.set_xlim(0.0, max(top_speed, float(np.max(speed))) * 1.05)
    ax.set_ylim(0.0, None)
    ax.set_xlabel("motor speed [rpm]")
    ax.set_ylabel("|motor torque| [N·m]")
    ax.legend(loc="upper right", fontsize=8)
    envelope = Plot(
        key="drive-envelope",
        title="Torque and speed",
        caption="The motor's operating points against its envelope: peak torque (dashed), rated "
        "torque for the RMS, and its highest speed.",
        svg=svg(fig),
    )
    return [torque, envelope]


def duty_plots(analysis: Analysis) -> list[Plot]:
    """Every figure of life, film and drive the analysis has."""
    out = [p for p in (life_plot(analysis), film_plot(analysis)) if p is not None]
    return out + drive_plots(analysis)
