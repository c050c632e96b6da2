"""How long the live designer takes to answer one edit, per shipped sample.

Run ``python benchmarks/serve.py``: for every sample, the time of
:func:`camcad.serve.payload.evaluate` (validate, analyse without fit and
toolpath, cards, warnings, drawing and curves as JSON-ready data) and of
``json.dumps`` of its answer, the median of ``REPEATS`` runs after one
warm-up, in milliseconds, with the answer's size; then, when Chromium and
Selenium are installed, the latency a designer sees: from the change event of
an edit (the base radius, committed as on leaving the field) to the page
redrawn (cards, drawing, uPlot charts, one animation frame after), measured by
the page itself (``body.dataset.latency``) against a real ``camcad serve``,
median of ``REPEATS`` edits. Prints Markdown tables, with the load average
before and after.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad.serve.payload import evaluate  # noqa: E402

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

REPEATS = 5
EDIT = """
const f = document.querySelector('[name="cam.base_radius"]');
f.value = String(+f.value + (arguments[0] % 2 ? 0.5 : -0.5));
f.dispatchEvent(new Event('change', {bubbles: true}));
"""


def _wait(driver: object, condition: str, seconds: float = 120.0) -> None:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if driver.execute_script(f"return Boolean({condition})"):  # type: ignore[attr-defined]
            return
        time.sleep(0.01)
    raise TimeoutError(condition)


def browser_latency() -> list[str]:
    """Edit-to-redrawn-page latency per sample in headless Chromium (empty when it is not installed)."""
    import shutil
    import tempfile
    import threading

    try:
        from tests.readers.browser import chromium

        context = chromium()
        driver = context.__enter__()
    except BaseException as err:  # pytest.skip when Chromium or Selenium is missing
        return [f"(no browser latency: {err})"]
    from camcad.serve import make_server

    lines = [
        "| sample | edit → redrawn page [ms] | of which the request [ms] | of which drawing [ms] |",
        "|---|---:|---:|---:|",
    ]
    try:
        driver.set_window_size(1400, 1000)
        with tempfile.TemporaryDirectory() as tmp:
            for csv in (ROOT / "samples").glob("*.csv"):
                shutil.copy(csv, Path(tmp) / csv.name)
            for path in sorted((ROOT / "samples").glob("*.toml")):
                design = Path(tmp) / path.name
                shutil.copy(path, design)
                srv, url = make_server(design, port=0)
                threading.Thread(target=srv.serve_forever, daemon=True).start()
                try:
                    driver.get(url)
                    try:
                        _wait(
                            driver,
                            "document.body.dataset.state === 'ok' && document.body.dataset.busy === '0'",
                            seconds=30.0,
                        )
                    except TimeoutError:  # the page never drew this design (a server error): say so, go on
                        lines.append(f"| {path.stem} | (no answer) | | |")
                        continue
                    times, fetches, draws = [], [], []
                    for i in range(REPEATS + 1):
                        rev = driver.execute_script("return +document.body.dataset.revision")
                        driver.execute_script(EDIT, i)
                        _wait(
                            driver,
                            f"+document.body.dataset.revision > {rev} && document.body.dataset.busy === '0'",
                        )
                        got = driver.execute_script(
                            "const d = document.body.dataset; return [+d.latency, +d.fetchMs, +d.drawMs]"
                        )
                        times.append(got[0])
                        fetches.append(got[1])
                        draws.append(got[2])
                    cells = [statistics.median(x[1:]) for x in (times, fetches, draws)]
                    lines.append(f"| {path.stem} | " + " | ".join(f"{c:.0f}" for c in cells) + " |")
                finally:
                    srv.shutdown()
                    srv.server_close()
    finally:
        context.__exit__(None, None, None)
    return lines


def _load() -> str:
    """The machine's load average (1, 5, 15 min): the timings mean little on a busy machine."""
    import os

    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + f" on {os.cpu_count()} CPUs"


def main() -> None:
    """Measure and print."""
    print(_load())
    print()
    lines = ["| sample | evaluate [ms] | JSON [ms] | answer [kB] |", "|---|---:|---:|---:|"]
    for path in sorted((ROOT / "samples").glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        evaluate(data, source=str(path))
        times, dumps = [], []
        for _ in range(REPEATS):
            start = time.perf_counter()
            out = evaluate(data, source=str(path))
            middle = time.perf_counter()
            text = json.dumps(out)
            times.append(middle - start)
            dumps.append(time.perf_counter() - middle)
        size = len(text) / 1000
        median, dump = statistics.median(times) * 1e3, statistics.median(dumps) * 1e3
        lines.append(f"| {path.stem} | {median:.0f} | {dump:.0f} | {size:.0f} |")
    print("\n".join(lines))
    print()
    print("\n".join(browser_latency()))
    print()
    print(_load())


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("serve"):  # the printed tables become its section of benchmarks/README.md
        main()
