"""Time of the report stage (``write_report``) per shipped sample, against another checkout.

Run ``python benchmarks/report.py [--against DIR]``: each sample is analysed
once (fit and toolpath included, as in a build), then the report is written
``REPEATS`` times, in a fresh interpreter per checkout and sample,
alternating between the checkouts so both see the same machine load. The
first write (which pays for loading matplotlib's fonts) and the median wall
time of the rest are shown; the ratio is taken on the least CPU time of the
later writes, the figure least moved by other work on a shared machine.
``--against`` names another checkout of camcad (e.g. ``git archive HEAD |
tar -x -C /tmp/base``); the table then gives both times and the ratio now /
then. Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 5

_CHILD = r"""
import json, statistics, sys, tempfile, time
from pathlib import Path
from camcad.design import load_design
from camcad.pipeline import analyse
from camcad.report import write_report
analysis = analyse(load_design(sys.argv[1]))
times, cpu = [], []
with tempfile.TemporaryDirectory() as tmp:
    for _ in range(int(sys.argv[2])):
        start, start_cpu = time.perf_counter(), time.process_time()
        write_report(analysis, Path(tmp) / "report.html")
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    size = (Path(tmp) / "report.html").stat().st_size
later = times[1:] or times
best = min(cpu[1:] or cpu)
print(json.dumps({"first": times[0], "median": statistics.median(later), "cpu": best, "bytes": size}))
"""


def time_report(tree: Path, sample: Path) -> dict[str, float]:
    """First and median later write_report times [s] and the page size [bytes], in a fresh process."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    run = [sys.executable, "-c", _CHILD, str(sample), str(REPEATS)]
    done = subprocess.run(run, cwd=tree, capture_output=True, text=True, check=True, env=env)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    """Measure and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, help="another camcad checkout to compare with")
    args = parser.parse_args()
    other = args.against
    samples = sorted(p.name for p in (ROOT / "samples").glob("*.toml"))
    if other is not None:
        samples = [s for s in samples if (other / "samples" / s).exists()]
    header = "| sample | now: first / median wall, CPU [ms] | size [kB]"
    header += " | before: first / median wall, CPU [ms] | size [kB] | ratio (CPU) |" if other else " |"
    lines = [header, "|---|" + "---:|" * (5 if other else 2)]
    ratios = []
    for name in samples:
        now = time_report(ROOT, ROOT / "samples" / name)
        row = f"| {Path(name).stem} | {now['first'] * 1e3:.0f} / {now['median'] * 1e3:.0f}"
        row += f", {now['cpu'] * 1e3:.0f}"
        row += f" | {now['bytes'] / 1e3:.0f}"
        if other is not None:
            then = time_report(other, other / "samples" / name)
            ratio = now["cpu"] / then["cpu"]
            ratios.append(ratio)
            row += f" | {then['first'] * 1e3:.0f} / {then['median'] * 1e3:.0f}, {then['cpu'] * 1e3:.0f}"
            row += f" | {then['bytes'] / 1e3:.0f} | {ratio:.2f}×"
        lines.append(row + " |")
    if ratios:
        lines.append(f"\nmedian ratio {statistics.median(ratios):.2f}×, worst {max(ratios):.2f}×")
    print("\n".join(lines))


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("report"):  # the printed tables become its section of benchmarks/README.md
        main()
