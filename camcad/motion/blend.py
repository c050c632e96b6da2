"""Blend points: solve the boundary values of the segments whose law adapts to its neighbours.

A *blend point* is a segment joint next to a segment whose law can meet given
boundary values (``polynomial``, ``inclined-sine``). At every blend point the
derivatives v = ds/dφ and a = d²s/dφ² either **match** the neighbour (the
default: the two one-sided values are made equal) or are **specified** by the
user (``start = {v = …}`` / ``end = {…}``); the jerk j is matched too where a
polynomial's degree allows (degree ≥ 7, or a specified jerk). The displacement
always matches: it is the running sum of the lifts.

The unknowns of all adaptive segments are found together in one linear
equality-constrained least-squares problem (a KKT solve): the conditions are
the constraints, and where they leave freedom (a ``degree`` above the lowest,
or two adaptive segments sharing a blend point) the motion of least jerk norm
Σ ∫ (d³s/dφ³)² dφ is taken. With no freedom this is plain Hermite
interpolation: a polynomial between rests with s, v, a given is the 3-4-5
law, with j too the 4-5-6-7 law.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre

from camcad._typing import FloatArray
from camcad.errors import DesignError
from camcad.motion._blendlaws import MAX_POLYNOMIAL_DEGREE, InclinedSine, Polynomial
from camcad.motion.laws import Law
from camcad.motion.segments import SegmentKind, SegmentSpec

__all__ = ["is_adaptive", "resolve_blends"]

_ORDERS = (1, 2, 3)
_NAMES = {1: "v", 2: "a", 3: "j"}
_QUAD = np.polynomial.legendre.leggauss(
    32
)  # exact for the jerk Gram of degree ≤ 15 (and ~1e-16 for the sines)
_KKT_RTOL = 1e-9  # a constraint residual above this share of its scale means the conditions conflict
_RCOND_MIN = 1e-14  # a KKT matrix less well conditioned than this has no unique solution


def is_adaptive(law: Law | None) -> bool:
    """True for a law that still has to take its boundary values from its neighbours."""
    return isinstance(law, (Polynomial, InclinedSine)) and not law.resolved


@dataclass(frozen=True, slots=True)
class _Expr:
    """An affine expression row · u + const over the global unknowns u."""

    row: FloatArray
    const: float


class _Family:
    """An adaptive segment: its unknowns u (physical units), its derivatives in them, its jerk."""

    def __init__(self, seg: SegmentSpec, offset: int, size: int) -> None:
        self.seg, self.offset, self.size = seg, offset, size
        self.h = seg.signed_lift
        self.beta = seg.span

    def local(self, order: int, x: float) -> tuple[FloatArray, float]:
        """(row over own unknowns, const): d^order s/dφ^order at x, relative to the segment's start for s."""
        raise NotImplementedError

    def accepts(self, order: int) -> bool:
        """Whether the family can meet a condition on derivative ``order`` at an end."""
        raise NotImplementedError

    def own(self) -> list[tuple[FloatArray, float]]:
        """Conditions the family must meet whatever its neighbours (s at both ends)."""
        return []

    def jerk(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """d³s/dφ³ at normalised x as (matrix (len(x), size), const (len(x),))."""
        raise NotImplementedError

    def build(self, u: FloatArray) -> Law:
        """The resolved law for the solved unknowns."""
        raise NotImplementedError


class _PolyFamily(_Family):
    """s = base + Σ d_i P_i(2x − 1), Legendre coefficients d [mm]."""

    def __init__(self, seg: SegmentSpec, offset: int, degree: int) -> None:
        super().__init__(seg, offset, degree + 1)
        self.degree = degree

    def _basis(self, order: int, x: float | FloatArray) -> FloatArray:
        u = 2.0 * np.asarray(x, dtype=float) - 1.0
        eye = np.eye(self.size)
        cols = [
            legendre.legval(u, legendre.legder(eye[i], order)) if order else legendre.legval(u, eye[i])
            for i in range(self.size)
        ]
        out: FloatArray = np.asarray(cols, dtype=float).T * (2.0 / self.beta) ** order  # du/dφ = 2/β
        return out

    def local(self, order: int, x: float) -> tuple[FloatArray, float]:
        return self._basis(order, x), 0.0

    def accepts(self, order: int) -> bool:
        return True

    def own(self) -> list[tuple[FloatArray, float]]:
        return [(self._basis(0, 0.0), 0.0), (self._basis(0, 1.0), self.h)]

    def jerk(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self._basis(3, x), np.zeros(len(x))

    def build(self, u: FloatArray) -> Law:
        coefficients = tuple(float(c) / self.h for c in u)
        assert isinstance(self.seg.law, Polynomial)
        return dataclasses.replace(self.seg.law, coefficients=coefficients)


class _InclinedFamily(_Family):
    """Inclined sine with unknown end velocities u = (v₀, v₁) [mm/rad]; affine in them."""

    def __init__(self, seg: SegmentSpec, offset: int) -> None:
        super().__init__(seg, offset, 2)

    def _affine(self, order: int, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """d^order s/dφ^order as const + matrix · (v₀, v₁), from the law at c = (0,0), (1,0), (0,1)."""
        scale = self.h / self.beta**order  # s = h y(x), x = (φ − φ₀)/β
        base = InclinedSine(start_velocity=0.0, end_velocity=0.0).evaluate(x)[order] * scale
        e0 = InclinedSine(start_velocity=1.0, end_velocity=0.0).evaluate(x)[order] * scale - base
        e1 = InclinedSine(start_velocity=0.0, end_velocity=1.0).evaluate(x)[order] * scale - base
        per = self.beta / self.h  # c = v β / h: unknowns in mm/rad
        return np.stack([e0 * per, e1 * per], axis=-1), base

    def local(self, order: int, x: float) -> tuple[FloatArray, float]:
        m, c = self._affine(order, np.array([x]))
        return m[0], float(c[0])

    def accepts(self, order: int) -> bool:
        return order == 1

    def jerk(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self._affine(3, x)

    def build(self, u: FloatArray) -> Law:
        per = self.beta / self.h
        return InclinedSine(start_velocity=float(u[0]) * per, end_velocity=float(u[1]) * per)


def _fixed_value(seg: SegmentSpec, order: int, at_end: bool) -> float:
    """One-sided derivative of a segment whose law is fixed, at its start or end [mm/rad^order]."""
    if seg.kind is SegmentKind.DWELL or seg.law is None:
        return 0.0
    y = seg.law.evaluate(1.0 if at_end else 0.0)[order]
    return float(seg.signed_lift * y / seg.span**order)


def _j_active(seg: SegmentSpec, k: int, n: int, segments: Sequence[SegmentSpec], at_end: bool) -> bool:
    """Whether a polynomial end carries a jerk condition: given there or across the blend, or auto."""
    own = seg.end if at_end else seg.start
    if own.j is not None:
        return True
    other = segments[(k + 1) % n] if at_end else segments[(k - 1) % n]
    across = other.start if at_end else other.end
    if is_adaptive(other.law) and across.j is not None:
        return True
    return isinstance(seg.law, Polynomial) and seg.law.degree >= 7


def _lowest_degree(seg: SegmentSpec, k: int, n: int, segments: Sequence[SegmentSpec]) -> int:
    """s, v, a at both ends (6 conditions) plus each end whose jerk is given: Hermite degree."""
    return 5 + sum(_j_active(seg, k, n, segments, e) for e in (False, True))


def _check_boundary_fields(segments: Sequence[SegmentSpec]) -> None:
    for k, seg in enumerate(segments):
        for label, bnd in (("start", seg.start), ("end", seg.end)):
            if bnd.is_match:
                continue
            if not is_adaptive(seg.law):
                name = seg.law.name if seg.law is not None else "dwell"
                raise DesignError(
                    f"motion[{k}].{label}",
                    f"a {name!r} segment has its own boundary values; only law = 'polynomial' or "
                    "'inclined-sine' can meet given ones",
                )
            if isinstance(seg.law, InclinedSine):
                for order in (2, 3):
                    if bnd.value(order) is not None:
                        raise DesignError(
                            f"motion[{k}].{label}.{_NAMES[order]}",
                            "the inclined sine starts and ends with a = 0 and its own jerk; only v can be "
                            "given (use law = 'polynomial' to give a or j)",
                        )


def resolve_blends(segments: Sequence[SegmentSpec]) -> tuple[SegmentSpec, ...]:
    """Solve every adaptive segment's law from its boundary conditions.

    Parameters
    ----------
    segments
        The program as stated, in order over one turn (the last meets the first).

    Returns
    -------
    tuple[SegmentSpec, ...]
        The same segments, each adaptive law replaced by its resolved form
        (segments that need nothing are returned as they are).

    Raises
    ------
    DesignError
        ``motion[i].start.v`` (…) for a value given to a law that cannot take
        it; ``motion[i].degree`` for a degree too low for the conditions;
        ``motion[i]`` when the conditions cannot be met together.
    """
    segs = tuple(segments)
    if not any(is_adaptive(g.law) for g in segs):
        return segs
    try:
        return _resolved(segs, repr(segs))  # a sweep's variants state one program many times: solved once
    except TypeError:  # a segment that cannot be a key (unhashable data): solved here
        return _resolve(segs)


@functools.lru_cache(maxsize=64)
def _resolved(segs: tuple[SegmentSpec, ...], text: str) -> tuple[SegmentSpec, ...]:
    """:func:`_resolve`, kept for the last programs (frozen specs in, frozen specs out).

    ``text`` (the specs' repr) is part of the key so that equal but distinct
    inputs (−0.0 and 0.0) are never mixed up.
    """
    return _resolve(segs)


def _resolve(segs: tuple[SegmentSpec, ...]) -> tuple[SegmentSpec, ...]:
    """The body of :func:`resolve_blends`."""
    n = len(segs)
    _check_boundary_fields(segs)
    families: dict[int, _Family] = {}
    size = 0
    for k, seg in enumerate(segs):
        if isinstance(seg.law, Polynomial) and not seg.law.resolved:
            lowest = _lowest_degree(seg, k, n, segs)
            degree = seg.law.degree or lowest
            if degree < lowest:
                raise DesignError(
                    f"motion[{k}].degree",
                    f"degree = {degree} cannot meet the {lowest + 1} boundary conditions (s, v, a at "
                    "both ends"
                    f"{' and the given jerk' if lowest > 5 else ''}); allowed: {lowest} ≤ degree ≤ "
                    f"{MAX_POLYNOMIAL_DEGREE}, or omit degree",
                )
            families[k] = _PolyFamily(seg, size, degree)
        elif isinstance(seg.law, InclinedSine) and not seg.law.resolved:
            families[k] = _InclinedFamily(seg, size)
        else:
            continue
        size += families[k].size

    rows: list[FloatArray] = []
    rhs: list[float] = []
    where: list[int] = []  # the segment each condition belongs to, for messages

    def expr(k: int, order: int, at_end: bool) -> _Expr:
        row = np.zeros(size)
        fam = families.get(k)
        if fam is None:
            return _Expr(row, _fixed_value(segs[k], order, at_end))
        local, const = fam.local(order, 1.0 if at_end else 0.0)
        row[fam.offset : fam.offset + fam.size] = local
        return _Expr(row, const)

    def add(e: _Expr, value: float, k: int) -> None:
        rows.append(e.row)
        rhs.append(value - e.const)
        where.append(k)

    for k, fam in families.items():
        for local, value in fam.own():
            row = np.zeros(size)
            row[fam.offset : fam.offset + fam.size] = local
            rows.append(row)
            rhs.append(value)
            where.append(k)

    for k in range(n):  # the blend point at the end of segment k, start of segment k + 1
        r = (k + 1) % n
        left_fam, right_fam = families.get(k), families.get(r)
        if left_fam is None and right_fam is None:
            continue
        for order in _ORDERS:
            sides = []  # (segment, at_end, family, specified value, takes this order)
            for idx, at_end, side_fam in ((k, True, left_fam), (r, False, right_fam)):
                bnd = segs[idx].end if at_end else segs[idx].start
                takes = side_fam is not None and side_fam.accepts(order)
                if takes and order == 3 and isinstance(side_fam, _PolyFamily):
                    takes = _j_active(segs[idx], idx, n, segs, at_end)
                given = bnd.value(order) if side_fam is not None else None
                sides.append((idx, at_end, side_fam, given, takes))
            (lk, l_end, _, l_val, l_takes), (rk, r_end, _, r_val, r_takes) = sides
            if l_val is not None or r_val is not None:
                for idx, at_end, _fam, val, takes in sides:
                    given = val if val is not None else (r_val if idx == lk and at_end else l_val)
                    if takes and given is not None:
                        add(expr(idx, order, at_end), given, idx)
                continue
            if not (l_takes or r_takes):
                continue
            if order == 3 and any(
                isinstance(f, _PolyFamily) and not took
                for f, took in ((left_fam, l_takes), (right_fam, r_takes))
            ):
                continue  # a polynomial without a jerk condition here leaves its jerk free
            left, right = expr(lk, order, l_end), expr(rk, order, r_end)
            add(_Expr(left.row - right.row, left.const - right.const), 0.0, lk if l_takes else rk)

    u = np.zeros(size)
    for members in _components(families, n):
        cols = np.concatenate(
            [np.arange(families[k].offset, families[k].offset + families[k].size) for k in members]
        )
        picked = [i for i, k in enumerate(where) if k in members]
        sub = {k: families[k] for k in members}
        a = np.asarray([rows[i][cols] for i in picked], dtype=float).reshape(len(picked), cols.size)
        u[cols] = _solve(sub, cols, a, np.asarray([rhs[i] for i in picked], dtype=float))
    out = list(segs)
    for k, fam in families.items():
        out[k] = dataclasses.replace(segs[k], law=fam.build(u[fam.offset : fam.offset + fam.size]))
    return tuple(out)


def _components(families: dict[int, _Family], n: int) -> list[set[int]]:
    """Groups of adaptive segments joined by blend points between two of them (solved together)."""
    parent = {k: k for k in families}

    def find(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for k in families:
        r = (k + 1) % n
        if r in families:
            parent[find(k)] = find(r)
    groups: dict[int, set[int]] = {}
    for k in families:
        groups.setdefault(find(k), set()).add(k)
    return [groups[g] for g in sorted(groups)]


def _solve(families: dict[int, _Family], cols: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Least jerk norm subject to the conditions: [2Q Aᵀ; A 0] [u; λ] = [−2q; b] (a KKT system).

    ``cols`` are the global columns of this group's unknowns, in the order of
    ``a``'s columns. Hand-written rather than ``scipy.optimize.minimize``: the
    problem is an equality-constrained quadratic, solved exactly by one LU
    factorisation, whose condition (LAPACK ``gecon``) tells a unique solution
    from a free or conflicting one.
    """
    size = cols.size
    position = {int(c): i for i, c in enumerate(cols)}
    q_mat = np.zeros((size, size))
    q_lin = np.zeros(size)
    nodes, weights = _QUAD
    x = 0.5 * (nodes + 1.0)
    for fam in families.values():
        m, c = fam.jerk(x)
        w = 0.5 * weights * fam.beta  # ∫₀^β (·)² dφ = β ∫₀¹ (·)² dx
        sl = slice(position[fam.offset], position[fam.offset] + fam.size)
        q_mat[sl, sl] += m.T @ (w[:, None] * m)
        q_lin[sl] += m.T @ (w * c)
    norms = np.linalg.norm(a, axis=1)
    norms[norms == 0.0] = 1.0
    a, b = a / norms[:, None], b / norms  # each condition to unit scale: conditioning is fair
    first = min(families)
    label = f"motion[{first}]"
    names = ", ".join(f"motion[{k}]" for k in sorted(families))
    conflict = (
        f"the boundary conditions of {names} cannot all be met: they ask more than the laws can give "
        "(give a higher degree, or leave a value to match its neighbour)"
    )
    if a.shape[0] > size:
        raise DesignError(label, conflict)
    scale = max(float(np.max(np.abs(q_mat))), 1e-300)
    kkt = np.block([[2.0 * q_mat / scale, a.T], [a, np.zeros((a.shape[0], a.shape[0]))]])
    import scipy.linalg  # here, not at the top: only designs with blend points pay for it
    import scipy.linalg.lapack

    lu, piv = scipy.linalg.lu_factor(kkt, check_finite=False)
    rcond, _ = scipy.linalg.lapack.dgecon(lu, float(np.linalg.norm(kkt, 1)), norm="1")
    if not rcond > _RCOND_MIN:
        if a.shape[0] and np.linalg.matrix_rank(a) < a.shape[0]:
            raise DesignError(label, conflict)
        raise DesignError(
            label,
            f"the boundary conditions leave the motion of {names} undetermined (a jerk-free freedom); "
            "specify the velocity at one of its ends",
        )
    sol = scipy.linalg.lu_solve((lu, piv), np.concatenate([-2.0 * q_lin / scale, b]), check_finite=False)
    u: FloatArray = sol[:size]
    resid = np.abs(a @ u - b)
    ref = np.maximum(np.abs(b), np.abs(a) @ np.abs(u)) + 1e-300
    if np.any(resid > _KKT_RTOL * ref + 1e-12):
        raise DesignError(label, f"the boundary conditions of {names} are numerically inconsistent")
    return u
