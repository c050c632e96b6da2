"""``camcad serve`` attacked as a web page, a local user and a careless client would (issue 32).

Every check talks to a real server over a real socket: a ``camcad serve``
subprocess (its stderr captured, so a traceback in the user's terminal fails
the test) or :func:`camcad.serve.make_server` in a thread when the test needs
the server's threads or options. Requests are written byte for byte on raw
sockets, so a malformed one is sent as it is and not repaired by a client
library; answers are parsed by :mod:`http.client`'s own response reader.
"""

from __future__ import annotations

import contextlib
import hashlib
import html.parser
import http.client
import json
import os
import re
import shutil
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from camcad.design import load_design

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "samples"
SECRET = "top-secret-credential-7f3a9c"  # a line no answer may ever contain


def _layout(base: Path) -> Path:
    """design/cam.toml (the measured-table sample, its table beside it), secret/ next to design/."""
    design = base / "design"
    (design / "tables").mkdir(parents=True)
    (base / "secret").mkdir()
    (base / "secret" / "creds.txt").write_text(f"0, 0\n{SECRET}\n", encoding="utf-8")
    shutil.copy(SAMPLES / "measured_table.toml", design / "cam.toml")
    shutil.copy(SAMPLES / "measured_lift.csv", design / "measured_lift.csv")
    shutil.copy(SAMPLES / "measured_lift.csv", design / "tables" / "copy.csv")
    (design / "out.csv").symlink_to(base / "secret" / "creds.txt")
    (design / "in.csv").symlink_to("measured_lift.csv")
    os.mkfifo(design / "pipe.csv")
    return design / "cam.toml"


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}


class Answer:
    """A parsed HTTP answer."""

    def __init__(self, status: int, headers: dict[str, str], body: bytes) -> None:
        self.status, self.headers, self.body = status, headers, body

    def json(self):
        assert self.headers.get("content-type") == "application/json", self.headers
        return json.loads(self.body)


def _parse(sock: socket.socket, method: str) -> Answer:
    response = http.client.HTTPResponse(sock, method=method)
    response.begin()
    body = response.read()
    return Answer(response.status, {k.lower(): v for k, v in response.getheaders()}, body)


def raw(port: int, data: bytes, timeout: float = 120.0) -> Answer:
    """Send ``data`` as it is and nothing more (half-close), then read and parse the answer."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as sock:
        with contextlib.suppress(OSError):  # the server may have answered and closed already
            sock.sendall(data)
            sock.shutdown(socket.SHUT_WR)
        return _parse(sock, data.split(b" ", 1)[0].decode("latin-1"))


def request(
    port: int,
    method: str,
    path: str,
    body: object = None,
    *,
    token: str | None = None,
    headers: dict[str, str] | None = None,
) -> Answer:
    """A well-formed request (JSON body, token header unless None), as bytes on a socket."""
    data = b"" if body is None else json.dumps(body).encode()
    head = {"Host": f"127.0.0.1:{port}"}
    if body is not None:
        head |= {"Content-Type": "application/json", "Content-Length": str(len(data))}
    if token is not None:
        head["X-Camcad-Token"] = token
    head |= headers or {}
    lines = [f"{method} {path} HTTP/1.1", *(f"{k}: {v}" for k, v in head.items()), "", ""]
    return raw(port, "\r\n".join(lines).encode() + data)


class Served:
    """A ``camcad serve`` subprocess: its port, token, design file and captured stderr."""

    def __init__(self, design: Path, stderr: Path) -> None:
        self.design, self.stderr_path = design, stderr
        self._err = open(stderr, "wb")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "camcad", "serve", str(design), "--port", "0"],
            stdout=subprocess.PIPE, stderr=self._err, env=_env(), cwd=design.parent,
        )  # fmt: skip
        line = self.proc.stdout.readline().decode()
        match = re.search(r"http://127\.0\.0\.1:(\d+)/\?token=([A-Za-z0-9_-]+)", line)
        assert match, (line, stderr.read_text())
        self.line = line
        self.port, self.token = int(match.group(1)), match.group(2)

    def stop(self) -> tuple[int, str]:
        self.proc.send_signal(signal.SIGTERM)
        code = self.proc.wait(timeout=60)
        self._err.close()
        return code, self.stderr_path.read_text(encoding="utf-8", errors="replace")


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    base = tmp_path_factory.mktemp("serve")
    server = Served(_layout(base), base / "stderr.txt")
    try:
        yield server
    finally:
        code, stderr = server.stop()
        # after every attack of this module: no traceback in the user's terminal, a clean stop
        assert "Traceback" not in stderr, stderr
        assert stderr.strip() == "camcad: interrupted", stderr
        assert code == 130


# 1. the token


def test_the_address_printed_carries_a_random_token(served, tmp_path):
    from camcad.serve import make_server

    assert len(served.token) >= 43  # token_urlsafe(32): 256 random bits
    assert served.line.startswith("camcad designer for ") and f"?token={served.token}" in served.line
    tokens = set()
    for _ in range(2):
        srv, url = make_server(served.design)
        tokens.add(url.split("token=")[1])
        srv.server_close()
    assert len(tokens) == 2 and served.token not in tokens  # a new one every run


def test_page_and_api_need_the_token(served):
    port, token = served.port, served.token
    analyse = {"values": {"cam.base_radius": "50"}}
    for answer in (
        request(port, "GET", "/"),
        request(port, "GET", "/?token=wrong"),
        request(port, "GET", f"/?token={token[:-1]}"),
        request(port, "GET", "/?token=" + "é" * 43),
        request(port, "POST", "/api/analyse", analyse),
        request(port, "POST", "/api/analyse", analyse, token="wrong"),
        request(port, "POST", "/api/save", analyse, token=""),
        request(port, "POST", "/api/build", analyse, token=token.upper() if token != token.upper() else "x"),
    ):
        assert answer.status == 403 and "token" in answer.json()["error"]
    page = request(port, "GET", f"/?token={token}")
    assert page.status == 200 and b'name="cam.base_radius"' in page.body
    assert request(port, "POST", "/api/analyse", analyse, token=token).json()["ok"] is True
    assert request(port, "POST", f"/api/analyse?token={token}", analyse).json()["ok"] is True
    assert served.design.read_text() == (SAMPLES / "measured_table.toml").read_text()  # nothing saved


# 2. host, origin, methods, headers


def _security_headers_of(answer: Answer) -> None:
    csp = answer.headers["content-security-policy"]
    directives = dict(d.strip().split(" ", 1) for d in csp.split(";"))
    assert directives["default-src"] == "'self'"
    assert "unsafe-inline" not in csp and "unsafe-eval" not in csp
    assert directives["frame-ancestors"] == "'none'"
    assert answer.headers["x-frame-options"] == "DENY"
    assert answer.headers["x-content-type-options"] == "nosniff"


def test_host_origin_and_methods(served):
    port, token = served.port, served.token
    body = {"values": {}}
    foreign = request(port, "GET", f"/?token={token}", headers={"Host": f"evil.example:{port}"})
    assert foreign.status == 403 and "loopback" in foreign.json()["error"]
    for origin in (
        "http://evil.example",
        f"http://127.0.0.1:{port + 1}",
        "null",
        f"https://127.0.0.1:{port}",
    ):
        answer = request(port, "POST", "/api/analyse", body, token=token, headers={"Origin": origin})
        assert answer.status == 403 and "Origin" in answer.json()["error"], origin
    for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}"):
        answer = request(port, "POST", "/api/analyse", body, token=token, headers={"Origin": origin})
        assert answer.status == 200 and answer.json()["ok"] is True
    for method in ("OPTIONS", "PUT", "DELETE", "PATCH", "HEAD", "TRACE"):
        answer = request(port, method, "/api/analyse", token=token)
        assert answer.status == 405, method
        if method != "HEAD":
            assert answer.json()["error"] == f"{method} is not allowed"
    form_post = request(port, "POST", "/api/analyse", token=token, headers={"Content-Type": "text/plain"})
    assert form_post.status == 415


def test_every_answer_sends_the_security_headers(served):
    port, token = served.port, served.token
    answers = [
        request(port, "GET", f"/?token={token}"),
        request(port, "GET", "/static/designer.js"),
        request(port, "GET", "/static/designer.css"),
        request(port, "GET", "/"),
        request(port, "GET", f"/nothing?token={token}"),
        request(port, "OPTIONS", "/"),
        request(port, "POST", "/api/analyse", {"values": {}}, token=token),
        raw(port, b"BREW /pot HTTP/1.1\r\n\r\n"),
        raw(port, b"nonsense\r\n\r\n"),
    ]
    assert [a.status for a in answers] == [200, 200, 200, 403, 404, 405, 200, 501, 400]
    for answer in answers:
        _security_headers_of(answer)
    assert answers[1].headers["content-type"].startswith("text/javascript")


class _Inline(html.parser.HTMLParser):
    """Collects what a Content-Security-Policy without 'unsafe-inline' would block in a page."""

    def __init__(self) -> None:
        super().__init__()
        self.blocked: list[str] = []
        self.scripts: list[str] = []
        self._in: str | None = None

    def handle_starttag(self, tag, attrs):
        names = dict(attrs)
        self.blocked += [f"{tag} {k}" for k in names if k == "style" or k.startswith("on")]
        if tag == "script":
            self.scripts.append(names.get("src") or "")
        self._in = tag if tag in ("script", "style") else None

    def handle_data(self, data):
        if self._in and data.strip():
            self.blocked.append(f"inline {self._in}")


def test_the_page_needs_no_inline_script_or_style(served):
    page = request(served.port, "GET", f"/?token={served.token}")
    parser = _Inline()
    parser.feed(page.body.decode())
    assert parser.blocked == []
    assert parser.scripts == ["/static/designer.js"]
    script = request(served.port, "GET", "/static/designer.js").body.decode()
    assert "X-Camcad-Token" in script and "eval(" not in script


# 3. malformed requests


def _post_head(port: int, token: str, length: str | None, extra: str = "") -> bytes:
    lines = [
        "POST /api/analyse HTTP/1.1",
        f"Host: 127.0.0.1:{port}",
        "Content-Type: application/json",
        f"X-Camcad-Token: {token}",
    ]
    if length is not None:
        lines.append(f"Content-Length: {length}")
    return ("\r\n".join(lines) + "\r\n" + extra + "\r\n").encode()


def test_malformed_requests_get_a_json_error(served):
    port, token = served.port, served.token
    good = b'{"values": {}}'
    deep = b'{"values": ' + b"[" * 100_000 + b"]" * 100_000 + b"}"
    cases = {
        "length abc": (_post_head(port, token, "abc") + good, 400),
        "length 1e9": (_post_head(port, token, "1e9") + good, 400),
        "length -1": (_post_head(port, token, "-1") + good * 1000, 400),
        "length +14": (_post_head(port, token, "+14") + good, 400),
        "length missing": (_post_head(port, token, None) + good, 411),
        "two lengths": (_post_head(port, token, "14", "Content-Length: 14\r\n") + good, 400),
        "chunked": (_post_head(port, token, None, "Transfer-Encoding: chunked\r\n") + b"e\r\n" + good, 411),
        "length 1e9 digits": (_post_head(port, token, "1000000000") + good, 413),
        "length 1000001": (_post_head(port, token, "1000001") + b"{" * 1000, 413),
        "body shorter": (_post_head(port, token, "100") + good, 400),
        "nested 100 000 deep": (_post_head(port, token, str(len(deep))) + deep, 400),
        "a list": (_post_head(port, token, "6") + b"[1, 2]", 400),
        "a string": (_post_head(port, token, "4") + b'"ab"', 400),
        "values a list": (_post_head(port, token, "15") + b'{"values": [1]}', 400),
        "a value an object": (_post_head(port, token, "26") + b'{"values": {"cam.x": {}}}', 400),
        "not JSON": (_post_head(port, token, "5") + b"{oops", 400),
        "not UTF-8": (_post_head(port, token, "4") + b"\xff\xfe\xfa\xfb", 400),
        "a huge integer": (_post_head(port, token, "5000") + b"9" * 5000, 400),
        "header line too long": (b"GET / HTTP/1.1\r\nX-Long: " + b"a" * 70_000 + b"\r\n\r\n", 431),
        "request line too long": (b"GET /" + b"a" * 70_000 + b" HTTP/1.1\r\n\r\n", 414),
    }
    for name, (data, status) in cases.items():
        started = time.monotonic()
        answer = raw(port, data)
        assert answer.status == status, (name, answer.status, answer.body[:200])
        assert answer.json()["error"], name
        _security_headers_of(answer)
        assert time.monotonic() - started < 5.0, name  # answered at once, not after a timeout
    # a body over the cap really sent: refused (413) without reading it, the answer still arrives
    big = _post_head(port, token, "1500000") + b" " * 1_500_000
    assert raw(port, big).status == 413
    # and the server goes on serving
    assert request(port, "POST", "/api/analyse", {"values": {}}, token=token).json()["ok"] is True


# 5. point-table files


def test_point_table_files_stay_in_the_design_folder(served, tmp_path):
    port, token = served.port, served.token
    refused = {
        "/etc/passwd": "leads out",
        "../secret/creds.txt": "leads out",
        str(served.design.parent.parent / "secret" / "creds.txt"): "leads out",
        "out.csv": "leads out",  # a link inside the folder to a file outside it
        "/dev/zero": "leads out",
        "pipe.csv": "not a regular file",  # a FIFO would block a reader forever
        "tables": "not a regular file",
        "missing.csv": "no such file",
        "a\nb.csv": "no such file",
        "nul\x00.csv": "cannot be read",
    }
    for name, why in refused.items():
        for route in ("/api/analyse", "/api/save", "/api/build"):
            started = time.monotonic()
            answer = request(port, "POST", route, {"values": {"motion[0].file": name}}, token=token)
            text = answer.body.decode()
            assert time.monotonic() - started < 10.0
            assert SECRET not in text and "root:" not in text, (name, route)
            assert answer.status == (422 if route == "/api/build" else 200), (name, route)
            [error] = answer.json()["errors"]
            assert error["field"] == "motion[0].file" and why in error["message"], (name, error)
            assert json.dumps(name, ensure_ascii=False) in error["message"]  # the value, escaped
            assert "\n" not in error["message"]
    assert served.design.read_text() == (SAMPLES / "measured_table.toml").read_text()  # nothing saved
    # inside the folder: a link to a file there and a file in a subfolder read as the file itself
    own = request(port, "POST", "/api/analyse", {"values": {}}, token=token).json()
    for name in ("in.csv", "tables/copy.csv", "./tables/../measured_lift.csv"):
        out = request(port, "POST", "/api/analyse", {"values": {"motion[0].file": name}}, token=token).json()
        assert out["ok"] is True and out["summary"]["geometry"] == own["summary"]["geometry"], name
        assert out["drawing"]["profile"] == own["drawing"]["profile"]


# 7. the command line


def test_a_design_file_not_in_utf8_exits_2_with_one_line(tmp_path):
    bad = tmp_path / "latin1.toml"
    text = (SAMPLES / "quintero_vap_b01.toml").read_text(encoding="utf-8")
    bad.write_bytes(text.replace('name = "', 'name = "Größe ', 1).encode("latin-1", errors="replace"))
    done = subprocess.run(
        [sys.executable, "-m", "camcad", "serve", str(bad)],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("camcad: error: ")
    assert str(bad) in done.stderr and "UTF-8" in done.stderr and done.stdout == ""


def test_a_port_in_use_exits_2_naming_the_port(tmp_path):
    design = tmp_path / "cam.toml"
    shutil.copy(SAMPLES / "quintero_vap_b01.toml", design)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = subprocess.run(
            [sys.executable, "-m", "camcad", "serve", str(design), "--port", str(port)],
            capture_output=True, text=True, env=_env(), timeout=120,
        )  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("camcad: error: --port: ")
    assert f"{port} is in use" in done.stderr and "Traceback" not in done.stderr


# 6. save


@contextlib.contextmanager
def _serving(design: Path, **options):
    from camcad.serve import make_server

    srv, _ = make_server(design, **options)
    thread = threading.Thread(target=srv.serve_forever, daemon=True)
    thread.start()
    try:
        yield srv
    finally:
        srv.shutdown()
        srv.server_close()


def _save(srv, values: dict, **extra) -> Answer:
    return request(srv.server_address[1], "POST", "/api/save", {"values": values, **extra}, token=srv.token)


def test_save_keeps_comments_layout_mode_and_the_link(tmp_path):
    real = tmp_path / "real"
    (tmp_path / "work").mkdir()
    real.mkdir()
    target = real / "cam.toml"
    shutil.copy(SAMPLES / "measured_table.toml", target)
    shutil.copy(SAMPLES / "measured_lift.csv", tmp_path / "work" / "measured_lift.csv")
    target.chmod(0o600)
    link = tmp_path / "work" / "cam.toml"
    link.symlink_to(target)
    before = target.read_text(encoding="utf-8")
    with _serving(link) as srv:
        answer = _save(srv, {"cam.base_radius": "52.5", "dynamics.spring_rate": "", "fit.tolerance": "0.002"})
        assert answer.status == 200, answer.body
        assert answer.json()["saved"] == str(link)
    after = target.read_text(encoding="utf-8")
    # the same text, line for line, but for the three keys changed: independent of tomlkit's output
    expected = before.replace("base_radius = 45.0          # mm", "base_radius = 52.5          # mm")
    expected = expected.replace("spring_rate = 1.5           # N/mm\n", "")
    assert after.startswith(expected.rstrip("\n")), after
    assert tomllib.loads(after[len(expected.rstrip("\n")) :]) == {"fit": {"tolerance": 0.002}}
    assert link.is_symlink() and link.resolve() == target  # written through the link
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    assert sorted(p.name for p in real.iterdir()) == ["cam.toml"]  # no temporary file left behind
    design = load_design(link)
    assert design.cam.base_radius == 52.5
    assert design.dynamics.spring_rate == load_design(_without_spring_rate(tmp_path)).dynamics.spring_rate


def _without_spring_rate(tmp_path: Path) -> Path:
    """The sample with its spring_rate line removed (the loader's default then applies)."""
    path = tmp_path / "work" / "default_spring.toml"
    text = (SAMPLES / "measured_table.toml").read_text(encoding="utf-8")
    path.write_text(re.sub(r"\nspring_rate = .*\n", "\n", text), encoding="utf-8")
    return path


def test_save_refuses_a_file_changed_on_disk(tmp_path):
    design = tmp_path / "cam.toml"
    shutil.copy(SAMPLES / "quintero_vap_b01.toml", design)
    with _serving(design) as srv:
        port = srv.server_address[1]
        page = request(port, "GET", f"/?token={srv.token}").body.decode()
        loaded = re.search(r'data-loaded="([0-9a-f]{64})"', page).group(1)
        assert loaded == hashlib.sha256(design.read_bytes()).hexdigest()
        edited = design.read_text() + "# an edit made in another editor\n"
        design.write_text(edited)
        answer = _save(srv, {"cam.base_radius": "52.5"}, loaded=loaded)
        assert answer.status == 409 and answer.json()["conflict"] is True
        assert "changed on disk" in answer.json()["errors"][0]["message"]
        assert design.read_text() == edited  # not overwritten
        # without the page's revision (an API client) refused as well: the file is not the one loaded
        assert _save(srv, {"cam.base_radius": "52.5"}).status == 409
        # reloading the page takes the file as it is now; Save from the new page writes
        page = request(port, "GET", f"/?token={srv.token}").body.decode()
        fresh = re.search(r'data-loaded="([0-9a-f]{64})"', page).group(1)
        assert fresh == hashlib.sha256(edited.encode()).hexdigest()
        assert (
            _save(srv, {"cam.base_radius": "53"}, loaded=loaded).status == 409
        )  # the old page still refused
        answer = _save(srv, {"cam.base_radius": "53"}, loaded=fresh)
        assert (
            answer.status == 200
            and answer.json()["revision"] == hashlib.sha256(design.read_bytes()).hexdigest()
        )
        assert design.read_text() == edited.replace("base_radius = 40.0", "base_radius = 53", 1)
        # saving again from the same page (its revision updated by the answer) works
        assert _save(srv, {"cam.base_radius": "54"}, loaded=answer.json()["revision"]).status == 200


def test_save_never_writes_a_file_it_did_not_load(tmp_path):
    one, two = tmp_path / "one.toml", tmp_path / "two.toml"
    shutil.copy(SAMPLES / "quintero_vap_b01.toml", one)
    two.write_text(one.read_text() + "# the other file\n")
    link = tmp_path / "cam.toml"
    link.symlink_to(one)
    with _serving(link) as srv:
        link.unlink()
        link.symlink_to(two)  # the link now leads to another file
        answer = _save(srv, {"cam.base_radius": "52.5"})
        assert answer.status == 409 and "not to the file loaded" in answer.json()["errors"][0]["message"]
        one.unlink()  # and the file loaded is gone
        assert _save(srv, {"cam.base_radius": "52.5"}).status == 409
    assert two.read_text().endswith("# the other file\n") and "52.5" not in two.read_text()


# 4. load


def _threads() -> int:
    return sum(1 for t in threading.enumerate() if t.name.startswith("camcad-serve"))


def test_fifty_concurrent_analyses_all_get_an_answer(tmp_path):
    from tests.conftest import serving

    with serving(tmp_path) as (srv, _, _):
        port, token = srv.server_address[1], srv.token
        start = threading.Barrier(50)
        answers: list[object] = [None] * 50

        def one(i: int) -> None:
            start.wait()
            try:
                body = {"values": {"cam.base_radius": str(40 + i % 5)}}
                answers[i] = request(port, "POST", "/api/analyse", body, token=token)
            except OSError as err:  # a reset connection would land here
                answers[i] = err

        clients = [threading.Thread(target=one, args=(i,)) for i in range(50)]
        for c in clients:
            c.start()
        assert _threads() <= 16
        for c in clients:
            c.join(timeout=300)
    assert all(isinstance(a, Answer) and a.status == 200 for a in answers), answers
    radii = {a.json()["drawing"]["base_radius"] for a in answers}
    assert radii == {40, 41, 42, 43, 44}


def test_half_sent_requests_do_not_hold_threads_and_are_closed(tmp_path):
    from tests.conftest import serving

    timeout = 0.5
    with serving(tmp_path, timeout=timeout) as (srv, _, _):
        port = srv.server_address[1]
        before = threading.active_count()
        socks = []
        sent_at = time.monotonic()
        for _ in range(200):
            s = socket.create_connection(("127.0.0.1", port), timeout=60)
            s.sendall(f"POST /api/analyse HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Le".encode())
            socks.append(s)
        time.sleep(0.2)
        assert threading.active_count() <= before and _threads() == 16  # no thread per connection
        closed_at = []
        for s in socks:  # each is closed by the server (EOF), the first of them after the timeout
            s.settimeout(60)
            try:
                assert s.recv(1024) == b""
            except ConnectionResetError:
                pass
            closed_at.append(time.monotonic() - sent_at)
            s.close()
        assert timeout * 0.9 <= min(closed_at) and max(closed_at) < 200 / 16 * timeout + 20
        assert threading.active_count() <= before
        # a request that arrives whole is served afterwards
        answer = request(port, "POST", "/api/analyse", {"values": {}}, token=srv.token)
        assert answer.status == 200 and answer.json()["ok"] is True


def test_a_full_queue_answers_503_at_once(tmp_path):
    from tests.conftest import serving

    with serving(tmp_path, workers=1, max_pending=1, timeout=5.0) as (srv, _, _):
        port = srv.server_address[1]
        slow = []
        for _ in range(3):  # one held by the worker, one queued: the queue is full
            slow.append(socket.create_connection(("127.0.0.1", port), timeout=30))
            slow[-1].sendall(b"GET / HTTP/1.1\r\n")
            time.sleep(0.2)
        started = time.monotonic()
        answer = request(port, "POST", "/api/analyse", {"values": {}}, token=srv.token)
        assert answer.status == 503 and "busy" in answer.json()["error"]
        assert time.monotonic() - started < 2.0
        _security_headers_of(answer)
        for s in slow:
            s.close()


def test_a_design_whose_own_table_leads_out_is_not_served(tmp_path):
    """The confinement holds for the file's own value too: the server does not start (exit 2 in the CLI)."""
    from camcad.errors import DesignError
    from camcad.serve import make_server

    design = _layout(tmp_path)
    design.write_text(design.read_text().replace('"measured_lift.csv"', '"../secret/creds.txt"'))
    with pytest.raises(DesignError) as caught:
        make_server(design)
    assert caught.value.path == "motion[0].file" and "leads out" in caught.value.message
    assert SECRET not in str(caught.value)
