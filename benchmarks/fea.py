"""The finite-element check on the shipped plate samples: mesh size, time, and peak-stress convergence.

Run ``python benchmarks/fea.py`` (``--quick`` skips the refined reference).
For every shipped plate cam with a bore it prints a Markdown row: the load
cases, the default mesh (P2 nodes, triangles), the time of the whole check
(best of ``REPEATS``, wall and CPU, split into the load cases, the mesh and
the rest: assembly, factorisation, solves and stress recovery), the peak von
Mises stress of the default mesh and of a refined one (3× the elements
across the contact, a third of the growth rate, half the largest element),
and their difference in per cent.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad.design import load_design  # noqa: E402
from camcad.fea import FeaSpec, analyse_fea, load_cases, mesh_plate  # noqa: E402
from camcad.geometry.spec import CamStyle  # noqa: E402
from camcad.pipeline import analyse  # noqa: E402

REPEATS = 3


def _timed(fn):  # type: ignore[no-untyped-def]
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="skip the refined reference mesh")
    args = parser.parse_args()
    print(
        "| sample | cases | nodes | triangles | loads [s] | mesh [s] | solve [s] | total wall / CPU [s] "
        "| peak von Mises [MPa] | refined [MPa] (nodes) | difference |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for path in sorted((ROOT / "samples").glob("*.toml")):
        design = load_design(path)
        if design.cam.style is not CamStyle.PLATE or design.cam.bore <= 0.0:
            continue
        spec = design.fea or FeaSpec()
        analysis = analyse(design, fit=False, toolpath=False)
        setup, plate = design.dynamics_setup(), design.plate()
        best = None
        cam, dynamics = analysis.cam, analysis.dynamics
        for _ in range(REPEATS):
            (cases, _), t_loads, _ = _timed(lambda c=cam, d=dynamics, u=setup, f=spec: load_cases(c, d, u, f))
            _, t_mesh, _ = _timed(lambda c=cam, p=plate, k=cases, f=spec: mesh_plate(c, p, k, f))
            result, wall, cpu = _timed(
                lambda c=cam, p=plate, u=setup, d=dynamics, f=spec: analyse_fea(
                    c, p, setup=u, dynamics=d, spec=f
                )
            )
            if best is None or wall < best[1]:
                best = (result, wall, cpu, t_loads, t_mesh)
        assert best is not None
        result, wall, cpu, t_loads, t_mesh = best
        peak = result.peak
        assert peak is not None
        refined_text, diff_text = "—", "—"
        if not args.quick:
            outer = max(float(abs(result.nodes).max()), 1e-9)
            finer = dataclasses.replace(
                spec,
                contact_divisions=3 * spec.contact_divisions,
                growth=spec.growth / 3.0,
                mesh_size=0.5 * (spec.mesh_size or outer / 10.0),
            )
            ref = analyse_fea(analysis.cam, plate, setup=setup, dynamics=analysis.dynamics, spec=finer)
            assert ref.peak is not None
            refined_text = f"{ref.peak.peak.value:.2f} ({len(ref.nodes)})"
            diff_text = f"{100.0 * (peak.peak.value / ref.peak.peak.value - 1.0):+.2f} %"
        print(
            f"| {path.stem} | {len(result.cases)} | {len(result.nodes)} | {len(result.cells)} "
            f"| {t_loads:.2f} | {t_mesh:.2f} | {wall - t_loads - t_mesh:.2f} | {wall:.2f} / {cpu:.2f} "
            f"| {peak.peak.value:.2f} | {refined_text} | {diff_text} |",
            flush=True,
        )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("fea"):  # the printed tables become its section of benchmarks/README.md
        main()
