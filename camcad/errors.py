"""The camcad error hierarchy and the exit code each error maps to.

Exit codes are defined here once: each error class carries its code in the
class attribute ``exit_code`` and :func:`exit_code` maps any exception.
``DesignError`` is bad input (exit 2), with its subclass ``UsageError`` for
a bad command-line option; ``OutputError`` is an output file or folder that
cannot be written (exit 2); ``DesignLimitError`` is a valid design that breaks
a limit the user cannot ignore, such as undercut or gouge (exit 3).

Every error carries the design field it concerns as data, ``field`` (a TOML
path such as ``cam.base_radius``, an option such as ``--output``, or empty),
set by the caller that knows the path; a stage below the design layer names a
:class:`~camcad.knobs.Knob` (or :class:`~camcad.knobs.TableKey`) instead, which the
design layer turns into the path where the error leaves the core
(:func:`camcad.design.paths.named_error`); its text names it (in front,
``"cam.base_radius: undercut at …"``, unless the message names it already),
so nothing reads it back out of a message.
"""

from __future__ import annotations

import errno
import os
import unicodedata

from camcad.knobs import Blame

__all__ = [
    "EXIT_INTERRUPTED",
    "EXIT_INVALID",
    "EXIT_LIMIT",
    "EXIT_OK",
    "EXIT_PIPE_CLOSED",
    "EXIT_UNEXPECTED",
    "ArcSearchStallError",
    "CamcadError",
    "DesignError",
    "DesignLimitError",
    "ExportError",
    "FitError",
    "GcodeSyntaxError",
    "GougeError",
    "NotStarShapedError",
    "OutputError",
    "UndercutError",
    "UsageError",
    "ValueRuleError",
    "exit_code",
    "printable",
]

EXIT_OK = 0
EXIT_UNEXPECTED = 1
EXIT_INVALID = 2  # bad input: usage, design file, output folder
EXIT_LIMIT = 3  # a design limit is violated
EXIT_INTERRUPTED = 130  # 128 + SIGINT, also used for SIGTERM and SIGHUP
EXIT_PIPE_CLOSED = 141  # 128 + SIGPIPE: the reader of stdout went away


def printable(text: str) -> str:
    r"""``text`` with every control character and line or paragraph separator escaped (``\n``, ``\x1b``).

    A user's string in an error line (a file name with a newline in it)
    cannot start a second line or move the cursor: the message stays one line.

    Examples
    --------
    >>> printable("a.csv\ncamcad: error: forged")
    'a.csv\\ncamcad: error: forged'
    """
    if text.isprintable():
        return text
    return "".join(
        ch.encode("unicode_escape").decode("ascii") if unicodedata.category(ch) in ("Cc", "Zl", "Zp") else ch
        for ch in text
    )


class CamcadError(Exception):
    """Base class for all camcad errors (its text is one line: control characters escaped).

    Parameters
    ----------
    *args
        The message (as for :class:`Exception`).
    field
        The design field (TOML path, or a stage's :class:`~camcad.knobs.Knob`
        or :class:`~camcad.knobs.TableKey`) or command-line option the error
        concerns, empty when none; the text starts with it.
    """

    exit_code: int = EXIT_UNEXPECTED
    field: str | Blame = ""

    def __init__(self, *args: object, field: str | Blame = "") -> None:
        super().__init__(*args)
        self.field = field

    def __str__(self) -> str:
        """``field: message`` with control characters escaped (:func:`printable`).

        The field is put in front unless the message names it already (a
        limit's message that names its field for the report too).
        """
        text = super().__str__()
        if self.field and str(self.field) not in text:
            text = f"{self.field}: {text}"
        return printable(text)

    @property
    def message(self) -> str:
        """What is wrong, without the field in front (``field`` holds it)."""
        text = str(self.args[0]) if self.args else ""
        return text.removeprefix(f"{self.field}: ") if self.field else text

    def with_field(self, field: str | Blame) -> CamcadError:
        """Name ``field`` unless a field is named already (a caller that knows the TOML path)."""
        if not self.field:
            self.field = field
        return self


class DesignError(CamcadError, ValueError):
    """The design file or a specification is invalid (CLI exit 2).

    Parameters
    ----------
    path
        Field path such as ``motion[2].angle`` (empty for file-level errors),
        kept as ``field``.
    message
        What is wrong, with the value and what is allowed.
    """

    def __init__(self, path: str | Blame, message: str) -> None:
        super().__init__(message, field=path)

    def __str__(self) -> str:
        """``path: message``, always in that form (escaped, :func:`printable`)."""
        text = str(self.args[0]) if self.args else ""
        return printable(f"{self.field}: {text}" if self.field else text)

    @property
    def path(self) -> str | Blame:
        """The field path (``field``; this older name stays for callers that use it)."""
        return self.field

    exit_code = EXIT_INVALID


class UsageError(DesignError):
    """A command-line option has a value that is not allowed (CLI exit 2); ``path`` is the option."""


class ValueRuleError(DesignError):
    """A design value breaks its key's own rule (type, range, word), the rule ``camcad schema`` states too."""


# What to do about an operating-system error while writing output, by errno.
_OUTPUT_ADVICE = {
    errno.ENOSPC: "free space on that disk or choose another --output",
    errno.EDQUOT: "free space within your disk quota or choose another --output",
    errno.EACCES: "make it writable or choose another --output",
    errno.EPERM: "make it writable or choose another --output",
    errno.EROFS: "the disk is read-only; choose another --output",
    errno.EEXIST: "remove or rename it, or choose another --output",
    errno.EISDIR: "a folder of that name is in the way; remove or rename it, or choose another --output",
    errno.ENOTDIR: "a file is in the way of a folder; remove or rename it, or choose another --output",
    errno.ENAMETOOLONG: "choose a shorter --output",
}


class OutputError(CamcadError, OSError):
    """An output file or folder cannot be written (CLI exit 2).

    The message names ``--output``, the real path the user asked for (never
    a hidden temporary one), what went wrong and what to do.

    Parameters
    ----------
    path
        The file or folder in the user's output folder.
    problem
        What went wrong, e.g. ``"no space left on device"``.
    advice
        What to do; empty when there is nothing useful to say.
    """

    exit_code = EXIT_INVALID

    def __init__(self, path: str | os.PathLike[str], problem: str, advice: str = "") -> None:
        self.path = os.fspath(path)
        self.problem = problem
        self.advice = advice
        super().__init__(f"--output: cannot write {self.path}: {problem}" + (f"; {advice}" if advice else ""))
        self.field = "--output"  # the text names it already (``__str__`` below)
        self.filename = self.path

    def __str__(self) -> str:
        """The one-line message (``OSError`` would format errno and filename instead)."""
        return printable(str(self.args[0]))

    @classmethod
    def from_os_error(cls, err: OSError, path: str | os.PathLike[str]) -> OutputError:
        """The error for ``err`` raised while writing ``path``, with advice chosen by its errno."""
        problem = (err.strerror or str(err) or type(err).__name__).lower()
        new = cls(path, problem, _OUTPUT_ADVICE.get(err.errno or 0, "choose another --output"))
        new.errno = err.errno
        return new


class DesignLimitError(CamcadError):
    """A valid design violates a hard design limit (CLI exit 3)."""

    exit_code = EXIT_LIMIT


class UndercutError(DesignLimitError):
    """The pitch curve is sharper than the roller, or a flat-follower profile has a cusp."""

    def __init__(
        self,
        message: str,
        *,
        phi_range: tuple[float, float],
        worst: float,
        suggested_base_radius: float | None,
        field: str | Blame = "",
    ) -> None:
        super().__init__(message, field=field)
        self.phi_range = phi_range
        self.worst = worst
        self.suggested_base_radius = suggested_base_radius


class GougeError(DesignLimitError):
    """The milling tool is larger than a concave radius of the profile."""

    def __init__(
        self, message: str, *, phi_range: tuple[float, float], max_tool_radius: float, field: str | Blame = ""
    ) -> None:
        super().__init__(message, field=field)
        self.phi_range = phi_range
        self.max_tool_radius = max_tool_radius


class FitError(DesignLimitError):
    """The NURBS fit cannot meet the tolerance within the control-point budget (a hard limit)."""

    def __init__(
        self, message: str, *, best_error: float, control_point_count: int, field: str | Blame = ""
    ) -> None:
        super().__init__(message, field=field)
        self.best_error = best_error
        self.control_point_count = control_point_count

    exit_code = EXIT_LIMIT


class ExportError(CamcadError):
    """An export produced a file that failed its own check (e.g. a non-manifold solid)."""


class NotStarShapedError(DesignLimitError, ExportError):
    """A ray from the cam axis meets the profile twice, so a polar table (lift.csv) cannot be written."""


class GcodeSyntaxError(CamcadError, ValueError):
    """A G-code line the reader does not understand (exit 2: bad input).

    Parameters
    ----------
    line_no
        1-based number of the line in the program.
    line
        The line as read.
    why
        What is wrong with it.
    """

    exit_code = EXIT_INVALID

    def __init__(self, line_no: int, line: str, why: str) -> None:
        super().__init__(f"line {line_no}: {why}: {line.strip()!r}")
        self.line_no = line_no


class ArcSearchStallError(CamcadError, ValueError):
    """The arc search found no arc that passes its measurement (the fit falls back to the biarc march).

    Internal: the arc-spline fit catches it, so it reaching a user is a bug (exit 1).
    """

    exit_code = EXIT_UNEXPECTED


def exit_code(err: BaseException) -> int:
    """Map an exception to the CLI exit code: 2 bad input, 3 design limit, 1 otherwise.

    A camcad error carries its code; any other ``OSError`` is an unreadable
    input or unwritable output (2); ``KeyboardInterrupt`` is 130.
    """
    if isinstance(err, CamcadError):
        return err.exit_code
    if isinstance(err, OSError):
        return EXIT_INVALID
    if isinstance(err, KeyboardInterrupt):
        return EXIT_INTERRUPTED
    return EXIT_UNEXPECTED
