"""The camcad error hierarchy and the exit code each error maps to.

``DesignError`` is bad input (exit 2); ``DesignLimitError`` is a valid design
that breaks a limit the user cannot ignore, such as undercut or gouge (exit 3).
"""

from __future__ import annotations

__all__ = [
    "CamcadError",
    "DesignError",
    "DesignLimitError",
    "ExportError",
    "FitError",
    "GougeError",
    "JumpError",
    "UndercutError",
    "exit_code",
]


class CamcadError(Exception):
    """Base class for all camcad errors."""


class DesignError(CamcadError, ValueError):
    """The design file or a specification is invalid (CLI exit 2).

    Parameters
    ----------
    path
        Field path such as ``motion[2].angle`` (empty for file-level errors).
    message
        What is wrong, with the value and what is allowed.
    """

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        self.message = message
        super().__init__(f"{path}: {message}" if path else message)


class DesignLimitError(CamcadError):
    """A valid design violates a hard design limit (CLI exit 3)."""


class UndercutError(DesignLimitError):
    """The pitch curve is sharper than the roller, or a flat-follower profile has a cusp."""

    def __init__(
        self,
        message: str,
        *,
        phi_range: tuple[float, float],
        worst: float,
        suggested_base_radius: float | None,
    ) -> None:
        super().__init__(message)
        self.phi_range = phi_range
        self.worst = worst
        self.suggested_base_radius = suggested_base_radius


class GougeError(DesignLimitError):
    """The milling tool is larger than a concave radius of the profile."""

    def __init__(self, message: str, *, phi_range: tuple[float, float], max_tool_radius: float) -> None:
        super().__init__(message)
        self.phi_range = phi_range
        self.max_tool_radius = max_tool_radius


class JumpError(DesignLimitError):
    """The follower leaves the cam (contact force below the margin)."""


class FitError(CamcadError):
    """The NURBS fit cannot meet the tolerance within the control-point budget."""

    def __init__(self, message: str, *, best_error: float, control_points: int) -> None:
        super().__init__(message)
        self.best_error = best_error
        self.control_points = control_points


class ExportError(CamcadError):
    """An export produced a file that failed its own check (e.g. a non-manifold solid)."""


def exit_code(err: BaseException) -> int:
    """Map an exception to the CLI exit code: 2 bad input, 3 design limit, 1 otherwise."""
    if isinstance(err, (DesignError, OSError)):
        return 2
    if isinstance(err, (DesignLimitError, FitError)):
        return 3
    return 1
