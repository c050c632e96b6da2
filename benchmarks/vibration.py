"""Follower-train vibration (issue 34): one speed and a 200-speed map, against a plain solve_ivp.

Run ``python benchmarks/vibration.py``. A cycloidal rise-dwell-return-dwell
(10 mm, 100° rises) drives a single-mass train (0.5 kg, k_f = 200 N/mm,
ζ = 0.05, return spring 10 N/mm, 40 N). It prints, best of ``REPEATS``
(wall and process CPU): the periodic response at one speed
(:func:`train_response`, true extremes included), a 200-point speed map
(:func:`speed_map`, true extremes at every speed), and a plain ``solve_ivp`` (DOP853, rtol 1e-10) run from
rest over enough turns for the transient to decay below 1e-9 of the lift
(ζ·ω_n·t ≥ ln 1e9), at the same speed, with the ratio of the times and the
largest difference of the last turn's output from the periodic one.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from scipy.integrate import solve_ivp  # noqa: E402

from camcad.dynamics.vibration import Train, speed_map, train_response  # noqa: E402
from camcad.motion.laws import Cycloidal  # noqa: E402
from camcad.motion.program import MotionProgram  # noqa: E402
from camcad.motion.segments import SegmentKind, SegmentSpec  # noqa: E402

REPEATS = 3
RPM = 60.0 / (2.0 * math.pi)


def best(fn):
    wall, cpu, out = math.inf, math.inf, None
    for _ in range(REPEATS):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall, cpu = min(wall, time.perf_counter() - w0), min(cpu, time.process_time() - c0)
    return wall, cpu, out


def main() -> None:
    d = math.pi / 180.0
    program = MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=100 * d, lift=10.0, law=Cycloidal()),
            SegmentSpec(kind=SegmentKind.DWELL, span=80 * d),
            SegmentSpec(kind=SegmentKind.RETURN, span=100 * d, lift=10.0, law=Cycloidal()),
            SegmentSpec(kind=SegmentKind.DWELL, span=80 * d),
        ]
    )
    m, kf, zeta = 0.5e-3, 200.0, 0.05
    train = Train(
        mass=(m,),
        contact_rate=kf,
        contact_damping=2 * zeta * math.sqrt(kf * m),
        spring_rate=10.0,
        preload=40.0,
        weight=(0.5 * 9.80665,),
    )
    rpm = 600.0
    w1, c1, res = best(lambda: train_response(program, train, speed_rpm=rpm, spring_loaded=False))
    speeds = np.linspace(100.0, 3000.0, 200)
    w2, c2, _ = best(lambda: speed_map(program, train, speeds_rpm=speeds))

    omega = rpm / RPM
    a, bs, bv, f = train.state_space()
    wn = float(train.natural_frequencies()[0])
    period = 2 * math.pi / omega
    turns = math.ceil(math.log(1e9) / (zeta * wn * period)) + 1

    def rhs(t, y):
        mo = program.evaluate(np.array([omega * t]))
        return a @ y + bs * mo.s[0] + bv * mo.v[0] * omega + f

    def plain():
        t = (turns - 1) * period + res.phi / omega
        return solve_ivp(
            rhs, (0.0, turns * period), np.zeros(2), method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t
        )

    w3, c3, sol = best(plain)
    diff = float(np.max(np.abs(sol.y[0] - res.x)))
    print("| case | wall s | CPU s |")
    print("| --- | --- | --- |")
    print(f"| one speed ({rpm:g} rpm, {res.phi.size} angles) | {w1:.4f} | {c1:.4f} |")
    print(f"| speed map, 200 speeds | {w2:.4f} | {c2:.4f} |")
    print(f"| plain solve_ivp, {turns} turns, one speed | {w3:.4f} | {c3:.4f} |")
    print(f"\nratio solve_ivp / one speed: {w3 / w1:.1f}×; solve_ivp / map per speed: {w3 / (w2 / 200):.0f}×")
    print(f"largest difference of the settled solve_ivp turn: {diff:.2e} mm")


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("vibration"):  # the printed tables become its section of benchmarks/README.md
        main()
