"""The live designer: ``camcad serve DESIGN.toml`` edits a design in the browser.

A local web page shows the design's fields as a form (grouped as in the TOML,
labelled in words with the schema's units and ranges), the motion program as
an editor (segments added, split, deleted, reordered, dragged on the s/v/a/j
charts; laws with their parameters; point tables uploaded), and redraws the
cam with its follower, the motion curves, pressure angle, curvature and
dynamics, the key numbers and the warnings on every change (analysis without
fit and toolpath); undo/redo and a pinned design to compare against. It
saves the TOML and downloads the shop files as a zip. Stack: the standard
library's HTTP server, the page's own JavaScript and the vendored uPlot
chart library (no web framework, no CDN, nothing to install beyond camcad).
Modules: ``form`` (fields from the schema, values back to a design mapping, TOML text),
``payload`` (the JSON the page draws), ``page`` (HTML, CSS, script),
``toml_edit`` (Save: only the changed keys, comments kept), ``app`` (the
server: loopback only, a per-run token, same-origin POSTs, bounded threads;
see its docstring and docs/reference/serve-security.md).
"""

from __future__ import annotations

import webbrowser
from pathlib import Path

from camcad.serve.app import Designer, DesignerServer, make_server

__all__ = ["Designer", "DesignerServer", "make_server", "serve"]


def serve(path: str | Path, *, port: int = 0, open_browser: bool = False) -> None:
    """Serve the designer for ``path`` on 127.0.0.1 until interrupted (Ctrl-C).

    ``port`` 0 takes a free port; ``open_browser`` opens the page in the default browser. The
    address printed carries the run's token (``http://127.0.0.1:PORT/?token=…``): the page and
    every API call need it.
    """
    server, url = make_server(path, port=port)
    print(f"camcad designer for {path} at {url}  (Ctrl-C to stop)", flush=True)
    if open_browser:
        webbrowser.open(url)
    try:
        server.serve_forever()
    finally:
        server.server_close()
