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
from collections.abc import Sequence
from importlib import resources

from camcad.report import CSS
from camcad.serve.form import Field, Group

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
        options = ['<option value="">(default)</option>'] + [
            f'<option value="{_e(c)}"{" selected" if c == field.value else ""}>{_e(c)}</option>'
            for c in choices
        ]
        control = f"<select {attrs}>{''.join(options)}</select>"
    else:
        mode = ' inputmode="decimal"' if field.kind in ("float", "int", "number") else ""
        extra = f'{mode} autocomplete="off" spellcheck="false"'
        control = f'<input type="text" {attrs} value="{_e(field.value)}"{extra}>'
    shown = field.hint and not (field.choices or field.kind == "bool")  # a list shows its own choices
    hint = f'<span class="hint">{_e(field.hint)}</span>' if shown else ""
    return (
        f'<div class="field"><label for="{ident}">{_e(field.key)}</label>{control}{hint}'
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
    title = f"[[motion]] {group.title[6:]}" if group.title.startswith("motion[") else f"[{group.title}]"
    return f'<fieldset id="group-{_e(group.title)}"><legend>{_e(title)}</legend>{body}</fieldset>'


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
#status { color: var(--muted); font-size: 12.5px; }
#general-error:empty, #notice:empty { display: none; }
body[data-state="invalid"] #cam-drawing, body[data-state="invalid"] .charts,
body[data-state="invalid"] #cards { opacity: 0.45; }
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
main.designer-main { padding: 0; max-width: none; }
"""

_SCRIPT = (resources.files("camcad.serve") / "static" / "designer.js").read_bytes()

STATIC: dict[str, tuple[bytes, str]] = {
    "/static/designer.js": (_SCRIPT, "text/javascript; charset=utf-8"),
    "/static/designer.css": ((CSS + _PAGE_CSS).encode("utf-8"), "text/css; charset=utf-8"),
}
"""The page's script and style sheet by URL path: (bytes, Content-Type); the same for every design."""


def render_page(
    groups: Sequence[Group], *, title: str, stem: str, notice: str = "", revision: str = ""
) -> str:
    """The whole page for a design's form groups; ``stem`` names the downloaded zip.

    ``notice`` is shown in the page's error banner from the start (e.g. a design file on disk that
    no longer reads); ``revision`` names the file's content the form shows (sent back with Save).
    """
    fields = "".join(_group(g) for g in groups)
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
        '<span id="status"></span></div>\n'
        f'<section class="alert bad" id="notice" role="alert">{_e(notice)}</section>\n'
        '<section class="alert bad" id="general-error" role="alert"></section>\n'
        '<div id="alerts"></div>\n'
        '<section class="glance"><figure id="cam-drawing"><div id="cam-drawing-svg"></div>'
        '<figcaption id="cam-caption"></figcaption></figure><div id="cards"></div></section>\n'
        '<section class="charts" id="charts"></section>\n'
        '</main>\n</div>\n<script src="/static/designer.js"></script>\n</body>\n</html>\n'
    )
