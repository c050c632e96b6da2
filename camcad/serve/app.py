"""The designer's local web server: the page, and three JSON endpoints, on a loopback address only.

The standard library's threading HTTP server is enough for one user on one
machine and adds no dependency. Requests are accepted only with a loopback
``Host`` header (no DNS rebinding from a web page) and POSTs only as
``application/json`` (a cross-site form cannot send that without the
browser asking first).

Endpoints: ``GET /`` the page; ``POST /api/analyse`` the form's values →
:func:`camcad.serve.payload.evaluate`; ``POST /api/save`` writes the design
file (atomically, through :mod:`camcad.export.records`); ``POST /api/build``
builds every shop file (fit and toolpath included) and returns them as a
zip.
"""

from __future__ import annotations

import io
import json
import sys
import tempfile
import threading
import zipfile
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import tomllib

from camcad.design import parse_design
from camcad.errors import CamcadError, DesignError
from camcad.export.records import write_text
from camcad.serve.form import design_data, form_groups, toml_text
from camcad.serve.page import render_page
from camcad.serve.payload import evaluate

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["Designer", "make_server"]

MAX_BODY = 1_000_000  # bytes of one request
_LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")


class Designer:
    """The state of one design being edited: its file, its mapping as read, and how to answer requests."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        text = self.path.read_text(encoding="utf-8-sig")
        self.base: dict[str, Any] = tomllib.loads(text)
        parse_design(self.base, source=str(self.path))  # refuse to start on an invalid file: fix it first
        self.lock = threading.Lock()

    def page(self) -> str:
        """The designer page for the design as read."""
        name = str(self.base.get("cam", {}).get("name", self.path.stem))
        return render_page(form_groups(self.base), title=name, stem=self.path.stem)

    def data(self, values: dict[str, Any]) -> dict[str, Any]:
        """The design mapping with the form's values applied."""
        return design_data(self.base, values)

    def analyse(self, values: dict[str, Any]) -> dict[str, Any]:
        """The page's JSON for the form's values."""
        return evaluate(self.data(values), source=str(self.path))

    def save(self, values: dict[str, Any]) -> dict[str, Any]:
        """Write the design file (comments of the original are not kept); refuse an invalid design."""
        data = self.data(values)
        try:
            parse_design(data, source=str(self.path))
        except DesignError as err:
            return {"saved": None, "errors": [{"field": err.path, "message": err.message}]}
        with self.lock:
            write_text(self.path, toml_text(data, header="written by camcad serve"))
        return {"saved": str(self.path), "errors": []}

    def build_zip(self, values: dict[str, Any]) -> bytes:
        """Every shop file of ``camcad build`` for the form's values, as zip bytes (fixed dates)."""
        from camcad.pipeline import build

        design = parse_design(self.data(values), source=str(self.path))
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "out"
            build(design, out)
            buf = io.BytesIO()
            with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as archive:
                for file in sorted(p for p in out.rglob("*") if p.is_file()):
                    info = zipfile.ZipInfo(str(file.relative_to(out)), date_time=(1980, 1, 1, 0, 0, 0))
                    info.compress_type = zipfile.ZIP_DEFLATED
                    archive.writestr(info, file.read_bytes())
        return buf.getvalue()


def _handler(designer: Designer) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        server_version = "camcad-serve"

        def log_message(self, format: str, *args: Any) -> None:
            """Quiet: the terminal shows only the address and errors."""

        def _send(self, status: int, body: bytes, kind: str, extra: dict[str, str] | None = None) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            for key, value in (extra or {}).items():
                self.send_header(key, value)
            self.end_headers()
            self.wfile.write(body)

        def _json(self, status: int, data: Any) -> None:
            self._send(status, json.dumps(data, allow_nan=False).encode("utf-8"), "application/json")

        def _loopback(self) -> bool:
            given = self.headers.get("Host") or ""
            host = given.split("]")[0] + "]" if given.startswith("[") else given.rsplit(":", 1)[0]
            if host in _LOOPBACK_HOSTS:
                return True
            self._send(HTTPStatus.FORBIDDEN, b"loopback only", "text/plain")
            return False

        def do_GET(self) -> None:
            """The page."""
            if not self._loopback():
                return
            if self.path not in ("/", "/index.html"):
                self._send(HTTPStatus.NOT_FOUND, b"not found", "text/plain")
                return
            self._send(HTTPStatus.OK, designer.page().encode("utf-8"), "text/html; charset=utf-8")

        def do_POST(self) -> None:
            """The JSON endpoints."""
            if not self._loopback():
                return
            if (self.headers.get("Content-Type") or "").split(";")[0].strip() != "application/json":
                self._send(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, b"application/json only", "text/plain")
                return
            length = int(self.headers.get("Content-Length") or 0)
            if length > MAX_BODY:
                self._send(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, b"too large", "text/plain")
                return
            try:
                body = json.loads(self.rfile.read(length) or b"{}")
                values = {str(k): v for k, v in dict(body.get("values", {})).items()}
            except (ValueError, TypeError, AttributeError):
                self._send(HTTPStatus.BAD_REQUEST, b'expected {"values": {...}}', "text/plain")
                return
            if self.path == "/api/analyse":
                self._json(HTTPStatus.OK, designer.analyse(values))
            elif self.path == "/api/save":
                self._json(HTTPStatus.OK, designer.save(values))
            elif self.path == "/api/build":
                try:
                    data = designer.build_zip(values)
                except DesignError as err:
                    self._json(
                        HTTPStatus.UNPROCESSABLE_ENTITY,
                        {"errors": [{"field": err.path, "message": err.message}]},
                    )
                    return
                except CamcadError as err:
                    self._json(
                        HTTPStatus.UNPROCESSABLE_ENTITY, {"errors": [{"field": "", "message": str(err)}]}
                    )
                    return
                name = f"{designer.path.stem}-shop-files.zip"
                self._send(HTTPStatus.OK, data, "application/zip",
                           {"Content-Disposition": f'attachment; filename="{name}"'})  # fmt: skip
            else:
                self._send(HTTPStatus.NOT_FOUND, b"not found", "text/plain")

    return Handler


def make_server(path: str | Path, *, port: int = 0) -> tuple[ThreadingHTTPServer, str]:
    """A designer server for the design file on 127.0.0.1 (``port`` 0: a free one) and its URL.

    Raises
    ------
    DesignError
        When the design file cannot be read or is invalid (fix it before editing it here).
    OSError
        When the port is taken.
    """
    try:
        designer = Designer(path)
    except FileNotFoundError:
        raise DesignError("", f"design file not found: {path}") from None
    except tomllib.TOMLDecodeError as err:
        raise DesignError("", f"{path} is not valid TOML: {err}") from None
    server = ThreadingHTTPServer(("127.0.0.1", port), _handler(designer))
    server.daemon_threads = True
    return server, f"http://127.0.0.1:{server.server_address[1]}/"
