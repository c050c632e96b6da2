"""Cost of issue 16's motion design: blend-point solves and point-table smoothing.

Run ``python benchmarks/motion_blend.py``; prints the best of five wall-clock
times per case and writes them to its section of benchmarks/README.md.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec
from camcad.motion.table import smooth_table

RAD = math.radians


def best(fn: Callable[[], object], repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def web_cutter() -> list[SegmentSpec]:
    return [
        SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
        SegmentSpec(kind=SegmentKind.RISE, span=RAD(60), lift=10, law=make_law("polynomial", degree=7)),
        SegmentSpec(kind=SegmentKind.RISE, span=RAD(60), lift=33.3, law=make_law("constant-velocity")),
        SegmentSpec(kind=SegmentKind.RETURN, span=RAD(120), lift=43.3, law=make_law("polynomial", degree=7)),
        SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
    ]


def ring(count: int) -> list[SegmentSpec]:
    law = make_law("polynomial")
    out = []
    for _ in range(count // 2):
        out.append(SegmentSpec(kind=SegmentKind.RISE, span=RAD(360 / count), lift=1.0, law=law))
        out.append(SegmentSpec(kind=SegmentKind.RETURN, span=RAD(360 / count), lift=1.0, law=law))
    return out


def table(points: int) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(0, 2 * math.pi, points, endpoint=False)
    truth = MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=RAD(120), lift=10, law=make_law("poly-4567")),
            SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
            SegmentSpec(kind=SegmentKind.RETURN, span=RAD(120), lift=10, law=make_law("poly-4567")),
            SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
        ]
    )
    return phi, truth.evaluate(phi).s + np.random.default_rng(0).normal(0, 0.005, points)


def main() -> None:
    cases: list[tuple[str, Callable[[], object]]] = [
        ("web cutter (2 septics, 1 KKT each)", lambda: MotionProgram.from_segments(web_cutter())),
        ("ring of 60 linked quintics", lambda: MotionProgram.from_segments(ring(60))),
        ("ring of 360 linked quintics", lambda: MotionProgram.from_segments(ring(360))),
    ]
    for n in (360, 3600):
        phi, s = table(n)
        cases.append((f"table of {n} points", lambda phi=phi, s=s: smooth_table(phi, s, noise=0.005)))
    print("| case | best time [ms] |")
    print("| --- | ---: |")
    for name, fn in cases:
        repeat = 1 if "360 linked" in name else 5
        print(f"| {name} | {1000 * best(fn, repeat):.1f} |")


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("motion-blend"):  # the printed tables become its section of benchmarks/README.md
        main()
