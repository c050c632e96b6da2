"""The designer's page: the form (rendered here from :mod:`camcad.serve.form`), styles and script.

One HTML page with no external references; its style sheet and script are
served beside it (:data:`STATIC`, ``/static/designer.css`` and
``/static/designer.js``), so the page holds no inline script or style and
the server's Content-Security-Policy can forbid both. The script posts the
form's values to ``/api/analyse`` as the user types (debounced; only the
latest answer is drawn), sending the token of the page's address in the
``X-Camcad-Token`` header, and draws the returned cam and curves as SVG.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from importlib import resources
from typing import Any

from camcad.report import CSS
from camcad.serve.form import Field, Group, motion_info

__all__ = ["STATIC", "render_page"]


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)


def _input(field: Field) -> str:
    ident = "f-" + "".join(c if c.isalnum() else "-" for c in field.path)
    attrs = (
        f'id="{ident}" name="{_e(field.path)}" data-kind="{_e(field.kind)}" aria-describedby="{ident}-err"'
    )
    if field.choices or field.kind == "bool":
        choices = field.choices or ("true", "false")
        default = [] if field.required else ['<option value="">(default)</option>']
        options = default + [
            f'<option value="{_e(c)}"{" selected" if c == field.value else ""}>{_e(c)}</option>'
            for c in choices
        ]
        control = f"<select {attrs}>{''.join(options)}</select>"
    else:
        mode = ' inputmode="decimal"' if field.kind in ("float", "int", "number") else ""
        extra = f'{mode} autocomplete="off" spellcheck="false"'
        control = f'<input type="text" {attrs} value="{_e(field.value)}"{extra}>'
    shown = field.hint and not (field.choices or field.kind == "bool")  # a list shows its own choices
    hint = f'<span class="hint" id="{ident}-hint">{_e(field.hint)}</span>' if shown else ""
    if shown:
        control = control.replace(
            f'aria-describedby="{ident}-err"', f'aria-describedby="{ident}-hint {ident}-err"'
        )
    unit = f' <span class="unit">[{_e(field.unit)}]</span>' if field.unit else ""
    words = field.label or field.key
    return (
        f'<div class="field"><label for="{ident}" title="{_e(field.path)}">{_e(words)}{unit}</label>'
        f"{control}{hint}"
        f'<span class="err" id="{ident}-err" data-for="{_e(field.path)}" role="alert"></span></div>'
    )


def _group(group: Group) -> str:
    body = "".join(_input(f) for f in group.fields)
    if group.more:
        body += (
            f"<details><summary>{len(group.more)} more (defaults)</summary>"
            + "".join(_input(f) for f in group.more)
            + "</details>"
        )
    title = group.title[:1].upper() + group.title[1:]
    legend = f"<legend>{_e(title)} <code>[{_e(group.title)}]</code></legend>"
    return f'<fieldset id="group-{_e(group.title)}">{legend}{body}</fieldset>'


def _motion_editor(motion: Sequence[Mapping[str, Any]]) -> str:
    """The motion program's editor: filled in by the script from the segments and the schema's motion keys."""
    data = _e(json.dumps(list(motion), allow_nan=False))
    info = _e(json.dumps(motion_info(), ensure_ascii=False))
    return (
        '<fieldset id="group-motion"><legend>Motion <code>[[motion]]</code></legend>'
        f'<div id="motion-editor" data-motion="{data}" data-info="{info}"></div>'
        '<div class="seg-actions"><button type="button" id="seg-add">Add segment</button></div>'
        '<div class="upload"><label for="table-file">Point table CSV (angle °, lift)</label>'
        '<input type="file" id="table-file" accept=".csv,text/csv">'
        '<button type="button" id="table-save" disabled>Save into the design folder and use it</button>'
        '<span class="err" id="table-err" role="alert"></span></div>'
        "</fieldset>"
    )


_PAGE_CSS = """
.designer { display: grid; grid-template-columns: minmax(280px, 380px) minmax(0, 1fr); gap: 16px;
            max-width: 1800px; margin: 0 auto; padding: 12px; }
.designer form { max-height: calc(100vh - 24px); overflow-y: auto; position: sticky; top: 12px; }
fieldset { border: 1px solid var(--line); border-radius: 6px; background: var(--card); margin: 0 0 10px;
           padding: 6px 10px 8px; min-width: 0; }
legend { font-weight: 600; font-family: ui-monospace, monospace; font-size: 13px; }
.field { display: grid; grid-template-columns: minmax(0, 9em) minmax(0, 1fr); gap: 1px 8px; margin: 4px 0;
         align-items: center; }
.field label { font-family: ui-monospace, monospace; font-size: 12.5px; overflow-wrap: anywhere; }
.field input, .field select { width: 100%; font: inherit; padding: 3px 5px; border: 1px solid #b9c3cf;
                              border-radius: 4px; min-width: 0; }
.field input[aria-invalid="true"], .field select[aria-invalid="true"] { border-color: var(--bad-edge);
                                                                         background: var(--bad); }
.field .hint { grid-column: 2; color: var(--muted); font-size: 11.5px; }
.field .err { grid-column: 1 / -1; color: var(--bad-edge); font-size: 12.5px; }
.field .err:empty { display: none; }
details summary { cursor: pointer; color: var(--muted); font-size: 12.5px; margin: 4px 0; }
.bar { display: flex; flex-wrap: wrap; gap: 8px; align-items: center; margin-bottom: 10px; }
.bar button { font: inherit; padding: 5px 12px; border-radius: 5px; border: 1px solid #1f5f9e;
              background: #1f5f9e; color: #fff; cursor: pointer; }
.bar button.secondary { background: #fff; color: #1f5f9e; }
#status { color: var(--muted); font-size: 12.5px; flex: 1 1 12em; min-width: 0; white-space: nowrap;
          overflow: hidden; text-overflow: ellipsis; }
#general-error:empty, #notice:empty { display: none; }
body[data-state="invalid"] #cam-drawing, body[data-state="invalid"] .charts,
body[data-state="invalid"] #cards, body[data-state="invalid"] #speed-range { opacity: 0.45; }
#speed-range { font-size: 13px; margin: 6px 0; }
#speed-range:empty { display: none; }
#cam-drawing svg { width: 100%; height: auto; display: block; max-height: 70vh; }
.charts { display: grid; grid-template-columns: repeat(auto-fill, minmax(min(100%, 330px), 1fr)); gap: 10px;
          margin-top: 12px; }
.chart { background: var(--card); border: 1px solid var(--line); border-radius: 6px; padding: 6px; }
.chart h3 { margin: 0 0 2px; font-size: 13px; }
.chart svg { width: 100%; height: auto; display: block; }
.glance { margin-top: 0; }
@media (max-width: 900px) {
  .designer { grid-template-columns: minmax(0, 1fr); }
  .designer form { max-height: none; position: static; }
}
main.designer-main { padding: 0; max-width: none; min-width: 0; }
legend code { font-weight: 400; color: var(--muted); font-size: 11.5px; }
.field label .unit { color: var(--muted); }
.segment { border: 1px solid var(--line); border-left: 5px solid var(--seg, #9bb3cc); border-radius: 5px;
           padding: 4px 8px; margin: 6px 0; }
.segment h4 { margin: 2px 0; font-size: 13px; display: flex; flex-wrap: wrap; gap: 4px; align-items: center; }
.segment h4 span { flex: 1 1 auto; }
.segment button, .seg-actions button, .upload button { font: inherit; font-size: 12px; padding: 2px 7px;
  border: 1px solid #9bb3cc; background: #fff; color: #1f3b57; border-radius: 4px; cursor: pointer; }
.upload { display: grid; gap: 4px; margin-top: 8px; font-size: 12.5px; }
.upload input { max-width: 100%; }
.upload .err:empty { display: none; }
.upload .err { color: var(--bad-edge); }
button:focus-visible, input:focus-visible, select:focus-visible, summary:focus-visible {
  outline: 3px solid #f0a030; outline-offset: 1px; }
#motion-diagram { display: grid; grid-template-columns: repeat(auto-fill, minmax(min(100%, 420px), 1fr));
                  gap: 10px; margin-bottom: 12px; }
.stale-tag { display: none; color: var(--bad-edge); font-weight: 600; font-size: 11.5px; }
body[data-state="invalid"] .stale-tag { display: inline; }
body[data-state="invalid"] .card { outline: 2px dashed var(--bad-edge); }
.uplot { font-family: inherit; }
.u-legend { font-size: 11.5px; }
.chart .plot { width: 100%; overflow: hidden; }
#pin-note:empty { display: none; }
#compare { overflow-x: auto; margin-bottom: 10px; }
#compare table { font-size: 12.5px; border-collapse: collapse; }
#compare td, #compare th { padding: 2px 8px; border-bottom: 1px solid var(--line); text-align: right; }
#compare td:first-child, #compare th:first-child { text-align: left; }
#pin-note { font-size: 12px; color: #6c5b7b; }
"""

_FILES = resources.files("camcad.serve") / "static"
_UPLOT = (_FILES / "uPlot.iife.min.js").read_bytes()  # uPlot 1.6.32 (MIT, uPlot.LICENSE), vendored
_SCRIPT = (_FILES / "designer.js").read_bytes()
_UPLOT_CSS = (_FILES / "uPlot.min.css").read_text(encoding="utf-8")

STATIC: dict[str, tuple[bytes, str]] = {
    "/static/designer.js": (_UPLOT + b"\n" + _SCRIPT, "text/javascript; charset=utf-8"),
    "/static/designer.css": ((CSS + _UPLOT_CSS + _PAGE_CSS).encode("utf-8"), "text/css; charset=utf-8"),
}
"""The page's script (the vendored uPlot charting library, then the designer's own) and style sheet by URL
path: (bytes, Content-Type); the same for every design. Nothing is fetched from the network."""


def render_page(
    groups: Sequence[Group],
    *,
    title: str,
    stem: str,
    notice: str = "",
    revision: str = "",
    motion: Sequence[Mapping[str, Any]] = (),
) -> str:
    """The whole page for a design's form groups; ``stem`` names the downloaded zip.

    ``notice`` is shown in the page's error banner from the start (e.g. a design file on disk that
    no longer reads); ``revision`` names the file's content the form shows (sent back with Save).
    """
    parts = [_group(g) for g in groups]
    at = next((i + 1 for i, g in enumerate(groups) if g.title == "follower"), min(2, len(parts)))
    fields = "".join([*parts[:at], _motion_editor(motion), *parts[at:]])
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>camcad designer: {_e(title)}</title>\n"
        '<link rel="icon" href="data:,">\n<link rel="stylesheet" href="/static/designer.css">\n</head>\n'
        f'<body data-state="loading" data-revision="0" data-stem="{_e(stem)}" data-loaded="{_e(revision)}">\n'
        '<div class="designer">\n'
        f'<form id="design-form" autocomplete="off">{fields}</form>\n'
        '<main class="designer-main">\n'
        f"<header><h1>{_e(title)}</h1></header>\n"
        '<div class="bar"><button type="button" id="save">Save TOML</button>'
        '<button type="button" class="secondary" id="build">Download shop files (.zip)</button>'
        '<button type="button" class="secondary" id="undo" disabled>Undo</button>'
        '<button type="button" class="secondary" id="redo" disabled>Redo</button>'
        '<button type="button" class="secondary" id="pin" aria-pressed="false">Pin for compare</button>'
        '<span id="status" role="status"></span><span id="pin-note"></span></div>\n'
        f'<section class="alert bad" id="notice" role="alert">{_e(notice)}</section>\n'
        '<section class="alert bad" id="general-error" role="alert"></section>\n'
        '<div id="alerts"></div>\n'
        '<section id="compare" aria-live="polite"></section>\n'
        '<section id="motion-diagram" aria-label="motion diagram: drag a segment boundary on the '
        'displacement chart"></section>\n'
        '<section class="glance"><figure id="cam-drawing"><div id="cam-drawing-svg"></div>'
        '<figcaption id="cam-caption"></figcaption></figure><div id="cards"></div>'
        '<p id="speed-range" aria-live="polite"></p></section>\n'
        '<section class="charts" id="charts"></section>\n'
        '</main>\n</div>\n<script src="/static/designer.js"></script>\n</body>\n</html>\n'
    )
