"""End-to-end build time per stage for every shipped sample, with ratios against a baseline.

Run ``python benchmarks/pipeline.py``; it prints a Markdown table of the
median of a few builds per sample (milliseconds per stage, written into a
temporary folder), the wall time of the whole ``camcad build`` and
``camcad check`` commands per sample, the import time of ``camcad.pipeline``
and of everything a build imports (lazily loaded modules included), and the
peak memory (RSS) of one build, each in a fresh process.

- ``--save FILE`` stores the figures as JSON;
- ``--baseline FILE`` adds the ratio now / baseline to every cell, so a
  reader sees the speed-up rather than absolute times that move 2× with the
  machine's load (take both runs on the same machine, one after the other);
- ``--against DIR`` measures another checkout (e.g. ``git worktree add
  /tmp/base HEAD``) in the same run, interleaved with this one sample by
  sample, and prints the ratios against it (``--save-against FILE`` stores
  its figures); this is the fairest comparison on a loaded machine;
- ``--samples DIR`` takes the design files from DIR (default: ``samples/``);
  use the same folder for both checkouts.

Every figure is measured in a subprocess running the checkout's own
``camcad`` (``PYTHONPATH`` and the working directory set to it), with its
bytecode compiled first and ``PYTHONDONTWRITEBYTECODE`` unset, as after a
``pip install`` (which compiles it): otherwise every process would compile
camcad's ~130 modules again (0.1–0.2 s), a cost no installed copy pays.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]

STAGES = ("geometry", "dynamics", "fit", "toolpath", "tables", "dxf", "mesh", "step", "gcode", "report")
COMMANDS = ("build_cmd", "check_cmd")
REPEATS = 3
IMPORT_REPEATS = 5
SAMPLE = "quintero_vap_b01"  # the sample of the import and memory figures

_WORKER = """
import inspect, json, sys, tempfile, time
from pathlib import Path
from camcad.design import load_design
from camcad.pipeline import build
design = load_design(Path(sys.argv[1]))
serial = {"parallel": False} if "parallel" in inspect.signature(build).parameters else {}
runs, totals, cpu_runs, cpu_totals = [], [], [], []
for _ in range(int(sys.argv[2])):
    stages, cpu, mark = {}, {}, [time.process_time()]

    def progress(name, seconds):
        stages[name] = seconds
        now = time.process_time()
        cpu[name], mark[0] = now - mark[0], now

    with tempfile.TemporaryDirectory() as tmp:
        start, start_cpu = time.perf_counter(), time.process_time()
        build(design, Path(tmp) / "out", progress=progress, **serial)
        totals.append(time.perf_counter() - start)
        cpu_totals.append(time.process_time() - start_cpu)
    runs.append(stages)
    cpu_runs.append(cpu)
print(json.dumps({"runs": runs, "totals": totals, "cpu_runs": cpu_runs, "cpu_totals": cpu_totals}))
"""


def _run(root: Path, args: list[str], *, ok: tuple[int, ...] = (0,)) -> subprocess.CompletedProcess[str]:
    """Run ``python ARGS`` with ``root``'s camcad; fail unless the exit code is in ``ok``."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(root)
    done = subprocess.run(
        [sys.executable, *args], cwd=root, env=env, capture_output=True, text=True, check=False
    )
    if done.returncode not in ok:
        raise RuntimeError(f"{args} in {root} exited {done.returncode}:\n{done.stderr[-2000:]}")
    return done


def _wall(root: Path, args: list[str], *, ok: tuple[int, ...] = (0,)) -> float:
    start = time.perf_counter()
    _run(root, args, ok=ok)
    return time.perf_counter() - start


def _cpu(root: Path, args: list[str], *, ok: tuple[int, ...] = (0,)) -> tuple[float, float]:
    """Wall time and CPU time (user + system of the child) [s] of ``python ARGS``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = _wall(root, args, ok=ok)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def stage_times(root: Path, design: Path) -> tuple[dict[str, float], dict[str, float]]:
    """Median stage times and total of REPEATS builds in one process [ms]: wall, and CPU (the least).

    The first build also loads the libraries the stages import on first use.
    The builds run serially (``parallel=False`` where ``build`` has it: the
    report is not drawn in a forked child), so each stage's time is its own;
    the ``camcad build`` command (:func:`command_times`) runs as a user runs it.
    """
    out = json.loads(_run(root, ["-c", _WORKER, str(design), str(REPEATS)]).stdout.splitlines()[-1])
    wall = {s: 1000.0 * statistics.median(r.get(s, 0.0) for r in out["runs"]) for s in STAGES}
    cpu = {s: 1000.0 * min(r.get(s, 0.0) for r in out["cpu_runs"]) for s in STAGES}
    wall["total"] = 1000.0 * statistics.median(out["totals"])
    cpu["total"] = 1000.0 * min(out["cpu_totals"])
    return wall, cpu


def command_times(root: Path, design: Path) -> tuple[dict[str, float], dict[str, float]]:
    """Wall (median) and CPU (least) time [ms] of the whole ``camcad build`` and ``camcad check`` commands."""
    builds, checks = [], []
    for _ in range(REPEATS):
        with tempfile.TemporaryDirectory() as tmp:
            builds.append(_cpu(root, ["-m", "camcad", "build", str(design), "-o", f"{tmp}/out", "-q"]))
        checks.append(_cpu(root, ["-m", "camcad", "check", str(design)], ok=(0, 3)))
    wall = {
        "build_cmd": statistics.median(b[0] for b in builds),
        "check_cmd": statistics.median(c[0] for c in checks),
    }
    cpu = {"build_cmd": min(b[1] for b in builds), "check_cmd": min(c[1] for c in checks)}
    return {k: 1000.0 * v for k, v in wall.items()}, {k: 1000.0 * v for k, v in cpu.items()}


def import_ms(root: Path) -> float:
    """Median wall time [ms] of ``import camcad.pipeline`` in a fresh interpreter (minus a bare start)."""
    bare = statistics.median(_wall(root, ["-c", "pass"]) for _ in range(IMPORT_REPEATS))
    full = statistics.median(_wall(root, ["-c", "import camcad.pipeline"]) for _ in range(IMPORT_REPEATS))
    return 1000.0 * max(full - bare, 0.0)


def build_import_ms(root: Path, design: Path) -> float:
    """Median time [ms] a whole ``camcad build`` spends importing (``-X importtime``, lazy ones included)."""
    totals = []
    for _ in range(REPEATS):
        with tempfile.TemporaryDirectory() as tmp:
            err = _run(
                root, ["-X", "importtime", "-m", "camcad", "build", str(design), "-o", f"{tmp}/out", "-q"]
            ).stderr
        # top-level entries (one space before the name) hold their children's time
        top = [ln.split("|") for ln in err.splitlines() if ln.startswith("import time:") and "|" in ln]
        totals.append(
            sum(int(p[1]) for p in top if p[1].strip().isdigit() and p[2][:2] == " " + p[2].strip()[:1])
        )
    return statistics.median(totals) / 1000.0


def peak_rss_mb(root: Path, design: Path) -> float:
    """Peak resident memory [MB] of one ``camcad build`` in a fresh process (or of a child it forked)."""
    code = (
        "import resource, runpy, sys; sys.argv = ['camcad', 'build', sys.argv[1], '-o', sys.argv[2], '-q']\n"
        "try:\n    runpy.run_module('camcad', run_name='__main__')\nexcept SystemExit:\n    pass\n"
        "print(max(resource.getrusage(who).ru_maxrss"
        " for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)))"
    )
    with tempfile.TemporaryDirectory() as tmp:
        out = _run(root, ["-c", code, str(design), f"{tmp}/out"]).stdout.splitlines()[-1]
    return float(out) / 1024.0  # ru_maxrss is in KiB on Linux


def measure(roots: list[Path], samples: Path) -> list[dict[str, Any]]:
    """Every figure for each checkout, measured interleaved (sample by sample, checkout by checkout)."""
    figures: list[dict[str, Any]] = [{"samples": {}, "cpu": {}} for _ in roots]
    for root in roots:  # as installed: the bytecode is there
        _run(root, ["-m", "compileall", "-q", str(root / "camcad")])
    for path in sorted(samples.glob("*.toml")):
        for root, fig in zip(roots, figures, strict=True):
            try:
                (wall, cpu), (cmd_wall, cmd_cpu) = stage_times(root, path), command_times(root, path)
            except RuntimeError as err:  # a sample the other checkout cannot build
                print(f"skipped {path.stem} in {root}: {str(err).splitlines()[0]}", file=sys.stderr)
                continue
            row = {**wall, **cmd_wall}
            fig["samples"][path.stem] = row
            fig["cpu"][path.stem] = {**cpu, **cmd_cpu}
            print(f"{root.name or root} {path.stem}: {row['total']:.0f} ms", file=sys.stderr, flush=True)
    design = samples / f"{SAMPLE}.toml"
    for _ in range(2):  # twice, alternating, and the smaller of the two medians
        for root, fig in zip(roots, figures, strict=True):
            for key, value in (
                ("import_ms", import_ms(root)),
                ("build_import_ms", build_import_ms(root, design)),
                ("peak_rss_mb", peak_rss_mb(root, design)),
            ):
                fig[key] = min(fig.get(key, value), value)
    return figures


def cell(now: float, base: float | None) -> str:
    """``123`` or ``123 (0.45×)`` against a baseline."""
    if base is None or base <= 0.0:
        return f"{now:.0f}"
    return f"{now:.0f} ({now / base:.2f}×)"


def report(now: dict[str, Any], base: dict[str, Any] | None, *, key: str = "samples") -> str:
    """The Markdown table (wall times, or ``key="cpu"`` CPU times) and the import and memory lines."""
    columns = (*STAGES, "total", *COMMANDS)
    lines = ["| sample | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    base_samples = base.get(key, {}) if base else {}
    for name, row in now.get(key, {}).items():
        old = base_samples.get(name, {})
        lines.append(f"| {name} | " + " | ".join(cell(row.get(c, 0.0), old.get(c)) for c in columns) + " |")
    lines.append("")
    what = f"median of {REPEATS} (wall)" if key == "samples" else f"least of {REPEATS} (CPU, user + system)"
    lines.append(
        f"milliseconds, {what}; stages and total: builds in one process (total includes "
        "loading libraries on first use); build_cmd, check_cmd: the whole command in a fresh process"
    )
    if key != "samples":
        return "\n".join(lines)
    for key, label, unit in (
        ("import_ms", "import camcad.pipeline", "ms"),
        ("build_import_ms", f"imports of one whole build ({SAMPLE})", "ms"),
        ("peak_rss_mb", f"peak RSS of one build ({SAMPLE})", "MB"),
    ):
        value = now.get(key)
        if not isinstance(value, float):
            continue
        old_value = base.get(key) if base else None
        known = isinstance(old_value, float) and old_value > 0.0
        ratio = f" ({value / old_value:.2f}× the baseline)" if known else ""
        lines.append(f"{label}: {value:.0f} {unit}{ratio}")
    return "\n".join(lines)


def main() -> None:
    """Measure, print, and optionally save the figures or compare them with a baseline."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--save", type=Path, help="write the figures as JSON")
    parser.add_argument("--baseline", type=Path, help="a JSON written by --save: print ratios against it")
    parser.add_argument("--against", type=Path, help="another checkout to measure interleaved and compare")
    parser.add_argument("--save-against", type=Path, help="write the other checkout's figures as JSON")
    parser.add_argument("--samples", type=Path, default=ROOT / "samples", help="folder of design files")
    args = parser.parse_args()
    roots = [ROOT] + ([args.against.resolve()] if args.against else [])
    figures = measure(roots, args.samples.resolve())
    now = figures[0]
    base = figures[1] if args.against else (json.loads(args.baseline.read_text()) if args.baseline else None)
    print(report(now, base))
    print()
    print(report(now, base, key="cpu"))
    if args.save:
        args.save.write_text(json.dumps(now, indent=2, sort_keys=True) + "\n")
    if args.save_against and args.against:
        args.save_against.write_text(json.dumps(figures[1], indent=2, sort_keys=True) + "\n")


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("pipeline"):  # the printed tables become its section of benchmarks/README.md
        main()
