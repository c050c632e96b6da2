"""Benchmark of the rotary program: blocks per revolution against equal angle steps, and plan time.

Run ``python benchmarks/rotary.py [tolerance_mm]`` (default 0.005); prints a
Markdown table per shipped plate sample (``samples/*.toml``, each with its
own tool, as ``machine = "rotary"``):

- blocks: G93 blocks per revolution as planned (each as long as the written
  X–θ spiral stays within tolerance of the exact offset curve);
- uniform: the fewest equal steps of the cam's turn that meet the same
  tolerance, measured the same way (radial gap of the written words on a
  0.005° grid of the exact curve), as a post-processor writing fixed angle
  increments needs;
- the certified deviation and the time to plan (median of 3).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.spec import CamStyle
from camcad.toolpath.rotary import ANGLE_DECIMALS, X_DECIMALS, plan_rotary
from camcad.toolpath.spec import Machine

ROOT = Path(__file__).resolve().parents[1]


def uniform_blocks(cam: Cam, radius: float, tolerance: float) -> int:
    """Fewest equal turn steps whose written X–θ spiral stays within ``tolerance`` (radial gap)."""
    phi = np.linspace(0.0, 2.0 * math.pi, 72_001)
    q = cam.offset_curve(phi, radius).point
    r = np.hypot(q[:, 0], q[:, 1])
    turn = np.unwrap(-np.arctan2(q[:, 1], q[:, 0]))

    def fits(n: int) -> bool:
        targets = turn[0] + (turn[-1] - turn[0]) * np.arange(n + 1) / n
        idx = np.searchsorted(turn, targets) if turn[-1] > turn[0] else np.searchsorted(-turn, -targets)
        idx = np.clip(idx, 0, phi.size - 1)
        x = np.round(r[idx], X_DECIMALS)
        t = np.radians(np.round(np.degrees(turn[idx]), ANGLE_DECIMALS))
        k = np.clip(np.searchsorted(idx, np.arange(phi.size), side="right") - 1, 0, n - 1)
        along = (turn - t[k]) / (t[k + 1] - t[k])
        return bool(np.max(np.abs(r - (x[k] + along * (x[k + 1] - x[k])))) <= tolerance)

    lo, hi = 4, 8
    while not fits(hi):
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return hi


def main(tolerance: float = 0.005) -> None:
    print("| sample | tool Ø | blocks / rev | uniform / rev | uniform / blocks | deviation [mm] | plan [s] |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for path in sorted((ROOT / "samples").glob("*.toml")):
        design = load_design(path)
        if design.cam.style is not CamStyle.PLATE:
            continue
        spec = replace(design.gcode, machine=Machine.ROTARY, tolerance=tolerance)
        cam = Cam.from_design(design)
        times = []
        for _ in range(3):
            start = time.perf_counter()
            tp = plan_rotary(cam, spec, name=design.cam.name, thickness=design.cam.thickness)
            times.append(time.perf_counter() - start)
        uniform = uniform_blocks(cam, spec.tool_radius, tolerance)
        print(
            f"| {path.stem} | {spec.tool_diameter:g} | {tp.blocks_per_revolution} | {uniform} | "
            f"{uniform / tp.blocks_per_revolution:.1f} | {tp.max_deviation:.5f} | {sorted(times)[1]:.2f} |"
        )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("rotary"):  # the printed tables become its section of benchmarks/README.md
        main(float(sys.argv[1]) if len(sys.argv) > 1 else 0.005)
