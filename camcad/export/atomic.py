"""Write a file through a temporary sibling so a failed export leaves nothing behind.

Every camcad exporter writes through :func:`atomic_write`: the writer fills a
temporary file in the target folder, the file is checked to be non-empty and
flushed to disk, and only then renamed over the target with
:func:`os.replace`, which is atomic on POSIX and Windows within one file
system. If the writer raises, or produces an empty file, the temporary file
is removed and the target is left as it was (absent or the old version).
"""

from __future__ import annotations

import os
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from camcad.errors import DesignError, ExportError

__all__ = ["StagedFolder", "atomic_write", "atomic_write_bytes", "atomic_write_text", "staged_folder"]


def _temporary_sibling(path: Path) -> Path:
    """Return a fresh hidden name next to ``path`` that keeps its suffix (format sniffers use it)."""
    return path.with_name(f".{path.stem}.{secrets.token_hex(6)}.tmp{path.suffix}")


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
    OSError
        When the folder is not writable; nothing is left behind.

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


def _staging_path(outdir: Path) -> Path:
    """Check that ``outdir`` can be created or written; make a temporary sibling folder."""
    if outdir.exists() and not outdir.is_dir():
        raise DesignError("--output", f"{outdir} exists and is not a folder")
    parent = outdir.parent if outdir.parent != Path("") else Path(".")
    probe = parent
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir() or not os.access(probe, os.W_OK):
        raise DesignError("--output", f"cannot create {outdir}: {probe} is not a writable folder")
    try:
        parent.mkdir(parents=True, exist_ok=True)
        return Path(tempfile.mkdtemp(prefix=f".{outdir.name}.camcad-", dir=parent))
    except OSError as err:
        raise DesignError("--output", f"cannot write to {parent}: {err.strerror or err}") from None


@contextmanager
def staged_folder(outdir: str | os.PathLike[str]) -> Iterator[StagedFolder]:
    """Write a set of files all or nothing.

    Yields a temporary folder beside ``outdir``. When the block ends normally
    every file in it is moved into ``outdir`` (created if needed), each by an
    atomic rename; when the block raises, the temporary folder is removed and
    ``outdir`` is left exactly as it was. Either way nothing temporary stays.

    Raises
    ------
    DesignError
        With path ``--output`` when ``outdir`` cannot be created or written.
    """
    target = Path(outdir)
    staging = StagedFolder(path=_staging_path(target), target=target)
    try:
        yield staging
        target.mkdir(parents=True, exist_ok=True)
        for item in sorted(staging.path.iterdir()):
            os.replace(item, target / item.name)
    finally:
        shutil.rmtree(staging.path, ignore_errors=True)
