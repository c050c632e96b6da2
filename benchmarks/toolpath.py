"""Toolpath stage before/after: planning time, blocks and measured deviations, G-code compared.

Run ``python benchmarks/toolpath.py --out DIR`` to plan every shipped sample
(``samples/*.toml``, or ``--samples DIR``), write each program as
``DIR/<sample>.ngc`` and the figures as ``DIR/toolpath.json``:

- ``plan_ms``: median wall time of ``plan_toolpath`` over ``--repeats`` runs [ms];
- ``plan_cpu_ms``: the least CPU time of those runs [ms] (steadier than wall time on a
  shared machine: other processes' load does not count);
- ``contour_blocks``: blocks of one finishing contour (leads excluded);
- ``rough_blocks``: blocks of one roughing contour (leads excluded);
- ``program_blocks``: blocks of the whole program;
- ``finish_dev``: the planner's measured two-way deviation of the finishing contour [mm];
- ``finish_hausdorff``, ``rough_hausdorff``: the two-way distance of the
  written finishing and (last) roughing contour to their exact offset curves
  ``cam.offset_curve(φ, r)`` and ``cam.offset_curve(φ, r + stock)``, measured from the
  moves alone by :mod:`camcad.toolpath.verify` [mm];
- ``min_clearance``: the smallest clearance of the tool from the exact profile [mm].

``--compare OTHER`` then prints, per sample, whether the two programs are
byte-identical (whole, and from the finishing pass on), the block counts and
deviations side by side, and the planning CPU time ratio now / other. To
compare against another checkout (e.g. ``git worktree add /tmp/base HEAD``),
run this script with ``PYTHONPATH=/tmp/base --root /tmp/base`` for it, and
the same ``--samples`` folder in both runs.
"""

from __future__ import annotations

import argparse
import importlib
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

_FINISH = "profile finishing pass"  # the comment that opens the finishing pass


def _args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="folder for <sample>.ngc and toolpath.json")
    parser.add_argument("--samples", type=Path, help="folder of design files (default: the root's samples/)")
    parser.add_argument("--root", type=Path, help="checkout whose camcad is planned (default: this one)")
    parser.add_argument("--repeats", type=int, default=3, help="plans per sample for the median time")
    parser.add_argument("--compare", type=Path, help="an --out folder of another run: print the comparison")
    return parser.parse_args()


def measure(root: Path, samples: Path, out: Path, repeats: int) -> dict[str, dict[str, float]]:
    """Plan every sample, write its program, return the figures per sample."""
    sys.path.insert(0, str(root))
    design_mod = importlib.import_module("camcad.design")
    cam_mod = importlib.import_module("camcad.geometry.cam")
    toolpath = importlib.import_module("camcad.toolpath")
    writer = importlib.import_module("camcad.export.gcode")
    verify = importlib.import_module("camcad.toolpath.verify")
    out.mkdir(parents=True, exist_ok=True)
    figures: dict[str, dict[str, float]] = {}
    for path in sorted(samples.glob("*.toml")):
        design = design_mod.load_design(path)
        cam = cam_mod.Cam.from_design(design)
        kw = {"name": design.cam.name, "thickness": design.cam.thickness, "bore": design.cam.bore}
        times, cpu = [], []
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            tp = toolpath.plan_toolpath(cam, design.gcode, **kw)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
        text = writer.render_gcode(tp)
        (out / f"{path.stem}.ngc").write_text(text)
        check = toolpath.check_toolpath(
            tp.moves, cam, design.gcode, thickness=design.cam.thickness, bore=design.cam.bore
        )
        runs = [r for r in verify._runs(tp.moves) if any(m.kind.is_arc for m in r)]
        rough = runs[-2] if len(runs) >= 2 and tp.rough_offset != tp.tool_radius else runs[-1]
        # the verifier's own measure of a finishing contour, applied to the last roughing pass
        rough_h, _, _ = verify._measure_finish(rough, verify._Projector(cam, tp.rough_offset))
        planar = [m for m in rough if verify._planar(m)]
        figures[path.stem] = {
            "plan_ms": 1000.0 * statistics.median(times),
            "plan_cpu_ms": 1000.0 * min(cpu),
            "contour_blocks": tp.contour_blocks,
            "rough_blocks": len(planar) - 2,
            "program_blocks": writer.count_blocks(text),
            "finish_dev": tp.max_deviation,
            "finish_hausdorff": check.hausdorff,
            "rough_hausdorff": rough_h,
            "min_clearance": check.min_clearance,
            "tolerance": design.gcode.tolerance,
            "problems": len(check.problems),
        }
        print(path.stem, {k: round(v, 5) for k, v in figures[path.stem].items()}, flush=True)
    (out / "toolpath.json").write_text(json.dumps(figures, indent=2, sort_keys=True) + "\n")
    return figures


def compare(now_dir: Path, base_dir: Path) -> str:
    """Markdown table: programs identical?, blocks and deviations now vs base, time ratio."""
    now = json.loads((now_dir / "toolpath.json").read_text())
    base = json.loads((base_dir / "toolpath.json").read_text())
    lines = [
        "| sample | cam.ngc | finishing pass on | finish blocks | rough blocks | program blocks "
        "| finish Hausdorff [µm] | rough Hausdorff [µm] | plan CPU [ms] | ratio |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name in sorted(set(now) & set(base)):
        a, b = now[name], base[name]
        texts = [(d / f"{name}.ngc").read_text() for d in (now_dir, base_dir)]
        same = texts[0] == texts[1]
        finish = [t[t.index(_FINISH) :] for t in texts]  # the finishing pass and what follows it

        def pair(key: str, scale: float = 1.0, fmt: str = "{:.0f}", row_a: Any = a, row_b: Any = b) -> str:
            return f"{fmt.format(row_b[key] * scale)} → {fmt.format(row_a[key] * scale)}"

        lines.append(
            f"| {name} | {'identical' if same else 'differs'} "
            f"| {'identical' if finish[0] == finish[1] else 'differs'} | {pair('contour_blocks')} "
            f"| {pair('rough_blocks')} | {pair('program_blocks')} "
            f"| {pair('finish_hausdorff', 1e3, '{:.2f}')} "
            f"| {pair('rough_hausdorff', 1e3, '{:.2f}')} | {pair('plan_cpu_ms')} "
            f"| {a['plan_cpu_ms'] / b['plan_cpu_ms']:.2f}× |"
        )
    return "\n".join(lines)


def main() -> None:
    """Measure (and compare) as the command line asks."""
    args = _args()
    root = (args.root or Path(__file__).resolve().parents[1]).resolve()
    measure(root, args.samples or root / "samples", args.out, args.repeats)
    if args.compare:
        print(compare(args.out, args.compare))


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("toolpath", fence=True):  # the printed tables become its section of benchmarks/README.md
        main()
