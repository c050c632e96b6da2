"""Tolerance Monte Carlo throughput: made cams per CPU-second one at a time, batched, and by the quadratics.

Run ``python benchmarks/tolerance.py [--one 20] [--batch 500] [--million 1000000]``.
On ``samples/tolerance_roller.toml`` with its ``[tolerance]`` table and the
dynamics of ``samples/offset_roller.toml`` (so the contact stress is a real
figure), it times with CPU time (``time.process_time``, this process only):

- one at a time: :func:`camcad.inspect.tolerance.variant_figures` on a single made cam, ``--one`` times;
- batched exact: the same function on ``--batch`` made cams at once (what ``evaluation = "exact"`` runs);
- quadratic: fitting the stencil, evaluating ``--batch`` cams, and certifying (``evaluation = "quadratic"``);

then runs the whole command's study (:func:`camcad.explore.tolerance.tolerance_study`,
``evaluation = "quadratic"``, Parquet) on ``--million`` made cams and reports
its wall time, its CPU time and the peak resident memory of this process.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad.design import parse_design  # noqa: E402
from camcad.design.schema import parse_tolerance  # noqa: E402
from camcad.explore.tolerance import tolerance_study  # noqa: E402
from camcad.geometry.cam import Cam  # noqa: E402
from camcad.inspect.batch import certify, response  # noqa: E402
from camcad.inspect.spec import Evaluation  # noqa: E402
from camcad.inspect.tolerance import draw, variant_figures  # noqa: E402

SAMPLE = ROOT / "samples" / "tolerance_roller.toml"
DYNAMICS = ROOT / "samples" / "offset_roller.toml"


def cpu(fn):  # type: ignore[no-untyped-def]
    start = time.process_time()
    out = fn()
    return time.process_time() - start, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--one", type=int, default=20)
    parser.add_argument("--batch", type=int, default=500)
    parser.add_argument("--million", type=int, default=1_000_000)
    args = parser.parse_args()
    data = tomllib.loads(SAMPLE.read_text(encoding="utf-8"))
    data["dynamics"] = tomllib.loads(DYNAMICS.read_text(encoding="utf-8"))["dynamics"]
    table = data.pop("tolerance")
    design = parse_design(data)
    spec = parse_tolerance(table, design)
    cam, setup = Cam.from_design(design), design.dynamics_setup()
    drawn = draw(spec.tolerances, samples=max(args.one, args.batch), seed=spec.seed)

    def part(lo: int, hi: int) -> dict:  # type: ignore[type-arg]
        return {k: v[lo:hi] for k, v in drawn.items()}

    variant_figures(cam, part(0, 1), setup=setup)  # warm caches and imports
    t_one, _ = cpu(lambda: [variant_figures(cam, part(i, i + 1), setup=setup) for i in range(args.one)])
    t_batch, _ = cpu(lambda: variant_figures(cam, part(0, args.batch), setup=setup))
    t_fit, fitted = cpu(lambda: response(cam, spec.tolerances, setup=setup))
    t_eval, _ = cpu(lambda: fitted.figures(part(0, args.batch)))
    t_cert, cert = cpu(lambda: certify(cam, fitted, part(0, args.batch), setup=setup))
    one = args.one / t_one
    rows = [
        ("one at a time, exact", args.one, t_one, one),
        ('batched, exact (`evaluation = "exact"`)', args.batch, t_batch, args.batch / t_batch),
        ("quadratic: evaluation alone", args.batch, t_eval, args.batch / t_eval),
    ]
    load = os.getloadavg()
    print(
        f"{SAMPLE.name} with the dynamics of {DYNAMICS.name}; {len(spec.tolerances)} tolerances; "
        f"{os.cpu_count()} cores; load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}\n"
    )
    print("| made cams evaluated | cams | CPU [s] | cams per CPU-second | vs one at a time |")
    print("|---|---|---|---|---|")
    for name, count, t, rate in rows:
        print(f"| {name} | {count} | {t:.3f} | {rate:,.0f} | {rate / one:,.0f}× |")
    print(
        f"\nquadratic, fixed costs: fitting on {fitted.stencil_variants} re-solved cams {t_fit:.2f} s CPU, "
        f"certifying on {len(cert.indices)} re-solved cams {t_cert:.2f} s CPU; largest difference from "
        f"the exact re-solve there: dwell {cert.dwell:.1e} mm, peak |a| {cert.acceleration:.1e} mm/rad², "
        f"peak |α| {cert.pressure_angle:.1e} rad, contact stress {cert.stress:.1e} MPa.\n"
    )
    big = dataclasses.replace(spec, samples=args.million, evaluation=Evaluation.QUADRATIC)
    with tempfile.TemporaryDirectory() as out:
        wall0, cpu0 = time.perf_counter(), time.process_time()
        tolerance_study(cam, big, Path(out) / "t", name="bench", source=str(SAMPLE), setup=setup)
        wall, used = time.perf_counter() - wall0, time.process_time() - cpu0
        size = (Path(out) / "t" / "tolerance.parquet").stat().st_size
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f'`camcad tolerance`\'s study of {args.million:,} made cams (`evaluation = "quadratic"`, Parquet '
        f"{size / 1e6:.0f} MB): {wall:.1f} s wall, {used:.1f} s CPU, peak RSS {peak:.0f} MB "
        f"(limit: 600 s). The same by the batched exact re-solve would take "
        f"{args.million * t_batch / args.batch / 60:.0f} CPU-minutes."
    )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("tolerance"):  # the printed tables become its section of benchmarks/README.md
        main()
