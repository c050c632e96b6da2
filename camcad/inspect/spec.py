"""The options of a tolerance study (the design file's ``[tolerance]`` table, issue 38).

Nothing here reads the file: :func:`camcad.design.schema.parse_tolerance`
validates the table and builds a :class:`ToleranceSpec`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from camcad.inspect.tolerance import Method, Tolerance

__all__ = ["Evaluation", "StudyMethod", "ToleranceSpec"]


class StudyMethod(enum.Enum):
    """How ``camcad tolerance`` spreads the errors: Monte Carlo on made cams, or first order."""

    MONTE_CARLO = "monte-carlo"
    LINEAR = "linear"


class Evaluation(enum.Enum):
    """How the Monte-Carlo made cams are evaluated: each re-solved, or by the certified quadratics.

    ``EXACT``: every made cam re-solved (:func:`camcad.inspect.tolerance.variant_figures`);
    ``QUADRATIC``: every figure as a quadratic in the errors fitted on a stencil of
    re-solved cams and certified on a sample (:mod:`camcad.inspect.batch`), for 10⁵–10⁶ variants.
    """

    EXACT = "exact"
    QUADRATIC = "quadratic"


@dataclass(frozen=True, slots=True, kw_only=True)
class ToleranceSpec:
    """A tolerance study.

    Attributes
    ----------
    tolerances
        The toleranced quantities (mm; ``PHASE`` rad), in the order of the file's keys.
    keys
        The design-file key of each (``tolerance.form_pm``), for messages and tables.
    samples, seed
        Monte-Carlo variants and the seed of NumPy's default generator.
    method
        Monte Carlo (with the linear figures beside it) or linear only.
    dwell_accuracy
        Required dwell accuracy ±E [lift unit: mm, or degrees of swing] for the
        allocation; None: no allocation.
    confidence
        Fraction of parts within ±E for an RSS allocation, in (0, 1).
    allocation
        ``RSS`` or ``WORST_CASE``.
    evaluation
        ``EXACT`` or ``QUADRATIC`` (Monte Carlo only).
    """

    tolerances: tuple[Tolerance, ...]
    keys: tuple[str, ...]
    samples: int = 1000
    seed: int = 0
    method: StudyMethod = StudyMethod.MONTE_CARLO
    dwell_accuracy: float | None = None
    confidence: float = 0.9973
    allocation: Method = Method.RSS
    evaluation: Evaluation = Evaluation.EXACT
