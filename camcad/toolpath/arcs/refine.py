"""Fewer arcs on a closed arc spline: drop one arc and refit the rest to the curve by minimax.

The layered search (:mod:`camcad.toolpath.arcs.search`) keeps, in each cell
of end states, the one farthest along the curve. That choice is greedy: a
short arc before a dwell or a curvature jump sets up the next one, and the
loop closes where it can. This module takes the search's loop and moves all
its arcs at once.

A closed tangent-continuous arc spline of n arcs is fixed by its start
(point p₀, tangent angle θ₀) and each arc's curvature κᵢ and length sᵢ:
x = (p₀, θ₀, κ₁…κₙ, s₁…sₙ); joint i + 1 is joint i moved along arc i. The
loop closes when pₙ = p₀ and θₙ = θ₀ + W (W the total turn, ±2π), and it
starts abeam C(a) when (p₀ − C(a))·T(a) = 0. The fit minimises the largest
normal gap of curve samples from the circle of the arc each sample lies
along (between the nearest samples of its two joints). The largest gap is
not smooth, so Levenberg–Marquardt minimises Σ (g/τ)^(2p) with τ the current
largest gap and p = 8 (the 16-norm), then 16 once that stalls (Marquardt
1963, with his scaling of the damping by the diagonal; the step is that of
Gauss–Newton on (g/τ)^p, tried also at twice its length), the four
equations held by the KKT system,
with the Jacobian by hand (a change of κⱼ or sⱼ moves the loop after arc j
rigidly: a turn about joint j + 1). It is hand-written because
``scipy.optimize`` costs 0.3 s to import in a build that otherwise needs
no SciPy, and its SLSQP with differenced gradients took 10 s per loop here.

:func:`thin_loop` tries, for each arc i, the loop with arcs i − 1, i, i + 1
replaced by a biarc between the joints around them (the rest unchanged, so
the loop stays closed; the arcs next to the start instead give half their
length to each neighbour), refits the candidates whose guess starts nearest
the curve, and keeps the first whose two-way deviation, measured by
:func:`~camcad.toolpath.arcs.biarc.measure_deviation`, is within the
tolerance; it stops after ``_TRIES`` failed refits in a row. It runs only
when asked (``[gcode] fewest_arcs``): on the shipped samples it drops 1–2
arcs on seven of twelve (every loop then within 1.2 times the asymptotic
fewest arcs of ``benchmarks/gcode.py``) for up to 0.27 s more per contour.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.toolpath.arcs.biarc import (
    CurveFn,
    Pieces,
    abeam,
    angle_of,
    biarc_pieces,
    circle_gap,
    cross,
    left_normal,
    measure_deviation,
    single_arcs,
)

__all__ = ["thin_loop"]

_STRETCH = (1.0, 2.0)  # × the Gauss–Newton step: a step of twice the length is taken when it does better
_POWER, _POWER_MAX = 8, 16  # the fit minimises the 2p-norm of the gaps, p from 8 to 16
_SAMPLES_PER_ARC = 24  # curve samples per arc the gaps are taken at (at least _MIN_SAMPLES)
_MIN_SAMPLES = 512
_TARGET = 0.95  # × tolerance: the sampled largest gap a refit must reach before it is measured
_ITERATIONS = 80  # Levenberg–Marquardt steps per refit at most
_STALL, _PROGRESS = 6, 0.1  # a refit stalls when its largest gap fell less than 10 % in 6 steps
_WINDOW = 6  # samples either side of a joint's last nearest sample searched for its next
_RATIOS = np.array([0.5, 0.7, 1.0, 1.4, 2.0])  # d₁/d of the biarcs tried in place of three arcs
_NEAR = 1.05  # × target: a refit stalled farther off than this stops; nearer, p doubles
_TRIES = 4  # failed drops in a row before thinning stops
_LARGEST_LOOP = 96  # arcs: a longer loop is left as the search made it (dense Jacobian, O(n²) per step)


@dataclass(frozen=True, slots=True)
class _Loop:
    """Chain x = (p₀, θ₀, κ…, s…) of n arcs: joints (n + 1, 2), tangent angles, unit tangents, dchord/dκ."""

    x: FloatArray
    n: int
    p: FloatArray
    th: FloatArray
    tan: FloatArray
    dchord: FloatArray


def _joints(x: FloatArray, n: int) -> _Loop:
    """The chain's joints, their tangent angles and unit tangents, and dchord/dκ of each arc."""
    k, s = x[3 : 3 + n], x[3 + n :]
    half = 0.5 * k * s
    th = np.empty(n + 1)
    th[0] = 0.0
    np.cumsum(k * s, out=th[1:])
    th += x[2]
    tan = np.empty((n + 1, 2))
    tan[:, 0], tan[:, 1] = np.cos(th), np.sin(th)
    mid = th[:-1] + half
    small = np.abs(half) < 1e-4
    hh = np.where(small, 1.0, half)
    sin_h = np.sin(hh)
    sinc = np.where(small, 1.0 - half * half / 6.0, sin_h / hh)
    dsinc = np.where(small, -half / 3.0, (hh * np.cos(hh) - sin_h) / (hh * hh))
    u0, u1 = np.cos(mid), np.sin(mid)
    p = np.empty((n + 1, 2))
    p[0] = 0.0
    length = s * sinc
    np.cumsum(length * u0, out=p[1:, 0])
    np.cumsum(length * u1, out=p[1:, 1])
    p += x[:2]
    # d(chord)/dκ = (s²/2)·(sinc'(h) u + sinc(h) u⊥), h = κs/2
    scale = 0.5 * s * s
    dchord = np.empty((n, 2))
    dchord[:, 0] = scale * (dsinc * u0 - sinc * u1)
    dchord[:, 1] = scale * (dsinc * u1 + sinc * u0)
    return _Loop(x, n, p, th, tan, dchord)


def _assign(p: FloatArray, q: FloatArray, near: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Arc index of each curve sample (those from joint i's nearest sample to joint i + 1's are on arc i).

    Also returns each joint's nearest sample; given last step's (``near``),
    only ``_WINDOW`` samples either side are searched, and all where the
    nearest is at a window's edge.
    """
    n, m = p.shape[0] - 1, q.shape[0]
    if near is None:
        found = np.argmin(np.sum((q[None, :, :] - p[:-1, None, :]) ** 2, axis=2), axis=1)
    else:
        idx = (near[:, None] + np.arange(-_WINDOW, _WINDOW + 1)[None, :]) % m
        best = np.argmin(np.sum((q[idx] - p[:-1, None, :]) ** 2, axis=2), axis=1)
        found = idx[np.arange(n), best]
        edge = (best == 0) | (best == 2 * _WINDOW)
        if edge.any():
            found[edge] = np.argmin(np.sum((q[None, :, :] - p[:-1][edge][:, None, :]) ** 2, axis=2), axis=1)
    rel = (found - found[0]) % m
    order = np.argsort(rel, kind="stable")
    seg = np.searchsorted(rel[order], (np.arange(m) - found[0]) % m, side="right") - 1
    out: np.ndarray = order[np.clip(seg, 0, n - 1)]
    return out, found


def _gaps(
    loop: _Loop, q: FloatArray, seg: np.ndarray, *, jacobian: bool = True
) -> tuple[FloatArray, FloatArray | None]:
    """Signed gaps (m,) [mm] of the samples from their arcs' circles, and (``jacobian``) dg/dx (m, 3 + 2n)."""
    x, n, p, dchord = loop.x, loop.n, loop.p, loop.dchord
    k, s = x[3 : 3 + n], x[3 + n :]
    pi, t, ki = p[seg], loop.tan[seg], k[seg]
    w = q - pi
    w0, w1 = w[:, 0], w[:, 1]
    b = cross(t, w)  # w·n, n the left normal
    ww = w0 * w0 + w1 * w1
    # circle_gap's form written out: the Jacobian below needs its f, root and den (root kept off 0)
    f = ki * ww - 2.0 * b
    root = np.sqrt(np.maximum(1.0 - 2.0 * ki * b + ki * ki * ww, 1e-300))
    den = 1.0 + root
    g = f / den
    if not jacobian:
        return g, None
    # partial derivatives of g by the arc's start point, start angle and curvature
    d_b_p, d_ww_p = -left_normal(t), -2.0 * w
    d_b_th = -(w0 * t[:, 0] + w1 * t[:, 1])

    d_f_p = ki[:, None] * d_ww_p - 2.0 * d_b_p
    d_d_p = -2.0 * ki[:, None] * d_b_p + (ki * ki)[:, None] * d_ww_p
    gp = (d_f_p - (g / (2.0 * root))[:, None] * d_d_p) / den[:, None]
    gth = (-2.0 * d_b_th - (g / (2.0 * root)) * (-2.0 * ki * d_b_th)) / den
    gk = (ww - (g / (2.0 * root)) * (-2.0 * b + 2.0 * ki * ww)) / den
    # a change of κⱼ or sⱼ (j before the sample's arc) turns the loop after arc j about joint j + 1
    rm = gth + cross(pi, gp)  # gθ + (pᵢ × gp)
    turn = rm[:, None] - (gp[:, 1:2] * p[None, 1 : n + 1, 0] - gp[:, 0:1] * p[None, 1 : n + 1, 1])
    before = np.arange(n)[None, :] < seg[:, None]
    t_end = loop.tan[1:]
    jk = np.where(before, s[None, :] * turn + gp @ dchord.T, 0.0)
    jk[np.arange(seg.size), seg] += gk
    js = np.where(before, k[None, :] * turn + gp @ t_end.T, 0.0)
    jac = np.concatenate((gp, (rm - cross(x[:2], gp))[:, None], jk, js), axis=1)
    return g, jac


def _closure(loop: _Loop, turn: float, c0: FloatArray, t0: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The four equations (closed in point and angle, start abeam C(a)) and their Jacobian (4, 3 + 2n)."""
    x, n, p, th, dchord = loop.x, loop.n, loop.p, loop.th, loop.dchord
    k, s = x[3 : 3 + n], x[3 + n :]
    c = np.array([p[n, 0] - p[0, 0], p[n, 1] - p[0, 1], th[n] - th[0] - turn, float((p[0] - c0) @ t0)])
    rel = left_normal(p[n] - p[1:])  # J(pₙ − pⱼ₊₁)
    t_end = loop.tan[1:]
    jac = np.zeros((4, 3 + 2 * n))
    jac[0:2, 2] = left_normal(p[n] - p[0])
    jac[0:2, 3 : 3 + n] = (dchord + s[:, None] * rel).T
    jac[0:2, 3 + n :] = (t_end + k[:, None] * rel).T
    jac[2, 3 : 3 + n], jac[2, 3 + n :] = s, k
    jac[3, 0:2] = t0
    return c, jac


def _onto(x: FloatArray, n: int, turn: float, c0: FloatArray, t0: FloatArray, steps: int) -> _Loop:
    """The chain moved onto the four equations by up to ``steps`` least-change Newton steps."""
    loop = _joints(x, n)
    for _ in range(steps):
        c, a = _closure(loop, turn, c0, t0)
        if np.abs(c).max() <= 1e-12:
            break
        loop = _joints(loop.x - a.T @ np.linalg.solve(a @ a.T, c), n)
    return loop


def _minimax(
    x: FloatArray, n: int, q: FloatArray, turn: float, c0: FloatArray, t0: FloatArray, target: float
) -> tuple[FloatArray, float]:
    """Levenberg–Marquardt on Σ (g/τ)^(2p) under the four equations: the best x and its largest gap [mm].

    Returns as soon as the largest sampled gap is at most ``target``; the
    equations hold to 1e-9 mm (and rad) at every returned x. When the gap
    falls less than ``_PROGRESS`` in ``_STALL`` steps, p doubles (up to
    ``_POWER_MAX``: the norm nears the maximum), and then the refit stops. A
    refit that stalls more than ``_NEAR`` times the target away stops at the
    first stall: on the shipped samples the 32-norm never took such a refit
    to the target, and those steps were a third of all the refits' steps.
    """
    size = x.size
    loop = _onto(x, n, turn, c0, t0, 8)  # a dropped arc leaves the loop open by millimetres
    seg, near = _assign(loop.p, q)
    g, jac = _gaps(loop, q, seg)
    c, a = _closure(loop, turn, c0, t0)
    best = (math.inf, loop.x)
    lam, power = 1e-3, _POWER
    seen: list[float] = []
    for _ in range(_ITERATIONS):
        tau = float(np.abs(g).max())
        if np.abs(c).max() <= 1e-9 and tau < best[0]:
            best = (tau, loop.x)
            if tau <= target:
                break
        seen.append(tau)
        if len(seen) > _STALL and tau > (1.0 - _PROGRESS) * seen[-1 - _STALL]:
            if power >= _POWER_MAX or tau > _NEAR * target:
                break  # stalled above the target: this arc count does not fit here
            power, seen = 2 * power, []
        assert jac is not None
        u = g / tau
        r = u**power
        jr = (power * u ** (power - 1) / tau)[:, None] * jac
        h, grad = jr.T @ jr, jr.T @ r
        f0 = float(r @ r)
        kkt = np.zeros((size + 4, size + 4))
        kkt[:size, size:], kkt[size:, :size] = a.T, a
        rhs = np.concatenate((-grad, -c))
        diag = np.diag(h) + 1e-12
        while True:
            kkt[:size, :size] = h
            kkt[np.arange(size), np.arange(size)] += lam * diag
            try:
                step = np.linalg.solve(kkt, rhs)[:size]
            except np.linalg.LinAlgError:
                step = None
            if step is not None:
                found = None
                for stretch in _STRETCH:
                    cand = _onto(loop.x + stretch * step, n, turn, c0, t0, 1)  # nearly linear over a step
                    # the trial keeps the samples' arcs; they are assigned again once it is taken
                    gn, _ = _gaps(cand, q, seg, jacobian=False)
                    fn = float(np.sum((gn / tau) ** (2 * power))) if np.all(np.isfinite(gn)) else math.inf
                    if fn < f0 and (found is None or fn < found[0]):
                        found = (fn, cand)
                    elif found is not None:
                        break
                if found is not None:
                    trial = found[1]
                    break
            lam *= 8.0
            if lam > 1e6:
                return best[1], best[0]
        loop = trial
        seg, near = _assign(loop.p, q, near)
        g, jac = _gaps(loop, q, seg)
        c, a = _closure(loop, turn, c0, t0)
        lam = max(lam / 4.0, 1e-9)
    tau = float(np.abs(g).max())
    if np.abs(c).max() <= 1e-9 and tau < best[0]:
        best = (tau, loop.x)
    return best[1], best[0]


def _chain(pieces: Pieces) -> tuple[FloatArray, int]:
    """The chain x = (p₀, θ₀, κ…, s…) of the non-empty pieces in order (arcs and lines), and its length."""
    length = pieces.length().ravel()
    keep = np.flatnonzero(length > 0.0)
    start_tangent = pieces.tangents()[0].reshape(-1, 2)[keep[0]]
    head = np.concatenate((pieces.start.reshape(-1, 2)[keep[0]], angle_of(start_tangent[None])))
    return np.concatenate((head, pieces.curvature().ravel()[keep], length[keep])), int(keep.size)


def _pieces(curve: CurveFn, x: FloatArray, n: int, a: float, q: FloatArray, phi_q: FloatArray) -> Pieces:
    """The loop's arcs as pieces, their φ-intervals from a to a + 2π between the joints abeam on the curve."""
    loop = _joints(x, n)
    p = loop.p
    near = np.argmin(np.sum((q[None, :, :] - p[1:n, None, :]) ** 2, axis=2), axis=1)
    at, _ = abeam(curve, p[1:n], phi_q[near])
    edges = np.concatenate(([a], at, [a + 2.0 * math.pi]))
    t = loop.tan[:-1]
    end = p[1:].copy()
    end[-1] = p[0]
    return single_arcs(edges[:-1], edges[1:], p[:-1], t, end)


def _drop(x: FloatArray, n: int, i: int) -> FloatArray:
    """The chain without arc i, half its length given to each neighbour (a first guess for a refit)."""
    k, s = x[3 : 3 + n].copy(), x[3 + n :].copy()
    if i == 0:  # the loop then starts halfway along the old first arc
        half = _joints(np.concatenate((x[:3], k[:1], 0.5 * s[:1])), 1)
        p, th = half.p, half.th
        head = np.concatenate((p[1], th[1:2]))
        s[1] += 0.5 * s[0]
        s[n - 1] += 0.5 * s[0]
        return np.concatenate((head, k[1:], s[1:]))
    s[i - 1] += 0.5 * s[i]
    s[(i + 1) % n] += 0.5 * s[i]
    return np.concatenate((x[:3], np.delete(k, i), np.delete(s, i)))


def _merges(
    x: FloatArray, n: int, q: FloatArray, seg: np.ndarray
) -> tuple[np.ndarray, FloatArray, FloatArray]:
    """For each arc 0 < i < n − 1: the chain with arcs i − 1, i, i + 1 replaced by a biarc.

    The biarc runs between the joints around the three arcs with their
    tangents (so the rest of the loop is unchanged and it stays closed), its
    d₁/d each of ``_RATIOS`` (:func:`~camcad.toolpath.arcs.biarc.biarc_pieces`). Returns the
    arc index of each guess (k,), the guesses (k, 3 + 2(n − 1)) and each
    guess's largest gap [mm] on the samples ``seg`` puts on the three arcs.
    """
    loop = _joints(x, n)
    p, tan = loop.p, loop.tan
    k, s = x[3 : 3 + n], x[3 + n :]
    i = np.repeat(np.arange(1, n - 1), _RATIOS.size)
    p0, p1 = p[i - 1], p[i + 2]
    t0, t1 = tan[i - 1], tan[i + 2]
    zero = np.zeros(i.size)
    biarc = biarc_pieces(zero, zero, p0, t0, p1, t1, ratio=np.tile(_RATIOS, n - 2))
    curvature, length = biarc.curvature(), biarc.length()
    ka, kb, sa, sb = curvature[:, 0], curvature[:, 1], length[:, 0], length[:, 1]
    joint, tm = biarc.end[:, 0], biarc.tangents()[0][:, 1]
    ok = np.isfinite(ka + kb + sa + sb) & np.all(np.isfinite(tm), axis=1)
    out = np.empty((i.size, 3 + 2 * (n - 1)))
    out[:, :3] = x[:3]
    for row in np.flatnonzero(ok):
        j = i[row]
        kk = np.concatenate((k[: j - 1], [ka[row], kb[row]], k[j + 2 :]))
        ss = np.concatenate((s[: j - 1], [sa[row], sb[row]], s[j + 2 :]))
        out[row, 3:] = np.concatenate((kk, ss))
    # the largest gap of each guess: the rest of the loop is unchanged, so only the samples of the
    # three arcs count, each measured from the biarc's arc it lies along (split at the joint's normal)
    first = np.searchsorted(seg, np.arange(n + 1))  # seg is sorted (from the start joint's sample on)
    lo, hi = first[i - 1], first[i + 2]
    width = int((hi - lo).max())
    idx = lo[:, None] + np.arange(width)[None, :]
    inside = idx < hi[:, None]
    w = q[np.minimum(idx, q.shape[0] - 1)]
    second = np.sum((w - joint[:, None, :]) * tm[:, None, :], axis=2) > 0.0
    start = np.where(second[..., None], joint[:, None, :], p0[:, None, :])
    tang = np.where(second[..., None], tm[:, None, :], t0[:, None, :])
    kap = np.where(second, kb[:, None], ka[:, None])
    v = w - start
    b = cross(tang, v)
    vv = np.sum(v * v, axis=2)
    worst = np.where(inside, np.abs(circle_gap(kap, b, vv)), 0.0).max(axis=1)
    return i[ok], out[ok], worst[ok]


def thin_loop(curve: CurveFn, pieces: Pieces, tolerance: float, a: float) -> tuple[Pieces, FloatArray] | None:
    """A closed arc spline with fewer arcs than ``pieces`` within ``tolerance`` [mm] of the curve, or None.

    Parameters
    ----------
    curve
        The exact closed curve C(φ), C(φ + 2π) = C(φ).
    pieces
        A closed tangent-continuous arc spline within ``tolerance`` (the
        search's), its φ-intervals from its start to the same φ + 2π.
    tolerance
        Two-way deviation allowed [mm].
    a
        φ [rad] the loop starts abeam of.

    Returns
    -------
    (Pieces, FloatArray) or None
        Single arcs (an empty second piece each) whose φ-intervals run from a
        to a + 2π, starting abeam C(a), and their measured two-way deviations;
        None when no arc could be dropped.
    """
    x, n = _chain(pieces)
    if n < 4 or n > _LARGEST_LOOP:
        return None
    turn = 2.0 * math.pi * round(float(np.sum(x[3 : 3 + n] * x[3 + n :])) / (2.0 * math.pi))
    m = max(_MIN_SAMPLES, _SAMPLES_PER_ARC * n)
    phi_q = a + 2.0 * math.pi * (np.arange(m) + 0.5) / m
    q = curve(phi_q)[0]
    c0, d0, _ = curve(np.array([a]))
    c0, t0 = c0[0], d0[0] / np.linalg.norm(d0[0])
    out: tuple[Pieces, FloatArray] | None = None
    tried = 0
    while tried < _TRIES and n > 3:
        seg, near = _assign(_joints(x, n).p, q)
        # the samples from the start joint's nearest on, so that their arc indices are sorted
        which, guesses, first = _merges(x, n, np.roll(q, -near[0], axis=0), np.roll(seg, -near[0]))
        ends = [_drop(x, n, 0), _drop(x, n, n - 1)]
        loops = [_joints(gx, n - 1) for gx in ends]
        gaps = [_gaps(lp, q, _assign(lp.p, q)[0], jacobian=False)[0] for lp in loops]
        first = np.concatenate((first, [float(np.abs(g).max()) for g in gaps]))
        which = np.concatenate((which, [0, n - 1]))
        guesses = np.concatenate((guesses, ends))
        order = np.argsort(first, kind="stable")
        _, pick = np.unique(which[order], return_index=True)  # each arc's best guess
        pick = order[np.sort(pick)]
        pick = pick[np.argsort(first[pick], kind="stable")]  # guesses nearest the curve first
        for guess in guesses[pick[:_TRIES]]:
            fit, gap = _minimax(guess, n - 1, q, turn, c0, t0, _TARGET * tolerance)
            tried += 1
            if gap > _TARGET * tolerance:
                continue
            pc = _pieces(curve, fit, n - 1, a, q, phi_q)
            with np.errstate(invalid="ignore", divide="ignore"):
                dev = measure_deviation(curve, pc)
            if np.all(pc.hi > pc.lo) and np.all(dev <= tolerance):
                x, n, out, tried = fit, n - 1, (pc, dev), 0
                break
        else:
            break
    return out
