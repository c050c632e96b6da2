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
from collections.abc import Callable
from pathlib import Path

from camcad.errors import ExportError

__all__ = ["atomic_write", "atomic_write_bytes", "atomic_write_text"]


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
