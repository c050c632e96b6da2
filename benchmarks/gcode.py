"""Benchmark of the G-code toolpath: biarc blocks against G1-only paths at the same tolerance.

Run ``python benchmarks/gcode.py [tolerance_mm] [sample ...]`` (default
0.005, every sample); prints a Markdown table per shipped sample
(``samples/*.toml``; named samples, e.g. ``linear_cam``, print their rows
only and leave ``benchmarks/README.md`` as it was). A linear cam is planned
as its bar (:func:`camcad.toolpath.bar.plan_bar`: the open edge, its dwells
cut as lines); barrel cams have their own benchmark (``barrel.py``) and are
left out; every other sample as a plate's outline:

- contour blocks: one finishing contour (leads excluded) written with biarcs,
  with greedy maximal G1 chords (the fewest an interpolating G1 path can
  have at this tolerance, found and measured by the same machinery) and
  with uniform φ-steps (what a spline-to-G1 post-processor typically
  writes: the coarsest uniform step whose chords stay in tolerance);
- program blocks: the whole program (all roughing passes, finishing, bore
  and leads), biarcs against greedy G1;
- the measured deviation of the written biarc contour and the time to plan
  (fit, round, measure) the whole program;
- the asymptotic fewest arcs of a tangent-continuous arc spline within the
  fit band ε (0.8 tol less the rounding allowance, the band the arcs are
  searched in), N ≈ ∫ (|κ'| / (72√3 ε))^{1/3} ds, and the finishing arc
  spline's arcs over it (κ' = dκ/ds of the exact offset curve by central
  differences of the exact curvature at φ ± 1e-5 rad, integrated on 200 000
  midpoints). Arcs are the spline's pieces before tab edges split them
  (``Toolpath.contour_arcs``); contour blocks count those splits too;
- the same with ``[gcode] fewest_arcs = true`` (the search's loop refitted
  with arcs dropped, :mod:`camcad.toolpath.arcs.refine`): its arcs, arcs / N,
  its measured deviation and its plan time (plan times: least of 3).

Every G1 path meets the same two-way tolerance as the biarcs (fit to 0.8 tol,
measured after rounding), so the ratios compare like with like.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from camcad.design import Design, load_design
from camcad.export.gcode import count_blocks, render_gcode
from camcad.geometry.cam import Cam
from camcad.geometry.families import family_of
from camcad.toolpath import Toolpath, plan_toolpath
from camcad.toolpath.arcs.biarc import chord_pieces, measure_deviation
from camcad.toolpath.bar import plan_bar
from camcad.toolpath.contour import offset_curve
from camcad.toolpath.plan import _fit_tolerance
from camcad.toolpath.spec import GcodeSpec

ROOT = Path(__file__).resolve().parents[1]


def uniform_chords(cam: Cam, radius: float, tol: float) -> int:
    """Fewest uniform φ-steps whose chords of cam.offset_curve(φ, radius) stay within ``tol`` [mm]."""
    curve = offset_curve(cam, radius)

    def fits(n: int) -> bool:
        phi = np.linspace(0.0, 2.0 * math.pi, n + 1)
        pt, d1, _ = curve(phi)
        t = d1 / np.linalg.norm(d1, axis=1)[:, None]
        pieces = chord_pieces(phi[:-1], phi[1:], pt[:-1], t[:-1], pt[1:], t[1:])
        return bool(measure_deviation(curve, pieces).max() <= tol)

    lo, hi = 8, 16
    while not fits(hi):
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return hi


def fewest_arcs(cam: Cam, radius: float, band: float, n: int = 200_000) -> float:
    """Fewest arcs N ≈ ∫ (|κ'| / (72√3 ε))^{1/3} ds of cam.offset_curve(φ, radius) for a band ε [mm]."""
    curve = offset_curve(cam, radius)

    def curvature(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        _, d1, d2 = curve(phi)
        speed = np.linalg.norm(d1, axis=1)
        return (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3, speed

    phi = (np.arange(n) + 0.5) * (2.0 * math.pi / n)
    h = 1e-5
    ahead, _ = curvature(phi + h)
    behind, _ = curvature(phi - h)
    _, speed = curvature(phi)
    rate = np.abs(ahead - behind) / (2.0 * h) / speed  # |dκ/ds|
    ds = speed * (2.0 * math.pi / n)
    return float(np.sum((rate / (72.0 * math.sqrt(3.0) * band)) ** (1.0 / 3.0) * ds))


Planner = Callable[..., Toolpath]


def least_of_3(plan: Planner, spec: GcodeSpec) -> tuple[Toolpath, float]:
    """The plan and its least wall time [s] of three runs (the machine's other load moves single runs)."""
    times = []
    for _ in range(3):
        start = time.perf_counter()
        out = plan(spec)
        times.append(time.perf_counter() - start)
    return out, min(times)


def planner(design: Design) -> tuple[Cam, Planner] | None:
    """The cam whose finishing path is measured and its planner ``plan(spec, arcs=True)``; None: a barrel.

    A linear cam's part is its bar (the cam with its stroke length, an open
    edge): it is planned as the bar; every other design as the plate of
    ``Cam.from_design`` cut along its outline.
    """
    cam = Cam.from_design(design)
    (part, *_) = family_of(design.cam.style).parts(cam, design.family_options())
    if part.barrel is not None:
        return None
    name, thickness = design.cam.name, design.cam.thickness
    if part.bar is not None:
        bar_cam, bar = part.cam, part.bar

        def plan_edge(spec: GcodeSpec, arcs: bool = True) -> Toolpath:
            return plan_bar(bar_cam, bar, spec, name=name, thickness=thickness, arcs=arcs)

        return bar_cam, plan_edge

    def plan_plate(spec: GcodeSpec, arcs: bool = True) -> Toolpath:
        return plan_toolpath(cam, spec, name=name, thickness=thickness, bore=design.cam.bore, arcs=arcs)

    return cam, plan_plate


def main(tolerance: float = 0.005, samples: Sequence[str] = ()) -> None:
    """Print the benchmark table for every shipped sample, or for the named ones."""
    rows = []
    for path in sorted((ROOT / "samples").glob("*.toml")):
        if samples and path.stem not in samples:
            continue
        design = load_design(path)
        spec = replace(design.gcode, tolerance=tolerance)
        found = planner(design)
        if found is None:
            continue
        cam, plan = found
        arcs, elapsed = least_of_3(plan, spec)
        lines = plan(spec, arcs=False)
        uniform = uniform_chords(cam, spec.tool_radius, 0.8 * tolerance)
        least = fewest_arcs(cam, spec.tool_radius, _fit_tolerance(tolerance))
        thin, thin_time = least_of_3(plan, replace(spec, fewest_arcs=True))
        prog_arcs = count_blocks(render_gcode(arcs))
        prog_lines = count_blocks(render_gcode(lines))
        rows.append(
            (
                path.stem,
                arcs.contour_blocks,
                lines.contour_blocks,
                uniform,
                lines.contour_blocks / arcs.contour_blocks,
                uniform / arcs.contour_blocks,
                prog_arcs,
                prog_lines,
                prog_lines / prog_arcs,
                arcs.max_deviation,
                elapsed,
                least,
                arcs.contour_arcs,
                arcs.contour_arcs / least,
                thin.contour_arcs,
                thin.contour_arcs / least,
                thin.max_deviation,
                thin_time,
            )
        )
    print(f"G-code blocks at tolerance {tolerance:g} mm (contour = one finishing pass, leads excluded)\n")
    print(
        "| sample | contour biarc | contour G1 greedy | contour G1 uniform | G1 greedy / biarc "
        "| G1 uniform / biarc | program biarc | program G1 greedy | program ratio "
        "| deviation [mm] | plan time [s] | fewest arcs N | arcs | arcs / N "
        "| fewest_arcs: arcs | arcs / N | deviation [mm] | plan time [s] |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]:.1f} | {r[5]:.1f} | {r[6]} | {r[7]} "
            f"| {r[8]:.1f} | {r[9]:.5f} | {r[10]:.2f} | {r[11]:.1f} | {r[12]} | {r[13]:.2f} "
            f"| {r[14]} | {r[15]:.2f} | {r[16]:.5f} | {r[17]:.2f} |"
        )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    tol = float(sys.argv[1]) if len(sys.argv) > 1 else 0.005
    if len(sys.argv) > 2:  # named samples: their rows only, not a section of the README
        main(tol, sys.argv[2:])
    else:
        with captured("gcode"):  # the printed tables become its section of benchmarks/README.md
            main(tol)
