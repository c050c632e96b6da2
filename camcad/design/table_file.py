"""Reading a point table's file safely: a regular file of bounded size, never blocking, never echoed.

A design names its point table by a path relative to the design file's
folder (``file = "measured_lift.csv"``). Design files come from colleagues
and the internet, and ``camcad serve`` reads them on a workstation, so the
reader refuses whatever is not a plain table on disk (issue 32):

- only a regular file: a FIFO, a device (``/dev/zero``, ``/dev/urandom``), a
  socket or a folder is refused; the file is opened with ``O_NONBLOCK`` and
  checked with ``fstat`` on the open descriptor, so a FIFO never blocks and
  nothing can be swapped in between the check and the read;
- at most :data:`MAX_TABLE_BYTES` (16 MiB; 36 000 rows of three numbers take
  well under 1 MiB), and never more than that is read;
- optionally confined to a folder (``confine_to``): the path with every
  symlink resolved must lie inside it, so ``..``, an absolute path or a link
  cannot lead out;
- the messages name the path and what is wrong, never the file's content.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from camcad.errors import DesignError

__all__ = ["MAX_TABLE_BYTES", "read_table_file"]

MAX_TABLE_BYTES = 16 * 1024 * 1024
"""Largest point-table file read [bytes] (16 MiB)."""


def _shown(path: Path | str) -> str:
    """A path for a one-line message: control characters escaped, length capped."""
    text = repr(str(path))
    return text if len(text) <= 200 else text[:100] + "…" + text[-99:]


def read_table_file(name: str, *, folder: Path | None, where: str, confine_to: Path | None = None) -> str:
    """The text of a point table's file, read by the rules of the module notes.

    Parameters
    ----------
    name
        The path as the design states it; relative paths are taken from ``folder``.
    folder
        The design file's folder (None: the working folder).
    where
        Field path for errors (``motion[0].file``).
    confine_to
        A folder the resolved path (symlinks followed) must stay inside;
        None: no confinement.

    Returns
    -------
    str
        The file's text (UTF-8; a BOM at the start is dropped).

    Raises
    ------
    DesignError
        Naming ``where`` and the path: not found, not a regular file, too
        large, outside ``confine_to``, not UTF-8, or unreadable.
    """
    if "\0" in name:
        raise DesignError(where, "the path holds a NUL character; allowed: a file name")
    file = (folder if folder is not None else Path.cwd()) / name
    if confine_to is not None:
        root = Path(os.path.realpath(confine_to))
        real = Path(os.path.realpath(file))
        if not real.is_relative_to(root):
            raise DesignError(
                where,
                f"{_shown(name)} leads outside the design's folder; allowed: a file inside {_shown(root)}",
            )
    flags = (
        os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    )
    try:
        fd = os.open(file, flags)
    except OSError as err:
        raise DesignError(where, f"cannot read {_shown(file)}: {err.strerror or err}") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            what = (
                "a folder" if stat.S_ISDIR(info.st_mode) else "not a regular file (a device, pipe or socket)"
            )
            raise DesignError(where, f"cannot read {_shown(file)}: it is {what}; allowed: a regular file")
        if info.st_size > MAX_TABLE_BYTES:
            raise DesignError(
                where,
                f"cannot read {_shown(file)}: {info.st_size} bytes; allowed: at most {MAX_TABLE_BYTES} "
                f"bytes (16 MiB)",
            )
        chunks: list[bytes] = []
        size = 0
        while size <= MAX_TABLE_BYTES:
            chunk = os.read(fd, min(1 << 20, MAX_TABLE_BYTES + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as err:
        raise DesignError(where, f"cannot read {_shown(file)}: {err.strerror or err}") from None
    finally:
        os.close(fd)
    if size > MAX_TABLE_BYTES:  # the file grew after fstat
        raise DesignError(
            where, f"cannot read {_shown(file)}: allowed: at most {MAX_TABLE_BYTES} bytes (16 MiB)"
        )
    data = b"".join(chunks)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise DesignError(
            where, f"{_shown(file)} is not UTF-8 text (byte offset {err.start}); allowed: a UTF-8 CSV"
        ) from None
