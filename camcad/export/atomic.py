"""Write files all or nothing: one file through a temporary sibling, a set through a staged folder.

Every camcad exporter writes through :func:`atomic_write`: the writer fills a
temporary file in the target folder, the file is checked to be non-empty and
flushed to disk, and only then renamed over the target with
:func:`os.replace`, which is atomic on POSIX and Windows within one file
system. If the writer raises, or produces an empty file, the temporary file
is removed and the target is left as it was (absent or the old version).

A build writes its files into :func:`staged_folder`, a hidden folder beside
the output folder, and moves them in only when every file was written; see
there for the guarantees and their limits.
"""

from __future__ import annotations

import os
import re
import secrets
import shutil
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camcad.errors import ExportError, OutputError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no lock between concurrent builds
    fcntl = None  # type: ignore[assignment]

__all__ = ["StagedFolder", "atomic_write", "atomic_write_bytes", "atomic_write_text", "staged_folder"]

LOCK_WAIT_S = 30.0
"""How long a build waits for another build to finish moving files into the same folder [s]."""

_TEMPORARY_FILE = re.compile(r"^\.(?P<stem>.*)\.[0-9a-f]{12}\.tmp(?P<suffix>.*)$")
_STAGING_FOLDER = re.compile(r"^\..*\.camcad-(?P<pid>[0-9]+)-[0-9a-f]+$")


def _temporary_sibling(path: Path) -> Path:
    """Return a fresh hidden name next to ``path`` that keeps its suffix (format sniffers use it)."""
    return path.with_name(f".{path.stem}.{secrets.token_hex(6)}.tmp{path.suffix}")


def _public_name(name: str) -> str:
    """The target name of a temporary sibling's name (``.cam.0a1b2c3d4e5f.tmp.ngc`` → ``cam.ngc``)."""
    match = _TEMPORARY_FILE.match(name)
    return match["stem"] + match["suffix"] if match else name


def atomic_write(path: str | os.PathLike[str], writer: Callable[[Path], object]) -> Path:
    """Create ``path`` by calling ``writer`` on a temporary sibling, then renaming it.

    Parameters
    ----------
    path
        Target file. Its folder must exist.
    writer
        Called once with the temporary path (same folder, same suffix); it must
        create that file. Its return value is ignored.

    Returns
    -------
    Path
        The target path.

    Raises
    ------
    ExportError
        When the writer created no file or an empty one.
    OutputError
        When the file cannot be written (full disk, no permission, a folder
        in the way); it names ``path``, never the temporary file, and nothing
        is left behind.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     atomic_write(Path(folder) / "a.txt", lambda tmp: tmp.write_text("hi")).read_text()
    'hi'
    """
    target = Path(path)
    tmp = _temporary_sibling(target)
    done = False
    try:
        writer(tmp)
        if not tmp.is_file() or tmp.stat().st_size == 0:
            raise ExportError(
                f"writing {target.name} produced {'no' if not tmp.is_file() else 'an empty'} "
                "file; nothing was written"
            )
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(tmp, target)
        done = True
    except OutputError:
        raise
    except OSError as err:
        raise OutputError.from_os_error(err, target) from err
    finally:
        if not done:
            tmp.unlink(missing_ok=True)
    return target


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Atomically write ``data`` to ``path``; see :func:`atomic_write`."""
    return atomic_write(path, lambda tmp: tmp.write_bytes(data))


def atomic_write_text(path: str | os.PathLike[str], text: str, *, encoding: str = "utf-8") -> Path:
    r"""Atomically write ``text`` to ``path`` with ``\n`` line ends; see :func:`atomic_write`."""

    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding=encoding, newline="\n") as handle:
            handle.write(text)

    return atomic_write(path, write)


@dataclass(frozen=True, slots=True)
class StagedFolder:
    """A temporary folder beside the output folder; ``path`` is where files are written."""

    path: Path
    target: Path


def _existing_folder(outdir: Path) -> Path:
    """The nearest existing folder above ``outdir``, checked to be writable; the staging folder goes there.

    Raises
    ------
    OutputError
        When ``outdir`` or one of its parents is a file, or the folder is not writable.
    """
    if "\0" in os.fspath(outdir):
        raise OutputError(
            repr(os.fspath(outdir)), "the path holds a NUL character", "choose another --output"
        )
    if os.path.lexists(outdir) and not outdir.is_dir() and not outdir.is_symlink():  # a link: its target
        raise OutputError(
            outdir, "it is a file, not a folder", "remove or rename it, or choose another --output"
        )
    probe = outdir.parent
    while not probe.is_dir():
        if os.path.lexists(probe):
            raise OutputError(outdir, f"{probe} is a file, not a folder", "choose another --output")
        probe = probe.parent
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(outdir, f"{probe} is not a writable folder", "choose another --output")
    return probe


def _process_alive(pid: int) -> bool:
    """Whether a process ``pid`` runs on this machine (POSIX; elsewhere always ``True``)."""
    if os.name != "posix":  # pragma: no cover - os.kill(pid, 0) would end the process on Windows
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):  # another user's process, or not a process id: leave it
        return True
    return True


def _remove_stale_staging(folder: Path) -> None:
    """Remove staging folders in ``folder`` left by camcad processes that no longer run (killed)."""
    with suppress(OSError), os.scandir(folder) as entries:
        for entry in entries:
            match = _STAGING_FOLDER.match(entry.name)
            if match and entry.is_dir(follow_symlinks=False) and not _process_alive(int(match["pid"])):
                shutil.rmtree(entry.path, ignore_errors=True)


def _make_staging(folder: Path, outdir: Path) -> Path:
    """Create ``.<outdir name>.camcad-<pid>-<random>`` in ``folder`` with the default permissions."""
    while True:
        path = folder / f".{outdir.name}.camcad-{os.getpid()}-{secrets.token_hex(4)}"
        try:
            path.mkdir()
        except FileExistsError:
            continue
        except OSError as err:
            raise OutputError.from_os_error(err, outdir) from err
        return path


def _make_parents(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; return the ones created, outermost first."""
    missing = []
    probe = folder
    while not probe.is_dir():
        missing.append(probe)
        probe = probe.parent
    created = []
    for path in reversed(missing):
        try:
            path.mkdir()
        except FileExistsError:
            continue
        except OSError as err:
            _remove_folders(created)
            raise OutputError.from_os_error(err, path) from err
        created.append(path)
    return created


def _remove_folders(created: list[Path]) -> None:
    """Remove the folders :func:`_make_parents` created, innermost first, while they are empty."""
    for path in reversed(created):
        try:
            path.rmdir()
        except OSError:
            return


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP back until the block ends (main thread only).

    Moving the files and cleaning up take milliseconds; a signal in between
    would leave a half-moved output folder, so it is delivered afterwards.
    The signals' Python handlers are swapped for one that only notes them, and
    the first noted one is raised again when the block ends. A thread signal
    mask would not do: the kernel hands a process signal to any thread that
    does not block it (numpy's BLAS threads, started before the mask), whose
    C handler then has the main thread's Python handler run inside the block.
    """
    if threading.current_thread() is not threading.main_thread():
        yield  # pragma: no cover - a worker thread cannot set handlers
        return
    pending: list[int] = []

    def note(signum: int, frame: object) -> None:
        pending.append(signum)

    previous: dict[int, Any] = {}
    for sig in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", signal.SIGTERM)):
        handler = signal.getsignal(sig)
        if handler is not None:  # None: set outside Python, cannot be put back
            previous[sig] = signal.signal(sig, note)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if pending:
            signal.raise_signal(pending[0])  # its own handler runs now, after the block


@contextmanager
def _output_lock(outdir: Path) -> Iterator[None]:
    """Hold ``.<outdir name>.camcad-lock`` beside ``outdir`` so two builds never move files in at once.

    The lock file is removed when the block ends; one left by a killed build
    is taken over (the kernel releases a dead process's lock) and removed.

    Raises
    ------
    OutputError
        When another build holds the lock for longer than :data:`LOCK_WAIT_S`.
    """
    if fcntl is None:  # pragma: no cover - Windows
        yield
        return
    lock = outdir.parent / f".{outdir.name}.camcad-lock"
    deadline = time.monotonic() + LOCK_WAIT_S
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise OutputError.from_os_error(err, outdir) from err
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            # The holder before us may have removed the file: then lock the new one.
            if os.path.samestat(os.fstat(fd), os.stat(lock)):
                break
        except (BlockingIOError, FileNotFoundError):
            pass
        os.close(fd)
        if time.monotonic() > deadline:
            raise OutputError(
                outdir,
                f"another camcad build has been moving files into it for over {LOCK_WAIT_S:g} s",
                f"wait for it to end, or remove {lock} if no camcad runs",
            )
        time.sleep(0.02)
    try:
        yield
    finally:
        with _signals_held():
            with suppress(OSError):
                lock.unlink()
            os.close(fd)


def _check_destinations(outdir: Path, names: list[str]) -> None:
    """Raise OutputError unless every ``outdir / name`` can be replaced by a file."""
    if not os.access(outdir, os.W_OK | os.X_OK):
        raise OutputError(outdir, "permission denied", "make it writable or choose another --output")
    for name in names:
        dest = outdir / name
        if dest.is_dir() and not dest.is_symlink():
            raise OutputError(
                dest,
                "a folder of that name is in the way",
                "remove or rename it, or choose another --output",
            )


def _move_files(staging: Path, outdir: Path, names: list[str]) -> None:
    """Move ``names`` from ``staging`` into ``outdir``; on any error put every replaced file back.

    Each old file is first hard-linked (or copied) into ``staging/.previous``
    so it can be restored; each new file then replaces it atomically.
    """
    backup = staging / ".previous"
    backup.mkdir()
    moved: list[tuple[str, bool]] = []
    try:
        for name in names:
            dest = outdir / name
            had_old = os.path.lexists(dest)
            try:
                if had_old:
                    try:
                        os.link(dest, backup / name, follow_symlinks=False)
                    except (OSError, NotImplementedError):  # no hard links here: keep a copy
                        shutil.copy2(dest, backup / name, follow_symlinks=False)
                os.replace(staging / name, dest)
            except OSError as err:
                raise OutputError.from_os_error(err, dest) from err
            moved.append((name, had_old))
    except BaseException:
        for name, had_old in reversed(moved):
            with suppress(OSError):
                if had_old:
                    os.replace(backup / name, outdir / name)
                else:
                    (outdir / name).unlink()
        raise


def _commit(staging: Path, outdir: Path) -> None:
    """Move every file of ``staging`` into ``outdir`` all or nothing (see :func:`staged_folder`).

    Waiting for the lock can be interrupted; creating the parents, the move
    and its rollback run with SIGINT, SIGTERM and SIGHUP held back.
    """
    names = sorted(p.name for p in staging.iterdir())
    with _signals_held():
        created = _make_parents(outdir.parent)
    try:
        with _output_lock(outdir), _signals_held():
            if not os.path.lexists(outdir):
                try:
                    os.rename(staging, outdir)  # a new folder appears at once, complete
                except OSError as err:
                    raise OutputError.from_os_error(err, outdir) from err
                return
            if not outdir.is_dir():
                raise OutputError(
                    outdir, "it is a file, not a folder", "remove or rename it, or choose another --output"
                )
            _check_destinations(outdir, names)
            _move_files(staging, outdir, names)
    except BaseException:
        with _signals_held():
            _remove_folders(created)
        raise


def _outside_staging(err: OSError, staging: Path, outdir: Path) -> OSError:
    """``err`` as an OutputError naming the path in ``outdir`` instead of the hidden staging folder.

    An error without a path (a failed ``write``) names ``outdir``; one about a
    path outside the staging folder is returned unchanged.
    """
    path = err.path if isinstance(err, OutputError) else err.filename
    if path is None:
        return err if isinstance(err, OutputError) else OutputError.from_os_error(err, outdir)
    try:
        relative = Path(os.fsdecode(path)).relative_to(staging)
    except ValueError:
        return err
    parts = [_public_name(part) for part in relative.parts]
    public = outdir if any(part.startswith(".") for part in parts) else outdir.joinpath(*parts)  # ours
    if not isinstance(err, OutputError):
        return OutputError.from_os_error(err, public)
    new = OutputError(public, err.problem, err.advice)
    new.errno = err.errno
    return new


@contextmanager
def staged_folder(outdir: str | os.PathLike[str]) -> Iterator[StagedFolder]:
    """Write a set of files all or nothing.

    Yields a hidden folder ``.<name>.camcad-<pid>-<random>`` beside
    ``outdir`` (in its nearest existing parent). When the block ends normally
    the files move into ``outdir``: a new ``outdir`` (and its missing parents)
    appears at once by one rename; into an existing one every destination is
    first checked to be replaceable (no folder in the way), then each file
    replaces its old version atomically, and on any error the files moved so
    far are put back. Two builds into one folder take turns through a lock
    file beside it, so the result is one build's files, never a mix.

    When the block raises (including ``KeyboardInterrupt``) nothing is moved
    and the staging folder is removed: ``outdir`` is left byte for byte as it
    was and nothing is left beside it. Staging folders of killed camcad
    processes are removed by the next build into the same place. Only a
    SIGKILL in the milliseconds of the final move can leave a mix.

    Raises
    ------
    OutputError
        Naming ``--output`` and the path in ``outdir`` (never the hidden
        folder) when ``outdir`` cannot be created or written, or an operating
        system error occurs while writing in the block.
    """
    target = Path(outdir)
    folder = _existing_folder(target)
    # OUTDIR may be (or lie under) a symbolic link to another file system: stage beside the folder the
    # link leads to, so the final rename stays within one file system (no "invalid cross-device link")
    real = Path(os.path.realpath(target))
    if real != target.absolute():
        folder = _existing_folder(real)
    _remove_stale_staging(folder)
    staging: Path | None = None
    try:
        # a signal between the folder's creation and the try below would leave it behind: held back
        # until ``staging`` names it, then delivered inside this try, whose clean-up removes it
        with _signals_held():
            staging = _make_staging(folder, real)
        try:
            yield StagedFolder(path=staging, target=target)
            _commit(staging, real)
        except OSError as err:
            mapped = _outside_staging(err, staging, target)
            if mapped is err:
                raise
            raise mapped from err
    finally:
        if staging is not None:
            with _signals_held():
                shutil.rmtree(staging, ignore_errors=True)
