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

Engines: ``jobs == 1`` evaluates in this process; ``jobs > 1`` uses a
:class:`concurrent.futures.ProcessPoolExecutor` (the standard library's pool,
started by ``forkserver``); ``scheduler="tcp://host:8786"`` sends the chunks
to a running ``dask.distributed`` scheduler (the extra ``camcad[cluster]``;
camcad must be installed on its workers).
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import re
import shutil
import signal
import socket
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camcad.errors import CamcadError, OutputError, UsageError
from camcad.explore.measures import Limit, Measure, analysis_row, failed_row
from camcad.explore.pareto import pareto_mask
from camcad.explore.plan import Chunk, SweepPlan
from camcad.explore.space import Variable, design_with
from camcad.explore.table import csv_text, parquet_bytes

__all__ = [
    "FORMATS",
    "SweepPlan",
    "SweepResult",
    "evaluate_chunk",
    "evaluate_point",
    "run_sweep",
    "sweep",
]

FORMATS = ("parquet", "csv")

SCHEDULER_TIMEOUT_S = 10
"""How long ``--scheduler`` waits for the scheduler's answer once its port accepts a connection [s]."""

PROBE_TIMEOUT_S = 3.0
"""How long ``--scheduler`` waits for the scheduler's port to accept a TCP connection [s]."""

SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")

_ADDRESS = re.compile(
    r"^(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[^\s/:\[\]]+):(?P<port>[0-9]{1,5})/?$"
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
    """The rows of one chunk, each with its ``index`` in the sweep (what a worker runs)."""
    return [
        {"index": chunk.start + i}
        | evaluate_point(chunk.data, chunk.variables, values, limits=chunk.limits, source=chunk.source)
        for i, values in enumerate(chunk.points)
    ]


def _serial(chunks: Sequence[Chunk]) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    for k, chunk in enumerate(chunks):
        yield k, evaluate_chunk(chunk)


PARENT_POLL_S = 0.2
"""How often a local worker checks that the sweep that started it still runs [s]."""


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has ended: no such process, or a zombie its own parent has not reaped yet."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as stat:
            return stat.read().rpartition(b")")[2].split()[0] in (b"Z", b"X")
    except FileNotFoundError:
        return True
    except OSError:  # no /proc here: ask the kernel whether it can be signalled
        pass
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # another user's process: it exists
        pass
    return False


def _die_with(parent: int) -> None:
    """Run in each local worker as it starts: end it when the sweep process ``parent`` is gone.

    A sweep killed outright (SIGKILL, out of memory) cannot stop its pool,
    so each worker watches for itself: a daemon thread asks every
    :data:`PARENT_POLL_S` whether ``parent`` still exists and ends the worker
    at once when not (on Linux the kernel also ends it with its own parent,
    the fork server, by ``PR_SET_PDEATHSIG``). The worker's stdout is the null
    device, so no worker holds the caller's pipe open (``camcad sweep … | tee``).
    """
    import threading
    import warnings

    warnings.simplefilter("ignore")  # as in the command line: a library's warnings are not camcad's lines
    with contextlib.suppress(OSError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    if sys.platform.startswith("linux"):
        import ctypes

        with contextlib.suppress(OSError, AttributeError):
            pr_set_pdeathsig = 1  # <linux/prctl.h>
            ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)

    def watch() -> None:
        while not _gone(parent):
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="camcad-parent-watch", daemon=True).start()


def _processes(chunks: Sequence[Chunk], jobs: int) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    import multiprocessing

    method = "forkserver" if sys.platform != "win32" else "spawn"
    with ProcessPoolExecutor(
        max_workers=jobs,
        mp_context=multiprocessing.get_context(method),
        initializer=_die_with,
        initargs=(os.getpid(),),
    ) as pool:
        futures = {pool.submit(evaluate_chunk, chunk): k for k, chunk in enumerate(chunks)}
        try:
            for future in as_completed(futures):
                try:
                    rows = future.result()
                except BrokenProcessPool as err:
                    raise CamcadError(
                        "a sweep worker process died (killed, or out of memory); the finished chunks are "
                        "kept: run the same command again to resume"
                    ) from err
                yield futures[future], rows
        finally:
            for future in futures:
                future.cancel()


def scheduler_address(text: str) -> tuple[str, int]:
    """The host and port of a ``--scheduler`` address ``[scheme://]host:port`` (scheme tcp, tls, ws, wss).

    Raises
    ------
    UsageError
        Naming ``--scheduler`` when the text is not such an address.
    """
    match = _ADDRESS.match(text.strip())
    scheme = (match["scheme"] or "tcp").lower() if match else ""
    if match is None or scheme not in SCHEDULER_SCHEMES or not 1 <= int(match["port"]) <= 65535:
        raise UsageError(
            "--scheduler",
            f"{text!r} is not a scheduler address (allowed: SCHEME://HOST:PORT with SCHEME "
            f"{', '.join(SCHEDULER_SCHEMES)} and PORT 1 to 65535, e.g. tcp://host:8786)",
        )
    return match["host"].strip("[]"), int(match["port"])


def _probe(scheduler: str) -> None:
    """Raise UsageError naming ``--scheduler`` unless its port accepts a connection within seconds.

    A refused or unreachable port is found here at once (Dask's own client
    would retry it until its timeout, then need as long again to close).
    """
    host, port = scheduler_address(scheduler)
    try:
        with socket.create_connection((host, port), timeout=PROBE_TIMEOUT_S):
            pass
    except OSError as err:
        why = (
            f"no answer within {PROBE_TIMEOUT_S:g} s"
            if isinstance(err, TimeoutError)
            else err.strerror or err
        )
        raise UsageError("--scheduler", f"cannot reach the Dask scheduler {scheduler!r}: {why}") from None


@contextlib.contextmanager
def _quiet_distributed() -> Iterator[None]:
    """Keep dask.distributed's own log lines (its handlers write to stderr) off the terminal."""
    logger = logging.getLogger("distributed")
    disabled = logger.disabled
    logger.disabled = True
    try:
        yield
    finally:
        logger.disabled = disabled


def _connect(scheduler: str) -> Any:
    """A ``distributed.Client`` of the scheduler, or UsageError naming ``--scheduler`` within seconds.

    A client that failed to connect is closed here, with a short timeout, so
    that its finaliser does not wait 2 × the timeout later and print a
    traceback when the process ends.
    """
    from distributed import Client

    made: list[Any] = []

    class _Client(Client):  # type: ignore[misc]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            made.append(self)
            super().__init__(*args, **kwargs)

    _probe(scheduler)
    try:
        return _Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s", set_as_default=False)
    except Exception as err:  # refused, timed out, or something that is not a scheduler answered
        for client in made:
            with contextlib.suppress(Exception):  # whatever the half-made client raises on closing
                client.close(timeout=1)
            client.status = "closed"  # its finaliser has nothing left to do
        why = (
            f"{err}"
            if isinstance(err, (OSError, TimeoutError, ValueError))
            else "no Dask scheduler answers there"
        )
        raise UsageError("--scheduler", f"cannot reach the Dask scheduler {scheduler!r}: {why}") from None


def _dask(chunks: Sequence[Chunk], scheduler: str) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    try:
        from distributed import as_completed as dask_completed
    except ImportError:
        raise UsageError("--scheduler", "needs dask.distributed: pip install 'camcad[cluster]'") from None
    with _quiet_distributed():
        yield from _on_cluster(chunks, scheduler, dask_completed)


def _on_cluster(
    chunks: Sequence[Chunk], scheduler: str, dask_completed: Any
) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    client = _connect(scheduler)
    try:
        futures = client.map(evaluate_chunk, list(chunks), pure=False)
        index = {future.key: k for k, future in enumerate(futures)}
        try:
            with client.as_current():
                for future, rows in dask_completed(futures, with_results=True):
                    yield index[future.key], rows
        finally:
            client.cancel(futures)
    finally:
        client.close()


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
        if scheduler is not None:
            results = _dask(work, scheduler)
        elif jobs == 1 or len(work) == 1:
            results = _serial(work)
        else:
            results = _processes(work, min(jobs, len(work)))
        for j, rows in results:
            finished[todo[j]] = rows
            if on_chunk is not None:
                on_chunk(todo[j], rows)
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
