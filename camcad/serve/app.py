"""The designer's local web server: the page, its script and style, and three JSON endpoints.

The standard library's HTTP machinery is enough for one user on one machine
and adds no dependency; what a server on a workstation must not allow is
handled here (see docs/reference/serve-security.md):

- it listens on 127.0.0.1 only, and answers only requests addressed to a
  loopback name (``Host``: no DNS rebinding from a web page);
- a random token made at start (:func:`secrets.token_urlsafe`, printed in
  the page's address as Jupyter does) is required on the page and on every
  API call (``X-Camcad-Token`` header or ``token`` query), compared in
  constant time (:func:`hmac.compare_digest`); a POST must come from the
  server's own origin (``Origin`` absent or equal) and be
  ``application/json``; other methods (OPTIONS included) get 405;
- every answer sends a Content-Security-Policy without inline script,
  ``X-Frame-Options: DENY`` and ``X-Content-Type-Options: nosniff``;
- a request body needs a valid ``Content-Length`` of at most
  :data:`MAX_BODY` bytes, must be a JSON object; anything else is refused
  with a JSON error (400, 411, 413), never a traceback;
- a bounded pool of worker threads (``workers``) serves the accepted
  connections in order, a listen backlog of :data:`BACKLOG` and a queue of
  up to ``max_pending`` connections hold a burst, at most ``analyses``
  analyses or builds run at once, and a request must arrive whole within
  ``timeout`` seconds or its socket is closed;
- point-table files must be regular files in the design file's folder
  (links followed) of at most :data:`MAX_TABLE_BYTES`;
- Save edits only the changed keys of the text it loaded (comments and layout
  kept, :mod:`camcad.serve.toml_edit`), writes through a link to its target
  atomically with the target's mode, and refuses (409) when the file changed
  on disk since it was loaded or last saved.

- an uploaded point table is written only on the user's click, as a new file
  with a plain name (letters, digits, ``._-``, ending ``.csv``) in the design
  file's folder, never over a file the server did not write itself
  (``O_EXCL``), after the table parser has read it.

Endpoints: ``GET /?token=…`` the page; ``GET /static/designer.js`` and
``/static/designer.css``; ``POST /api/analyse`` the form's values →
:func:`camcad.serve.payload.evaluate`; ``POST /api/save`` writes the design
file; ``POST /api/build`` builds every shop file (fit and toolpath included)
and returns them as a zip; ``POST /api/table`` ``{"table": {"name", "text"}}``
writes an uploaded point table beside the design.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import hmac
import io
import json
import os
import queue
import re
import secrets
import socket
import socketserver
import stat
import sys
import tempfile
import threading
import time
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

from camcad.design import load_design, parse_design
from camcad.design.paths import named_error
from camcad.errors import CamcadError, DesignError, UsageError
from camcad.export.records import json_safe
from camcad.serve.form import design_data, form_fields, form_groups
from camcad.serve.page import STATIC, render_page
from camcad.serve.payload import evaluate
from camcad.serve.toml_edit import edit_toml

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["BACKLOG", "MAX_BODY", "MAX_TABLE_BYTES", "Designer", "DesignerServer", "make_server"]

MAX_BODY = 1_000_000  # bytes of one request body
MAX_DESIGN_BYTES = 16 * 1024 * 1024  # a design file is a few kB; refuse to read a huge one
MAX_TABLE_BYTES = 16 * 1024 * 1024  # a point table (36 000 rows of three numbers take ~1 MB)
BACKLOG = 128  # connections the kernel holds before the server accepts them
TOKEN_HEADER = "X-Camcad-Token"
_LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")
_LENGTH = re.compile(r"[0-9]{1,12}")
_TABLE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}\.csv", re.IGNORECASE)
_CSP = (
    "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
    "object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
)
SECURITY_HEADERS = (
    ("Content-Security-Policy", _CSP),
    ("X-Frame-Options", "DENY"),
    ("X-Content-Type-Options", "nosniff"),
    ("Referrer-Policy", "no-referrer"),
    ("Cross-Origin-Resource-Policy", "same-origin"),
    ("Cross-Origin-Opener-Policy", "same-origin"),
    ("Cache-Control", "no-store"),
)
"""Sent with every answer, errors included."""


def _quote(text: str) -> str:
    """A user's string in a message: quoted, with newlines and control characters escaped."""
    return json.dumps(text, ensure_ascii=False)


@dataclass(frozen=True, slots=True)
class _Loaded:
    """The design file as last read or written: its text, mapping, resolved target and content stamp."""

    text: str
    data: dict[str, Any]
    target: Path  # the file itself, links resolved
    stamp: tuple[int, str]  # size [bytes], SHA-256 of the content


def _read_design(path: Path) -> _Loaded:
    """Read and parse a design file (a regular file, UTF-8, TOML); DesignError naming the file otherwise."""
    try:
        target = path.resolve(strict=True)
        with open(target, "rb") as file:
            info = os.fstat(file.fileno())
            if not stat.S_ISREG(info.st_mode):
                raise DesignError("", f"cannot read design file {path}: it is not a regular file")
            if info.st_size > MAX_DESIGN_BYTES:
                raise DesignError(
                    "",
                    f"cannot read design file {path}: {info.st_size} bytes; "
                    f"allowed: at most {MAX_DESIGN_BYTES}",
                )
            raw = file.read(MAX_DESIGN_BYTES + 1)
    except FileNotFoundError:
        raise DesignError("", f"design file not found: {path}") from None
    except (OSError, ValueError) as err:  # ValueError: a NUL in the path
        raise DesignError(
            "", f"cannot read design file {path}: {getattr(err, 'strerror', None) or err}"
        ) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise DesignError(
            "", f"cannot read design file {path}: not UTF-8 text ({err.reason} at byte {err.start})"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise DesignError("", f"{path} is not valid TOML: {err}") from None
    except (RecursionError, ValueError):  # nesting or digits past Python's limits: the loader names the field
        load_design(path)
        raise DesignError("", f"{path} is not valid TOML") from None
    return _Loaded(text=text, data=data, target=target, stamp=(len(raw), hashlib.sha256(raw).hexdigest()))


def _stamp_on_disk(target: Path) -> tuple[int, str] | None:
    """Size and SHA-256 of the file now (None when it is gone or not a regular file)."""
    try:
        with open(target, "rb") as file:
            if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
                return None
            raw = file.read(MAX_DESIGN_BYTES + 1)
    except OSError:
        return None
    return len(raw), hashlib.sha256(raw).hexdigest()


def _resolved(path: Path) -> Path | None:
    """Where ``path`` leads now, links followed (None for a loop or an unreadable folder)."""
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return None


def _write_atomically(target: Path, text: str) -> tuple[int, str]:
    """Replace ``target`` by ``text`` (UTF-8) atomically, keeping its mode; its new stamp.

    A temporary file in the target's own folder is written, flushed to disk,
    given the target's permission bits and renamed onto the target, so a
    reader sees the old file or the new one, never a part; the folder is
    synced so the rename survives a crash.
    """
    raw = text.encode("utf-8")
    mode = stat.S_IMODE(os.stat(target).st_mode)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".camcad-tmp")
    try:
        with os.fdopen(fd, "wb") as file:
            file.write(raw)
            file.flush()
            os.fsync(file.fileno())
            os.fchmod(file.fileno(), mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    with contextlib.suppress(OSError):  # not every system can open a folder to sync it
        folder = os.open(target.parent, os.O_RDONLY)
        try:
            os.fsync(folder)
        finally:
            os.close(folder)
    return len(raw), hashlib.sha256(raw).hexdigest()


def _check_tables(data: Mapping[str, Any], folder: Path) -> None:
    """Refuse a point-table file outside ``folder`` (links followed), not a regular file, or too big.

    Raises
    ------
    DesignError
        Naming ``motion[i].file`` and the value given; never the file's content.
    """
    motion = data.get("motion")
    if not isinstance(motion, list):
        return
    for i, table in enumerate(motion):
        if not isinstance(table, Mapping) or not isinstance(table.get("file"), str):
            continue
        field, name = f"motion[{i}].file", table["file"]
        allowed = f"allowed: a file in the design file's folder {folder} or below it"
        try:
            real = (folder / name).resolve()
            inside = real == folder or folder in real.parents
            info = os.stat(real) if inside else None
        except FileNotFoundError:
            raise DesignError(field, f"{_quote(name)}: no such file; {allowed}") from None
        except (OSError, ValueError, RuntimeError) as err:  # a NUL, a link loop
            raise DesignError(
                field, f"{_quote(name)} cannot be read ({type(err).__name__}); {allowed}"
            ) from None
        if info is None:
            raise DesignError(field, f"{_quote(name)} leads out of the design file's folder; {allowed}")
        if not stat.S_ISREG(info.st_mode):
            raise DesignError(
                field, f"{_quote(name)} is not a regular file (a folder, device, pipe or socket); {allowed}"
            )
        if info.st_size > MAX_TABLE_BYTES:
            raise DesignError(
                field, f"{_quote(name)} is {info.st_size} bytes; allowed: at most {MAX_TABLE_BYTES} bytes"
            )


class Designer:
    """The state of one design being edited: its file, its mapping as read, and how to answer requests."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.folder = self.path.absolute().parent.resolve()
        self.lock = threading.Lock()
        self.loaded = _read_design(self.path)
        self.notice = ""
        self.written: set[str] = set()  # point tables this server wrote (it may write them again)
        self._form: tuple[_Loaded, Mapping[str, Any]] | None = None  # the fields of the file loaded
        self._validate(self.loaded.data)  # refuse to start on an invalid file: fix it first

    def _validate(self, data: Mapping[str, Any]) -> None:
        _check_tables(data, self.folder)
        parse_design(data, source=str(self.path))

    def refresh(self) -> None:
        """Take the file as it is on disk now when it changed and is valid; else keep it as it was.

        A file that changed but no longer reads leaves a notice for the page (and Save refused).
        """
        with self.lock:
            if (
                _stamp_on_disk(self.loaded.target) == self.loaded.stamp
                and _resolved(self.path) == self.loaded.target
            ):
                self.notice = ""
                return
            try:
                loaded = _read_design(self.path)
                self._validate(loaded.data)
            except DesignError as err:
                self.notice = (
                    f"{self.path} changed on disk and cannot be loaded ({err}); the page shows it as it "
                    "was, and Save is refused until the file is fixed and this page reloaded"
                )
                return
            except RecursionError:
                self.notice = f"{self.path} changed on disk and cannot be loaded"
                return
            self.loaded, self.notice = loaded, ""

    @property
    def revision(self) -> str:
        """The SHA-256 of the design file's content as last loaded or saved (the page sends it with Save)."""
        return self.loaded.stamp[1]

    def page(self) -> str:
        """The designer page for the design as on disk (re-read when it changed)."""
        self.refresh()
        base = self.loaded.data
        name = str(base.get("cam", {}).get("name", self.path.stem))
        return render_page(
            form_groups(base),
            title=name,
            stem=self.path.stem,
            notice=self.notice,
            revision=self.revision,
            motion=[t for t in base.get("motion", []) if isinstance(t, Mapping)],
        )

    def _fields(self, loaded: _Loaded) -> Mapping[str, Any]:
        """The form's fields of ``loaded`` (made once per file loaded or saved, not on every edit)."""
        cached = self._form
        if cached is None or cached[0] is not loaded:
            cached = self._form = (loaded, form_fields(loaded.data))
        return cached[1]

    def data(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """The design mapping with the form's values applied; its point tables checked."""
        loaded = self.loaded
        data = design_data(loaded.data, values, self._fields(loaded))
        _check_tables(data, self.folder)
        return data

    def analyse(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """The page's JSON for the form's values."""
        try:
            data = self.data(values)
        except DesignError as err:
            return {"ok": False, "errors": [{"field": named_error(err).field, "message": err.message}]}
        return evaluate(data, source=str(self.path))

    def save(self, values: Mapping[str, Any], revision: str = "") -> dict[str, Any]:
        """Write the design file: only the changed keys, comments kept; ``conflict`` when it changed on disk.

        ``revision`` is the :attr:`revision` the page was made from (empty: the design as loaded now).
        Returns ``{"saved": path or None, "errors": [...], "conflict": bool}`` and, once saved, the new
        ``revision``.
        """
        loaded = self.loaded
        if revision and revision != loaded.stamp[1]:
            return self._conflict("was loaded again from disk after this page was made")
        try:
            data = design_data(loaded.data, values, self._fields(loaded))
            _check_tables(data, self.folder)
            parse_design(data, source=str(self.path))
        except DesignError as err:
            return {
                "saved": None,
                "conflict": False,
                "errors": [{"field": named_error(err).field, "message": err.message}],
            }
        with self.lock:
            if self.loaded is not loaded:  # loaded anew while this request was validated: the form is old
                return self._conflict("was loaded again from disk after this form was filled in")
            now = _resolved(self.path)
            if now != loaded.target:
                return self._conflict(
                    f"now leads to {now or 'no readable file'}, not to the file loaded ({loaded.target})"
                )
            if _stamp_on_disk(loaded.target) != loaded.stamp:
                return self._conflict("changed on disk since it was loaded")
            try:
                text = edit_toml(loaded.text, loaded.data, data)
            except ValueError as err:
                return {"saved": None, "conflict": False, "errors": [{"field": "", "message": str(err)}]}
            try:
                stamp = _write_atomically(loaded.target, text)
            except OSError as err:
                message = f"cannot write {loaded.target}: {err.strerror or err}"
                return {"saved": None, "conflict": False, "errors": [{"field": "", "message": message}]}
            self.loaded = _Loaded(text=text, data=tomllib.loads(text), target=loaded.target, stamp=stamp)
        return {"saved": str(self.path), "conflict": False, "errors": [], "revision": stamp[1]}

    def save_table(self, table: Any) -> dict[str, Any]:
        """Write an uploaded point table ``{"name": "lift.csv", "text": "…"}`` beside the design file.

        The name must be a plain file name ending ``.csv``; the text must read as a point table
        (:func:`camcad.motion.table.parse_table_text`); an existing file is never replaced unless this
        server wrote it. Returns ``{"saved": name or None, "rows": n, "errors": [...]}``.
        """
        from camcad.motion.table import parse_table_text

        def refused(message: str) -> dict[str, Any]:
            return {"saved": None, "rows": 0, "errors": [{"field": "table", "message": message}]}

        if not isinstance(table, Mapping):
            return refused('expected {"name": "lift.csv", "text": "angle_deg,lift_mm\\n…"}')
        name, text = table.get("name"), table.get("text")
        if not isinstance(name, str) or not _TABLE_NAME.fullmatch(name):
            return refused(
                f"file name {_quote(str(name))[:120]}: allowed: letters, digits, '.', '_', '-', ending .csv"
            )
        if not isinstance(text, str) or not text.strip():
            return refused(f"{_quote(name)}: the file is empty")
        try:
            angle, _, _ = parse_table_text(text, where="table")
        except DesignError as err:
            return refused(f"{_quote(name)}: {err.message}")
        target = self.folder / name
        raw = text.encode("utf-8")
        with self.lock:
            try:
                if name in self.written and target.is_file() and not target.is_symlink():
                    _write_atomically(target, text)
                else:
                    fd = os.open(
                        target, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o644
                    )
                    with os.fdopen(fd, "wb") as file:
                        file.write(raw)
            except FileExistsError:
                return refused(
                    f"{_quote(name)} already exists in {self.folder}; choose another name (a file the "
                    "designer did not write is never replaced)"
                )
            except OSError as err:
                return refused(f"cannot write {target}: {err.strerror or err}")
            self.written.add(name)
        return {"saved": name, "rows": len(angle), "errors": []}

    def _conflict(self, what: str) -> dict[str, Any]:
        message = (
            f"not saved: {self.path} {what}; reload the page to edit the file as it is now "
            "(the changes on this page are then lost: copy them first)"
        )
        return {"saved": None, "conflict": True, "errors": [{"field": "", "message": message}]}

    def build_zip(self, values: Mapping[str, Any]) -> bytes:
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


class _DeadlineReader(io.RawIOBase):
    """A socket's input that ends in a timeout at a fixed moment, however slowly the bytes come."""

    def __init__(self, sock: socket.socket, seconds: float) -> None:
        super().__init__()
        self.sock = sock
        self.deadline = time.monotonic() + seconds

    def readable(self) -> bool:
        """Yes."""
        return True

    def readinto(self, buffer: Any) -> int:
        """Up to ``len(buffer)`` bytes; TimeoutError once the deadline has passed."""
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("the request did not arrive in time")
        self.sock.settimeout(left)
        return self.sock.recv_into(buffer)


def _error_body(message: str) -> bytes:
    return json.dumps({"ok": False, "error": message, "errors": [{"field": "", "message": message}]}).encode()


class _Handler(BaseHTTPRequestHandler):
    server: DesignerServer
    server_version = "camcad-serve"
    sys_version = ""
    protocol_version = "HTTP/1.0"  # one request per connection

    def setup(self) -> None:
        """The socket's timeouts: each write within ``timeout`` s, the whole request within ``timeout`` s."""
        self.timeout = self.server.request_timeout
        super().setup()
        self.rfile.close()
        self._reader = _DeadlineReader(self.connection, self.server.request_timeout)
        self.rfile = io.BufferedReader(self._reader)
        self._unread = False  # a request body not read (drained before the connection is closed)

    def log_message(self, format: str, *args: Any) -> None:
        """Quiet: the terminal shows only the address and unexpected errors."""

    def end_headers(self) -> None:
        """Every answer carries the security headers."""
        for key, value in SECURITY_HEADERS:
            self.send_header(key, value)
        super().end_headers()

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        """Errors of the HTTP layer (bad request line, too long a header, unknown method) as JSON."""
        self.close_connection = True
        self.request_version = self.protocol_version  # an answer with headers, even to a garbled line
        self._send(code, _error_body(message or HTTPStatus(code).phrase), "application/json")

    def _send(self, status: int, body: bytes, kind: str, extra: Mapping[str, str] | None = None) -> None:
        self.connection.settimeout(self.server.request_timeout)
        self._answered = True
        self.send_response(status)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(body)))
        for key, value in (extra or {}).items():
            self.send_header(key, value)
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _json(self, status: int, data: Any) -> None:
        # An analysis answer is JSON-ready by construction (payload.evaluate: finite numbers, None for
        # gaps) and goes straight to the encoder; anything else (numpy values, non-finite numbers) takes
        # the slower walk that writes them as summary.json does (camcad.export.records.json_safe).
        try:
            body = json.dumps(data, allow_nan=False)
        except (TypeError, ValueError):
            body = json.dumps(json_safe(data), allow_nan=False)
        self._send(status, body.encode("utf-8"), "application/json")

    def _refuse(self, status: int, message: str, extra: Mapping[str, str] | None = None) -> None:
        self.close_connection = True
        self._send(status, _error_body(message), "application/json", extra)
        if self._unread:
            self._drain()

    # the checks, in the order they are made

    def _loopback(self) -> bool:
        given = self.headers.get("Host") or ""
        host = given.split("]")[0] + "]" if given.startswith("[") else given.rsplit(":", 1)[0]
        if host in _LOOPBACK_HOSTS:
            return True
        self._refuse(HTTPStatus.FORBIDDEN, "loopback only: the Host header must name 127.0.0.1 or localhost")
        return False

    def _token(self, query: str) -> bool:
        given = self.headers.get(TOKEN_HEADER) or (parse_qs(query).get("token") or [""])[0]
        expected = self.server.token.encode("ascii")
        if given and hmac.compare_digest(given.encode("utf-8", "backslashreplace"), expected):
            return True
        self._refuse(
            HTTPStatus.FORBIDDEN,
            "a valid token is required: open the address camcad serve printed (…/?token=…)",
        )
        return False

    def _origin(self) -> bool:
        origin = self.headers.get("Origin")
        if origin is None or origin in self.server.origins:
            return True
        self._refuse(HTTPStatus.FORBIDDEN, f"cross-origin request refused (Origin {_quote(origin)})")
        return False

    def _body(self) -> dict[str, Any] | None:
        """The request's JSON object (``values`` checked), or None after answering with the error."""
        if (self.headers.get("Content-Type") or "").split(";")[0].strip().lower() != "application/json":
            self._refuse(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, "the body must be application/json")
            return None
        if self.headers.get("Transfer-Encoding") is not None:
            self._refuse(HTTPStatus.LENGTH_REQUIRED, "send a Content-Length, not a Transfer-Encoding")
            return None
        lengths = self.headers.get_all("Content-Length") or []
        if not lengths:
            self._refuse(HTTPStatus.LENGTH_REQUIRED, "a Content-Length is required")
            return None
        text = lengths[0].strip()
        if len(lengths) > 1 or not _LENGTH.fullmatch(text):
            self._refuse(
                HTTPStatus.BAD_REQUEST, f"Content-Length {_quote(', '.join(lengths))}: not a number of bytes"
            )
            return None
        length = int(text)
        if length > MAX_BODY:
            self._refuse(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"{length} bytes; allowed: at most {MAX_BODY}")
            return None
        try:
            raw = self.rfile.read(length)
            self._unread = False
        except TimeoutError:
            self._refuse(HTTPStatus.REQUEST_TIMEOUT, "the body did not arrive in time")
            return None
        if len(raw) != length:
            self._refuse(HTTPStatus.BAD_REQUEST, f"the body has {len(raw)} bytes, not the {length} announced")
            return None
        try:
            body = json.loads(raw)
        except RecursionError:
            self._refuse(HTTPStatus.BAD_REQUEST, "the JSON is nested too deep")
            return None
        except ValueError as err:  # not JSON, not UTF-8, an integer too long
            self._refuse(HTTPStatus.BAD_REQUEST, f"not JSON: {str(err)[:200]}")
            return None
        values = body.get("values", {}) if isinstance(body, dict) else None
        if not isinstance(values, dict):
            self._refuse(
                HTTPStatus.BAD_REQUEST, 'expected a JSON object {"values": {"cam.base_radius": "40", …}}'
            )
            return None
        for key, value in values.items():
            if value is not None and not isinstance(value, (str, bool, int, float)):
                self._refuse(HTTPStatus.BAD_REQUEST, f"values[{_quote(key)}]: a string, number or boolean")
                return None
        if not isinstance(body.get("loaded", ""), str):
            self._refuse(HTTPStatus.BAD_REQUEST, '"loaded": the revision string the page was given')
            return None
        return body

    def _drain(self) -> None:
        """Read and drop what the client still sends of a refused request (2 s, 1 MB at most).

        The client then reads the answer rather than a connection reset.
        """
        with contextlib.suppress(OSError, ValueError):
            self.connection.shutdown(socket.SHUT_WR)
            left, until = MAX_BODY, min(time.monotonic() + 2.0, self._reader.deadline)
            while left > 0 and time.monotonic() < until:
                self.connection.settimeout(max(0.001, min(0.25, until - time.monotonic())))
                chunk = self.connection.recv(min(left, 65536))
                if not chunk:
                    break
                left -= len(chunk)

    # the methods

    def _guard(self, method: Any) -> None:
        """Run a method; an unexpected error is one line in the terminal and a 500 JSON answer."""
        self._answered = False
        try:
            method()
        except OSError:  # the client went away or took too long: nothing to answer
            raise
        except Exception as err:
            print(f"camcad serve: unexpected error: {type(err).__name__}: {err}", file=sys.stderr, flush=True)
            if not self._answered:
                self._refuse(
                    HTTPStatus.INTERNAL_SERVER_ERROR, f"unexpected error: {type(err).__name__}: {err}"
                )

    def do_GET(self) -> None:
        """The page (token required) and its script and style sheet."""
        self._guard(self._get)

    def do_POST(self) -> None:
        """The JSON endpoints (token, same origin and a JSON object required)."""
        self._guard(self._post)

    def _get(self) -> None:
        if not self._loopback():
            return
        url = urlsplit(self.path)
        if url.path in STATIC:
            body, kind = STATIC[url.path]
            self._send(HTTPStatus.OK, body, kind)
            return
        if not self._token(url.query):
            return
        if url.path not in ("/", "/index.html"):
            self._refuse(HTTPStatus.NOT_FOUND, "not found")
            return
        page = self.server.run(self.server.designer.page)
        self._send(HTTPStatus.OK, page.encode("utf-8"), "text/html; charset=utf-8")

    def _post(self) -> None:
        self._unread = True
        if not (self._loopback() and self._token(urlsplit(self.path).query) and self._origin()):
            return
        route = urlsplit(self.path).path
        if route not in ("/api/analyse", "/api/save", "/api/build", "/api/table"):
            self._refuse(HTTPStatus.NOT_FOUND, "not found")
            return
        body = self._body()
        if body is None:
            return
        values, designer = body.get("values", {}), self.server.designer
        if route == "/api/analyse":
            self._json(HTTPStatus.OK, self.server.run(designer.analyse, values))
        elif route == "/api/table":
            out = self.server.run(designer.save_table, body.get("table"))
            self._json(HTTPStatus.OK if out["saved"] else HTTPStatus.UNPROCESSABLE_ENTITY, out)
        elif route == "/api/save":
            out = self.server.run(designer.save, values, body.get("loaded", ""))
            self._json(HTTPStatus.CONFLICT if out["conflict"] else HTTPStatus.OK, out)
        else:
            try:
                data = self.server.run(designer.build_zip, values)
            except CamcadError as err:  # bad input or a hard limit: the field as data, the message without it
                errors = [{"field": named_error(err).field, "message": err.message}]
                self._json(HTTPStatus.UNPROCESSABLE_ENTITY, {"ok": False, "errors": errors})
                return
            name = f"{designer.path.stem}-shop-files.zip"
            self._send(HTTPStatus.OK, data, "application/zip",
                       {"Content-Disposition": f'attachment; filename="{name}"'})  # fmt: skip

    def _not_allowed(self) -> None:
        self._refuse(HTTPStatus.METHOD_NOT_ALLOWED, f"{self.command} is not allowed", {"Allow": "GET, POST"})

    do_OPTIONS = do_PUT = do_DELETE = do_PATCH = do_HEAD = do_TRACE = do_CONNECT = _not_allowed


_BUSY = (
    b"HTTP/1.0 503 Service Unavailable\r\nContent-Type: application/json\r\nConnection: close\r\n"
    + b"".join(f"{k}: {v}\r\n".encode() for k, v in SECURITY_HEADERS)
    + b"Retry-After: 1\r\n"
)


class DesignerServer(socketserver.TCPServer):
    """The designer's HTTP server on 127.0.0.1: a bounded pool of worker threads, timed-out sockets.

    Parameters
    ----------
    designer
        The design being edited.
    port
        The port on 127.0.0.1 (0: a free one).
    workers
        Threads serving connections (each reads one request, answers it and closes).
    analyses
        Analyses, saves and builds run at once (the rest wait their turn).
    max_pending
        Accepted connections waiting for a worker; past it a connection is answered 503 at once.
    timeout
        Seconds a request may take to arrive whole (and each write of the answer).
    """

    allow_reuse_address = True
    request_queue_size = BACKLOG

    def __init__(
        self,
        designer: Designer,
        port: int = 0,
        *,
        workers: int = 16,
        analyses: int = 2,
        max_pending: int = 512,
        timeout: float = 10.0,
    ) -> None:
        self._queue: queue.Queue[tuple[socket.socket, Any] | None] = queue.Queue()
        self._workers: list[threading.Thread] = []  # (server_close runs when the bind fails)
        super().__init__(("127.0.0.1", port), _Handler)
        self.designer = designer
        self.token = secrets.token_urlsafe(32)
        self.request_timeout = float(timeout)
        self.max_pending = max_pending
        port = self.server_address[1]
        self.origins = frozenset({f"http://127.0.0.1:{port}", f"http://localhost:{port}"})
        self._compute = threading.BoundedSemaphore(analyses)
        self._workers = [
            threading.Thread(target=self._work, name=f"camcad-serve-{i}", daemon=True) for i in range(workers)
        ]
        for thread in self._workers:
            thread.start()

    @property
    def url(self) -> str:
        """The page's address with the token (``http://127.0.0.1:PORT/?token=…``)."""
        return f"http://127.0.0.1:{self.server_address[1]}/?token={self.token}"

    def run(self, func: Any, *args: Any) -> Any:
        """``func(*args)`` once one of the ``analyses`` slots is free."""
        with self._compute:
            return func(*args)

    def process_request(self, request: Any, client_address: Any) -> None:
        """Queue the connection for a worker, or answer 503 at once when the queue is full."""
        if self._queue.qsize() >= self.max_pending:
            with contextlib.suppress(OSError):
                request.settimeout(0.5)
                body = _error_body("busy: too many requests waiting; try again")
                request.sendall(_BUSY + f"Content-Length: {len(body)}\r\n\r\n".encode() + body)
            self.shutdown_request(request)
            return
        self._queue.put((request, client_address))

    def _work(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            request, client_address = item
            try:
                self.finish_request(request, client_address)
            except Exception:
                self.handle_error(request, client_address)
            finally:
                self.shutdown_request(request)

    def handle_error(self, request: Any, client_address: Any) -> None:
        """One line for an unexpected error; nothing for a client that went away or took too long."""
        err = sys.exc_info()[1]
        if isinstance(err, OSError):  # reset, broken pipe, timeout
            return
        print(f"camcad serve: unexpected error: {type(err).__name__}: {err}", file=sys.stderr, flush=True)

    def server_close(self) -> None:
        """Close the listening socket, stop the workers and close the connections still waiting."""
        super().server_close()
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                break
            if item is not None:
                self.shutdown_request(item[0])
        for _ in self._workers:
            self._queue.put(None)


def make_server(path: str | Path, *, port: int = 0, **options: Any) -> tuple[DesignerServer, str]:
    """A designer server for the design file on 127.0.0.1 (``port`` 0: a free one) and its URL with the token.

    ``options`` go to :class:`DesignerServer` (workers, analyses, max_pending, timeout).

    Raises
    ------
    DesignError
        When the design file cannot be read or is invalid (fix it before editing it here).
    UsageError
        When the port is taken or cannot be used (naming ``--port``).
    """
    designer = Designer(path)
    try:
        server = DesignerServer(designer, port, **options)
    except OSError as err:
        if err.errno == errno.EADDRINUSE:
            raise UsageError(
                "--port", f"{port} is in use; choose another port, or 0 for a free one"
            ) from None
        why = err.strerror or str(err)
        raise UsageError("--port", f"cannot listen on 127.0.0.1 port {port}: {why}") from None
    return server, server.url
