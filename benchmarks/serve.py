"""How long the live designer takes to answer one edit, per shipped sample.

Run ``python benchmarks/serve.py``: for every sample, the time of
:func:`camcad.serve.payload.evaluate` (validate, analyse without fit and
toolpath, cards, warnings, drawing and curves as JSON-ready data) and of
``json.dumps`` of its answer, the median of ``REPEATS`` runs after one
warm-up, in milliseconds, with the answer's size. Prints a Markdown table.
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


def main() -> None:
    """Measure and print."""
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


if __name__ == "__main__":
    main()
