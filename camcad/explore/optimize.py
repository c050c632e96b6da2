"""Constrained optimization of a design over chosen design-file keys, and two-objective Pareto fronts.

The problem (after Quang & Hung 2015, whose design problem is to make the cam
as small as possible and keep the contact stress low by choosing the base
radius, the offset and the face width under limits on pressure angle,
curvature and contact stress):

    minimise   f(x)                   one measure of :data:`~camcad.explore.measures.MEASURES`
    over       x in [low, high]       the continuous variables (``--vary name=low:high``)
               and every combination of the discrete ones (``--vary law=a,b``), by enumeration
    subject to the limits             ``--limit`` and the design's own (``max_pressure_angle``,
                                      ``allowable_stress``, ``min_contact_force`` for a follower
                                      held on by a spring), the curvature limit
                                      (``min_curvature_radius``; no undercut or cusp, always)

Every function value comes from a full analysis of the variant
(:func:`camcad.pipeline.analyse`, no fit, no toolpath), so the constraints are
evaluated at the true extremes over the turn (one-sided limits at joints
included, :mod:`camcad.extremes`). The continuous search is scipy's SLSQP
(default) or trust-constr, on variables scaled to [0, 1], with finite-difference
gradients. The pressure-angle limit |α| ≤ A is given to the solver as two
smooth constraints, max α ≤ A and −min α ≤ A: at the smallest cam both
usually hold with equality at once (the rise and the return), a corner that
the single constraint max |α| ≤ A would hide from a gradient method.

The limits are those of ``camcad check`` and ``camcad size``, one set
(issue 31): every plate of a conjugate pair and every flank of a groove is
held to them (:mod:`camcad.explore.measures`,
:func:`camcad.geometry.sizing.feasible_margins`), the curvature limit is
:func:`camcad.geometry.sizing.meets_curvature`, and a ``--limit`` that
replaces one of the design's own is written into every variant's design
file (``cam.max_pressure_angle``, ``dynamics.allowable_stress``,
``dynamics.min_contact_force``), so ``camcad check`` on the optimum's file
judges by it. Constraints are met with a small reserve (:data:`RESERVE`,
relative), so the design file of the optimum passes ``camcad check`` and not
only the solver's tolerance. A candidate is feasible when every constraint
holds (margin ≥ 0) and the analysis finds no broken limit (``camcad
check``'s verdict, without its fit and FE stages: a design with ``[fea]``
or a tight ``fit.tolerance`` is judged on them only by ``check``). The optimum's values are given with
the fewest significant digits (6 to 17) at which the design, analysed again,
is still feasible: the values printed, written to ``optimum.toml`` and typed
back all give the same passing design. A constraint is reported *active* when its margin is
within :data:`ACTIVE` (relative) of its limit.

Two objectives give a Pareto front by the ε-constraint method: the two
single-objective optima, then ``points − 2`` optima of the first objective
with the second bounded by values spaced evenly between them, filtered to
the non-dominated ones (:func:`~camcad.explore.pareto.pareto_mask`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from camcad.errors import CamcadError, UsageError
from camcad.explore.measures import MEASURES, Limit, Measure, measure_values
from camcad.explore.pareto import pareto_mask
from camcad.explore.space import Variable, apply_values, design_with

__all__ = [
    "ACTIVE",
    "MAX_COMBINATIONS",
    "MAX_FRONT_POINTS",
    "MAX_STARTS",
    "METHODS",
    "RESERVE",
    "Candidate",
    "ConstraintState",
    "OptimizeResult",
    "Problem",
    "design_limits",
    "limits_data",
    "optimize",
]

METHODS = ("slsqp", "trust-constr")
RESERVE = 1e-7
"""Relative margin the solver must keep from every limit (so the optimum passes ``camcad check``)."""
ACTIVE = 1e-4
"""A constraint whose relative margin is below this is reported active."""
MAX_STARTS = 1000
"""Most local searches (``--starts``) per combination of the discrete choices."""
MAX_FRONT_POINTS = 200
"""Most points of a two-objective front (``--points``)."""
MAX_COMBINATIONS = 1000
"""Most combinations of the discrete choices (``--vary name=a,b,…``), each a full optimization."""
_INVALID = -10.0  # the relative margin of every constraint at a design that cannot be analysed
_FD_STEP = 1e-7  # finite-difference step on the variables scaled to [0, 1]
_EDGE_STEP = 1e-5  # scaled step that probes whether an optimum sits on the edge of the valid designs


@dataclass(frozen=True, slots=True, kw_only=True)
class Problem:
    """What to optimize: the base design's mapping, variables, one or two objectives and the limits."""

    data: Mapping[str, Any]
    source: str = ""
    variables: tuple[Variable, ...]
    objectives: tuple[Measure, ...]
    limits: tuple[Limit, ...] = ()
    method: str = "slsqp"
    starts: int = 1  # the design's own values, then Latin-hypercube starts
    points: int = 7  # points of a two-objective front
    seed: int = 0
    batch: bool = True  # analyse each iterate with its finite-difference neighbours together (same numbers)


@dataclass(frozen=True, slots=True, kw_only=True)
class ConstraintState:
    """One constraint at a candidate: value and limit in the measure's unit, relative margin, active."""

    name: str
    value: float | None
    limit: float
    margin: float  # relative, ≥ 0 holds
    active: bool


@dataclass(frozen=True, slots=True, kw_only=True)
class Candidate:
    """A design the optimizer ended at: its values, objectives, constraints and the design mapping."""

    values: dict[str, Any]
    objectives: dict[str, float | None]
    measures: dict[str, float | None]
    constraints: tuple[ConstraintState, ...]
    bounds: tuple[str, ...]  # variables at a bound, e.g. "offset = 0 (lower bound)"
    feasible: bool
    data: dict[str, Any] = field(repr=False)
    evaluations: int
    message: str
    findings: tuple[str, ...] = ()

    @property
    def active(self) -> tuple[str, ...]:
        """The active constraints' names."""
        return tuple(c.name for c in self.constraints if c.active)

    def summary(self) -> dict[str, Any]:
        """A JSON-ready record of the candidate."""
        return {
            "values": self.values,
            "objectives": self.objectives,
            "feasible": self.feasible,
            "active_constraints": list(self.active),
            "at_bounds": list(self.bounds),
            "constraints": [
                {
                    "name": c.name,
                    "value": c.value,
                    "limit": c.limit if math.isfinite(c.limit) else None,
                    "margin": c.margin,
                    "active": c.active,
                }
                for c in self.constraints
            ],
            "measures": self.measures,
            "findings": list(self.findings),
            "evaluations": self.evaluations,
            "solver": self.message,
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class OptimizeResult:
    """The optimum (one objective) or the front (two), and the optimum of each discrete combination."""

    best: Candidate | None
    front: tuple[Candidate, ...]
    tried: tuple[Candidate, ...]
    evaluations: int

    def summary(self) -> dict[str, Any]:
        """A JSON-ready record (``optimize.json``)."""
        return {
            "optimum": None if self.best is None else self.best.summary(),
            "front": [c.summary() for c in self.front],
            "tried": [c.summary() for c in self.tried],
            "evaluations": self.evaluations,
        }


# the design-file key holding each of the design's own limits (quantity, direction)
_OWN_KEYS: dict[tuple[str, str], tuple[str, str]] = {
    ("pressure_angle", "<="): ("cam", "max_pressure_angle"),
    ("contact_stress", "<="): ("dynamics", "allowable_stress"),
    ("contact_force_min", ">="): ("dynamics", "min_contact_force"),
}


def design_limits(data: Mapping[str, Any], limits: Sequence[Limit], *, source: str = "") -> tuple[Limit, ...]:
    """The limits an optimization keeps: the design's own, replaced or joined by ``limits``.

    The design's own are ``pressure_angle <= cam.max_pressure_angle``,
    ``contact_stress <= dynamics.allowable_stress`` when it is given, and
    ``contact_force_min >= dynamics.min_contact_force`` for a follower held on
    by a spring (a positive drive has no jump); a ``--limit`` on the same
    quantity and direction replaces it (:func:`limits_data` writes it into
    the design file).
    """
    design = design_with(data, (), (), source=source)
    own = [
        Limit(measure=MEASURES["pressure_angle"], op="<=", value=math.degrees(design.cam.max_pressure_angle))
    ]
    if design.dynamics.allowable_stress is not None:
        own.append(Limit(measure=MEASURES["contact_stress"], op="<=", value=design.dynamics.allowable_stress))
    if not design.dynamics_setup().positive_drive:
        own.append(
            Limit(measure=MEASURES["contact_force_min"], op=">=", value=design.dynamics.min_contact_force)
        )
    given = {(lim.measure.name, lim.op) for lim in limits}
    return tuple([lim for lim in own if (lim.measure.name, lim.op) not in given] + list(limits))


def limits_data(data: Mapping[str, Any], limits: Sequence[Limit], *, source: str = "") -> dict[str, Any]:
    """The design mapping with each ``--limit`` that replaces one of the design's own written in.

    ``pressure_angle<=40`` sets ``cam.max_pressure_angle = 40``,
    ``contact_stress<=800`` ``dynamics.allowable_stress = 800``,
    ``contact_force_min>=5`` ``dynamics.min_contact_force = 5`` (the last
    only for a follower held on by a spring): the design file of the optimum
    then carries the limits it was found under, and ``camcad check`` judges
    it by them.

    Raises
    ------
    UsageError
        Naming ``--limit`` when the design file does not accept the value there.
    """
    out: dict[str, Any] = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in data.items()}
    positive = design_with(data, (), (), source=source).dynamics_setup().positive_drive
    for lim in limits:
        place = _OWN_KEYS.get((lim.measure.name, lim.op))
        if place is None or (positive and lim.measure.name == "contact_force_min"):
            continue
        table, key = place
        out.setdefault(table, {})[key] = lim.value
        try:
            design_with(out, (), (), source=source)
        except CamcadError as err:
            raise UsageError(
                "--limit", f"{lim.text}: it replaces {table}.{key}, and the design file refuses it: {err}"
            ) from None
    return out


# The measures that are the larger of two smooth pieces, and the pieces' names: a limit ``≤`` on
# them is two solver constraints, and as an objective they are minimised in epigraph form.
_PIECES: dict[str, tuple[str, str]] = {
    "pressure_angle": ("max α", "−min α"),
    "torque": ("max T", "−min T"),
}


@dataclass(frozen=True, slots=True)
class _Point:
    """One analysed variant: its measures, the smooth pieces of the max-type ones and its undercut margin."""

    measures: dict[str, float | None]
    pieces: dict[str, tuple[float, ...]]  # measure name → pieces whose max is the measure
    rho_margin: float  # smallest convex radius − required [mm]
    rho_scale: float  # mm
    findings: tuple[str, ...]
    valid: bool

    def parts(self, m: Measure) -> tuple[float | None, ...]:
        """The measure as the pieces whose max it is (itself alone for most)."""
        if m.name in self.pieces:
            return self.pieces[m.name]
        return (self.measures.get(m.column),)


def _width(lim: Limit) -> int:
    """How many solver constraints a limit becomes (two for |α| ≤ A and |T| ≤ T_max)."""
    return 2 if lim.measure.name in _PIECES and lim.op == "<=" else 1


def _constraint_names(limits: Sequence[Limit]) -> list[str]:
    names: list[str] = []
    for lim in limits:
        if _width(lim) == 2:
            names += [f"{lim.text} ({piece})" for piece in _PIECES[lim.measure.name]]
        else:
            names.append(lim.text)
    return [*names, "curvature: convex ρ − required ≥ 0 mm"]


def _constraints(point: _Point, limits: Sequence[Limit]) -> tuple[list[float | None], np.ndarray]:
    """Constraint values (measure's unit) and relative margins (≥ 0 holds) at a point, undercut last."""
    n = sum(_width(lim) for lim in limits) + 1
    if not point.valid:
        return [None] * n, np.full(n, _INVALID)
    rho = point.rho_margin / point.rho_scale
    values: list[float | None] = []
    margins: list[float] = []
    for lim in limits:
        scale = max(abs(lim.value), 1.0)
        parts = point.parts(lim.measure) if lim.op == "<=" else (point.measures.get(lim.measure.column),)
        for value in parts:
            values.append(value)
            m = lim.margin(value)
            m = m / scale if math.isfinite(m) else _INVALID
            if rho < 0.0 and (lim.measure.name == "contact_stress" or m == _INVALID):
                # undercut or cusp: the Hertz stress loses its meaning (ρ → 0 or below) and a figure may
                # be missing; such limits take the undercut's own margin, which leads the solver back
                # across the boundary instead of into the stress's spike at the cusp
                m = rho
            margins.append(m)
    values.append(point.rho_margin)
    margins.append(rho)
    return values, np.array(margins)


class _Evaluator:
    """Analyses variants on demand and remembers them (the solver asks for f and g at the same x)."""

    def __init__(self, problem: Problem, fixed: Sequence[tuple[Variable, Any]], limits: Sequence[Limit]):
        self.problem = problem
        self.fixed = list(fixed)
        self.free = [v for v in problem.variables if v.continuous]
        self.limits = list(limits)
        self.cache: dict[tuple[float, ...], _Point] = {}
        self.asked: set[tuple[float, ...]] = set()

    def physical(self, x: np.ndarray) -> tuple[float, ...]:
        """Scaled [0, 1] values → the variables' values in the design file's units."""
        out = []
        for u, v in zip(x, self.free, strict=True):
            assert v.low is not None and v.high is not None
            out.append(float(v.low + float(np.clip(u, 0.0, 1.0)) * (v.high - v.low)))
        return tuple(out)

    def values_at(self, physical: Sequence[float]) -> tuple[list[Variable], list[Any]]:
        """The variables and their values with the continuous ones at ``physical`` (design-file units)."""
        return [v for v, _ in self.fixed] + self.free, [c for _, c in self.fixed] + list(physical)

    def __call__(self, x: np.ndarray) -> _Point:
        key = self.physical(x)
        if key not in self.cache and self.free and self.problem.batch:
            self._prefetch(np.asarray(x, dtype=float))
        return self.at(key)

    def _prefetch(self, x: np.ndarray) -> None:
        """Analyse ``x`` and its forward-difference neighbours together, as one batch.

        The solver asks for f and g at x and then, for its finite-difference
        gradient, at x + h·e_i (h = :data:`_FD_STEP`, −h where x + h leaves
        [0, 1]); those designs share x's motion structure, so they are
        analysed at once (:func:`camcad.explore.batch.analyse_many`, the same
        analyses to the bit) and kept. A neighbour the solver does not ask
        for costs a fraction of one analysis.
        """
        from camcad.explore.batch import analyse_many

        stencil = [x]
        for i in range(x.size):
            z = x.copy()
            step = _FD_STEP if x[i] + _FD_STEP <= 1.0 else -_FD_STEP
            z[i] = x[i] + step
            stencil.append(z)
        keys = list(dict.fromkeys(k for k in (self.physical(z) for z in stencil) if k not in self.cache))
        designs: list[tuple[tuple[float, ...], Any]] = []
        for key in keys:
            variables, values = self.values_at(key)
            try:
                designs.append(
                    (key, design_with(self.problem.data, variables, values, source=self.problem.source))
                )
            except CamcadError as err:
                self.cache[key] = _invalid(err)
        analysed = analyse_many([d for _, d in designs])
        for (key, design), got in zip(designs, analysed, strict=True):
            self.cache[key] = _invalid(got) if isinstance(got, CamcadError) else self._point(design, got)

    def at(self, physical: tuple[float, ...]) -> _Point:
        """The analysed variant with the continuous variables at ``physical`` (design-file units)."""
        self.asked.add(physical)  # the designs the search asked for (not those analysed ahead)
        if physical not in self.cache:
            self.cache[physical] = self._evaluate(physical)
        return self.cache[physical]

    def _evaluate(self, physical: tuple[float, ...]) -> _Point:
        from camcad.pipeline import analyse

        variables, values = self.values_at(physical)
        try:
            design = design_with(self.problem.data, variables, values, source=self.problem.source)
            analysis = analyse(design, fit=False, toolpath=False, strict=False)
        except CamcadError as err:
            return _invalid(err)
        return self._point(design, analysis)

    def _point(self, design: Any, analysis: Any) -> _Point:
        """The solver's view of an analysed variant: measures, pieces, the curvature margin, findings."""
        from camcad.geometry.sizing import feasible_margins

        summary = analysis.summary()
        measures = measure_values(analysis, summary)
        plates = [(r.part.cam, r.geometry.phi) for r in analysis.parts]  # every part: a pair's second plate
        signed = [_signed_pressure_deg(cam, phi) for cam, phi in plates]
        pieces: dict[str, tuple[float, ...]] = {
            "pressure_angle": (max(hi for hi, _ in signed), -min(lo for _, lo in signed))
        }
        t_max, t_min = summary["dynamics"].get("torque_max_Nmm"), summary["dynamics"].get("torque_min_Nmm")
        if t_max is not None and t_min is not None:
            pieces["torque"] = (float(t_max), -float(t_min))
        # the curvature limit of check and size, on every plate (camcad.geometry.sizing.meets_curvature)
        _, rho_margin, _, _ = feasible_margins(
            analysis.cam,
            analysis.geometry.phi,
            max_pressure_angle=math.pi / 2,
            min_curvature_radius=design.min_curvature_radius,
            conjugate=analysis.parts[-1].part.cam.conjugate,  # a pair's second plate's; else None
        )
        # every part's further curves (a groove's flanks) loop where their radius reaches 0 (hard)
        rho_margin = min([rho_margin, *(c.radius_margin for r in analysis.parts for c in r.part.checks)])
        findings = tuple(f.message for f in analysis.findings if not f.note)
        return _Point(measures, pieces, float(rho_margin), max(design.cam.base_radius, 1.0), findings, True)


def _invalid(err: CamcadError) -> _Point:
    """A variant the schema or a stage refused: no figures, its message."""
    return _Point({}, {}, -math.inf, 1.0, (str(err),), False)


def _signed_pressure_deg(cam: Any, phi: np.ndarray) -> tuple[float, float]:
    """The true max and min of the signed pressure angle over the turn [deg] (one-sided at joints)."""
    from camcad.extremes import extremes_rows

    joints = [bp.phi for bp in cam.program.breakpoints]

    def rows(p: np.ndarray, side: Any) -> np.ndarray:
        alpha = cam.state(p, side=side).pressure_angle
        return np.vstack((alpha, alpha))

    hi, lo = extremes_rows(rows, phi, joints, ("max", "min"), rests=cam.rests)  # α is constant on a dwell
    return math.degrees(hi.value), math.degrees(lo.value)


def _objective(point: _Point, m: Measure) -> float:
    value = point.measures.get(m.column)
    return math.inf if value is None else float(value)


def _solve(
    ev: _Evaluator, objective: Measure, x0: np.ndarray, *, method: str, limits: Sequence[Limit]
) -> tuple[np.ndarray, str]:
    """One local search from ``x0`` under ``limits``; returns the scaled variables and the solver's message.

    A max-type objective (:data:`_PIECES`) is minimised in epigraph form:
    an extra variable τ with τ ≥ each piece, minimise τ.
    """
    from scipy.optimize import BFGS, Bounds, NonlinearConstraint, minimize

    n = len(x0)
    if n == 0:
        return x0, "no continuous variable: evaluated"
    start = ev(x0)
    scale = abs(_objective(start, objective)) if start.valid else 1.0
    scale = scale if math.isfinite(scale) and scale > 0 else 1.0
    epigraph = objective.name in _PIECES

    def f(z: np.ndarray) -> float:
        if epigraph:
            return float(z[-1])
        value = _objective(ev(z), objective)
        return value / scale if math.isfinite(value) else 1e3

    def g(z: np.ndarray) -> np.ndarray:
        point = ev(z[:n])
        _, margins = _constraints(point, limits)
        if epigraph:
            parts = point.parts(objective) if point.valid else ()
            tau = np.array([z[-1] - (p / scale if p is not None else 1e3) for p in parts] or [-1e3])
            margins = np.concatenate((margins, tau))
        return margins - RESERVE

    z0 = x0
    bounds_lo, bounds_hi = np.zeros(n), np.ones(n)
    if epigraph:
        z0 = np.append(x0, _objective(start, objective) / scale if start.valid else 1e3)
        bounds_lo, bounds_hi = np.append(bounds_lo, -np.inf), np.append(bounds_hi, np.inf)
    if method == "slsqp":
        res = minimize(
            f,
            z0,
            method="SLSQP",
            bounds=list(zip(bounds_lo, bounds_hi, strict=True)),
            constraints=[{"type": "ineq", "fun": g}],
            options={"ftol": 1e-10, "maxiter": 200, "eps": _FD_STEP},
        )
    else:
        res = minimize(
            f,
            z0,
            method="trust-constr",
            jac="2-point",
            hess=BFGS(),
            bounds=Bounds(bounds_lo, bounds_hi),
            constraints=[NonlinearConstraint(g, 0.0, np.inf, jac="2-point", hess=BFGS())],
            options={"xtol": 1e-10, "gtol": 1e-10, "maxiter": 400, "finite_diff_rel_step": _FD_STEP},
        )
    return np.clip(np.asarray(res.x, dtype=float)[:n], 0.0, 1.0), f"{method}: {res.message}"


def _candidate(
    ev: _Evaluator,
    x: np.ndarray,
    objectives: Sequence[Measure],
    message: str,
    *,
    limits: Sequence[Limit],
    physical: tuple[float, ...] | None = None,
) -> Candidate:
    """The candidate at scaled ``x``, or at the continuous values ``physical`` when given (rounded ones)."""
    physical = ev.physical(x) if physical is None else physical
    point = ev.at(physical)
    variables, values = ev.values_at(physical)
    constraint_values, margins = _constraints(point, limits)
    limit_values = [lim.value for lim in limits for _ in range(_width(lim))] + [math.nan]
    states = [
        ConstraintState(
            name=name, value=value, limit=lim, margin=float(margin), active=bool(abs(margin) <= ACTIVE)
        )
        for name, value, margin, lim in zip(
            _constraint_names(limits), constraint_values, margins, limit_values, strict=True
        )
    ]
    bounds = []
    for i, (u, v) in enumerate(zip(x, ev.free, strict=True)):
        if u <= 1e-9:
            bounds.append(f"{v.name} = {v.low:g} (lower bound)")
        elif u >= 1.0 - 1e-9:
            bounds.append(f"{v.name} = {v.high:g} (upper bound)")
        elif point.valid:
            # the edge of the designs the schema accepts is a limit too (a keyway that must stay inside the
            # base circle, an offset below r_b + r_f): probe a step either way and say which one refuses
            for sign, word in ((-1.0, "lower"), (1.0, "higher")):
                probe = x.copy()
                probe[i] = float(np.clip(u + sign * _EDGE_STEP, 0.0, 1.0))
                beyond = ev(probe)
                if not beyond.valid:
                    bounds.append(f"{v.name} cannot go {word}: {beyond.findings[0]}")
    return Candidate(
        values={v.name: value for v, value in zip(variables, values, strict=True)},
        objectives={m.name: point.measures.get(m.column) for m in objectives},
        measures=dict(point.measures),
        constraints=tuple(states),
        bounds=tuple(bounds),
        # every limit holds and the analysis found none broken: `camcad check`'s verdict
        feasible=point.valid and bool(np.all(margins >= 0.0)) and not point.findings,
        data=apply_values(ev.problem.data, variables, values),
        evaluations=len(ev.asked),
        message=message,
        findings=point.findings,
    )


def _starts(ev: _Evaluator, count: int, seed: int) -> list[np.ndarray]:
    """The design's own values (clipped into the ranges), then Latin-hypercube points."""
    n = len(ev.free)
    own = []
    for v in ev.free:
        assert v.low is not None and v.high is not None
        current = _current(ev.problem.data, v)
        u = 0.5 if current is None else (current - v.low) / (v.high - v.low)
        own.append(float(np.clip(u, 0.0, 1.0)))
    starts = [np.array(own)]
    if count > 1 and n:
        from scipy.stats import qmc

        starts += list(qmc.LatinHypercube(d=n, rng=np.random.default_rng(seed)).random(count - 1))
    return starts


def _current(data: Mapping[str, Any], v: Variable) -> float | None:
    """The design file's value of a variable (its first place), or None when the file leaves it out."""
    table, _, key = v.path.partition(".")
    holder: Any = data.get(table, {})
    if table.startswith("motion["):
        index = table[len("motion[") : -1]
        segments = data.get("motion", [])
        if index == "*":
            moving = [s for s in segments if isinstance(s, Mapping) and s.get("kind") in ("rise", "return")]
            holder = moving[0] if moving else {}
        else:
            holder = segments[int(index)]
    value = holder.get(key) if isinstance(holder, Mapping) else None
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _better(a: Candidate, b: Candidate | None, objective: Measure) -> bool:
    """``a`` beats ``b``: feasible over infeasible, then the smaller objective (or the smaller violation)."""
    if b is None:
        return True
    if a.feasible != b.feasible:
        return a.feasible
    if a.feasible:
        fa, fb = a.objectives.get(objective.name), b.objectives.get(objective.name)
        return (math.inf if fa is None else fa) < (math.inf if fb is None else fb)
    worst_a = min((c.margin for c in a.constraints), default=0.0)
    worst_b = min((c.margin for c in b.constraints), default=0.0)
    return worst_a > worst_b


def _minimise(
    ev: _Evaluator,
    objective: Measure,
    objectives: Sequence[Measure],
    starts: Sequence[np.ndarray],
    *,
    method: str,
    limits: Sequence[Limit],
) -> Candidate:
    best: Candidate | None = None
    best_x = np.zeros(len(ev.free))
    for x0 in starts:
        x, message = _solve(ev, objective, x0, method=method, limits=limits)
        cand = _candidate(ev, x, objectives, message, limits=limits)
        if _better(cand, best, objective):
            best, best_x = cand, x
    assert best is not None
    return _shortest(ev, best, best_x, objectives, limits=limits)


def _shortest(
    ev: _Evaluator, cand: Candidate, x: np.ndarray, objectives: Sequence[Measure], *, limits: Sequence[Limit]
) -> Candidate:
    """The candidate at the fewest significant digits (6 to 17) of its values that keep it feasible.

    The values printed, written to the design file and typed back then give a
    design that passes. At an optimum limits are active: rounding a value to
    six digits can step over one (a corner of two pressure-angle limits moves
    by 10⁻⁵ mm). Each rounding is analysed again; at 17
    digits the value is the solver's own, so a feasible candidate stays feasible.
    """
    if not cand.feasible or not ev.free:
        return cand
    exact = ev.physical(x)
    for digits in range(6, 17):
        rounded = tuple(float(f"{v:.{digits}g}") for v in exact)
        inside = all(
            v.low is not None and v.high is not None and v.low <= r <= v.high
            for r, v in zip(rounded, ev.free, strict=True)
        )
        if not inside:
            continue
        if rounded == exact:
            return cand
        trial = _candidate(ev, x, objectives, cand.message, limits=limits, physical=rounded)
        if trial.feasible:
            return trial
    return cand


def optimize(problem: Problem, *, progress: Callable[[str], None] | None = None) -> OptimizeResult:
    """Solve the problem: the optimum (one objective) or the Pareto front (two).

    Raises
    ------
    UsageError
        No variable, not one or two objectives, an unknown method, fewer
        than one start or two front points.
    """
    if problem.method not in METHODS:
        raise UsageError("--method", f"{problem.method!r} is not allowed (allowed: {', '.join(METHODS)})")
    if not 1 <= len(problem.objectives) <= 2 or len(set(problem.objectives)) != len(problem.objectives):
        raise UsageError("--minimize", "give one objective, or two different ones for a Pareto front")
    if not problem.variables:
        raise UsageError("--vary", "give at least one variable, e.g. --vary base_radius=20:120")
    if not 1 <= problem.starts <= MAX_STARTS:
        raise UsageError("--starts", f"{problem.starts} is not allowed (allowed: 1 to {MAX_STARTS})")
    if problem.points > MAX_FRONT_POINTS or (len(problem.objectives) == 2 and problem.points < 2):
        raise UsageError("--points", f"{problem.points} is not allowed (allowed: 2 to {MAX_FRONT_POINTS})")
    if not 0 <= problem.seed <= 2**32 - 1:
        raise UsageError("--seed", f"{problem.seed} is not allowed (allowed: 0 to {2**32 - 1})")
    limits = design_limits(problem.data, problem.limits, source=problem.source)
    problem = replace(problem, data=limits_data(problem.data, problem.limits, source=problem.source))
    discrete = [v for v in problem.variables if not v.continuous]
    count = math.prod(len(v.choices or ()) for v in discrete)
    if count > MAX_COMBINATIONS:
        raise UsageError(
            "--vary",
            f"{count} combinations of the choices; allowed: at most {MAX_COMBINATIONS} "
            "(each is a full optimization: list fewer choices, or make a variable a range low:high)",
        )
    combos = list(itertools.product(*(v.choices or () for v in discrete)))
    tried: list[Candidate] = []
    everything: list[Candidate] = []
    evaluations = 0
    first = problem.objectives[0]
    for combo in combos:
        ev = _Evaluator(problem, list(zip(discrete, combo, strict=True)), limits)
        starts = _starts(ev, problem.starts, problem.seed)
        if progress is not None and combo:
            progress(", ".join(f"{v.name} = {c}" for v, c in zip(discrete, combo, strict=True)))
        best = _minimise(ev, first, problem.objectives, starts, method=problem.method, limits=limits)
        tried.append(best)
        everything.append(best)
        if len(problem.objectives) == 2:
            everything += _front(ev, problem, best, starts, limits)
        evaluations += len(ev.asked)
    if len(problem.objectives) == 1:
        best_all: Candidate | None = None
        for cand in tried:
            if _better(cand, best_all, first):
                best_all = cand
        return OptimizeResult(best=best_all, front=(), tried=tuple(tried), evaluations=evaluations)
    first_name, second_name = (m.name for m in problem.objectives)
    feasible = [c for c in everything if c.feasible]

    def value(c: Candidate, name: str) -> float:
        v = c.objectives.get(name)
        return math.nan if v is None else v

    mask = pareto_mask([value(c, first_name) for c in feasible], [value(c, second_name) for c in feasible])
    front = sorted(
        (c for c, on in zip(feasible, mask, strict=True) if on), key=lambda c: value(c, first_name)
    )
    unique: list[Candidate] = []
    for c in front:
        if not unique or c.values != unique[-1].values:
            unique.append(c)
    return OptimizeResult(best=None, front=tuple(unique), tried=tuple(tried), evaluations=evaluations)


def _front(
    ev: _Evaluator, problem: Problem, best: Candidate, starts: Sequence[np.ndarray], limits: Sequence[Limit]
) -> list[Candidate]:
    """The ε-constraint points between the two single-objective optima (``best`` minimises the first)."""
    first, second = problem.objectives
    other = _minimise(ev, second, problem.objectives, starts, method=problem.method, limits=limits)
    out = [other]
    lo, hi = other.objectives.get(second.name), best.objectives.get(second.name)
    if not (best.feasible and other.feasible and lo is not None and hi is not None and hi > lo):
        return out
    previous = [_scaled(ev, best)]
    for eps in np.linspace(hi, lo, problem.points)[1:-1]:
        bound = Limit(measure=second, op="<=", value=float(eps))
        cand = _minimise(
            ev, first, problem.objectives, previous, method=problem.method, limits=[*limits, bound]
        )
        out.append(cand)
        if cand.feasible:
            previous = [_scaled(ev, cand)]
    return out


def _scaled(ev: _Evaluator, cand: Candidate) -> np.ndarray:
    out = []
    for v in ev.free:
        assert v.low is not None and v.high is not None
        out.append((float(cand.values[v.name]) - v.low) / (v.high - v.low))
    return np.array(out)
