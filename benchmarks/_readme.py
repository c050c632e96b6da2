"""Each benchmark script writes its own section of ``benchmarks/README.md``.

A section is the text between ``<!-- BEGIN name -->`` and ``<!-- END name -->``;
:func:`replace_section` swaps it for a new one (appending the section when the
file has none of that name) and leaves every other byte of the file as it was.
:func:`publish` heads the script's table with the command, the machine, the
date and the load average, since absolute times move with the machine's load.
:func:`captured` runs a block, echoes what it prints and publishes it when the
block ends without an error (a failed run leaves the file as it was).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import io
import os
import platform
import re
import sys
from collections.abc import Iterator
from pathlib import Path

README = Path(__file__).resolve().parent / "README.md"


def _markers(name: str) -> tuple[str, str]:
    if not re.fullmatch(r"[a-z0-9][a-z0-9_-]*", name):
        raise ValueError(f"section name {name!r}: lower-case letters, digits, '-' and '_' only")
    return f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"


def replace_section(text: str, name: str, body: str) -> str:
    """``text`` with the section ``name`` holding ``body`` (appended at the end if absent).

    Raises
    ------
    ValueError
        When the markers of ``name`` are unbalanced or out of order (the file is not guessed at).
    """
    begin, end = _markers(name)
    inner = f"{begin}\n{body.strip()}\n{end}"
    starts, ends = text.count(begin), text.count(end)
    if starts == 0 and ends == 0:
        return f"{text.rstrip()}\n\n{inner}\n" if text.strip() else f"{inner}\n"
    if starts != 1 or ends != 1 or text.index(begin) > text.index(end):
        raise ValueError(f"{README.name}: the markers of section {name!r} are not one BEGIN before one END")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + inner + tail


def machine() -> str:
    """One line: CPU model, core count, Python, date (UTC) and the 1-minute load average."""
    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    try:
        load = f"{os.getloadavg()[0]:.2f}"
    except (OSError, AttributeError):
        load = "unknown"
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {now}, load average {load}"


def publish(name: str, body: str, command: str | None = None, path: Path = README) -> None:
    """Write ``body`` (markdown) as section ``name`` of ``path``, headed by the command and the machine.

    Headings in ``body`` move two levels down, below the file's own ``##`` heading of the section.
    """
    command = command or "python " + " ".join(["benchmarks/" + Path(sys.argv[0]).name, *sys.argv[1:]])
    head = f"Written by `{command}` on {machine()}.\n\n"
    body = re.sub(r"^(#{1,4}) ", r"\1## ", body, flags=re.MULTILINE)  # its headings nest under the section's
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    new = replace_section(old, name, head + body)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(new, encoding="utf-8")
    os.replace(tmp, path)


class _Tee(io.TextIOBase):
    def __init__(self, echo: io.TextIOBase | object) -> None:
        self.echo = echo
        self.parts: list[str] = []

    def write(self, s: str) -> int:
        self.parts.append(s)
        self.echo.write(s)  # type: ignore[attr-defined]
        return len(s)

    def flush(self) -> None:
        self.echo.flush()  # type: ignore[attr-defined]


@contextlib.contextmanager
def captured(name: str, command: str | None = None, fence: bool = False) -> Iterator[None]:
    """Echo what the block prints to stdout and publish it as section ``name`` when it succeeds.

    ``fence`` keeps output that is not markdown (plain columns) as a fenced text block.
    """
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        yield
    text = "".join(tee.parts).strip()
    if text and fence:
        text = f"```text\n{text}\n```"
    if text:
        publish(name, text, command)
