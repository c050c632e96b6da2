"""The camcad command line: build, check, size, compare, laws.

Exit codes (defined in :mod:`camcad.errors`): 0 success, 2 invalid input
(usage, unreadable or invalid design, unwritable output), 3 a design limit
violated (undercut, gouge, jump, pressure angle or stress limit), 1 anything
unexpected, 130 interrupted (SIGINT, SIGTERM, SIGHUP), 141 stdout closed by
its reader (``camcad check … | head``).
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from types import FrameType
from typing import Any

from camcad import _exit_interrupted
from camcad.cli.args import build_parser
from camcad.design.paths import named_error
from camcad.errors import (
    EXIT_INTERRUPTED,
    EXIT_PIPE_CLOSED,
    EXIT_UNEXPECTED,
    CamcadError,
    DesignLimitError,
    exit_code,
    printable,
)

__all__ = ["build_parser", "main"]


_INTERRUPTS: list[int] = []
"""The signals that interrupted this run: an import the signal broke may surface as another error."""


def _interrupt(signum: int, frame: FrameType | None) -> None:
    """SIGINT, SIGTERM and SIGHUP end a run alike: noted, then KeyboardInterrupt (clean up, exit 130)."""
    _INTERRUPTS.append(signum)
    raise KeyboardInterrupt


@contextmanager
def _terminate_like_interrupt() -> Iterator[None]:
    """Map SIGTERM and SIGHUP to KeyboardInterrupt while the block runs (main thread only)."""
    names = ("SIGTERM", "SIGHUP")
    signums = [getattr(signal, n) for n in names if hasattr(signal, n)]
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _interrupt) for s in signums}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _silence_stdout() -> None:
    """Point stdout at the null device, so the flush at exit does not fail on a closed pipe again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout is not a real file (e.g. captured by a test)
        pass


@contextmanager
def _no_library_logging() -> Iterator[None]:
    """Keep log records of the libraries camcad uses off stderr while the block runs.

    Without a handler Python prints warnings to stderr, e.g. matplotlib's
    when the home folder is not writable; camcad's own messages are its errors.
    """
    root = logging.getLogger()
    handler = logging.NullHandler()
    root.addHandler(handler)
    try:
        yield
    finally:
        root.removeHandler(handler)


@contextmanager
def _no_library_warnings() -> Iterator[None]:
    """Keep Python warnings of the libraries camcad uses (a SciPy ``RuntimeWarning``) off stderr.

    camcad reports what matters as findings, notes and errors of its own;
    a library's warning is a line the user cannot act on.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line and return the exit code.

    Ctrl-C (SIGINT, and SIGTERM, SIGHUP) at any moment gives one line,
    ``camcad: interrupted``, and exit 130: while a command runs it raises
    ``KeyboardInterrupt``, which cleans up (a staged output folder is
    removed); when this function is the process's entry point (the
    ``camcad`` command, ``python -m camcad``), a signal after it returns ends
    the process the same way. The heavy modules are imported by the command
    after the handling is in place.
    """
    entry = _is_entry_point()
    previous: Any = None
    code = EXIT_INTERRUPTED
    try:
        if threading.current_thread() is threading.main_thread():
            _INTERRUPTS.clear()
            previous = signal.signal(signal.SIGINT, _interrupt)
        try:
            code = _run(argv)
        except KeyboardInterrupt:  # a signal while an error line was printed
            print("camcad: interrupted", file=sys.stderr)
    except KeyboardInterrupt:  # the moment the handling was put in place
        print("camcad: interrupted", file=sys.stderr)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, _exit_interrupted if entry else previous)
    if entry and code == EXIT_INTERRUPTED:
        # CPython 3.11 remembers an interrupt that went through exec() of a string (dataclasses,
        # namedtuple) and then ends the process by SIGINT at exit, though camcad handled it; the
        # clean-up has run, so leave now with the documented code
        with suppress(OSError, ValueError):
            sys.stdout.flush()
        with suppress(OSError, ValueError):
            sys.stderr.flush()
        os._exit(EXIT_INTERRUPTED)
    return code


def _is_entry_point() -> bool:
    """Whether :func:`main` runs as the process's command (so a later SIGINT may end the process at once)."""
    main_module = sys.modules.get("__main__")
    spec = getattr(main_module, "__spec__", None)
    if spec is not None and spec.name == "camcad.__main__":  # python -m camcad
        return True
    return os.path.basename(sys.argv[0] if sys.argv else "") in ("camcad", "camcad.exe")  # the command


def _run(argv: Sequence[str] | None) -> int:
    """Parse, run the command, and map its errors to one line and an exit code."""
    try:
        args = build_parser().parse_args(argv)
        with _terminate_like_interrupt(), _no_library_logging(), _no_library_warnings():
            code = int(args.handler(args))
            sys.stdout.flush()
        return code
    except KeyboardInterrupt:
        print("camcad: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_PIPE_CLOSED
    except DesignLimitError as err:
        _say("design limit", str(named_error(err)))
        return exit_code(err)
    except CamcadError as err:
        _say("error", str(named_error(err)))
        return exit_code(err)
    except OSError as err:
        where = f": {os.fsdecode(err.filename)}" if err.filename else ""
        _say("error", f"{err.strerror or err}{where}")
        return exit_code(err)
    except Exception as err:  # the one place that maps surprises to exit 1
        if _INTERRUPTS:  # the signal broke an import (numpy turns it into an ImportError): an interrupt
            print("camcad: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
        _say("unexpected error", f"{type(err).__name__}: {err}")
        print("camcad: please report this with your design file", file=sys.stderr)
        return EXIT_UNEXPECTED


def _say(kind: str, message: str) -> None:
    """Print ``camcad: <kind>: <message>`` as one line on stderr: every user string in it escaped."""
    print(f"camcad: {kind}: {printable(message)}", file=sys.stderr)
