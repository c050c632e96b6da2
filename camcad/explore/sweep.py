"""Design-space sweeps: analyse many variants of one design, on one core, local processes or a Dask cluster.

Each design of the sweep is the base design with the variables' values
written in (:mod:`camcad.explore.space`), analysed as ``camcad check`` does
(:func:`camcad.pipeline.analyse` with ``strict=False``, no fit, no toolpath),
and becomes one row: its inputs, its verdicts and every summary figure
(:func:`camcad.explore.measures.analysis_row`). A design the schema refuses
or a stage cannot analyse is a row with its reason, never a failed sweep.

The designs are cut into chunks of ``chunk_size`` in a fixed order; a chunk
is the unit of work sent to a worker and of the record kept for resuming:
each finished chunk is written at once to ``OUTDIR/.camcad-sweep-<key>/``
(``key`` a hash of everything that decides the rows), and a sweep started
again with the same inputs reads those chunks instead of computing them.
The table and the page are written only when every chunk is done, all at
once (:func:`camcad.export.atomic.staged_folder`), and the chunk records are
then removed. The rows do not depend on the engine, the number of workers or
the order chunks finish in: one serial run, a process pool and a Dask
cluster give the same bytes.

Engines (:mod:`camcad.explore.cluster`, shared with ``camcad tolerance``):
``jobs == 1`` evaluates in this process; ``jobs > 1`` uses a
:class:`concurrent.futures.ProcessPoolExecutor` (the standard library's pool,
started by ``forkserver``); ``scheduler="tcp://host:8786"`` sends the chunks
to a running ``dask.distributed`` scheduler (the extra ``camcad[cluster]``;
camcad must be installed on its workers).
"""

from __future__ import annotations

import contextlib
import json
import math
import shutil
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camcad.errors import CamcadError, OutputError, UsageError
from camcad.explore.cluster import dask_map, process_map, scheduler_address, serial_map
from camcad.explore.measures import Limit, Measure, analysis_row, failed_row
from camcad.explore.pareto import pareto_mask
from camcad.explore.plan import Chunk, SweepPlan
from camcad.explore.space import Variable, design_with
from camcad.explore.table import csv_text, parquet_bytes

__all__ = [
    "FORMATS",
    "PACK",
    "SweepPlan",
    "SweepResult",
    "evaluate_chunk",
    "evaluate_chunks",
    "evaluate_point",
    "run_sweep",
    "sweep",
]

FORMATS = ("parquet", "csv")

_DIED = (
    "a sweep worker process died (killed, or out of memory); the finished chunks are "
    "kept: run the same command again to resume"
)

Progress = Callable[[int, int], None]
"""Called with (chunks done, chunks in all) as chunks finish, resumed ones first."""


@dataclass(frozen=True, slots=True, kw_only=True)
class SweepResult:
    """The rows in design order, the files written and how many chunks were read back from a previous run."""

    rows: tuple[dict[str, Any], ...]
    files: tuple[Path, ...] = ()
    resumed_chunks: int = 0


def evaluate_point(
    data: Mapping[str, Any],
    variables: Sequence[Variable],
    values: Sequence[Any],
    *,
    limits: Sequence[Limit] = (),
    source: str = "",
) -> dict[str, Any]:
    """The row of one design: its inputs, then :func:`~camcad.explore.measures.analysis_row`."""
    from camcad.pipeline import analyse

    row: dict[str, Any] = {v.name: value for v, value in zip(variables, values, strict=True)}
    try:
        design = design_with(data, variables, values, source=source)
        analysis = analyse(design, fit=False, toolpath=False, strict=False)
    except CamcadError as err:  # an invalid variant, or a limit a stage raises even when not strict
        row.update(failed_row(err, limits))
        return row
    row.update(analysis_row(analysis, limits))
    return row


def evaluate_chunk(chunk: Chunk) -> list[dict[str, Any]]:
    """The rows of one chunk, each with its ``index`` in the sweep (what a worker runs).

    With ``chunk.batch`` the chunk's variants that share one motion structure
    are analysed together (:mod:`camcad.explore.batch`), the others one by
    one (:func:`evaluate_point`); the rows are the same bytes either way.
    """
    if chunk.batch:
        from camcad.explore.batch import chunk_rows

        rows = chunk_rows(chunk.data, chunk.variables, chunk.points, limits=chunk.limits, source=chunk.source)
        return [{"index": chunk.start + i} | row for i, row in enumerate(rows)]
    return [
        {"index": chunk.start + i}
        | evaluate_point(chunk.data, chunk.variables, values, limits=chunk.limits, source=chunk.source)
        for i, values in enumerate(chunk.points)
    ]


PACK = 64
"""Most designs analysed in one batch: a process evaluates consecutive chunks together up to this many."""


def evaluate_chunks(chunks: Sequence[Chunk]) -> list[list[dict[str, Any]]]:
    """The rows of consecutive chunks of one plan, their variants analysed in one batch.

    The rows are each chunk's :func:`evaluate_chunk` rows (the batch analysis
    gives every design the bytes of its analysis alone, however the designs
    are grouped); a bigger batch only spreads its fixed cost over more designs.
    """
    if not chunks:
        return []
    first = chunks[0]
    if len(chunks) == 1 or not first.batch:
        return [evaluate_chunk(c) for c in chunks]
    from camcad.explore.batch import chunk_rows

    points = [p for c in chunks for p in c.points]
    rows = chunk_rows(first.data, first.variables, points, limits=first.limits, source=first.source)
    out: list[list[dict[str, Any]]] = []
    at = 0
    for c in chunks:
        out.append([{"index": c.start + i} | row for i, row in enumerate(rows[at : at + len(c.points)])])
        at += len(c.points)
    return out


def _packs(chunks: Sequence[Chunk], workers: int) -> list[list[int]]:
    """Consecutive chunk numbers packed up to :data:`PACK` designs, keeping at least 2 packs per worker."""
    if not chunks or not chunks[0].batch:
        return [[k] for k in range(len(chunks))]
    designs = sum(len(c.points) for c in chunks)
    size = max(1, min(PACK, designs // (2 * workers) if workers > 1 else PACK))
    packs: list[list[int]] = []
    count = 0
    for k, c in enumerate(chunks):
        if not packs or count + len(c.points) > size:
            packs.append([])
            count = 0
        packs[-1].append(k)
        count += len(c.points)
    return packs


def run_sweep(
    plan: SweepPlan,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    done: Mapping[int, list[dict[str, Any]]] | None = None,
    on_chunk: Callable[[int, list[dict[str, Any]]], None] | None = None,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """Evaluate every chunk not in ``done`` and return all rows in design order, with the ``pareto`` column.

    Parameters
    ----------
    jobs
        1: in this process; more: that many local worker processes.
    scheduler
        A Dask scheduler address (``tcp://host:8786``); overrides ``jobs``.
    done
        Rows of chunks already computed, by chunk number (a resumed sweep).
    on_chunk
        Called with each chunk's number and rows as soon as it is computed.
    """
    if jobs < 1:
        raise UsageError("--jobs", f"{jobs} is not allowed (allowed: 1 or more worker processes)")
    chunks = plan.chunks()
    finished: dict[int, list[dict[str, Any]]] = dict(done or {})
    todo = [k for k in range(len(chunks)) if k not in finished]
    if progress is not None:
        progress(len(finished), len(chunks))
    if todo:
        work = [chunks[k] for k in todo]
        workers = 1 if scheduler is None and (jobs == 1 or len(work) == 1) else max(jobs, 2)
        packs = [[work[i] for i in pack] for pack in _packs(work, workers)]
        places = [[todo[i] for i in pack] for pack in _packs(work, workers)]
        if scheduler is not None:
            results = dask_map(evaluate_chunks, packs, scheduler)
        elif workers == 1:
            results = serial_map(evaluate_chunks, packs)
        else:
            results = process_map(evaluate_chunks, packs, min(jobs, len(packs)), died=_DIED)
        for j, packed in results:
            for k, rows in zip(places[j], packed, strict=True):
                finished[k] = rows
                if on_chunk is not None:
                    on_chunk(k, rows)
                if progress is not None:
                    progress(len(finished), len(chunks))
    rows = [row for k in range(len(chunks)) for row in finished[k]]
    return _with_front(rows, plan.pareto)


def _with_front(rows: list[dict[str, Any]], pareto: tuple[Measure, Measure]) -> list[dict[str, Any]]:
    """Add ``pareto``: a feasible design on the front of the two objectives."""
    first, second = pareto

    def value(row: Mapping[str, Any], m: Measure) -> float:
        v = m.of(row) if row.get("feasible") else None
        return math.nan if v is None else v

    mask = pareto_mask([value(r, first) for r in rows], [value(r, second) for r in rows])
    return [row | {"pareto": bool(on)} for row, on in zip(rows, mask, strict=True)]


def _read_parts(folder: Path, key: str, count: int) -> dict[int, list[dict[str, Any]]]:
    """The chunks a previous run of the same sweep finished (unreadable or foreign records are ignored)."""
    found: dict[int, list[dict[str, Any]]] = {}
    if not folder.is_dir():
        return found
    for k in range(count):
        path = folder / f"chunk-{k:06d}.json"
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(record, dict) and record.get("key") == key and record.get("chunk") == k:
            found[k] = record["rows"]
    return found


def sweep(
    plan: SweepPlan,
    outdir: str | Path,
    *,
    fmt: str = "parquet",
    jobs: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
    on_chunk: Callable[[int, list[dict[str, Any]]], None] | None = None,
) -> SweepResult:
    """Run a sweep into ``outdir``: ``sweep.parquet`` (or ``sweep.csv``) and ``sweep.html``.

    Finished chunks are kept in ``outdir/.camcad-sweep-<key>/`` until the
    table is written, so an interrupted sweep started again with the same
    inputs resumes where it stopped; see the module docstring.

    Raises
    ------
    UsageError
        ``--format`` not parquet or csv, Parquet without pyarrow, a bad
        ``--jobs`` or an unreachable ``--scheduler``.
    OutputError
        When ``outdir`` cannot be written (names ``--output``).
    """
    from camcad.explore.page import sweep_page
    from camcad.export.atomic import atomic_write_bytes, atomic_write_text, staged_folder

    if fmt not in FORMATS:
        raise UsageError("--format", f"{fmt!r} is not allowed (allowed: {', '.join(FORMATS)})")
    if scheduler is not None:
        scheduler_address(scheduler)  # a mistyped address is refused before anything is written
    if fmt == "parquet":
        try:
            import pyarrow.parquet  # noqa: F401
        except ImportError:
            raise UsageError(
                "--format", "parquet needs pyarrow: pip install 'camcad[cluster]', or use --format csv"
            ) from None
    outdir = Path(outdir)
    key = plan.key()
    parts = outdir / f".camcad-sweep-{key[:16]}"
    created = [d for d in (parts, *parts.parents) if not d.exists()]  # what to remove if nothing gets done
    try:
        parts.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError.from_os_error(err, parts.parent) from err
    chunk_count = len(plan.chunks())
    done = _read_parts(parts, key, chunk_count)

    def keep(k: int, rows: list[dict[str, Any]]) -> None:
        record = {"key": key, "chunk": k, "rows": rows}
        atomic_write_text(parts / f"chunk-{k:06d}.json", json.dumps(record, separators=(",", ":")) + "\n")
        if on_chunk is not None:
            on_chunk(k, rows)

    try:
        rows = run_sweep(plan, jobs=jobs, scheduler=scheduler, done=done, on_chunk=keep, progress=progress)
    except BaseException:
        if not any(parts.glob("chunk-*.json")):  # nothing to resume from: leave no trace
            for folder in created:
                with contextlib.suppress(OSError):
                    folder.rmdir()
        raise
    name = f"sweep.{fmt}"
    with staged_folder(outdir) as staging:
        if fmt == "parquet":
            atomic_write_bytes(staging.path / name, parquet_bytes(rows))
        else:
            atomic_write_text(staging.path / name, csv_text(rows))
        atomic_write_text(staging.path / "sweep.html", sweep_page(plan, rows, table=name))
    shutil.rmtree(parts, ignore_errors=True)
    return SweepResult(
        rows=tuple(rows), files=(outdir / name, outdir / "sweep.html"), resumed_chunks=len(done)
    )
