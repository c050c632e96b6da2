"""Why a fit stops short of its tolerance: the :class:`FitError` that names the binding knob.

The count search stops at the smaller of two limits: the control-point
budget (the caller's ``max_control_points``, or the automatic one) and the
room the samples leave for knots. The error names the binding one in the
caller's own words (a design field path such as ``fit.max_control_points``,
also its ``field``), with its value, the control points reached, the best certified error and a
way out.
"""

from __future__ import annotations

from dataclasses import dataclass

from camcad.errors import FitError
from camcad.knobs import Knob

__all__ = ["Names", "SamplesTooFewError", "limit_error"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Names:
    """What the caller calls the knobs, for :class:`FitError` messages.

    ``samples`` None means the caller, not the user, chose the samples: a
    sample limit is then reported against the tolerance.
    """

    tolerance: str | Knob = "tolerance"
    max_control_points: str | Knob = "max_control_points"
    samples: str | Knob | None = "points"


class SamplesTooFewError(FitError):
    """The samples are too sparse for the control points the tolerance needs."""


def limit_error(
    *,
    names: Names,
    tolerance: float,
    n_samples: int,
    max_control_points: int,
    automatic_budget: bool,
    samples_bind: bool,
    reached: int,
    best: int | None,
    best_error: float,
    needed: int | None,
) -> FitError:
    """The error for a search that stopped short of the tolerance.

    Parameters
    ----------
    names
        The caller's names of the knobs.
    tolerance
        Requested tolerance [mm].
    n_samples
        Samples the fit used.
    max_control_points
        The budget (the caller's, or the automatic one).
    automatic_budget
        Whether the budget is the automatic one.
    samples_bind
        Whether the samples' room, not the budget, stopped the search.
    reached
        Control points of the largest count tried.
    best
        Control points of the count with the best certified error (None if
        no count gave a finite fit).
    best_error
        Its certified error [mm] (inf without a fit).
    needed
        Control points the h^{p+1} law predicts for the tolerance, if known.

    Returns
    -------
    FitError
        :class:`SamplesTooFewError` when the samples bind, else
        :class:`FitError`; ``best_error`` and ``control_points`` attached.
    """
    tol = f"{names.tolerance} = {tolerance:.3g} mm"
    at_best = "no finite fit" if best is None else f"best certified error {best_error:.3g} mm"
    if best is not None:
        at_best += f" with {best} control points"
    cps = reached if best is None else best
    if samples_bind and names.samples is None:
        message = (
            f"{names.tolerance}: {tolerance:.3g} mm is out of reach: {n_samples} samples leave room for "
            f"at most {reached} control points ({at_best}); relax {names.tolerance}"
        )
        return SamplesTooFewError(
            message, best_error=best_error, control_point_count=cps, field=names.tolerance
        )
    if samples_bind:
        message = (
            f"{names.samples}: {n_samples} samples leave room for at most {reached} control points, too "
            f"few for {tol} ({at_best}); sample more finely ({names.samples}) or relax {names.tolerance}"
        )
        return SamplesTooFewError(
            message, best_error=best_error, control_point_count=cps, field=names.samples or ""
        )
    if automatic_budget:
        message = (
            f"{names.tolerance}: {tolerance:.3g} mm is out of reach: the search reached {reached} control "
            f"points (the automatic limit, {max_control_points}), {at_best}; relax {names.tolerance} "
            f"(or set {names.max_control_points} higher if memory allows)"
        )
        return FitError(message, best_error=best_error, control_point_count=cps, field=names.tolerance)
    need = "" if needed is None else f" (about {needed} needed)"
    message = (
        f"{names.max_control_points}: {max_control_points} control points are too few for {tol}: the "
        f"search reached {reached}, {at_best}; raise {names.max_control_points}{need}, leave it out "
        f"(automatic) or relax {names.tolerance}"
    )
    return FitError(message, best_error=best_error, control_point_count=cps, field=names.max_control_points)
