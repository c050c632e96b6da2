"""The sweep's HTML page: counts, the Pareto front, the feasible region and the front's designs.

One self-contained file (figures inlined as PNG, drawn off-screen with
matplotlib's Agg canvas, no pyplot, no timestamps), the same bytes for the
same rows.
"""

from __future__ import annotations

import base64
import html
import io
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from camcad.explore.measures import Measure

if TYPE_CHECKING:
    from camcad.explore.plan import SweepPlan

__all__ = ["sweep_page"]

_DPI = 100
_CSS = (
    "body{font-family:system-ui,sans-serif;margin:2em;color:#222}"
    "table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #ccc;padding:2px 6px}"
    "td.n{text-align:right;font-variant-numeric:tabular-nums}figure{margin:1em 0}"
    "img{max-width:100%;height:auto}.scroll{overflow-x:auto}"
)


def _e(text: object) -> str:
    plain = "".join("\ufffd" if ord(c) < 32 or ord(c) == 127 else c for c in str(text))
    return html.escape(plain, quote=True)


def _png(fig: Figure) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, metadata={"Software": None})
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _label(m: Measure) -> str:
    return f"{m.text} [{m.unit}]"


def _values(rows: Sequence[Mapping[str, Any]], m: Measure) -> list[float]:
    out = []
    for row in rows:
        v = m.of(row)
        out.append(math.nan if v is None else v)
    return out


def _front_figure(rows: Sequence[Mapping[str, Any]], pareto: tuple[Measure, Measure]) -> str:
    first, second = pareto
    fig = Figure(figsize=(7.0, 4.6), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    groups = (
        ("feasible", [r for r in rows if r.get("feasible")], {"color": "#7f9fbf", "marker": "o", "s": 12}),
        (
            "limit broken",
            [
                r
                for r in rows
                if r.get("status") == "limit" or (r.get("status") == "ok" and not r.get("feasible"))
            ],
            {"color": "#d98c8c", "marker": "x", "s": 12},
        ),
    )
    for label, group, style in groups:
        if group:
            ax.scatter(_values(group, first), _values(group, second), label=label, linewidths=0.8, **style)
    front = sorted(
        (a, b)
        for a, b, r in zip(_values(rows, first), _values(rows, second), rows, strict=True)
        if r.get("pareto")
    )
    if front:
        ax.plot(
            [p[0] for p in front],
            [p[1] for p in front],
            "-o",
            color="#1f5f9e",
            ms=4,
            lw=1.4,
            label="Pareto front",
        )
    ax.set_xlabel(_label(first), fontsize=9)
    ax.set_ylabel(_label(second), fontsize=9)
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#eeeeee", linewidth=0.6)
    ax.legend(fontsize=8)
    return _png(fig)


def _region_figure(rows: Sequence[Mapping[str, Any]], plan: SweepPlan) -> str | None:
    """Feasible (green), limit broken (red) and invalid (black) designs over the first two numeric inputs."""
    numeric = [v for v in plan.variables if v.continuous]
    if not numeric:
        return None
    x = numeric[0]
    y_name = numeric[1].name if len(numeric) > 1 else None
    fig = Figure(figsize=(7.0, 4.6), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    y_label = y_name if y_name is not None else _label(plan.pareto[1])
    for label, test, style in (
        ("feasible", lambda r: r.get("feasible"), {"color": "#2e8b57", "marker": "o"}),
        (
            "limit broken",
            lambda r: r.get("status") != "invalid" and not r.get("feasible"),
            {"color": "#c0392b", "marker": "x"},
        ),
        ("invalid", lambda r: r.get("status") == "invalid", {"color": "#222222", "marker": "."}),
    ):
        group = [r for r in rows if test(r)]
        if not group:
            continue
        ys = [r.get(y_name) for r in group] if y_name is not None else _values(group, plan.pareto[1])
        ax.scatter([r.get(x.name) for r in group], ys, s=12, linewidths=0.8, label=label, **style)
    ax.set_xlabel(x.name, fontsize=9)
    ax.set_ylabel(y_label, fontsize=9)
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#eeeeee", linewidth=0.6)
    ax.legend(fontsize=8)
    return _png(fig)


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return f'<td class="n">{value:.6g}</td>'
    return f"<td>{_e('' if value is None else value)}</td>"


def sweep_page(plan: SweepPlan, rows: Sequence[Mapping[str, Any]], *, table: str) -> str:
    """The HTML text of ``sweep.html`` for the rows of ``plan`` (written beside the table ``table``)."""
    name = plan.data.get("cam", {}).get("name", "cam") if isinstance(plan.data.get("cam"), Mapping) else "cam"
    counts = {s: sum(1 for r in rows if r.get("status") == s) for s in ("ok", "limit", "invalid")}
    feasible = sum(1 for r in rows if r.get("feasible"))
    front_rows = sorted(
        (r for r in rows if r.get("pareto")), key=lambda r: (_values([r], plan.pareto[0])[0], r["index"])
    )
    first, second = plan.pareto
    header = ["index", *(v.name for v in plan.variables), first.column, second.column]
    front_png = _front_figure(rows, plan.pareto)
    body = [
        f"<h1>Sweep of {_e(name)}</h1>",
        f"<p>{len(rows)} designs ({_e(plan.sampling)}) from {_e(plan.source or 'the design')}: "
        f"{counts['ok']} within every limit of the design, {counts['limit']} breaking one, "
        f"{counts['invalid']} refused as input; {feasible} feasible"
        + (f" (also {', '.join(_e(lim.text) for lim in plan.limits)})" if plan.limits else "")
        + f". Every row, figure and verdict is in <code>{_e(table)}</code>.</p>",
        "<p>Variables: "
        + "; ".join(f"<code>{_e(v.name)}</code> = {_e(v.spec())}" for v in plan.variables)
        + "</p>",
        "<h2>Pareto front</h2>",
        f"<p>Feasible designs no other feasible design beats in both {_e(first.text)} and "
        f"{_e(second.text)} (both minimised): {len(front_rows)}.</p>",
        f'<figure id="front"><img alt="Pareto front" src="data:image/png;base64,{front_png}"></figure>',
    ]
    region = _region_figure(rows, plan)
    if region is not None:
        body += [
            "<h2>Feasible region</h2>",
            f'<figure id="region"><img alt="Feasible region" src="data:image/png;base64,{region}"></figure>',
        ]
    body.append("<h2>Designs on the front</h2>")
    body.append(
        '<div class="scroll"><table><tr>'
        + "".join(f"<th>{_e(h)}</th>" for h in header)
        + "</tr>"
        + "".join("<tr>" + "".join(_cell(r.get(h)) for h in header) + "</tr>" for r in front_rows)
        + "</table></div>"
    )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>Sweep of {_e(name)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )
