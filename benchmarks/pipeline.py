"""End-to-end build time per stage for every shipped sample, with ratios against a baseline.

Run ``python benchmarks/pipeline.py``; it prints a Markdown table of the
median of a few builds (milliseconds per stage, written into a temporary
folder), the import time of what a build needs and the peak memory (RSS) of
one build, each in a fresh process. ``--save FILE`` stores the figures as
JSON; ``--baseline FILE`` adds the ratio now / baseline to every cell, so a
reader sees the speed-up rather than absolute times that move 2× with the
machine's load (take both runs on the same machine, one after the other).
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
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
IMPORT_REPEATS = 5
SAMPLE = ROOT / "samples" / "quintero_vap_b01.toml"


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


def import_time() -> float:
    """Median wall time [s] of ``import camcad.pipeline`` in a fresh interpreter (minus a bare start)."""

    def run(code: str) -> float:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)
        return time.perf_counter() - start

    bare = statistics.median(run("pass") for _ in range(IMPORT_REPEATS))
    full = statistics.median(run("import camcad.pipeline") for _ in range(IMPORT_REPEATS))
    return max(full - bare, 0.0)


def peak_rss_mb() -> float:
    """Peak resident memory [MB] of one ``camcad build`` of the VAP sample, in a fresh process."""
    with tempfile.TemporaryDirectory() as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        subprocess.run(
            [sys.executable, "-m", "camcad", "build", str(SAMPLE), "-o", str(Path(tmp) / "out"), "-q"],
            check=True,
            cwd=ROOT,
        )
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(peak, before) / 1024.0  # ru_maxrss is in KiB on Linux


def measure() -> dict[str, object]:
    """Every figure of the run: per sample the stage medians and total [ms], import [ms], RSS [MB]."""
    samples = {}
    for path in sorted((ROOT / "samples").glob("*.toml")):
        stages, total = time_sample(path)
        samples[path.stem] = {**{s: stages[s] * 1000 for s in STAGES}, "total": total * 1000}
    return {"samples": samples, "import_ms": import_time() * 1000, "peak_rss_mb": peak_rss_mb()}


def cell(now: float, base: float | None) -> str:
    """``123`` or ``123 (0.45×)`` against a baseline."""
    if base is None or base <= 0.0:
        return f"{now:.0f}"
    return f"{now:.0f} ({now / base:.2f}×)"


def report(now: dict[str, object], base: dict[str, object] | None) -> str:
    """The Markdown table and the import and memory lines."""
    columns = (*STAGES, "total")
    lines = ["| sample | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    samples = now["samples"]
    assert isinstance(samples, dict)
    base_samples = base["samples"] if base else {}
    assert isinstance(base_samples, dict)
    for name, row in samples.items():
        old = base_samples.get(name, {})
        lines.append(f"| {name} | " + " | ".join(cell(row[c], old.get(c)) for c in columns) + " |")
    lines.append("")
    lines.append(f"milliseconds, median of {REPEATS} builds; total includes loading libraries on first use")
    for key, label, unit in (
        ("import_ms", "import camcad.pipeline", "ms"),
        ("peak_rss_mb", "peak RSS of one build", "MB"),
    ):
        value = now[key]
        assert isinstance(value, float)
        old_value = base.get(key) if base else None
        ratio = (
            f" ({value / old_value:.2f}× the baseline)" if isinstance(old_value, float) and old_value else ""
        )
        lines.append(f"{label}: {value:.0f} {unit}{ratio}")
    return "\n".join(lines)


def main() -> None:
    """Measure, print, and optionally save the figures or compare them with a baseline."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--save", type=Path, help="write the figures as JSON")
    parser.add_argument("--baseline", type=Path, help="a JSON written by --save: print ratios against it")
    args = parser.parse_args()
    base = json.loads(args.baseline.read_text()) if args.baseline else None
    now = measure()
    print(report(now, base))
    if args.save:
        args.save.write_text(json.dumps(now, indent=2, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
