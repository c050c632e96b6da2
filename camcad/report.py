"""Self-contained HTML reports of one design, or several side by side.

:func:`render_report` turns an :class:`~camcad.analysis.Analysis` into one
HTML page that opens offline: warnings first, the key numbers at a glance,
the figures (PNG, embedded as base64 ``data:`` URIs) and the full tables of
``summary.json``. :func:`render_compare` overlays several designs and tabulates
them as in Quintero & Vanegas (2016), section 5. This module gathers what a
page shows; the Jinja2 templates in ``camcad/templates`` (package data, with the
style sheet ``report.css``) lay it out. Autoescape is on: every value a
template writes is escaped (:func:`_e`) unless it is markup the templates
made; the page has no external references.

References
----------
.. [1] Quintero & Vanegas (2016), cam profile design with VAP motion laws
   (../shared/papers).
"""

from __future__ import annotations

import base64
import functools
import html
import math
from collections.abc import Callable, Mapping, Sequence
from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING, Any

import jinja2
import numpy as np
from markupsafe import Markup

from camcad._plots import Plot, compare_plots, report_plots
from camcad._plots.compare import compare_colors
from camcad.export.records import write_text
from camcad.findings import Finding, Severity
from camcad.report_tables import (
    fmt,
    joint_rows,
    label,
    large_acceleration_jumps,
    quantity_rows,
    split_unit,
)

if TYPE_CHECKING:
    from camcad.analysis import Analysis

__all__ = [
    "CSS",
    "alerts_html",
    "compare_table",
    "compare_text",
    "key_numbers_html",
    "render_compare",
    "render_report",
    "write_compare",
    "write_report",
]

_DASH = "—"
_TEMPLATES = files("camcad") / "templates"

CSS = (_TEMPLATES / "report.css").read_text(encoding="utf-8")
"""The report's style sheet (``camcad/templates/report.css``), for screens and print; the designer's too."""


# ---------------------------------------------------------------------------
# templates and small formatting helpers


def _e(text: object) -> str:
    """Text escaped for HTML (element content and quoted attributes); control characters become U+FFFD."""
    plain = "".join(
        "\ufffd" if (ord(c) < 32 and c not in "\t\n\r") or ord(c) == 127 else c for c in str(text)
    )
    return html.escape(plain, quote=True)


def _escaped(value: object) -> Markup:
    """A template value as markup: escaped by :func:`_e`, unless it is markup a template made already."""
    return value if isinstance(value, Markup) else Markup(_e(value))


def _looks_numeric(cell: object) -> bool:
    """Whether a cell, escaped, is a single number or the dash (it is then right-aligned)."""
    text = _e(cell)
    try:
        float(text.replace("−", "-"))
    except ValueError:
        return text == _DASH
    return True


@functools.cache
def _environment() -> jinja2.Environment:
    """The templates of ``camcad/templates``, autoescaped.

    Jinja2's own escaping is replaced by :func:`_e` (through ``finalize``,
    which sees every value before it is written), so that control characters
    in a user's text become U+FFFD and quotes are written as before.
    """
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("camcad", "templates"),
        autoescape=True,
        finalize=_escaped,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.tests["numeric_cell"] = _looks_numeric
    return env


def _render(template: str, **values: Any) -> str:
    """A template of ``camcad/templates`` filled with ``values``."""
    return _environment().get_template(template).render(**values)


def _num(value: Any, spec: str = ".6g") -> str:
    """A number for a table: fixed format, ``—`` for None or non-finite values."""
    if value is None:
        return _DASH
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    f = float(value)
    return format(f, spec) if math.isfinite(f) else _DASH


def _finite(values: Any) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    return arr[np.isfinite(arr)]


def _peak(values: Any, fn: Callable[[np.ndarray], Any] = np.max) -> float | None:
    arr = _finite(values)
    return float(fn(arr)) if arr.size else None


def _figure(plot: Plot, *, cls: str = "") -> dict[str, Any]:
    """A figure for the templates: the image as a ``data:`` URI (SVG, or PNG), or none for a note."""
    src = None
    if plot.svg is not None:
        src = "data:image/svg+xml;base64," + base64.b64encode(plot.svg).decode("ascii")
    elif plot.png is not None:
        src = "data:image/png;base64," + base64.b64encode(plot.png).decode("ascii")
    return {"key": plot.key, "title": plot.title, "caption": plot.caption, "src": src, "cls": cls}


def _is_records(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and bool(value) and all(isinstance(v, Mapping) for v in value)


def _alert(kind: str, title: str, items: Sequence[str], *, anchor: str = "") -> dict[str, Any]:
    """A highlighted box: ``kind`` is ``bad``, ``warn`` or ``ok``; ``items`` plain text."""
    return {"kind": kind, "title": title, "lines": list(items), "anchor": anchor}


def _finding_lines(findings: Sequence[Finding]) -> list[str]:
    """One line per broken limit: its kind and severity, the field to change, the message."""
    return [f"{f.kind} ({f.severity.value} limit, {f.field}): {f.message}" for f in findings]


def _jump_lines(analysis: Analysis, summary: Mapping[str, Any]) -> list[str]:
    """Banner lines for large acceleration jumps at motion joints (see :mod:`camcad.report_tables`)."""
    motion = summary.get("motion", {})
    unit = analysis.cam.follower_spec.kind.lift_unit
    a_peak = motion.get(f"a_max_abs_{unit}_per_rad2")
    return large_acceleration_jumps(
        motion.get("joints", []),
        unit=unit,
        a_peak=a_peak,
        mass_kg=analysis.design.dynamics.follower_mass,
        speed_rpm=analysis.design.cam.speed_rpm,
    )


def _alerts(analysis: Analysis, summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The banner: hard limits, soft limits, then notes and large acceleration jumps (camcad.findings)."""
    hard = [f for f in analysis.findings if f.hard]
    soft = [f for f in analysis.findings if f.severity is Severity.SOFT]
    notes = [f.message for f in analysis.findings if f.note] + _jump_lines(analysis, summary)
    out = []
    if hard:
        out.append(_alert("bad", "Hard limits broken", _finding_lines(hard), anchor="violations"))
    if soft:
        out.append(
            _alert("warn", f"Soft limits broken ({len(soft)})", _finding_lines(soft), anchor="warnings")
        )
    if notes:
        anchor = "" if soft else "warnings"
        out.append(_alert("warn", f"Notes ({len(notes)})", notes, anchor=anchor))
    if not out:
        out.append(_alert("ok", "No warnings", ["Every checked limit is met."], anchor="warnings"))
    return out


# ---------------------------------------------------------------------------
# key numbers (shared by the report header and the comparison table)


def _key_numbers(analysis: Analysis, summary: Mapping[str, Any]) -> dict[str, Any]:
    """The headline numbers of one design, from its summary with the sampled arrays as fallback."""
    motion = summary.get("motion", {})
    geo = summary.get("geometry", {})
    dyn = summary.get("dynamics", {})
    fit = summary.get("fit")
    d = analysis.dynamics
    unit = analysis.cam.follower_spec.kind.lift_unit  # mm on a slide, degrees of swing on an arm
    return {
        "lift": analysis.cam.program.lift,
        "stroke": motion.get(f"stroke_{unit}"),  # the true travel, max − min of s
        "v": motion.get(f"v_max_abs_{unit}_per_rad", _peak(np.abs(analysis.motion.v))),
        "a": motion.get(f"a_max_abs_{unit}_per_rad2", _peak(np.abs(analysis.motion.a))),
        "alpha": geo.get(
            "pressure_angle_max_deg", math.degrees(float(np.abs(analysis.geometry.pressure_angle).max()))
        ),
        "alpha_at": geo.get("pressure_angle_max_angle_deg"),
        "alpha_limit": math.degrees(analysis.geometry.max_pressure_angle),
        "rho": geo.get("curvature_radius_min_mm"),
        "rho_at": geo.get("curvature_radius_min_angle_deg"),
        "torque_max": dyn.get("torque_max_Nmm", _peak(d.torque)),
        "torque_min": dyn.get("torque_min_Nmm", _peak(d.torque, np.min)),
        "force_max": dyn.get("contact_force_max_N", _peak(d.contact_force)),
        "force_min": dyn.get("contact_force_min_N", _peak(d.contact_force, np.min)),
        "stress": dyn.get("hertz_stress_max_MPa", _peak(d.hertz_stress)),
        "stress_flank": dyn.get("hertz_stress_max_flank"),  # a groove: the flank that carries it
        "flanks": dyn.get("flanks"),
        "second_plate": summary.get("second_plate", {}).get("dynamics"),
        "stress_allowable": analysis.design.dynamics.allowable_stress,
        "control_points": None if fit is None else fit.get("control_points"),
        "fit_error": None if fit is None else fit.get("max_error_mm"),
        "fit_tolerance": None if fit is None else fit.get("tolerance_mm"),
    }


def _card(label: str, value: str, note: str = "", *, over: bool = False) -> dict[str, Any]:
    return {"label": label, "value": value, "note": note, "over": over}


def _cards(analysis: Analysis, k: Mapping[str, Any]) -> list[dict[str, Any]]:
    cam = analysis.cam
    follower = cam.follower.describe()
    alpha_over = k["alpha"] > k["alpha_limit"]
    alpha_note = f"limit {k['alpha_limit']:.2f}°"
    if k["alpha_at"] is not None:
        alpha_note += f", at φ = {k['alpha_at']:.1f}°"
    if abs(k["alpha"]) < 1e-9 and not cam.has_pitch_curve and cam.follower.guide.pivot is None:
        alpha_note = "always 0°: the face is square to its slide"
    rho_note = (
        f"convex profile, at φ = {k['rho_at']:.1f}°"
        if k["rho_at"] is not None
        else "profile has no convex part"
    )
    if k["rho"] is not None and k["rho"] < 0.0:  # the signed extreme: the profile loops or has a cusp
        rho_note = (
            f"< 0: the profile {'loops' if cam.has_pitch_curve else 'has a cusp'} at φ = {k['rho_at']:.1f}°"
        )
    stress_over = (
        k["stress_allowable"] is not None and k["stress"] is not None and k["stress"] > k["stress_allowable"]
    )
    stress_note = (
        f"allowable {k['stress_allowable']:g} MPa"
        if k["stress_allowable"] is not None
        else "no allowable set"
    )
    if k["stress_flank"] is not None:
        stress_note += f"; on the {k['stress_flank']} flank"
    second = k["second_plate"]
    if second is not None:  # a conjugate pair: the second plate with its own roller
        stress_note += f"; 2nd plate {_num(second.get('hertz_stress_max_MPa'), '.2f')} MPa"
        over2 = (
            k["stress_allowable"] is not None
            and (second.get("hertz_stress_max_MPa") or 0.0) > k["stress_allowable"]
        )
        stress_over = stress_over or over2
    # red exactly when the dynamics reports a jump (the banner's finding): a groove or a conjugate pair drives
    # the follower both ways, so a negative force there is the other flank or roller driving, not a jump
    force_over = any(f.kind == "jump" for f in analysis.findings)
    force_value, force_note = f"{_num(k['force_max'], '.3f')} N", f"min {_num(k['force_min'], '.3f')} N"
    if k["flanks"] is not None:  # a groove: the largest load on the flank that drives
        loads = {n: f["contact_force_max_N"] or 0.0 for n, f in k["flanks"].items()}
        worst = max(loads, key=lambda n: loads[n])
        force_value = f"{_num(loads[worst], '.3f')} N"
        force_note = f"{worst} flank; " + ", ".join(
            f"{n} flank max {_num(v, '.3f')} N" for n, v in loads.items()
        )
    elif second is not None:
        force_note += f"; 2nd plate max {_num(second.get('contact_force_max_N'), '.3f')} N"
    if k["control_points"] is None:
        fit_card = _card("NURBS fit", "not run")
    else:
        fit_card = _card(
            "NURBS fit",
            f"{k['control_points']} control points",
            f"max error {_num(1000.0 * k['fit_error'], '.3g')} µm "
            f"(tolerance {_num(1000.0 * k['fit_tolerance'], 'g')} µm)",
        )
    gcode = analysis.gcode.summary() if analysis.gcode is not None else None
    if gcode is not None:
        minutes = float(gcode.get("cycle_time_s", 0.0)) / 60.0
        tool = f"tool D{_num(float(gcode.get('tool_diameter_mm', 0.0)), 'g')} mm" + (
            " (chosen by camcad to fit the groove)" if gcode.get("tool_chosen") else ""
        )
        gcode_card = _card(
            "G-code",
            f"{gcode.get('blocks')} blocks",
            f"{gcode.get('arcs')} arcs, about {minutes:.1f} min; {tool}",
        )
    lift = cam.follower_spec.kind.lift
    shown = lift.symbol
    stroke_note = ""
    if k["stroke"] is not None and round(k["stroke"], 3) != round(k["lift"], 3):  # a segment overshoots
        stroke_note = f"nominal; true stroke {k['stroke']:.3f}{shown}"
    cards = [
        _card(lift.name, f"{k['lift']:.3f}{shown}", stroke_note),
        _card("Base radius", f"{cam.base_radius:.3f} mm", follower),
        _card("Max pressure angle", f"{k['alpha']:.2f}°", alpha_note, over=alpha_over),
        _card("Min curvature radius", f"{_num(k['rho'], '.3f')} mm", rho_note),
        _card(
            "Max torque", f"{_num(k['torque_max'], '.2f')} N·mm", f"min {_num(k['torque_min'], '.2f')} N·mm"
        ),
        _card("Max contact force", force_value, force_note, over=force_over),
        _card("Max Hertz stress", f"{_num(k['stress'], '.2f')} MPa", stress_note, over=stress_over),
        fit_card,
        *([gcode_card] if gcode is not None else []),
    ]
    return cards


def _program_table(analysis: Analysis) -> dict[str, Any]:
    program = analysis.cam.program
    rows = []
    for i, (seg, start) in enumerate(zip(program.segments, program.segment_bounds, strict=True)):
        law = seg.law.describe() if seg.law is not None else _DASH
        rows.append(
            [
                i,
                seg.kind.value,
                _num(math.degrees(start), ".2f"),
                _num(math.degrees(seg.span), ".2f"),
                _num(seg.lift, ".3f"),
                law,
            ]
        )
    lift = f"lift [{analysis.cam.follower_spec.kind.lift.short}]"
    header = ["#", "segment", "start [°]", "span [°]", lift, "law"]
    return {"header": header, "rows": rows}


def _design_table(analysis: Analysis) -> list[list[str]]:
    design, cam = analysis.design, analysis.cam
    spec = design.cam
    rows = [
        ("follower type", design.follower.kind.word),
        ("base radius [mm]", _num(spec.base_radius)),
        ("follower", cam.follower.describe()),
        *((label, _DASH if value is None else _num(value)) for label, value in cam.follower.rows()),
        ("rotation", spec.rotation.value),
        ("speed [rpm]", _num(spec.speed_rpm)),
        ("thickness [mm]", _num(spec.thickness)),
        ("bore diameter [mm]", _num(spec.bore)),
        ("max pressure angle [°]", _num(math.degrees(spec.max_pressure_angle))),
    ]
    return [[a, b] for a, b in rows]


def _quantities_table(section: Mapping[str, Any], *, skip: Sequence[str] = ()) -> dict[str, Any]:
    """A section of ``summary.json`` as quantity [unit] | value | where, nested sections below it."""
    rows = [[q, v, w] for q, v, w in quantity_rows(section, skip=skip)]
    nested: list[dict[str, Any]] = []
    for key, value in section.items():
        if key in skip:
            continue
        if isinstance(value, Mapping):
            nested.append(
                {
                    "title": label(key),
                    "records": None,
                    "section": _quantities_table(value),
                }
            )
        elif _is_records(value):
            nested.append({"title": label(key), "records": _records_table(value), "section": None})
    return {"rows": rows, "nested": nested}


def _has_records(table: Mapping[str, Any]) -> bool:
    """Whether a :func:`_quantities_table` holds a records table at any depth (it then spans the page)."""
    return any(n["records"] is not None or _has_records(n["section"]) for n in table["nested"])


def _records_table(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    keys: list[str] = []
    for rec in records:
        keys += [k for k in rec if k not in keys]
    header = [label(k) for k in keys]
    rows = [[fmt(rec.get(k), split_unit(k)[1]) for k in keys] for rec in records]
    return {"header": header, "rows": rows}


_SECTION_TITLES = {"gcode": "G-code", "fit": "NURBS fit", "second_plate": "Second plate"}
_NOT_TABLES = ("camcad_version", "design", "violations", "findings")


def _summary_tables(analysis: Analysis, summary: Mapping[str, Any]) -> dict[str, Any]:
    """The tables of the report: the design, the motion program, each summary section, the joints."""
    sections = []
    for name, section in summary.items():
        if name in _NOT_TABLES or not isinstance(section, Mapping):
            continue
        title = _SECTION_TITLES.get(name, name.replace("_", " ").capitalize())
        body = _quantities_table(section, skip=("joints",))
        sections.append({"name": name, "title": title, "body": body, "wide": _has_records(body)})
    motion = summary.get("motion", {})
    joints = motion.get("joints")
    table = None
    if joints:
        unit = analysis.cam.follower_spec.kind.lift_unit
        header, rows = joint_rows(
            joints,
            unit=unit,
            a_peak=motion.get(f"a_max_abs_{unit}_per_rad2"),
            mass_kg=analysis.design.dynamics.follower_mass,
            speed_rpm=analysis.design.cam.speed_rpm,
        )
        table = {"header": header, "rows": rows}
    return {
        "design_rows": _design_table(analysis),
        "program": _program_table(analysis),
        "sections": sections,
        "joints": table,
    }


# ---------------------------------------------------------------------------
# public API


def _fea_section(analysis: Analysis) -> list[dict[str, Any]]:
    """The finite-element check (issue 22) of every plate checked, by the same code (:func:`_fea_part`)."""
    return [_fea_part(r.fea, r.part) for r in analysis.parts if r.fea is not None]


def _fea_part(fea: Any, part: Any) -> dict[str, Any]:
    """One plate's FE check: a table of its load cases and a stress picture per case."""
    from camcad.fea.plot import stress_figures

    sfx = part.suffix

    rows = [
        [
            i,
            sc.case.label,
            _num(sc.case.angle_deg, ".2f"),
            _num(sc.case.force, ".2f"),
            _num(sc.case.peak_pressure, ".1f"),
            _num(sc.peak.value, ".1f"),
            sc.peak.where,
        ]
        for i, sc in enumerate(fea.cases, start=1)
    ]
    header = ["case", "load case", "φ [°]", "force [N]", "Hertz p0 [MPa]", "von Mises [MPa]", "where"]
    limit = "no allowable set" if fea.allowable_stress is None else f"allowable {fea.allowable_stress:g} MPa"
    figures = [
        _figure(Plot(key=f"fea{sfx}-{i}", title=title, caption=caption, png=png))
        for i, (title, caption, png) in enumerate(stress_figures(fea), start=1)
    ]
    return {
        "suffix": sfx,
        "heading": part.title("Finite-element check"),
        "model": fea.plane.value.join(("Plane ", " model")),
        "nodes": len(fea.nodes),
        "cells": len(fea.cells),
        "limit": limit,
        "header": header,
        "rows": rows,
        "figures": figures,
    }


def _duty_section(analysis: Analysis) -> list[dict[str, Any]] | None:
    """Life, lubricant film and drive (issue 35): a figure each; their numbers are in the tables."""
    if analysis.duty is None and analysis.drive is None:
        return None
    from camcad._plots.duty import duty_plots

    return [_figure(p) for p in duty_plots(analysis)]


def _vibration_section(analysis: Analysis) -> list[dict[str, Any]] | None:
    """The elastic follower train (issue 34): the speed map and the response at the design speed."""
    if getattr(analysis, "vibration", None) is None:
        return None
    from camcad._plots.vibration import vibration_plots

    return [_figure(p) for p in vibration_plots(analysis)]


def render_report(analysis: Analysis) -> str:
    """The HTML report of one analysed design.

    Parameters
    ----------
    analysis
        The result of :func:`camcad.pipeline.analyse`.

    Returns
    -------
    str
        A complete, self-contained HTML page: warnings, the cam drawing with
        the key numbers beside it, the figures (motion, pressure angle,
        curvature, dynamics, fit error, toolpath, solid; SVG embedded as
        ``data:`` URIs) and the tables of ``summary.json`` in words with units.
        Laid out for any width and for print (A4 or Letter: the drawing and
        the key numbers on page 1). Pure and deterministic: writes nothing,
        holds no time. The layout is ``camcad/templates/report.html.j2``.
    """
    summary = analysis.summary()
    name = analysis.design.cam.name
    source = analysis.design.source
    sub = [
        f"source: {source}" if source else "",
        analysis.cam.follower.describe(),
        f"speed {analysis.design.cam.speed_rpm:g} rpm",
    ]
    plots = report_plots(analysis)
    drawing = next((p for p in plots if p.key == "profile"), None)
    return _render(
        "report.html.j2",
        title=f"camcad report: {name}",
        css=Markup(CSS),  # the package's own style sheet, written as it is
        name=name,
        subtitle=" · ".join(s for s in sub if s),
        alerts=_alerts(analysis, summary),
        drawing=None if drawing is None else _figure(drawing),
        cards=_cards(analysis, _key_numbers(analysis, summary)),
        plots=[_figure(p, cls="small" if p.key == "solid" else "") for p in plots if p is not drawing],
        fea=_fea_section(analysis),
        duty=_duty_section(analysis),
        vibration=_vibration_section(analysis),
        version=summary.get("camcad_version", ""),
        **_summary_tables(analysis, summary),
    )


def key_numbers_html(analysis: Analysis) -> str:
    """The report's key-number cards of one analysis, as an HTML fragment (the designer shows them live)."""
    return _render("cards.html.j2", cards=_cards(analysis, _key_numbers(analysis, analysis.summary())))


def alerts_html(analysis: Analysis) -> str:
    """The report's warning banner of one analysis, as an HTML fragment."""
    return _render("alerts.html.j2", alerts=_alerts(analysis, analysis.summary()))


def write_report(analysis: Analysis, path: str | Path) -> Path:
    """Atomically write :func:`render_report` to ``path``; return the path."""
    return write_text(path, render_report(analysis))


_COMPARE_ROWS: tuple[tuple[str, str, str], ...] = (
    ("lift [mm]", "lift", ".3f"),
    ("max |v| [mm/rad]", "v", ".3f"),
    ("max |a| [mm/rad²]", "a", ".3f"),
    ("max pressure angle [°]", "alpha", ".2f"),
    ("min curvature radius [mm]", "rho", ".3f"),
    ("max torque [N·mm]", "torque_max", ".2f"),
    ("min torque [N·mm]", "torque_min", ".2f"),
    ("max contact force [N]", "force_max", ".3f"),
    ("max Hertz stress [MPa]", "stress", ".2f"),
    ("fit control points", "control_points", "d"),
)


def _names(analyses: Sequence[Analysis]) -> list[str]:
    """Design names, numbered when two designs share one."""
    names = [a.design.cam.name for a in analyses]
    return [f"{n} ({i + 1})" if names.count(n) > 1 else n for i, n in enumerate(names)]


def compare_table(analyses: Sequence[Analysis]) -> list[list[str]]:
    """The side-by-side table of several designs (Quintero & Vanegas 2016, section 5).

    Returns
    -------
    list[list[str]]
        A header row (``"quantity"`` then each design name) and one row per
        quantity: lift, max |v|, max |a|, max pressure angle, min curvature
        radius, max and min torque, max contact force, max Hertz stress and
        fit control points. Plain, unescaped strings in a fixed number format;
        ``—`` where a value does not exist (no fit, no convex part).
    """
    keys = [_key_numbers(a, a.summary()) for a in analyses]
    table = [["quantity", *_names(analyses)]]
    unit = _lift_unit_text(analyses)  # an arm's lift, |v| and |a| are in degrees of swing
    for text, key, spec in _COMPARE_ROWS:
        if key in ("lift", "v", "a"):
            text = text.replace("[mm", f"[{unit}")
        table.append([text, *(_num(k[key], spec) for k in keys)])
    return table


def _lift_unit_text(analyses: Sequence[Analysis]) -> str:
    """The lift's unit of several designs as shown: ``mm`` (slides), ``°`` (arms) or ``mm or °``."""
    units = {a.cam.follower_spec.kind.lift.short for a in analyses}
    return units.pop() if len(units) == 1 else "mm or °"


def _letter(i: int) -> str:
    """Column tag of the i-th design: A to Z, then A2 to Z2, and so on."""
    return chr(ord("A") + i % 26) + (str(i // 26 + 1) if i >= 26 else "")


def compare_text(analyses: Sequence[Analysis], *, width: int = 100) -> str:
    """:func:`compare_table` as terminal text no wider than ``width`` columns.

    When the names do not fit side by side, the designs become columns A, B,
    C, … named in a legend above the table (names cut with … to ``width``),
    and when even the tagged columns do not fit they are split into blocks
    of as many designs as fit. Control characters in names become spaces.
    """
    table = [[_terminal(c) for c in row] for row in compare_table(analyses)]

    def render(rows: list[list[str]]) -> list[str]:
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        return [
            "  ".join(
                c.rjust(w) if j else c.ljust(w) for j, (c, w) in enumerate(zip(r, widths, strict=True))
            ).rstrip()
            for r in rows
        ]

    plain = render(table)
    if max(len(line) for line in plain) <= width:
        return "\n".join(plain)
    names = table[0][1:]
    legend = [f"{_letter(i)} = {n}" for i, n in enumerate(names)]
    legend = [line if len(line) <= width else line[: width - 1] + "…" for line in legend]
    tagged = [[table[0][0], *(_letter(i) for i in range(len(names)))], *table[1:]]
    first = max(len(r[0]) for r in tagged)
    cell = max(len(c) for r in tagged for c in r[1:])
    per_block = max(1, (width - first) // (cell + 2))
    out = [*legend, ""]
    for lo in range(0, len(names), per_block):
        cols = [0, *range(1 + lo, 1 + min(lo + per_block, len(names)))]
        out += [*render([[r[c] for c in cols] for r in tagged]), ""]
    return "\n".join(out).rstrip("\n")


def _terminal(text: str) -> str:
    """One line of printable text: control characters (a newline in a cam name) become spaces."""
    return " ".join("".join(c if c.isprintable() else " " for c in text).split())


def render_compare(analyses: Sequence[Analysis]) -> str:
    """An HTML page comparing several analysed designs.

    Parameters
    ----------
    analyses
        Two or more analyses (one also works).

    Returns
    -------
    str
        A self-contained page: the table of :func:`compare_table`, the
        warnings of each design, and one figure per quantity (s, v, a,
        pressure angle, contact force, torque against the cam angle, one line
        per design) plus the profiles to scale, each sized for its column.
    """
    if not analyses:
        raise ValueError("render_compare needs at least one analysis")
    names = _names(analyses)
    table = compare_table(analyses)
    alerts = []
    for name, analysis in zip(names, analyses, strict=True):
        limits = [f for f in analysis.findings if not f.note]
        findings = [*_finding_lines(limits), *(f.message for f in analysis.findings if f.note)]
        findings += _jump_lines(analysis, analysis.summary())
        if findings:
            alerts.append(_alert("bad" if analysis.violations else "warn", name, findings))
    if not alerts:
        alerts.append(_alert("ok", "No warnings", ["Every design meets its checked limits."]))
    return _render(
        "compare.html.j2",
        title="camcad comparison",
        css=Markup(CSS),
        count=len(analyses),
        names=names,
        alerts=alerts,
        table={"header": table[0], "rows": table[1:]},
        key=[
            {"name": name, "color": color}
            for name, color in zip(names, compare_colors(len(names)), strict=True)
        ],
        plots=[_figure(p) for p in compare_plots(analyses, names)],
    )


def write_compare(analyses: Sequence[Analysis], path: str | Path) -> Path:
    """Atomically write :func:`render_compare` to ``path``; return the path."""
    return write_text(path, render_compare(analyses))
