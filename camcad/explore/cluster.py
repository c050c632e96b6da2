"""The process and Dask plumbing ``camcad sweep`` and ``camcad tolerance`` share.

Work is a list of items each mapped by one picklable function; every engine
yields ``(item number, result)`` as items finish, and the callers put the
results back in item order, so the engine and the number of workers never
change what is written:

- :func:`serial_map`: in this process;
- :func:`process_map`: a :class:`concurrent.futures.ProcessPoolExecutor`
  started by ``forkserver``, whose workers end with the command that started
  them (:func:`die_with`), even when that command is killed outright;
- :func:`dask_map`: a running ``dask.distributed`` scheduler
  (``--scheduler tcp://host:8786``; the extra ``camcad[cluster]``, camcad
  installed on its workers), reached within seconds or refused naming
  ``--scheduler`` (:func:`connect`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import signal
import socket
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from camcad.errors import CamcadError, UsageError

__all__ = [
    "PARENT_POLL_S",
    "PROBE_TIMEOUT_S",
    "SCHEDULER_SCHEMES",
    "SCHEDULER_TIMEOUT_S",
    "connect",
    "dask_map",
    "die_with",
    "process_map",
    "quiet_distributed",
    "scheduler_address",
    "serial_map",
]

T = TypeVar("T")
R = TypeVar("R")

SCHEDULER_TIMEOUT_S = 10
"""How long ``--scheduler`` waits for the scheduler's answer once its port accepts a connection [s]."""

PROBE_TIMEOUT_S = 3.0
"""How long ``--scheduler`` waits for the scheduler's port to accept a TCP connection [s]."""

SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")

_ADDRESS = re.compile(
    r"^(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[^\s/:\[\]]+):(?P<port>[0-9]{1,5})/?$"
)

PARENT_POLL_S = 0.2
"""How often a local worker checks that the command that started it still runs [s]."""


def gone(pid: int) -> bool:
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


def die_with(parent: int) -> None:
    """Run in each local worker as it starts: end it when the command's process ``parent`` is gone.

    A command killed outright (SIGKILL, out of memory) cannot stop its pool,
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
        while not gone(parent):
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="camcad-parent-watch", daemon=True).start()


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


def probe(scheduler: str) -> None:
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
def quiet_distributed() -> Iterator[None]:
    """Keep dask.distributed's own log lines (its handlers write to stderr) off the terminal."""
    logger = logging.getLogger("distributed")
    disabled = logger.disabled
    logger.disabled = True
    try:
        yield
    finally:
        logger.disabled = disabled


def connect(scheduler: str) -> Any:
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

    probe(scheduler)
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


def serial_map(fn: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[int, R]]:
    """Each item's result in this process, in order."""
    for k, item in enumerate(items):
        yield k, fn(item)


def process_map(fn: Callable[[T], R], items: Sequence[T], jobs: int, *, died: str) -> Iterator[tuple[int, R]]:
    """Results as ``jobs`` local worker processes finish them; ``died``: the message if a worker dies.

    The items not yet started are cancelled when the caller stops iterating
    (an error, Ctrl-C); a worker that dies (killed, out of memory) raises
    :class:`~camcad.errors.CamcadError` with ``died``.
    """
    import multiprocessing

    method = "forkserver" if sys.platform != "win32" else "spawn"
    with ProcessPoolExecutor(
        max_workers=jobs,
        mp_context=multiprocessing.get_context(method),
        initializer=die_with,
        initargs=(os.getpid(),),
    ) as pool:
        futures = {pool.submit(fn, item): k for k, item in enumerate(items)}
        try:
            for future in as_completed(futures):
                try:
                    result = future.result()
                except BrokenProcessPool as err:
                    raise CamcadError(died) from err
                yield futures[future], result
        finally:
            for future in futures:
                future.cancel()


def dask_map(fn: Callable[[T], R], items: Sequence[T], scheduler: str) -> Iterator[tuple[int, R]]:
    """Results as the workers of the Dask scheduler at ``scheduler`` finish them.

    Raises
    ------
    UsageError
        Naming ``--scheduler`` without dask.distributed or when the scheduler cannot be reached.
    """
    try:
        from distributed import as_completed as dask_completed
    except ImportError:
        raise UsageError("--scheduler", "needs dask.distributed: pip install 'camcad[cluster]'") from None
    with quiet_distributed():
        client = connect(scheduler)
        try:
            futures = client.map(fn, list(items), pure=False)
            index = {future.key: k for k, future in enumerate(futures)}
            try:
                with client.as_current():
                    for future, result in dask_completed(futures, with_results=True):
                        yield index[future.key], result
            finally:
                client.cancel(futures)
        finally:
            client.close()
