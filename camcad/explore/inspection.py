"""``camcad inspect``: a measured cam against its design, its actual motion, and a compensated program.

The numbers are :mod:`camcad.inspect`'s (the robust best fit, the normal
deviations, the GCV-smoothed form error and the motion re-solved on it).
This module names the measured file's lines in every refusal, writes the
files all or nothing (:func:`camcad.export.atomic.staged_folder`), and makes
the compensated ``cam.ngc`` and ``profile.dxf`` through the chain ``camcad
build`` uses: the corrected cam (:class:`~camcad.inspect.compensated.CompensatedCam`)
→ certified fit (:func:`camcad.fit.fit_cam_profile`) → tool path
(:func:`camcad.toolpath.plan_toolpath`) → G-code and DXF writers.

Files:

- ``inspection.csv``: per point, in the file's order: its line, x, y [mm],
  the cam angle of its foot on the design [°], the normal deviation [mm]
  (+ = more material), whether it is in the band and kept by the fit;
- ``inspection.json``: the fit (turn, centre, their σ; the keying phase if
  the CMM frame is the shaft's), the deviations, the verdict;
- ``actual_motion.csv``: nominal and actual lift, velocity, acceleration and
  one σ of each, per cam angle;
- ``inspection.html``: the polar deviation plot and the actual against the
  nominal motion;
- with a stock: ``cam.ngc`` and ``profile.dxf`` of the corrected profile.
"""

from __future__ import annotations

import base64
import dataclasses
import html
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad.errors import DesignError, DesignLimitError, UsageError
from camcad.geometry.cam import Cam
from camcad.inspect import ActualMotion, Inspection, actual_motion, compensate, inspect_points
from camcad.inspect.compensated import CompensatedCam, offset_error
from camcad.inspect.measured import MeasuredPoints

if TYPE_CHECKING:
    from camcad.design.spec import Design

__all__ = ["InspectionResult", "inspect_measured"]

_CSS = (
    "body{font-family:system-ui,sans-serif;margin:2em;color:#222}"
    "table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #ccc;padding:2px 6px}"
    "td.n{text-align:right;font-variant-numeric:tabular-nums}figure{margin:1em 0}"
    "img{max-width:100%;height:auto}"
)
PATH_ERROR_SHARE = 0.1
"""Share of the G-code tolerance the path may lie off the exact offset of the corrected profile."""


@dataclass(frozen=True, slots=True, kw_only=True)
class InspectionResult:
    """The files written, whether the part is within its band, and the summary of ``inspection.json``."""

    files: tuple[Path, ...]
    passed: bool
    summary: dict[str, Any]


def _relined(message: str, lines: list[int]) -> str:
    """The core's 0-based point numbers as the file's 1-based lines."""
    message = re.sub(
        r"\bpoints (\d+) and (\d+)\b", lambda m: f"lines {lines[int(m[1])]} and {lines[int(m[2])]}", message
    )
    return re.sub(r"\bpoint (\d+)\b", lambda m: f"line {lines[int(m[1])]}", message)


def _e(text: object) -> str:
    plain = "".join("\ufffd" if ord(c) < 32 or ord(c) == 127 else c for c in str(text))
    return html.escape(plain, quote=True)


def _r(x: float) -> str:
    return repr(float(x))


def _inspection_csv(measured: MeasuredPoints, ins: Inspection) -> str:
    out = ["line,x_mm,y_mm,cam_angle_deg,deviation_mm,in_band,inlier"]
    for i, line in enumerate(measured.lines):
        x, y = measured.points[i]
        out.append(
            f"{line},{_r(x)},{_r(y)},{_r(math.degrees(ins.angle[i]))},{_r(ins.deviation[i])},"
            f"{'false' if ins.outside[i] else 'true'},{'true' if ins.inlier[i] else 'false'}"
        )
    return "\n".join(out) + "\n"


def _motion_csv(cam: Cam, act: ActualMotion, unit: str) -> str:
    nominal = cam.motion(act.phi)
    head = [
        "angle_deg",
        f"lift_{unit}",
        f"lift_actual_{unit}",
        f"lift_std_{unit}",
        f"velocity_{unit}_per_rad",
        f"velocity_actual_{unit}_per_rad",
        f"velocity_std_{unit}_per_rad",
        f"acceleration_{unit}_per_rad2",
        f"acceleration_actual_{unit}_per_rad2",
        f"acceleration_std_{unit}_per_rad2",
    ]
    cols = [
        np.degrees(act.phi),
        nominal.s,
        act.lift,
        act.lift_std,
        nominal.v,
        act.velocity,
        act.velocity_std,
        nominal.a,
        act.acceleration,
        act.acceleration_std,
    ]
    rows = [",".join(head)]
    for i in range(act.phi.size):
        rows.append(",".join("" if math.isnan(c[i]) else _r(c[i]) for c in cols))
    return "\n".join(rows) + "\n"


def _polar_figure(ins: Inspection) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from camcad._plots import svg

    lower, upper = ins.band
    width = upper - lower
    zero = 2.0 * width  # deviations drawn about a circle of this radius, so that every value stays > 0
    fig = Figure(figsize=(5.6, 5.6), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="polar")
    ring = np.linspace(0.0, 2.0 * np.pi, 361)
    for r, style in ((zero, "-"), (zero + lower, "--"), (zero + upper, "--")):
        ax.plot(ring, np.full(ring.size, r), style, color="#c0392b" if style == "--" else "#555555", lw=0.8)
    order = np.argsort(ins.angle)
    u, dev = ins.angle[order], ins.deviation[order]
    ax.plot(u, zero + np.clip(dev, -zero, None), color="#1f5f9e", lw=0.8)
    bad = ins.outside[order]
    if np.any(bad):
        ax.plot(u[bad], zero + np.clip(dev[bad], -zero, None), "x", color="#c0392b", ms=5)
    ax.set_ylim(0.0, zero + max(upper, float(np.max(dev))) * 1.2)
    ax.set_yticks([zero + lower, zero, zero + upper])
    ax.set_yticklabels([f"{lower * 1000:g} µm", "0", f"+{upper * 1000:g} µm"], fontsize=7)
    ax.tick_params(labelsize=7)
    ax.set_title("normal deviation around the profile (cam angle)", fontsize=9)
    return base64.b64encode(svg(fig)).decode("ascii")


def _motion_figure(cam: Cam, act: ActualMotion, unit: str) -> str:
    from camcad._plots import figure, svg

    nominal = cam.motion(act.phi)
    fig = figure((7.0, 5.2), hspace=0.3)
    x = np.degrees(act.phi)
    ax1, ax2 = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
    err = act.lift - nominal.s
    ax1.fill_between(x, err - act.lift_std, err + act.lift_std, color="#b9cde3", lw=0, label="±1σ")
    ax1.plot(x, err, color="#1f5f9e", lw=1.0, label="actual − nominal")
    ax1.axhline(0.0, color="#222222", lw=0.6)
    ax1.set_ylabel(f"lift error [{unit}]", fontsize=9)
    ax1.legend(fontsize=7, loc="upper right")
    ax2.plot(x, nominal.a, color="#555555", lw=1.0, label="nominal")
    if not np.all(np.isnan(act.acceleration)):
        lo, hi = act.acceleration - act.acceleration_std, act.acceleration + act.acceleration_std
        ax2.fill_between(x, lo, hi, color="#f3c9a5", lw=0, label="±1σ")
        ax2.plot(x, act.acceleration, color="#d9731a", lw=0.9, label="actual")
    ax2.set_ylabel(f"acceleration [{unit}/rad²]", fontsize=9)
    ax2.set_xlabel("cam angle [°]", fontsize=9)
    ax2.legend(fontsize=7, loc="upper right")
    for ax in (ax1, ax2):
        ax.set_xlim(0.0, 360.0)
        ax.tick_params(labelsize=8)
        ax.grid(True, color="#eeeeee", linewidth=0.6)
    return base64.b64encode(svg(fig)).decode("ascii")


def _page(cam: Cam, ins: Inspection, act: ActualMotion, summary: dict[str, Any]) -> str:
    unit = summary["lift_unit"]
    fit = summary["fit"]
    verdict = "within" if summary["passed"] else "OUTSIDE"
    body = [
        f"<h1>Inspection of {_e(summary['design'])}</h1>",
        f"<p>{summary['points']} points from {_e(summary['measured'])} ({_e(summary['layout'])}) against "
        f"{_e(summary['source'])}: the part is <strong>{verdict}</strong> its band "
        f"{summary['band_mm'][0]:g} to +{summary['band_mm'][1]:g} mm "
        f"({summary['outside']} points outside).</p>",
        "<table>"
        f'<tr><td>turn of the measurement frame</td><td class="n">{fit["rotation_deg"]:.4f}° '
        f"± {fit['rotation_sigma_deg']:.4f}°</td></tr>"
        f'<tr><td>cam axis in the measurement frame</td><td class="n">({fit["centre_mm"][0]:.4f}, '
        f"{fit['centre_mm'][1]:.4f}) mm ± {max(fit['centre_sigma_mm']) * 1000:.2f} µm</td></tr>"
        f'<tr><td>largest deviation</td><td class="n">{summary["deviation"]["max_abs_mm"] * 1000:.2f} µm '
        f"(line {summary['deviation']['max_abs_line']})</td></tr>"
        f'<tr><td>scatter (robust σ)</td><td class="n">{summary["deviation"]["noise_mm"] * 1000:.2f} µm'
        "</td></tr>"
        f'<tr><td>largest lift error</td><td class="n">{summary["actual_motion"]["lift_error_max"]:.4g} '
        f"{_e(unit)} "
        f"(σ ≤ {summary['actual_motion']['lift_std_max']:.2g})</td></tr>"
        "</table>",
        "<h2>Deviation around the profile</h2>",
        '<figure id="polar"><img alt="polar deviation plot" src="data:image/svg+xml;base64,'
        f'{_polar_figure(ins)}">'
        "<figcaption>Normal deviation at each point's foot on the design, drawn about the solid circle; the "
        "dashed circles are the band, crosses the points outside it.</figcaption></figure>",
        "<h2>Actual against nominal motion</h2>",
        f'<figure id="motion"><img alt="actual motion" src="data:image/svg+xml;base64,'
        f'{_motion_figure(cam, act, unit)}"><figcaption>The follower re-solved on the design plus the '
        "smoothed "
        f"form error (Fourier order {summary['form']['order']}, chosen by generalised cross-validation), "
        "with one standard deviation of the smoothing.</figcaption></figure>",
    ]
    comp = summary.get("compensation")
    if comp is not None:
        body.append(
            "<h2>Compensation</h2><p>cam.ngc and profile.dxf cut the design offset by the negated form "
            "error "
            f"(at most {comp['correction_max_mm'] * 1000:.2f} µm, within the stock {comp['stock_mm']:g} mm) "
            f"with a Ø{comp['tool_diameter_mm']:g} mm tool.</p>"
        )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>Inspection of {_e(summary['design'])}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )


def _compensated_files(
    design: Design, cam: Cam, act: ActualMotion, *, stock: float, tool_diameter: float
) -> tuple[str, Any, CompensatedCam, dict[str, Any]]:
    """The corrected program's text, the fit for its DXF, the corrected cam and the figures."""
    from camcad.design.paths import path_of
    from camcad.fit import fit_cam_profile
    from camcad.geometry.families import family_of
    from camcad.toolpath import plan_toolpath
    from camcad.toolpath.spec import Machine

    if not family_of(design.cam.style).one_plate or design.gcode.machine is Machine.ROTARY:
        raise UsageError("--stock", "compensation mills a plate cam's outside profile on an XY machine only")
    spec = dataclasses.replace(design.gcode, tool_diameter=tool_diameter)
    comp = compensate(cam, act.form, stock=stock, tool_radius=spec.tool_radius)
    form = act.form

    def correction(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        e0, e1, e2 = form(u)
        return -e0, -e1, -e2

    corrected = CompensatedCam.of(cam, correction)
    off = offset_error(corrected, spec.tool_radius)
    if off > PATH_ERROR_SHARE * spec.tolerance:
        raise DesignLimitError(
            "the correction turns the profile's normal so much that the tool path would lie "
            f"{off * 1000:.3f} µm "
            f"off the corrected profile's offset, over {PATH_ERROR_SHARE:g} × the G-code tolerance "
            f"{spec.tolerance:g} mm; allowed: a smoother correction (a finer tolerance, or no correction)"
        )
    planned = plan_toolpath(
        corrected, spec, name=design.cam.name, thickness=design.cam.thickness, bore=design.cam.bore
    )
    from camcad.export.gcode import render_program

    program = render_program(planned, spec.dialect)
    fit = fit_cam_profile(
        corrected,
        tolerance=design.fit.tolerance,
        max_control_points=design.fit.max_control_points,
        name_of=path_of,  # a FitError names fit.tolerance, as the build's does
    )
    figures = {
        "stock_mm": stock,
        "tool_diameter_mm": tool_diameter,
        "correction_max_mm": float(np.max(np.abs(comp.correction))),
        "path_offset_error_mm": off,
        "fit_max_error_mm": float(fit.max_error),
        "toolpath_max_deviation_mm": float(planned.max_deviation),
    }
    return program.text, fit, corrected, figures


def inspect_measured(
    design: Design,
    measured: MeasuredPoints,
    outdir: str | Path,
    *,
    where: str,
    band: float,
    stock: float | None = None,
    tool_diameter: float | None = None,
) -> InspectionResult:
    """Judge the measured points against ``design`` and write the files (see the module notes).

    Raises
    ------
    DesignError
        Naming ``where`` (the measured file) and its line: a measurement the
        fit refuses (too few points, repeated points, a partial scan, the
        wrong size or the wrong cam).
    DesignLimitError
        A correction beyond the stock or that the tool cannot follow (with a stock).
    """
    from camcad.export.atomic import atomic_write_text, staged_folder

    cam = Cam.from_design(design)
    unit = design.follower.kind.lift_unit
    try:
        ins = inspect_points(cam, measured.points, band=band)
    except DesignError as err:
        if err.field != "measured":
            raise
        raise DesignError(where, _relined(err.message, measured.lines)) from None
    act = actual_motion(cam, ins)
    comp_files = None
    if stock is not None:
        comp_files = _compensated_files(
            design, cam, act, stock=stock, tool_diameter=tool_diameter or design.gcode.tool_diameter
        )
    nominal = cam.motion(act.phi)
    worst = int(np.argmax(np.abs(ins.deviation)))
    sigma = cam.sigma
    summary: dict[str, Any] = {
        "design": design.cam.name,
        "source": design.source,
        "measured": where,
        "layout": measured.layout,
        "lift_unit": unit,
        "points": int(ins.deviation.size),
        "inliers": int(np.count_nonzero(ins.inlier)),
        "band_mm": [ins.band[0], ins.band[1]],
        "fit": {
            "rotation_deg": math.degrees(ins.rotation),
            "rotation_sigma_deg": math.degrees(ins.rotation_sigma),
            "centre_mm": [float(v) for v in ins.centre],
            "centre_sigma_mm": [float(v) for v in ins.centre_sigma],
            "phase_deg_if_shaft_frame": math.degrees(-sigma * ins.rotation),
        },
        "deviation": {
            "min_mm": float(np.min(ins.deviation)),
            "max_mm": float(np.max(ins.deviation)),
            "max_abs_mm": float(abs(ins.deviation[worst])),
            "max_abs_line": measured.lines[worst],
            "noise_mm": ins.noise,
        },
        "outside": int(np.count_nonzero(ins.outside)),
        "outside_lines": [measured.lines[i] for i in np.flatnonzero(ins.outside)[:100]],
        "passed": ins.passed,
        "form": {"order": act.form.order, "noise_mm": act.form.noise},
        "actual_motion": {
            "lift_error_max": float(np.max(np.abs(act.lift - nominal.s))),
            "lift_std_max": float(np.max(act.lift_std)),
            "velocity_error_max": float(np.max(np.abs(act.velocity - nominal.v))),
        },
        "compensation": None if comp_files is None else comp_files[3],
    }
    page = _page(cam, ins, act, summary)
    outdir = Path(outdir)
    names = ["inspection.csv", "inspection.json", "actual_motion.csv", "inspection.html"]
    with staged_folder(outdir) as staging:
        atomic_write_text(staging.path / "inspection.csv", _inspection_csv(measured, ins))
        atomic_write_text(
            staging.path / "inspection.json", json.dumps(summary, indent=2, ensure_ascii=False) + "\n"
        )
        atomic_write_text(staging.path / "actual_motion.csv", _motion_csv(cam, act, unit))
        atomic_write_text(staging.path / "inspection.html", page)
        if comp_files is not None:
            from camcad.export.dxf import write_profile_dxf

            text, fit, corrected, _ = comp_files
            atomic_write_text(staging.path / "cam.ngc", text)
            write_profile_dxf(
                staging.path / "profile.dxf", cam=corrected, fit=fit, plate=design.plate(), options=design.dxf
            )
            names += ["cam.ngc", "profile.dxf"]
    return InspectionResult(files=tuple(outdir / n for n in names), passed=ins.passed, summary=summary)
