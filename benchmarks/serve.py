"""How long the live designer takes to answer one edit, per shipped sample and per cam family.

Run ``python benchmarks/serve.py [--against DIR] [--cpu N] [--repeats N] [--only a,b]``.
For every sample a real ``camcad serve`` runs in its own process (pinned to
CPU ``N`` with ``--cpu``, so the servers compared share one core), on a copy
of the sample with the samples' point tables beside it, and two figures are
taken, each the median of ``--repeats`` edits after one warm-up, an edit
being the base radius moved by ±0.5 mm:

- the request: ``POST /api/analyse`` with the form's values, from sending it
  to the last byte of the answer (validation, analysis without fit and
  toolpath, cards, warnings, drawing, curves, JSON encoding), with the
  answer's size;
- when Chromium and Selenium are installed, the latency a designer sees: from
  the change event of the edit to the page redrawn (cards, drawing, uPlot
  charts, one animation frame after), measured by the page itself
  (``body.dataset.latency``), median of the same number of edits.

With ``--against DIR`` (another checkout of camcad, e.g. the commit before
unpacked with ``git archive``) the same figures are taken of its server in
the same run, sample by sample, the two alternating which goes first, and
each cell gets the ratio now / before: on a machine others share, the ratio
moves much less than the absolute times. The last table gives the median per
cam family against the issue's targets (≤ 150 ms on a plate, ≤ 400 ms on a
conjugate pair). Prints Markdown tables with the load average before and after.
"""

from __future__ import annotations

import argparse
import contextlib
import http.client
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

TARGETS = {"plate": 150.0, "conjugate": 400.0}  # ms, issue 37: edit to the redrawn page, median
EDIT = """
const f = document.querySelector('[name="cam.base_radius"]');
f.value = String(+f.value + (arguments[0] % 2 ? 0.5 : -0.5));
f.dispatchEvent(new Event('change', {bubbles: true}));
"""
_SERVER = """
import sys
sys.path.insert(0, sys.argv[1])
from camcad.serve import make_server
srv, url = make_server(sys.argv[2], port=0)
print(url, flush=True)
srv.serve_forever()
"""


@contextlib.contextmanager
def _server(root: Path, design: Path, cpu: int | None):
    """``camcad serve`` of the camcad in ``root`` on ``design``, in its own process; yields its URL."""
    command = [sys.executable, "-c", _SERVER, str(root), str(design)]
    if cpu is not None and shutil.which("taskset"):
        command = ["taskset", "-c", str(cpu), *command]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, text=True, cwd=design.parent)
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        if not url.startswith("http://"):
            raise RuntimeError(f"the server of {root} did not start")
        yield url
    finally:
        proc.terminate()
        proc.wait(timeout=30)


class _Requests:
    """``POST /api/analyse`` to one server, timed: ±0.5 mm base-radius edits in turn."""

    def __init__(self, url: str, design: Path) -> None:
        self.port, token = int(url.split(":")[2].split("/")[0]), url.split("token=")[1]
        self.headers = {
            "Host": f"127.0.0.1:{self.port}",
            "Content-Type": "application/json",
            "X-Camcad-Token": token,
        }
        self.radius = float(tomllib.loads(design.read_text(encoding="utf-8"))["cam"]["base_radius"])
        self.times: list[float] = []
        self.size = 0.0

    def edit(self, i: int) -> None:
        """One edit; its time [ms] and the answer's size [kB] kept."""
        body = json.dumps({"values": {"cam.base_radius": str(self.radius + (0.5 if i % 2 else -0.5))}})
        start = time.perf_counter()
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=600)
        conn.request("POST", "/api/analyse", body=body, headers=self.headers)
        answer = conn.getresponse().read()
        self.times.append((time.perf_counter() - start) * 1e3)
        conn.close()
        self.size = len(answer) / 1000
        if not json.loads(answer).get("ok"):
            raise RuntimeError(f"the edit was refused: {answer[:200]!r}")


def _wait(driver: Any, condition: str, seconds: float = 600.0) -> None:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if driver.execute_script(f"return Boolean({condition})"):
            return
        time.sleep(0.01)
    raise TimeoutError(condition)


class _Page:
    """The designer page of one server in one browser, edited: edit → redrawn page as the page measures it."""

    def __init__(self, driver: Any, url: str) -> None:
        self.driver = driver
        self.times: list[tuple[float, float, float]] = []
        driver.get(url)
        _wait(driver, "document.body.dataset.state === 'ok' && document.body.dataset.busy === '0'")

    def edit(self, i: int) -> None:
        """One edit: (edit → redrawn page, of which the request, of which drawing) [ms] kept."""
        d = self.driver
        rev = d.execute_script("return +document.body.dataset.revision")
        d.execute_script(EDIT, i)
        _wait(d, f"+document.body.dataset.revision > {rev} && document.body.dataset.busy === '0'")
        got = d.execute_script("const d = document.body.dataset; return [+d.latency, +d.fetchMs, +d.drawMs]")
        self.times.append(tuple(got))


def _medians(times: list[Any]) -> Any:
    """Medians after the first (warm-up) run: of the numbers, or of each column of tuples."""
    rest = times[1:]
    if rest and isinstance(rest[0], tuple):
        return tuple(statistics.median(t[k] for t in rest) for k in range(len(rest[0])))
    return statistics.median(rest)


def _load() -> str:
    """The machine's load average (1, 5, 15 min): the timings mean little on a busy machine."""
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + f" on {os.cpu_count()} CPUs"


def _family(path: Path) -> str:
    return str(tomllib.loads(path.read_text(encoding="utf-8")).get("cam", {}).get("style", "plate"))


def _browsers(count: int, stack: Any) -> tuple[list[Any], str]:
    """``count`` headless Chromium drivers (one per checkout), or ([], reason) when it is missing."""
    drivers = []
    try:
        from tests.readers.browser import chromium

        for _ in range(count):
            driver = stack.enter_context(chromium())
            driver.set_window_size(1400, 1000)
            drivers.append(driver)
    except BaseException as err:  # pytest.skip when Chromium or Selenium is missing
        return [], str(err)
    return drivers, ""


def _ratio(now: float, before: float | None) -> str:
    return "" if before is None else f"{now / before:.2f}×"


def main() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", type=Path, help="another camcad checkout measured in the same run")
    parser.add_argument("--cpu", type=int, help="pin every server to this CPU (taskset)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--only", help="comma-separated sample names")
    parser.add_argument("--no-browser", action="store_true")
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # stopped: its servers and browsers closed too
    samples = sorted((ROOT / "samples").glob("*.toml"))
    if args.only:
        samples = [p for p in samples if p.stem in args.only.split(",")]
    roots = {"now": ROOT} | ({"before": args.against.resolve()} if args.against else {})
    print(_load())
    print()
    rows: dict[str, dict[str, Any]] = {}
    with contextlib.ExitStack() as stack:
        drivers, why = ([], "--no-browser") if args.no_browser else _browsers(len(roots), stack)
        tmp = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        for path in samples:
            row: dict[str, Any] = {"family": _family(path)}
            requests, pages = {}, {}
            with contextlib.ExitStack() as servers:
                for k, (name, root) in enumerate(roots.items()):  # every checkout's server, side by side
                    folder = tmp / path.stem / name
                    folder.mkdir(parents=True)
                    for csv in (ROOT / "samples").glob("*.csv"):
                        shutil.copy(csv, folder / csv.name)
                    design = folder / path.name
                    shutil.copy(path, design)
                    url = servers.enter_context(_server(root, design, args.cpu))
                    requests[name] = _Requests(url, design)
                    if drivers:
                        pages[name] = _Page(drivers[k], url)
                # edit by edit, the checkouts in turn, the one going first alternating
                for measured in (requests, pages):
                    for i in range(args.repeats + 1):
                        for name in list(measured) if i % 2 == 0 else list(reversed(measured)):
                            measured[name].edit(i)
            for name in roots:
                row[name] = {
                    "request": _medians(requests[name].times),
                    "size": requests[name].size,
                    "page": _medians(pages[name].times) if pages else None,
                }
            rows[path.stem] = row
            print(f"{path.stem}: {json.dumps(row)}", file=sys.stderr, flush=True)
    driver = drivers[0] if drivers else None
    against = "before" in roots
    head = "| sample | family | request [ms] | answer [kB] |"
    rule = "|---|---|---:|---:|"
    if against:
        head += " request before [ms] | × before | answer before [kB] |"
        rule += "---:|---:|---:|"
    if driver is not None:
        head += " edit → redrawn page [ms] | of which drawing [ms] |"
        rule += "---:|---:|"
        if against:
            head += " page before [ms] | × before |"
            rule += "---:|---:|"
    lines = [head, rule]
    for stem, row in rows.items():
        now, before = row["now"], row.get("before")
        cells = [stem, row["family"], f"{now['request']:.0f}", f"{now['size']:.0f}"]
        if before:
            cells += [
                f"{before['request']:.0f}",
                _ratio(now["request"], before["request"]),
                f"{before['size']:.0f}",
            ]
        if now["page"] is not None:
            cells += [f"{now['page'][0]:.0f}", f"{now['page'][2]:.0f}"]
            if before:
                cells += [f"{before['page'][0]:.0f}", _ratio(now["page"][0], before["page"][0])]
        lines.append("| " + " | ".join(cells) + " |")
    print("\n".join(lines))
    print()
    if driver is None:
        print(f"(no browser latency: {why})")
        print()
    key = "page" if driver is not None else "request"
    what = "edit → redrawn page" if driver is not None else "request"
    lines = [
        f"| family | samples | median {what} [ms] | target [ms] |"
        + (" before [ms] | × before |" if against else ""),
        "|---|---:|---:|---:|" + ("---:|---:|" if against else ""),
    ]
    for family in sorted({r["family"] for r in rows.values()}):
        group = [r for r in rows.values() if r["family"] == family]

        def median(name: str, group: list[dict[str, Any]] = group) -> float:
            values = [r[name][key] for r in group]
            return statistics.median(v[0] if isinstance(v, (tuple, list)) else v for v in values)

        target = TARGETS.get(family)
        cells = [family, str(len(group)), f"{median('now'):.0f}", "" if target is None else f"{target:.0f}"]
        if against:
            cells += [f"{median('before'):.0f}", _ratio(median("now"), median("before"))]
        lines.append("| " + " | ".join(cells) + " |")
    print("\n".join(lines))
    print()
    print(_load())


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    full = len(sys.argv) == 1 or not any(a.startswith("--only") for a in sys.argv)
    if full:
        with captured("serve"):  # the printed tables become its section of benchmarks/README.md
            main()
    else:  # a partial run prints only
        main()
