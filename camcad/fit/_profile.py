"""Tolerance-driven B-spline fit of a cam profile or any ordered point set.

Public names are re-exported by :mod:`camcad.fit`. The search picks the
smallest number of control points whose certified error (the largest true
distance from the exact profile to the curve, bounded over the whole turn by
:func:`camcad.fit.certify.certify_exact`, or from the samples when no exact
profile is known) is below the tolerance:

1. fixed knots: u = 0 and the motion breakpoints (multiplicity p − k);
2. for a count of free knots: place them (:mod:`camcad.fit.knots`), fit by
   least squares over chord-length parameters (Quang & Hung 2015, eq. 10),
   move the parameters one step towards the foot points and refit
   (parameter correction, Hoschek 1988), then re-place the knots from the
   refit's errors; a few passes, keeping the best;
3. choose counts by the h^{p+1} law until one passes, then scan a window of
   smaller counts (the max error is not monotone in the count, so no
   bisection). Counts are compared on a subsample of about
   ``SEARCH_SAMPLES`` points (more for programs of many segments); the chosen
   one is refitted on all samples and certified (:mod:`camcad.fit.certify`);
   if the certificate fails, the search goes on.

The budget is the caller's ``max_control_points`` or, by default, as many
control points as the samples leave room for (``MIN_SAMPLE_GAP`` samples
between knots), up to ``AUTO_MAX_CONTROL_POINTS``; it scales with the
program (more segments, more samples between breakpoints, more room).

References
----------
.. [1] Quang & Hung (2015), Computer aided cam design of roller-follower cam
   mechanism (../shared/papers/002_3938fa916e46e710.txt).
.. [2] Piegl & Tiller (1997), The NURBS Book, 2nd ed., Springer.
   doi:10.1007/978-3-642-59223-2
.. [3] Hoschek (1988), Intrinsic parametrization for approximation, Computer
   Aided Geometric Design 5(1), 27–31. doi:10.1016/0167-8396(88)90017-9
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.errors import FitError
from camcad.fit._limits import Names, limit_error
from camcad.fit.bspline import (
    SplineFit,
    chord_length_params,
    clamped_from_periodic,
    lsq_clamped,
    lsq_periodic,
)
from camcad.fit.certify import (
    Certificate,
    ExactProfile,
    certify,
    certify_exact,
    certify_exact_open,
    normal_distance,
    seam_jumps,
)
from camcad.fit.curve import BSplineCurve
from camcad.fit.knots import (
    MIN_SAMPLE_GAP,
    Density,
    FixedKnots,
    density_from_fit,
    estimate_free_knots,
    fixed_knots,
    place_knots,
)
from camcad.fit.result import ProfileFit
from camcad.fit.seam import longest_stretch, seam_parameter

__all__ = ["Breakpoint", "ProfileFit", "fit_open_profile", "fit_points", "fit_profile"]


@runtime_checkable
class Breakpoint(Protocol):
    """A motion breakpoint as :func:`fit_profile` reads it (e.g. ``camcad.motion.program.Breakpoint``)."""

    @property
    def phi(self) -> float:
        """Cam angle φ_k of the breakpoint [rad]."""

    @property
    def continuity(self) -> int:
        """The profile is C^k there."""


REPLACEMENTS = 2  # knot placements per count (equidistribution passes); more did not pay
WINDOW = 3  # smaller counts that must all fail before a count is accepted
START_SPANS = 16  # spans of the first count tried (then the h^{p+1} law)
SEARCH_SAMPLES = 1200  # the count search runs on about this many samples
SEARCH_SAMPLES_PER_SEGMENT = 24  # ... but at least this many per segment between breakpoints
AUTO_MAX_CONTROL_POINTS = 2500  # default budget: a 2500² float64 normal matrix is 50 MB


@dataclass(frozen=True, slots=True, kw_only=True)
class _Problem:
    """What the search needs: samples, parameters, fixed knots, limits."""

    params: FloatArray
    points: FloatArray
    exact: ExactProfile | None
    fixed: FixedKnots
    degree: int
    tolerance: float
    max_control_points: int
    automatic_budget: bool  # max_control_points is AUTO_MAX_CONTROL_POINTS, not the caller's
    names: Names
    seam_window: tuple[float, float] | None = None  # u of the middle half of the longest stretch

    @property
    def periodic(self) -> bool:
        return self.fixed.periodic

    def control_point_count(self, n_free: int) -> int:
        """Control points of the clamped form for ``n_free`` free knots (at most).

        A closed curve opened at a knot of multiplicity μ has
        (knots per period) + p + 1 − μ; inside the longest stretch μ = 1 if a
        free knot lies near its middle, else 0, which is what is counted.
        """
        p = self.degree
        if self.periodic:
            seam = int(self.fixed.multiplicity[0]) if self.seam_window is None else 0
            return self.fixed.n_fixed + n_free - seam + p + 1
        return self.fixed.n_fixed + n_free + p + 1

    def n_free_bounds(self) -> tuple[int, int]:
        """Smallest and largest admissible free-knot counts."""
        p = self.degree
        lo = max(0, p + 1 - self.fixed.n_fixed) if self.periodic else 0
        return lo, min(self.max_control_points - self.control_point_count(0), self.room())

    def room(self) -> int:
        """Free knots the samples allow (``MIN_SAMPLE_GAP`` samples between neighbours)."""
        t_ext = np.append(self.params, 1.0) if self.periodic else self.params
        index = np.interp(self.fixed.edges, t_ext, np.arange(len(t_ext), dtype=float))
        return int(np.sum(np.maximum(np.floor(np.diff(index) / MIN_SAMPLE_GAP) - 1, 0)))


@dataclass(frozen=True, slots=True, kw_only=True)
class _Trial:
    """The best layout found for one free-knot count."""

    n_free: int
    curve: BSplineCurve | None  # None when every layout was singular (error = inf)
    error: float  # mm, quick (normal-residual) max error at the samples
    density: Density  # knot density from this trial's errors
    params: FloatArray  # (n,) sample parameters after correction towards the foot points


def _fit_layout(problem: _Problem, knots: FloatArray, params: FloatArray) -> SplineFit:
    """Least-squares curve for one knot layout (Quang & Hung 2015, eq. 10)."""
    if problem.periodic:
        return lsq_periodic(params, problem.points, knots, problem.degree)
    return lsq_clamped(params, problem.points, knots, problem.degree)


def _corrected(params: FloatArray, fit: SplineFit, points: FloatArray, periodic: bool) -> FloatArray:
    """Parameters moved one Gauss–Newton step towards the foot points.

    Δt_i = (C(t_i) − D_i)·C'(t_i) / |C'(t_i)|² removes the tangential part of
    the residual, which the least-squares fit would otherwise spend control
    points on (parameter correction, Hoschek 1988; Piegl & Tiller 1997,
    §9.4.1). Falls back to ``params`` if the order of the samples would change.
    """
    r = fit.at_params - points
    d1 = fit.tangent_at_params
    new: FloatArray = params - np.einsum("ij,ij->i", r, d1) / np.einsum("ij,ij->i", d1, d1)  # Hoschek 1988
    if periodic:
        new = np.clip(new, 0.0, np.nextafter(1.0, 0.0))
    else:
        new = np.clip(new, 0.0, 1.0)
        new[0], new[-1] = 0.0, 1.0
    if np.any(np.diff(new) <= 0.0):
        return params
    readonly(new)
    return new


def _run_trial(problem: _Problem, n_free: int, density: Density, passes: int) -> _Trial:
    """Fit ``n_free`` free knots, placing them ``passes`` times; keep the best.

    Each pass places the knots by the current density, fits over the
    chord-length parameters, corrects the parameters once and refits
    (Quang & Hung 2015, eq. 10; Hoschek 1988), then derives the next density
    from the refit (:func:`camcad.fit.knots.density_from_fit`).
    """
    best = _Trial(n_free=n_free, curve=None, error=math.inf, density=density, params=problem.params)
    for _ in range(passes):
        knots = place_knots(problem.fixed, density, n_free, problem.params)
        try:
            fit = _fit_layout(problem, knots, problem.params)
            params = _corrected(problem.params, fit, problem.points, problem.periodic)
            fit = _fit_layout(problem, knots, params)
        except np.linalg.LinAlgError:
            break
        err = normal_distance(fit.at_params, fit.tangent_at_params, problem.points)
        density = density_from_fit(fit.curve, knots, problem.fixed, params, err)
        emax = float(np.max(err))
        if emax < best.error:
            best = _Trial(n_free=n_free, curve=fit.curve, error=emax, density=density, params=params)
    return best


def _subsample(problem: _Problem, size: int) -> _Problem:
    """Every k-th sample (ends kept), so the count search costs O(size), not O(n)."""
    n = len(problem.params)
    stride = max(1, n // size)
    if stride == 1:
        return problem
    idx = np.arange(0, n, stride)
    if not problem.periodic and idx[-1] != n - 1:
        idx = np.append(idx, n - 1)
    return dataclasses.replace(problem, params=problem.params[idx], points=problem.points[idx], exact=None)


@dataclass(slots=True)
class _Search:
    """Memoised trials of free-knot counts (mutable working state, private).

    Counts are compared on ``coarse`` (a subsample); the chosen count is
    refitted on all samples (``finals``) and certified there.
    """

    problem: _Problem
    coarse: _Problem
    trials: dict[int, _Trial] = field(default_factory=dict)
    finals: dict[int, _Trial] = field(default_factory=dict)
    rejected: dict[int, float] = field(default_factory=dict)

    def error(self, n_free: int) -> float:
        """Quick max error for ``n_free`` (or the certified one if rejected)."""
        if n_free in self.rejected:
            return self.rejected[n_free]
        return self.run(n_free).error

    def passes(self, n_free: int) -> bool:
        return self.error(n_free) <= self.problem.tolerance

    def run(self, n_free: int) -> _Trial:
        """Trial of ``n_free`` on the subsample, warm-started from the nearest count."""
        if n_free not in self.trials:
            near = min(self.trials, key=lambda k: abs(k - n_free), default=None)
            density = Density.uniform() if near is None else self.trials[near].density
            self.trials[n_free] = _run_trial(self.coarse, n_free, density, REPLACEMENTS)
        return self.trials[n_free]

    def final(self, n_free: int) -> _Trial:
        """Trial of ``n_free`` on all samples, from the subsample's knot density."""
        if n_free not in self.finals:
            trial = self.run(n_free)
            if self.coarse is not self.problem:
                full = _run_trial(self.problem, n_free, trial.density, REPLACEMENTS)
                trial = full if full.curve is not None else trial
            self.finals[n_free] = trial
        return self.finals[n_free]

    def certify(self, n_free: int) -> tuple[Certificate, Certificate | None]:
        """Full certificate: foot points of the samples, and the bound over the exact profile."""
        prob = self.problem
        trial = self.final(n_free)
        if trial.curve is None:  # only counts with a finite error are certified
            raise ValueError(f"no curve for {n_free} free knots")
        at_samples, _ = certify(trial.curve, prob.points, trial.params)
        if prob.exact is None:
            return at_samples, None
        bound = certify_exact if prob.periodic else certify_exact_open
        return at_samples, bound(trial.curve, prob.exact, prob.points, at_samples.foot)


def _certified_max(certs: tuple[Certificate, Certificate | None]) -> float:
    at_samples, between = certs
    return max(at_samples.max_error, between.max_error if between is not None else 0.0)


def _best_certified(search: _Search) -> tuple[int | None, float]:
    """(free-knot count, certified max error [mm]) of the best count tried, or (None, inf)."""
    finite = [k for k, t in search.trials.items() if t.curve is not None]
    if not finite:
        return None, math.inf
    best = min(finite, key=lambda k: search.error(k))
    err = search.error(best)
    if best not in search.rejected and search.final(best).curve is not None:
        err = _certified_max(search.certify(best))
    if search.rejected and min(search.rejected.values()) < err:
        best = min(search.rejected, key=search.rejected.__getitem__)
        err = search.rejected[best]
    return best, err


def _unreachable(search: _Search) -> FitError:
    """FitError naming the knob that stopped the search (:func:`camcad.fit._limits.limit_error`)."""
    prob = search.problem
    best, err = _best_certified(search)
    needed = None
    if best is not None and math.isfinite(err):
        est = estimate_free_knots(best, prob.fixed.n_segments, err, prob.tolerance, prob.degree)
        needed = prob.control_point_count(est)
    return limit_error(
        names=prob.names,
        tolerance=prob.tolerance,
        n_samples=len(prob.points),
        max_control_points=prob.max_control_points,
        automatic_budget=prob.automatic_budget,
        samples_bind=search.coarse.room() < prob.max_control_points - prob.control_point_count(0),
        reached=prob.control_point_count(max(search.trials, default=0)),
        best=None if best is None else prob.control_point_count(best),
        best_error=err,
        needed=needed,
    )


def _next_count(search: _Search, lo: int, hi: int) -> int | None:
    """The next free-knot count to try, or None when the smallest pass is settled.

    Without a passing count, go up by the h^{p+1} law. With one, go down
    from the smallest pass by the same law (but not below the largest
    failing count under it), then scan the ``WINDOW`` counts just below the
    smallest pass: it is settled once they all fail. The error is not
    monotone in the count, hence the scan rather than a bisection.
    """
    prob = search.problem
    p, segs, tol = prob.degree, prob.fixed.n_segments, prob.tolerance
    tried = {k: search.error(k) for k in search.trials}
    passing = sorted(k for k, e in tried.items() if e <= tol)
    if not passing:
        top = max(tried)
        if top >= hi:
            return None
        return min(max(estimate_free_knots(top, segs, tried[top], tol, p), top + 1), hi)
    best = passing[0]
    below = max((k for k in tried if k < best), default=None)
    est = estimate_free_knots(best, segs, tried[best], tol, p)
    est = min(max(est, lo, (below + 1) if below is not None else lo), best - 1)
    if est >= lo and est not in tried:
        return est
    return next((k for k in range(best - 1, best - WINDOW - 1, -1) if k >= lo and k not in tried), None)


def _search(problem: _Problem) -> tuple[BSplineCurve, tuple[Certificate, Certificate | None]]:
    """Smallest certified free-knot count (see the module docstring).

    The counts are compared on a subsample, which leaves room for fewer
    knots than all samples: if its room stops the search, the search runs
    again on a subsample four times larger (at last on all samples).
    """
    size = max(SEARCH_SAMPLES, SEARCH_SAMPLES_PER_SEGMENT * problem.fixed.n_segments)
    budget = problem.max_control_points - problem.control_point_count(0)
    while True:
        search = _Search(problem, _subsample(problem, size))
        try:
            return _search_on(search)
        except FitError:
            if search.coarse is problem or search.coarse.room() >= min(budget, problem.room()):
                raise
            size *= 4


def _search_on(search: _Search) -> tuple[BSplineCurve, tuple[Certificate, Certificate | None]]:
    """Run one search over the counts its subsample allows."""
    problem = search.problem
    lo, hi = search.coarse.n_free_bounds()
    if hi < lo:
        raise _unreachable(search)
    search.run(min(max(lo, START_SPANS - problem.fixed.n_segments), hi))
    while True:
        n_free = _next_count(search, lo, hi)
        if n_free is not None:
            search.run(n_free)
            continue
        passing = sorted(k for k in search.trials if search.passes(k))
        if not passing:
            # the refit on all samples may pass where the subsample did not
            best, err = _best_certified(search)
            if best is None or best in search.rejected or err > problem.tolerance:
                raise _unreachable(search)
            passing = [best]
        certs = search.certify(passing[0])
        err = _certified_max(certs)
        curve = search.final(passing[0]).curve
        if err <= problem.tolerance and curve is not None:
            return curve, certs
        search.rejected[passing[0]] = err  # failed between samples: settle again


def _result(
    problem: _Problem, curve: BSplineCurve, certs: tuple[Certificate, Certificate | None]
) -> ProfileFit:
    at_samples, _ = certs
    seam = None if problem.seam_window is None else seam_parameter(curve, *problem.seam_window)
    clamped = clamped_from_periodic(curve, seam=seam)
    params = at_samples.foot
    if problem.periodic:
        tangent_jump, curvature_jump = seam_jumps(clamped)
    else:
        tangent_jump, curvature_jump = 0.0, 0.0
    return ProfileFit(
        curve=curve,
        clamped=clamped,
        params=params,
        tolerance=problem.tolerance,
        max_error=_certified_max(certs),
        rms_error=at_samples.rms_error,
        control_point_count=len(clamped.control_points),
        degree=problem.degree,
        seam_tangent_jump=tangent_jump,
        seam_curvature_jump=curvature_jump,
        seam=0.0 if seam is None else seam,
    )


def _check_options(tolerance: float, max_control_points: int | None, degree: int) -> None:
    if not tolerance > 0.0:
        raise ValueError(f"tolerance must be > 0 mm, got {tolerance}")
    if degree < 1:
        raise ValueError(f"degree must be >= 1, got {degree}")
    if max_control_points is not None and max_control_points < 2 * (degree + 1):
        raise ValueError(
            f"max_control_points must be >= {2 * (degree + 1)} for degree {degree}, got {max_control_points}"
        )


def _check_points(points: FloatArray, degree: int) -> FloatArray:
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must have shape (n, 2), got {pts.shape}")
    if len(pts) < 4 * (degree + 1):
        raise ValueError(f"need at least {4 * (degree + 1)} points for degree {degree}, got {len(pts)}")
    if not np.all(np.isfinite(pts)):
        raise ValueError("points contain NaN or infinite values")
    return pts


def fit_profile(
    phi: FloatArray,
    points: FloatArray,
    *,
    exact: Callable[[FloatArray], FloatArray],
    breakpoints: Sequence[tuple[float, int] | Breakpoint] = (),
    tolerance: float = 1e-3,
    max_control_points: int | None = None,
    degree: int = 3,
) -> ProfileFit:
    """Fit a closed cam profile with a periodic B-spline and certify its error.

    Parameters
    ----------
    phi
        (n,) increasing cam angles φ in [0, 2π) [rad].
    points
        (n, 2) profile points at ``phi`` [mm], closing point not repeated.
    exact
        Exact profile: ``exact(phi)`` returns (m, 2) points [mm] at any
        angles in [0, 2π); the certificate evaluates it wherever it needs.
    breakpoints
        ``(phi_k, k)`` pairs (or objects with ``.phi`` and ``.continuity``):
        the profile is C^k at φ_k [rad]. They become knots of multiplicity
        p − k (none for k >= p). φ_k need not coincide with a sample.
    tolerance
        Largest allowed distance between curve and profile [mm].
    max_control_points
        Budget for the clamped form; None (default): automatic, as many as
        the samples leave room for, up to ``AUTO_MAX_CONTROL_POINTS`` (a
        memory bound on the least-squares system).
    degree
        Degree p (3: cubic).

    Returns
    -------
    ProfileFit
        The periodic curve (C^{p−1} at u = 0 by construction), its exact
        clamped form opened inside the longest stretch between breakpoints
        (:mod:`camcad.fit.seam`), and the certificate.

    Raises
    ------
    FitError
        The tolerance cannot be met within the budget; the message names
        the binding limit (``max_control_points``, the samples ``phi`` or
        ``tolerance``) and the count reached, and the error carries the
        best certified error.
    ValueError
        Inconsistent input.

    Notes
    -----
    Least squares over chord-length parameters with the closing chord
    (Quang & Hung 2015, eqs. 9–10) and one parameter correction (Hoschek
    1988), periodic basis, knots at the breakpoints, equidistributed free
    knots, foot-point certificate (Piegl & Tiller 1997, §6.1). The
    certified error bounds the distance from the whole exact profile to
    the curve, not only at the samples: between them it is maximised by
    adaptive subdivision (:func:`camcad.fit.certify.certify_exact`), so it
    holds at any sample step. The samples only feed the least squares:
    sparse samples give a worse fit, never a wrong certificate.

    Examples
    --------
    >>> phi = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    >>> circle = lambda a: 30.0 * np.column_stack((np.cos(a), np.sin(a)))
    >>> fit = fit_profile(phi, circle(phi), exact=circle, tolerance=1e-3)
    >>> fit.max_error <= 1e-3, fit.seam_tangent_jump < 1e-9
    (True, True)
    """
    return _fit_closed(
        phi,
        points,
        exact=exact,
        breakpoints=breakpoints,
        tolerance=tolerance,
        max_control_points=max_control_points,
        degree=degree,
        names=Names(samples="phi"),
    )


def _fit_closed(
    phi: FloatArray,
    points: FloatArray,
    *,
    exact: Callable[[FloatArray], FloatArray],
    breakpoints: Sequence[tuple[float, int] | Breakpoint],
    tolerance: float,
    max_control_points: int | None,
    degree: int,
    names: Names,
) -> ProfileFit:
    """:func:`fit_profile`, with the caller's names for its knobs in errors."""
    _check_options(tolerance, max_control_points, degree)
    pts = _check_points(points, degree)
    ang = np.asarray(phi, dtype=float)
    if ang.shape != (len(pts),):
        raise ValueError(f"phi must have shape ({len(pts)},), got {ang.shape}")
    if np.any(np.diff(ang) <= 0.0) or ang[-1] - ang[0] >= TWO_PI:
        raise ValueError("phi must increase strictly and span less than one turn (2π rad)")
    params = chord_length_params(pts, closed=True)
    phi_ext = np.append(ang, ang[0] + TWO_PI)
    t_ext = np.append(params, 1.0)

    def u_of(angle: float) -> float:  # chord-length parameter of a cam angle, unwrapped
        turns, rest = divmod(angle - ang[0], TWO_PI)
        return float(turns) + float(np.interp(ang[0] + rest, phi_ext, t_ext))

    pairs = []
    for bp in breakpoints:
        phi_k, k = (bp.phi, bp.continuity) if isinstance(bp, Breakpoint) else bp
        pairs.append((float(phi_k), int(k)))
    breaks = [(u_of(phi_k) % 1.0, k) for phi_k, k in pairs]
    stretch = longest_stretch([phi_k for phi_k, _ in pairs])
    lo, hi = stretch or (0.0, 0.0)
    quarter = 0.25 * (hi - lo)  # the seam opens in the stretch's middle half (camcad.fit.seam)
    probe = np.asarray(exact(ang[:2]), dtype=float)
    if probe.shape != (2, 2):
        raise ValueError(f"exact(phi) must return shape (len(phi), 2), got {probe.shape} for 2 angles")
    problem = _Problem(
        params=params,
        points=pts,
        exact=ExactProfile(point=exact, phi=ang, breaks=np.array([phi_k for phi_k, _ in pairs])),
        fixed=fixed_knots(breaks, degree=degree, periodic=True),
        degree=degree,
        tolerance=tolerance,
        max_control_points=AUTO_MAX_CONTROL_POINTS if max_control_points is None else max_control_points,
        automatic_budget=max_control_points is None,
        names=names,
        seam_window=None if stretch is None else (u_of(lo + quarter), u_of(hi - quarter)),
    )
    return _result(problem, *_search(problem))


def fit_open_profile(
    phi: FloatArray,
    points: FloatArray,
    *,
    exact: Callable[[FloatArray], FloatArray],
    breakpoints: Sequence[tuple[float, int] | Breakpoint],
    tolerance: float,
    max_control_points: int | None,
    degree: int,
    names: Names,
) -> ProfileFit:
    """A clamped open B-spline of an exact open curve (a linear cam's edge), certified over its whole length.

    As :func:`fit_profile` without the wrap: ``phi`` (n,) increases strictly
    from the curve's start to its end (both included), ``points`` (n, 2) [mm]
    are the exact curve there, the breakpoints inside become knots of
    multiplicity p − k, and the certificate bounds the distance from the
    whole exact curve (:func:`camcad.fit.certify.certify_exact_open`).
    """
    _check_options(tolerance, max_control_points, degree)
    pts = _check_points(points, degree)
    ang = np.asarray(phi, dtype=float)
    if ang.shape != (len(pts),) or np.any(np.diff(ang) <= 0.0):
        raise ValueError("phi must increase strictly, one angle per point")
    params = chord_length_params(pts, closed=False)
    pairs = [(bp.phi, bp.continuity) if isinstance(bp, Breakpoint) else bp for bp in breakpoints]
    inside = [(float(p), int(k)) for p, k in pairs if ang[0] < p < ang[-1]]
    breaks = [(float(np.interp(p, ang, params)), k) for p, k in inside]
    problem = _Problem(
        params=params,
        points=pts,
        exact=ExactProfile(point=exact, phi=ang, breaks=np.array([p for p, _ in inside], dtype=float)),
        fixed=fixed_knots(breaks, degree=degree, periodic=False),
        degree=degree,
        tolerance=tolerance,
        max_control_points=AUTO_MAX_CONTROL_POINTS if max_control_points is None else max_control_points,
        automatic_budget=max_control_points is None,
        names=names,
    )
    return _result(problem, *_search(problem))


def fit_points(
    points: FloatArray,
    *,
    closed: bool,
    tolerance: float = 1e-3,
    max_control_points: int | None = None,
    degree: int = 3,
) -> ProfileFit:
    """Fit any ordered point set, open or closed, within a tolerance.

    Parameters
    ----------
    points
        (n, 2) ordered points [mm]. For ``closed`` a repeated closing point
        is dropped.
    closed
        Periodic fit (C^{p−1} everywhere) or clamped open fit through the
        end points.
    tolerance
        Largest allowed distance from the points to the curve [mm].
    max_control_points
        Budget for the clamped form; None: automatic, as in
        :func:`fit_profile`.
    degree
        Degree p.

    Returns
    -------
    ProfileFit
        As :func:`fit_profile`; with no exact curve the certificate covers
        the given points only.

    Raises
    ------
    FitError
        The tolerance cannot be met within the budget (the message names
        the binding limit and the count reached).
    """
    _check_options(tolerance, max_control_points, degree)
    pts = _check_points(points, degree)
    if closed and np.allclose(pts[0], pts[-1], rtol=0.0, atol=1e-12 * np.ptp(pts)):
        pts = pts[:-1]
    problem = _Problem(
        params=chord_length_params(pts, closed=closed),
        points=pts,
        exact=None,
        fixed=fixed_knots((), degree=degree, periodic=closed),
        degree=degree,
        tolerance=tolerance,
        max_control_points=AUTO_MAX_CONTROL_POINTS if max_control_points is None else max_control_points,
        automatic_budget=max_control_points is None,
        names=Names(),
    )
    return _result(problem, *_search(problem))
