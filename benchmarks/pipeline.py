"""End-to-end build time per stage for every shipped sample.

Run ``python benchmarks/pipeline.py``; prints a Markdown table of the median
of a few builds (milliseconds per stage, written into a temporary folder).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad.design import load_design  # noqa: E402
from camcad.pipeline import build  # noqa: E402

STAGES = ("geometry", "dynamics", "fit", "toolpath", "tables", "dxf", "mesh", "gcode", "report")
REPEATS = 3


def time_sample(path: Path) -> tuple[dict[str, float], float]:
    """Median stage times [s] and median total [s] over REPEATS builds."""
    design = load_design(path)
    runs: list[dict[str, float]] = []
    totals = []
    for _ in range(REPEATS):
        stages: dict[str, float] = {}
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            build(design, Path(tmp) / "out", progress=stages.__setitem__)
            totals.append(time.perf_counter() - start)
        runs.append(stages)
    median = {s: statistics.median(r.get(s, 0.0) for r in runs) for s in STAGES}
    return median, statistics.median(totals)


def main() -> None:
    """Print the table."""
    print("| sample | " + " | ".join(STAGES) + " | total |")
    print("|---|" + "---:|" * (len(STAGES) + 1))
    for path in sorted((ROOT / "samples").glob("*.toml")):
        stages, total = time_sample(path)
        cells = " | ".join(f"{stages[s] * 1000:.0f}" for s in STAGES)
        print(f"| {path.stem} | {cells} | {total * 1000:.0f} |")
    print("\nmilliseconds, median of", REPEATS, "builds; total includes loading libraries on first use")


if __name__ == "__main__":
    main()
