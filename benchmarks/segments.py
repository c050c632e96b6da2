"""How the fit and the toolpath scale with the number of motion segments (issue 18).

Run ``python benchmarks/segments.py``. The 4-segment program is dwell 30°,
4-5-6-7 rise of 30 mm over 150°, dwell 60°, 4-5-6-7 return over 120° (base
radius 40 mm, roller 20 mm, tool 10 mm, like ``samples/quintero_poly4567``).
The n-segment programs split the rise and the return into (n − 2)/2
``polynomial`` pieces each of equal lift, ending where the 4-5-6-7 law
reaches that lift, with velocity and acceleration matched at every blend
point (the default), so the cam has nearly the same shape and n − 1 joints.
Prints the fit and toolpath stage times (best of ``--repeat`` in one process,
after a warm-up build that loads the libraries) and their ratio to the
4-segment program.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from typing import Any

from camcad.design.schema import parse_design
from camcad.pipeline import analyse

BASE: dict[str, Any] = {
    "cam": {"name": "segments", "base_radius": 40.0, "rotation": "ccw", "speed_rpm": 60.0, "thickness": 12.0,
            "bore": 20.0, "max_pressure_angle": 35.0},
    "follower": {"type": "translating-roller", "roller_radius": 20.0},
    "fit": {"tolerance": 0.001},
    "gcode": {"tool_diameter": 10.0, "step_down": 3.0, "stock_to_leave": 0.3},
}  # fmt: skip
RISE, RETURN, LIFT = 150.0, 120.0, 30.0


def poly4567(x: float) -> float:
    """The 4-5-6-7 polynomial rise, s/h at x = φ/β (Norton 2009, eq. 8.24b)."""
    return x**4 * (35.0 - 84.0 * x + 70.0 * x**2 - 20.0 * x**3)


def where(fraction: float) -> float:
    """x in [0, 1] where the 4-5-6-7 rise reaches ``fraction`` of its lift (bisection; it is monotonic)."""
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if poly4567(mid) < fraction else (lo, mid)
    return 0.5 * (lo + hi)


def split(kind: str, span: float, pieces: int) -> list[dict[str, Any]]:
    """A 4-5-6-7 rise (or return) of span [deg] as ``pieces`` linked polynomials, or one law."""
    if pieces == 1:
        return [{"kind": kind, "angle": span, "lift": LIFT, "law": "poly-4567"}]
    marks = [0.0, *(span * where(i / pieces) for i in range(1, pieces)), span]
    return [
        {"kind": kind, "angle": hi - lo, "lift": LIFT / pieces, "law": "polynomial"}
        for lo, hi in itertools.pairwise(marks)
    ]


def design(segments: int) -> Any:
    pieces = (segments - 2) // 2
    motion = [
        {"kind": "dwell", "angle": 30.0},
        *split("rise", RISE, pieces),
        {"kind": "dwell", "angle": 60.0},
        *split("return", RETURN, pieces),
    ]
    return parse_design({**BASE, "motion": motion}, source=f"{segments} segments")


def stage_seconds(segments: int, repeat: int) -> dict[str, float]:
    """Least fit and toolpath stage times [s] of ``repeat`` analyses."""
    best: dict[str, float] = {}
    d = design(segments)
    for _ in range(repeat):
        times: dict[str, float] = {}
        analyse(d, progress=times.__setitem__)
        for name in ("fit", "toolpath"):
            best[name] = min(best.get(name, math.inf), times[name])
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--segments", type=int, nargs="*", default=[4, 16, 32, 64, 128])
    args = parser.parse_args()
    analyse(design(4))  # warm-up: loads what the stages import on first use
    rows = []
    for n in args.segments:
        start = time.perf_counter()
        t = stage_seconds(n, args.repeat)
        rows.append((n, t["fit"], t["toolpath"], time.perf_counter() - start))
    base = rows[0][1] + rows[0][2]
    print("| segments | fit [ms] | toolpath [ms] | fit + toolpath [ms] | × the first |")
    print("|---:|---:|---:|---:|---:|")
    for n, fit, path, _ in rows:
        total = fit + path
        print(f"| {n} | {1000 * fit:.0f} | {1000 * path:.0f} | {1000 * total:.0f} | {total / base:.2f} |")


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("segments"):  # the printed tables become its section of benchmarks/README.md
        main()
