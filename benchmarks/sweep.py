"""Sweep throughput: designs per second on one core, local worker processes and a Dask LocalCluster.

Run ``python benchmarks/sweep.py [--designs 96] [--chunk 8]``. It sweeps the
base radius and the offset of ``samples/offset_roller.toml`` (analysis
without fit and toolpath, as ``camcad sweep`` does) through
:func:`camcad.explore.run_sweep` with each engine and prints a Markdown table:
wall time, designs per second, per core, and the speed-up against one
worker of the same engine. The engines' start-up (worker processes that
import camcad, a cluster's scheduler) is timed apart: the sweep is timed on
an engine that is already running, as a long sweep sees it. The projected
time for 10⁶ designs on a 64-core cluster is 10⁶ / (64 × the per-core
rate), from the rate of one core alone and from that of the 2-worker
LocalCluster. The machine's load average is printed too:
on a shared machine the figures move with it.

First, the batch analysis (issue 38, :mod:`camcad.explore.batch`) against the
per-design path, in one run: for every shipped plate-cam sample, a sweep of 64
variants of its base radius (r_b to 1.25·r_b, chunks of 16 as ``camcad
sweep`` makes them) run as ``camcad sweep --jobs 1`` does
(:func:`camcad.explore.run_sweep`), with batching off (each variant analysed
alone) and on (the chunks packed up to 64 designs per batch); CPU time of
this process (``time.process_time``, the best of ``--repeats`` alternating
runs); the rows checked identical. The ratio is designs per CPU-second
batched over one at a time.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad.explore import MEASURES, SweepPlan, grid_points, parse_variable  # noqa: E402
from camcad.explore.sweep import evaluate_chunk, run_sweep  # noqa: E402

SAMPLE = ROOT / "samples" / "offset_roller.toml"


def plan(designs: int, chunk: int) -> SweepPlan:
    data = tomllib.loads(SAMPLE.read_text(encoding="utf-8"))
    side = math.isqrt(designs)
    variables = (
        parse_variable(f"base_radius=60:100:{side}", data, flag="--grid", counted=True),
        parse_variable(f"offset=0:20:{designs // side}", data, flag="--grid", counted=True),
    )
    return SweepPlan(
        data=data,
        source=str(SAMPLE),
        variables=variables,
        points=tuple(grid_points(variables)),
        pareto=(MEASURES["base_radius"], MEASURES["contact_stress"]),
        chunk_size=chunk,
    )


BATCH_SAMPLES = (
    "offset_roller",
    "fea_plate",
    "hren_tappet",
    "indexing_drive",
    "measured_table",
    "packaging_rocker",
    "quintero_harmonic",
    "quintero_poly4567",
    "quintero_vap_b01",
    "quintero_vap_b02",
    "rocker_flat",
    "rotary_plate",
    "tolerance_roller",
    "web_cutter",
)
"""The shipped plate cams without ``[vibration]`` (slides and arms; the groove, pair and linear cam aside)."""


SPEED_SAMPLES = ("packaging_rocker", "rocker_flat")
"""The arms again, swept in speed (their pivot stays put) besides their base radius (the pivot moves)."""


def batch_plan(name: str, designs: int = 64, chunk: int = 16, key: str = "base_radius") -> SweepPlan:
    path = ROOT / "samples" / f"{name}.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    r = float(data["cam"][key])
    variables = (parse_variable(f"{key}={r!r}:{1.25 * r!r}:{designs}", data, flag="--grid", counted=True),)
    return SweepPlan(
        data=data,
        source=str(path),
        variables=variables,
        points=tuple(grid_points(variables)),
        pareto=(MEASURES["base_radius"], MEASURES["contact_stress"]),
        chunk_size=chunk,
    )


def batch_table(repeats: int, samples: tuple[str, ...] = BATCH_SAMPLES, key: str = "base_radius") -> None:
    """Designs per CPU-second of this process, one at a time and batched, per sample; rows compared."""
    from dataclasses import replace

    from camcad.explore.batch import BatchStats, chunk_rows

    heads = ("sample", "follower", "designs", "one at a time [designs/CPU-s]", "batched [designs/CPU-s]")
    print("| " + " | ".join((*heads, "ratio", "batched variants", "same rows")) + " |")
    print("|---|---|---|---|---|---|---|---|")
    total_one = total_batch = 0.0
    count = 0
    for name in samples:
        p = batch_plan(name, key=key)
        chunks = p.chunks()
        n = len(p.points)

        def run(batch: bool, p=p) -> tuple[float, list]:
            start = time.process_time()
            rows = run_sweep(replace(p, batch=batch))  # `camcad sweep --jobs 1`
            return time.process_time() - start, rows

        run(True)  # imports, caches
        one = many = math.inf
        rows_one = rows_many = None
        for _ in range(repeats):
            t, rows_one = run(False)
            one = min(one, t)
            t, rows_many = run(True)
            many = min(many, t)
        stats = BatchStats()
        for c in chunks:
            chunk_rows(c.data, c.variables, c.points, limits=c.limits, source=c.source, stats=stats)
        same = json.dumps(rows_one, sort_keys=True, default=repr) == json.dumps(
            rows_many, sort_keys=True, default=repr
        )
        kind = p.data["follower"].get("type", "translating-roller")
        print(
            f"| {name} | {kind} | {n} | {n / one:.1f} | {n / many:.1f} | {one / many:.2f}× "
            f"| {stats.batched}/{n} | {'yes' if same else 'NO'} |"
        )
        total_one += one
        total_batch += many
        count += n
    print(
        f"\nAll {len(samples)} samples, {key} varied: {count / total_one:.1f} designs per CPU-second "
        f"one at a time, {count / total_batch:.1f} batched: **{total_one / total_batch:.2f}×**.\n"
    )


def timed_map(submit_all, chunks) -> float:
    start = time.perf_counter()
    submit_all(chunks)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--designs", type=int, default=96)
    parser.add_argument("--chunk", type=int, default=8)
    parser.add_argument(
        "--repeats", type=int, default=3, help="alternating runs of each path (the best counts)"
    )
    parser.add_argument("--batch-only", action="store_true", help="only the batch table")
    args = parser.parse_args()
    print(
        "Batch analysis against one at a time, base radius varied (r_b to 1.25·r_b), "
        f"{args.repeats} runs each:\n"
    )
    batch_table(args.repeats)
    print("The arms again, their speed varied (rpm to 1.25·rpm; their pivot stays put):\n")
    batch_table(args.repeats, SPEED_SAMPLES, key="speed_rpm")
    if args.batch_only:
        return
    p = plan(args.designs, args.chunk)
    chunks = p.chunks()
    n = len(p.points)
    evaluate_chunk(chunks[0])  # warm caches and imports in this process
    rows: list[tuple[str, int, float, float]] = []  # engine, workers, wall [s], start-up [s]

    wall = timed_map(lambda cs: [evaluate_chunk(c) for c in cs], chunks)
    rows.append(("one core, this process (`--jobs 1`)", 1, wall, 0.0))

    import multiprocessing

    for workers in (1, 2):
        start = time.perf_counter()
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("forkserver")) as pool:
            list(pool.map(evaluate_chunk, chunks[:workers]))  # start the workers, import camcad
            up = time.perf_counter() - start
            wall = timed_map(lambda cs, pool=pool: list(pool.map(evaluate_chunk, cs)), chunks)
        rows.append((f"local processes (`--jobs {workers}`)", workers, wall, up))

    from distributed import Client, LocalCluster

    for workers in (1, 2):
        start = time.perf_counter()
        with (
            LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
            ) as cluster,
            Client(cluster) as client,
        ):
            client.gather(client.map(evaluate_chunk, chunks[:workers], pure=False))
            up = time.perf_counter() - start
            wall = timed_map(
                lambda cs, client=client: client.gather(client.map(evaluate_chunk, cs, pure=False)), chunks
            )
        rows.append((f"Dask LocalCluster, {workers} worker process(es)", workers, wall, up))

    load = os.getloadavg()
    print(
        f"{n} designs of {SAMPLE.name} in chunks of {args.chunk}; {os.cpu_count()} cores; "
        f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}\n"
    )
    print("| engine | workers | start-up [s] | sweep [s] | designs/s | per core | speed-up vs 1 worker |")
    print("|---|---|---|---|---|---|---|")
    single: dict[str, float] = {}
    for name, workers, wall, up in rows:
        rate = n / wall
        family = name.split(" (")[0].split(",")[0]
        if workers == 1:
            single.setdefault(family, rate)
        speed = rate / single.get(family, rate)
        print(
            f"| {name} | {workers} | {up:.1f} | {wall:.1f} | {rate:.1f} | {rate / workers:.1f} "
            f"| {speed:.2f}× |"
        )
    one = rows[0][2] and n / rows[0][2]
    dask2 = next(n / wall / 2 for name, workers, wall, _ in rows if name.startswith("Dask") and workers == 2)
    for label, rate in (("one core alone", one), ("per core of the 2-worker LocalCluster", dask2)):
        hours = 1e6 / (64 * rate) / 3600
        print(
            f"projected: 10^6 designs on 64 cores at {rate:.1f} designs/s per core ({label}): {hours:.2f} h"
        )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("sweep"):  # the printed tables become its section of benchmarks/README.md
        main()
