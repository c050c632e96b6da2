"""Self-contained HTML reports of one design, or several side by side.

:func:`render_report` turns an :class:`~camcad.analysis.Analysis` into one
HTML page that opens offline: warnings first, the key numbers at a glance,
the figures (PNG, embedded as base64 ``data:`` URIs) and the full tables of
``summary.json``. :func:`render_compare` overlays several designs and tabulates
them as in Quintero & Vanegas (2016), section 5. Every piece of text is
escaped with :func:`html.escape`; the page has no external references.

References
----------
.. [1] Quintero & Vanegas (2016), cam profile design with VAP motion laws
   (../shared/papers).
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

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

CSS = """
:root { --ink:#1d2733; --muted:#5b6877; --line:#d8dee6; --bg:#f5f7fa; --card:#fff;
        --warn:#fff4d6; --warn-edge:#e0a800; --bad:#fde2e1; --bad-edge:#c0392b;
        --ok:#e3f4e8; --ok-edge:#2e8b57; }
* { box-sizing: border-box; }
html { -webkit-text-size-adjust: 100%; }
body { margin:0; font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color:var(--ink); background:var(--bg); overflow-wrap: anywhere; }
main { max-width: 1400px; margin: 0 auto; padding: 20px clamp(10px, 3vw, 24px) 40px; }
header h1 { margin: 0 0 4px; font-size: clamp(19px, 4vw, 24px); }
header p { margin: 0; color: var(--muted); }
h2 { font-size: 18px; margin: 28px 0 10px; border-bottom: 1px solid var(--line); padding-bottom: 4px; }
h3 { font-size: 15px; margin: 18px 0 6px; }
.alert { border-left: 5px solid; border-radius: 4px; padding: 10px 14px; margin: 16px 0 0; }
.alert h2 { border: 0; margin: 0 0 6px; padding: 0; font-size: 16px; }
.alert ul, .alert p { margin: 0; padding-left: 20px; }
.alert p { padding-left: 0; }
.warn { background: var(--warn); border-color: var(--warn-edge); }
.bad { background: var(--bad); border-color: var(--bad-edge); }
.ok { background: var(--ok); border-color: var(--ok-edge); }
.glance { display: grid; grid-template-columns: minmax(0, 5fr) minmax(0, 6fr); gap: 14px; margin-top: 16px;
          align-items: start; }
.cards { display: grid; grid-template-columns: repeat(auto-fill, minmax(min(100%, 170px), 1fr)); gap: 10px; }
.card { background: var(--card); border: 1px solid var(--line); border-radius: 6px; padding: 8px 11px; }
.card.over { border-color: var(--bad-edge); background: var(--bad); }
.card .label { color: var(--muted); font-size: 12px; text-transform: uppercase; letter-spacing: .03em; }
.card .value { font-size: 20px; font-weight: 600; font-variant-numeric: tabular-nums; }
.card .note { color: var(--muted); font-size: 12px; }
.plots { display: grid; grid-template-columns: repeat(auto-fit, minmax(min(100%, 460px), 1fr)); gap: 14px; }
figure { margin: 0; background: var(--card); border: 1px solid var(--line); border-radius: 6px;
         padding: 10px; min-width: 0; }
figure img { width: 100%; height: auto; display: block; }
figure.small img { max-width: 460px; margin: 0 auto; }
figure.note { background: #f0f3f7; align-self: start; }
figcaption { color: var(--muted); font-size: 12.5px; margin-top: 6px; }
figcaption b { color: var(--ink); }
.scroll { max-width: 100%; overflow-x: auto; }
table { border-collapse: collapse; background: var(--card); margin: 4px 0 10px;
        font-variant-numeric: tabular-nums; max-width: 100%; }
th, td { border: 1px solid var(--line); padding: 4px 8px; text-align: left; vertical-align: top; }
th { background: #eef2f6; font-weight: 600; }
td.num { text-align: right; white-space: nowrap; }
td table { margin: 0; }
.tables { display: grid; grid-template-columns: repeat(auto-fit, minmax(min(100%, 400px), 1fr));
          gap: 0 24px; }
.tables > div { min-width: 0; }
.wide { grid-column: 1 / -1; }
.key { list-style: none; padding: 0; margin: 0 0 10px; display: flex; flex-wrap: wrap; gap: 4px 18px; }
.key .swatch { display: inline-block; width: 22px; height: 0; border-top: 4px solid; vertical-align: middle;
               margin-right: 6px; }
footer { margin-top: 30px; color: var(--muted); font-size: 12px; }
@media (max-width: 900px) {
  .glance { grid-template-columns: minmax(0, 1fr); }
}
@media (max-width: 560px) {
  body { font-size: 13px; }
  th, td { padding: 3px 5px; }
  .card .value { font-size: 18px; }
}
@page { size: auto; margin: 12mm 11mm; }
@media print {
  body { background: #fff; font-size: 9.5pt; }
  main { max-width: none; padding: 0; }
  h2 { margin: 12px 0 6px; font-size: 12pt; break-after: avoid; }
  .alert { margin-top: 8px; padding: 6px 10px; }
  .glance { grid-template-columns: minmax(0, 3fr) minmax(0, 2fr); gap: 8px; margin-top: 8px; }
  .glance figure img { max-height: 92mm; width: auto; max-width: 100%; margin: 0 auto; }
  .cards { grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 5px; }
  .card { padding: 4px 7px; }
  .card .value { font-size: 12pt; }
  .card .label, .card .note { font-size: 7.5pt; }
  .plots { display: block; orphans: 1; widows: 1; }  /* a row of figures is one line: break after any */
  .plots figure { display: inline-block; width: calc(50% - 4px); vertical-align: top; break-inside: avoid;
                  margin: 0 0 6px; padding: 4px; }
  .plots figure img { max-height: 56mm; width: auto; max-width: 100%; margin: 0 auto; }
  figure { border-color: #ccc; }
  .scroll { overflow: visible; }
  th, td { overflow-wrap: normal; word-break: normal; hyphens: manual; }
  .records table { width: auto; max-width: 100%; font-size: 6.5pt; }
  .records th, .records td { padding: 1px 2px; }
  .tables { display: block; column-count: 2; column-gap: 6mm; }
  .tables > .wide { column-span: all; }
  table { width: 100%; font-size: 8pt; }
  th, td { padding: 2px 4px; }
  figure.small img { max-height: 60mm; }
  tr, figure, .card { break-inside: avoid; }
  .tables > div { break-inside: avoid; }
}
"""


# ---------------------------------------------------------------------------
# small formatting helpers


def _e(text: object) -> str:
    """Text escaped for HTML (element content and quoted attributes); control characters become U+FFFD."""
    plain = "".join(
        "\ufffd" if (ord(c) < 32 and c not in "\t\n\r") or ord(c) == 127 else c for c in str(text)
    )
    return html.escape(plain, quote=True)


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


def _img(plot: Plot, *, cls: str = "") -> str:
    """A figure: the image as a ``data:`` URI (SVG, or PNG), or just its caption for a note."""
    klass = f' class="{cls}"' if cls else ""
    if plot.svg is not None:
        src = "data:image/svg+xml;base64," + base64.b64encode(plot.svg).decode("ascii")
    elif plot.png is not None:
        src = "data:image/png;base64," + base64.b64encode(plot.png).decode("ascii")
    else:
        return (
            f'<figure id="plot-{_e(plot.key)}" class="note {cls}"><figcaption><b>{_e(plot.title)}.</b> '
            f"{_e(plot.caption)}</figcaption></figure>"
        )
    return (
        f'<figure id="plot-{_e(plot.key)}"{klass}><img alt="{_e(plot.title)}" src="{src}">'
        f"<figcaption><b>{_e(plot.title)}.</b> {_e(plot.caption)}</figcaption></figure>"
    )


def _page(title: str, body: str) -> str:
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{_e(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<main>\n"
        f"{body}\n</main>\n</body>\n</html>\n"
    )


def _looks_numeric(cell: str) -> bool:
    """Whether an escaped cell is a single number (it is then right-aligned)."""
    try:
        float(cell.replace("−", "-"))
    except ValueError:
        return cell == _DASH
    return True


def _table(header: Sequence[str] | None, rows: Sequence[Sequence[str]]) -> str:
    """A table of already escaped cells; numeric cells are right-aligned."""
    out = ["<table>"]
    if header is not None:
        out.append("<tr>" + "".join(f"<th>{h}</th>" for h in header) + "</tr>")
    for row in rows:
        cells = [f'<td class="num">{c}</td>' if _looks_numeric(c) else f"<td>{c}</td>" for c in row]
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "".join(out)


def _is_records(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and bool(value) and all(isinstance(v, Mapping) for v in value)


def _alert(kind: str, title: str, items: Sequence[str], *, anchor: str = "") -> str:
    """A highlighted box: ``kind`` is ``bad``, ``warn`` or ``ok``; ``items`` plain text."""
    ident = f' id="{_e(anchor)}"' if anchor else ""
    if kind == "ok":
        body = "".join(f"<p>{_e(i)}</p>" for i in items)
    else:
        body = "<ul>" + "".join(f"<li>{_e(i)}</li>" for i in items) + "</ul>"
    return f'<section class="alert {kind}"{ident}><h2>{_e(title)}</h2>{body}</section>'


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


def _alerts(analysis: Analysis, summary: Mapping[str, Any]) -> str:
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
    return "\n".join(out)


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


def _card(label: str, value: str, note: str = "", *, over: bool = False) -> str:
    cls = "card over" if over else "card"
    note_html = f'<div class="note">{_e(note)}</div>' if note else ""
    return (
        f'<div class="{cls}"><div class="label">{_e(label)}</div>'
        f'<div class="value">{_e(value)}</div>{note_html}</div>'
    )


def _cards(analysis: Analysis, k: Mapping[str, Any]) -> str:
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
    return '<section class="cards" id="key-numbers">' + "".join(cards) + "</section>"


def _program_table(analysis: Analysis) -> str:
    program = analysis.cam.program
    rows = []
    for i, (seg, start) in enumerate(zip(program.segments, program.segment_bounds, strict=True)):
        law = seg.law.describe() if seg.law is not None else _DASH
        rows.append(
            [
                _e(i),
                _e(seg.kind.value),
                _e(_num(math.degrees(start), ".2f")),
                _e(_num(math.degrees(seg.span), ".2f")),
                _e(_num(seg.lift, ".3f")),
                _e(law),
            ]
        )
    lift = f"lift [{analysis.cam.follower_spec.kind.lift.short}]"
    header = ["#", "segment", "start [°]", "span [°]", lift, "law"]
    return _table(header, rows)


def _design_table(analysis: Analysis) -> str:
    design, cam = analysis.design, analysis.cam
    spec = design.cam
    rows = [
        ("follower type", design.follower.kind.word),
        ("base radius [mm]", _num(spec.base_radius)),
        ("follower", _e(cam.follower.describe())),
        *((label, _DASH if value is None else _num(value)) for label, value in cam.follower.rows()),
        ("rotation", spec.rotation.value),
        ("speed [rpm]", _num(spec.speed_rpm)),
        ("thickness [mm]", _num(spec.thickness)),
        ("bore diameter [mm]", _num(spec.bore)),
        ("max pressure angle [°]", _num(math.degrees(spec.max_pressure_angle))),
    ]
    return _table(None, [[_e(a), _e(b)] for a, b in rows])


def _quantities_table(section: Mapping[str, Any], *, skip: Sequence[str] = ()) -> str:
    """A section of ``summary.json`` as quantity [unit] | value | where, nested sections below it."""
    rows = [[_e(q), _e(v), _e(w)] for q, v, w in quantity_rows(section, skip=skip)]
    out = [_table(["quantity", "value", "where"], rows)] if rows else []
    for key, value in section.items():
        if key in skip:
            continue
        if isinstance(value, Mapping):
            out.append(f"<h4>{_e(label(key))}</h4>{_quantities_table(value)}")
        elif _is_records(value):
            out.append(f"<h4>{_e(label(key))}</h4>{_records_table(value)}")
    return "".join(out) or f"<p>{_DASH}</p>"


def _records_table(records: Sequence[Mapping[str, Any]]) -> str:
    keys: list[str] = []
    for rec in records:
        keys += [k for k in rec if k not in keys]
    header = [_e(label(k)) for k in keys]
    rows = [[_e(fmt(rec.get(k), split_unit(k)[1])) for k in keys] for rec in records]
    return f'<div class="scroll records">{_table(header, rows)}</div>'


_SECTION_TITLES = {"gcode": "G-code", "fit": "NURBS fit", "second_plate": "Second plate"}
_NOT_TABLES = ("camcad_version", "design", "violations", "findings")


def _summary_tables(analysis: Analysis, summary: Mapping[str, Any]) -> str:
    out = ['<section class="tables" id="tables">']
    out.append(f"<div><h3>Design</h3>{_design_table(analysis)}</div>")
    out.append(f"<div><h3>Motion program</h3>{_program_table(analysis)}</div>")
    for name, section in summary.items():
        if name in _NOT_TABLES or not isinstance(section, Mapping):
            continue
        title = _SECTION_TITLES.get(name, name.replace("_", " ").capitalize())
        body = _quantities_table(section, skip=("joints",))
        wide = ' class="wide"' if 'class="scroll records"' in body else ""  # a records table: full width
        out.append(f'<div id="table-{_e(name)}"{wide}><h3>{_e(title)}</h3>{body}</div>')
    motion = summary.get("motion", {})
    joints = motion.get("joints")
    if joints:
        unit = analysis.cam.follower_spec.kind.lift_unit
        header, rows = joint_rows(
            joints,
            unit=unit,
            a_peak=motion.get(f"a_max_abs_{unit}_per_rad2"),
            mass_kg=analysis.design.dynamics.follower_mass,
            speed_rpm=analysis.design.cam.speed_rpm,
        )
        table = _table([_e(h) for h in header], [[_e(c) for c in row] for row in rows])
        out.append(
            '<div class="wide" id="table-joints"><h3>Motion joints: what each jump means</h3>'
            f'<div class="scroll">{table}</div></div>'
        )
    out.append("</section>")
    return "\n".join(out)


# ---------------------------------------------------------------------------
# public API


def _fea_section(analysis: Analysis) -> str:
    """The finite-element check (issue 22): a table of its load cases and a stress picture per case."""
    fea = getattr(analysis, "fea", None)
    if fea is None:
        return ""
    from camcad.fea.plot import stress_figures

    rows = [
        [
            _e(i),
            _e(sc.case.label),
            _e(_num(sc.case.angle_deg, ".2f")),
            _e(_num(sc.case.force, ".2f")),
            _e(_num(sc.case.peak_pressure, ".1f")),
            _e(_num(sc.peak.value, ".1f")),
            _e(sc.peak.where),
        ]
        for i, sc in enumerate(fea.cases, start=1)
    ]
    header = ["case", "load case", "φ [°]", "force [N]", "Hertz p0 [MPa]", "von Mises [MPa]", "where"]
    limit = "no allowable set" if fea.allowable_stress is None else f"allowable {fea.allowable_stress:g} MPa"
    figures = "".join(
        _img(Plot(key=f"fea-{i}", title=title, caption=caption, png=png))
        for i, (title, caption, png) in enumerate(stress_figures(fea), start=1)
    )
    return (
        f'<h2 id="fea-heading">Finite-element check</h2>\n<section id="fea">'
        f"<p>{_e(fea.plane.value.join(('Plane ', ' model')))}, {len(fea.nodes)} nodes, {len(fea.cells)} "
        f"quadratic triangles; {_e(limit)}; fields in stress.vtu.</p>{_table(header, rows)}"
        f'<section class="plots">{figures}</section></section>'
    )


def _duty_section(analysis: Analysis) -> str:
    """Life, lubricant film and drive (issue 35): a figure each; their numbers are in the tables."""
    duty = getattr(analysis, "duty", None)
    if duty is None:
        return ""
    from camcad._plots.duty import duty_plots

    figures = "".join(_img(p) for p in duty_plots(analysis))
    return (
        '<h2 id="duty-heading">Life, lubrication and drive</h2>\n<section id="duty">'
        "<p>The numbers are in the tables <i>Life</i>, <i>Lubrication</i> and <i>Drive</i> below.</p>"
        f'<section class="plots">{figures}</section></section>'
    )


def _vibration_section(analysis: Analysis) -> str:
    """The elastic follower train (issue 34): the speed map and the response at the design speed."""
    if getattr(analysis, "vibration", None) is None:
        return ""
    from camcad._plots.vibration import vibration_plots

    figures = "".join(_img(p) for p in vibration_plots(analysis))
    return (
        '<h2 id="vibration-heading">Cams at speed</h2>\n<section id="vibration">'
        "<p>The follower train as the <code>[vibration]</code> table states it; the numbers are in the "
        "table <i>Vibration</i> below, vibration.csv and speed_map.csv.</p>"
        f'<section class="plots">{figures}</section></section>'
    )


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
        holds no time.
    """
    summary = analysis.summary()
    name = analysis.design.cam.name
    source = analysis.design.source
    version = summary.get("camcad_version", "")
    sub = [
        f"source: {source}" if source else "",
        analysis.cam.follower.describe(),
        f"speed {analysis.design.cam.speed_rpm:g} rpm",
    ]
    header = f"<header><h1>{_e(name)}</h1><p>{_e(' · '.join(s for s in sub if s))}</p></header>"
    plots = report_plots(analysis)
    drawing = next((p for p in plots if p.key == "profile"), None)
    rest = "".join(_img(p, cls="small" if p.key == "solid" else "") for p in plots if p is not drawing)
    glance = (
        '<section class="glance" id="glance">'
        + (_img(drawing) if drawing is not None else "")
        + _cards(analysis, _key_numbers(analysis, summary))
        + "</section>"
    )
    body = "\n".join(
        [
            header,
            _alerts(analysis, summary),
            glance,
            f'<h2 id="plots-heading">Plots</h2>\n<section class="plots" id="plots">{rest}</section>',
            _fea_section(analysis),
            _duty_section(analysis),
            _vibration_section(analysis),
            "<h2>Tables</h2>",
            _summary_tables(analysis, summary),
            f"<footer>camcad {_e(version)} · angles in degrees, lengths in mm</footer>",
        ]
    )
    return _page(f"camcad report: {name}", body)


def key_numbers_html(analysis: Analysis) -> str:
    """The report's key-number cards of one analysis, as an HTML fragment (the designer shows them live)."""
    return _cards(analysis, _key_numbers(analysis, analysis.summary()))


def alerts_html(analysis: Analysis) -> str:
    """The report's warning banner of one analysis, as an HTML fragment."""
    return _alerts(analysis, analysis.summary())


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
    header = [_e(h) for h in table[0]]
    rows = [[_e(c) for c in row] for row in table[1:]]
    alerts = []
    for name, analysis in zip(names, analyses, strict=True):
        limits = [f for f in analysis.findings if not f.note]
        findings = [*_finding_lines(limits), *(f.message for f in analysis.findings if f.note)]
        findings += _jump_lines(analysis, analysis.summary())
        if findings:
            alerts.append(_alert("bad" if analysis.violations else "warn", name, findings))
    if not alerts:
        alerts.append(_alert("ok", "No warnings", ["Every design meets its checked limits."]))
    plots = "".join(_img(p) for p in compare_plots(analyses, names))
    key = "".join(
        f'<li><span class="swatch" style="border-top-color:{color}"></span>{_e(name)}</li>'
        for name, color in zip(names, compare_colors(len(names)), strict=True)
    )
    body = "\n".join(
        [
            f"<header><h1>Comparison of {len(analyses)} cam designs</h1>"
            f"<p>{_e(' · '.join(names))}</p></header>",
            *alerts,
            '<h2>Side by side</h2><section id="compare-table"><div class="scroll">'
            f"{_table(header, rows)}</div></section>",
            f'<h2 id="plots-heading">Plots</h2>\n<ul class="key" id="key">{key}</ul>'
            f'\n<section class="plots" id="plots">{plots}</section>',
            "<footer>camcad · angles in degrees, lengths in mm</footer>",
        ]
    )
    return _page("camcad comparison", body)


def write_compare(analyses: Sequence[Analysis], path: str | Path) -> Path:
    """Atomically write :func:`render_compare` to ``path``; return the path."""
    return write_text(path, render_compare(analyses))
