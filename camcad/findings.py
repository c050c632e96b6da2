"""Typed findings: what an analysis found about a design, made once, rendered everywhere.

A :class:`Finding` is a broken limit (or a note) with the design field that
controls it, the value reached, the limit and one sentence for a person. Every
stage reports its messages this way, and only this way (no free warning
strings); the CLI, the report and ``summary.json`` render them, and one rule
decides what stops a build:

- **hard** limits make the part unusable (undercut, a flat face narrower than
  the contact's travel, a velocity jump, gouge, an unreachable fit
  tolerance): ``build`` stops with exit 3 and writes nothing;
- **soft** limits are engineering judgement (pressure angle, contact stress,
  follower jump): ``build`` writes the files and lists them as warnings, and
  ``build --strict`` turns them into exit 3;
- ``check`` exits 3 on either;
- **notes** are neither: what a person should know about the result (a
  model's assumption that does not hold everywhere, an FE load case left
  out). They never change an exit code.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Any

from camcad.knobs import Blame

__all__ = ["Finding", "Severity"]


class Severity(enum.Enum):
    """Whether a finding stops a build (hard), is a broken soft limit (soft) or only informs (note)."""

    HARD = "hard"
    SOFT = "soft"
    NOTE = "note"


@dataclass(frozen=True, slots=True, kw_only=True)
class Finding:
    """One broken design limit, or a note about the result.

    Attributes
    ----------
    kind
        What broke, e.g. ``"undercut"``, ``"pressure angle"`` (a note: what it is about).
    severity
        :class:`Severity`.
    field
        The design field that controls it, e.g. ``"cam.base_radius"``; a
        stage below the design layer names a :class:`~camcad.knobs.Knob`
        (or :class:`~camcad.knobs.TableKey`),
        which the design layer turns into the path
        (:func:`camcad.design.paths.named_finding`).
    message
        One sentence for a person: what, where, how much, and a way out.
    field_first
        Whether the message is shown with its field in front
        (``"cam.base_radius: undercut at …"``): a stage that names a knob
        leaves the path out of its text and sets this; naming the finding
        puts the path in front and clears it.
    angle
        Cam angle where it is worst [rad], or ``None``.
    value, limit
        The value reached and the limit, in ``unit``, or ``None``.
    unit
        Unit of ``value`` and ``limit`` (``"mm"``, ``"deg"``, ``"N"``, ``"MPa"``).
    """

    kind: str
    severity: Severity
    field: str | Blame
    message: str
    field_first: bool = False
    angle: float | None = None
    value: float | None = None
    limit: float | None = None
    unit: str = ""

    @property
    def hard(self) -> bool:
        """Whether this finding stops a build."""
        return self.severity is Severity.HARD

    @property
    def note(self) -> bool:
        """Whether this finding only informs: no limit is broken, no exit code changes."""
        return self.severity is Severity.NOTE

    @property
    def rank(self) -> int:
        """Sort key: hard findings first, then soft, then notes."""
        return _RANK[self.severity]

    def summary(self) -> dict[str, Any]:
        """JSON-ready dict for ``summary.json`` (angle in degrees)."""
        return {
            "kind": self.kind,
            "severity": self.severity.value,
            "field": str(self.field),
            "angle_deg": None if self.angle is None else round(math.degrees(self.angle), 6),
            "value": self.value,
            "limit": self.limit,
            "unit": self.unit,
            "message": f"{self.field}: {self.message}" if self.field_first else self.message,
        }


_RANK = {Severity.HARD: 0, Severity.SOFT: 1, Severity.NOTE: 2}
