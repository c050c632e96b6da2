"""Follower jump: where contact is lost, and the preload and speed that prevent it.

Both dynamic models give the contact force as C = F/c with the axial load
F = A·ω² + B (see :class:`~camcad.dynamics.energy.FollowerLoad`) and a
positive, speed- and preload-independent factor c: cos α for the energy
method (Quintero & Vanegas 2016, eq. 19), the eq. 25 denominator over
b_m − a_m for the guided tappet (Hren et al.). C ≥ margin is therefore
linear in the preload F0 and in ω², and both limits have closed forms.

Contact counts as kept where C ≥ margin and as lost (a jump) where C < margin;
with the default margin 0 an unloaded follower (C ≡ 0) does not jump.
"""

from __future__ import annotations

import math

import numpy as np

from camcad._typing import ArrayLike, FloatArray
from camcad.angles import TWO_PI

__all__ = [
    "covering_arc",
    "loss_runs",
    "min_preload",
    "preload_need",
    "speed_bounds",
    "speed_limits",
    "speed_window",
]


def min_preload(
    *,
    inertia: ArrayLike,
    static_without_preload: ArrayLike,
    ratio: ArrayLike,
    omega: float,
    margin: float = 0.0,
) -> float:
    """Find the smallest spring preload that keeps the contact force ≥ ``margin`` at every sample.

    Parameters
    ----------
    inertia
        (n,) A = m·a/1000 [N·s²]: inertia force per ω².
    static_without_preload
        (n,) m·g + k·s [N].
    ratio
        (n,) c > 0 [1] with C = F/c.
    omega
        Cam speed ω [rad/s].
    margin
        Required smallest contact force [N].

    Returns
    -------
    float
        F0* = max(0, max_φ(margin·c − A·ω² − m·g − k·s)) [N]. With F0 = F0*
        the smallest contact force equals the margin (or exceeds it if 0
        already suffices).
    """
    need = preload_need(
        inertia=inertia,
        static_without_preload=static_without_preload,
        ratio=ratio,
        omega=omega,
        margin=margin,
    )
    return max(0.0, float(np.max(need)))


def preload_need(
    *,
    inertia: ArrayLike,
    static_without_preload: ArrayLike,
    ratio: ArrayLike,
    omega: float,
    margin: float = 0.0,
) -> FloatArray:
    """(n,) margin·c − A·ω² − (m·g + k·s) [N]: the preload each angle needs; see :func:`min_preload`."""
    # ω·ω, not ω**2: libm's pow is not always the correctly rounded square (glibc: < 0.52 ulp), so a
    # scalar ω**2 can differ in the last bit from the same speeds squared as an array in a batch
    out: FloatArray = margin * np.asarray(ratio, dtype=float) - (
        np.asarray(inertia, dtype=float) * (omega * omega) + np.asarray(static_without_preload, dtype=float)
    )
    return out


def speed_bounds(
    *, inertia: ArrayLike, static: ArrayLike, ratio: ArrayLike, margin: float = 0.0
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per angle (n,): the need where A = 0, and the ω² bounds from above and from below.

    Returns ``(flat, upper, lower)``: ``flat`` = margin·c − B where A = 0
    (must be ≤ 0), else −inf; ``upper`` = (margin·c − B)/A where A < 0 (ω²
    must stay below its minimum), else +inf; ``lower`` the same where A > 0
    (ω² must exceed its maximum), else −inf. See :func:`speed_limits`.
    """
    a = np.asarray(inertia, dtype=float)
    need = margin * np.asarray(ratio, dtype=float) - np.asarray(static, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # A tiny: the bound ±inf, as A → 0
        bound = need / a
    flat: FloatArray = np.where(a == 0.0, need, -np.inf)
    upper: FloatArray = np.where(a < 0.0, bound, np.inf)
    lower: FloatArray = np.where(a > 0.0, bound, -np.inf)
    return flat, upper, lower


def speed_limits(
    *, inertia: ArrayLike, static: ArrayLike, ratio: ArrayLike, margin: float = 0.0
) -> tuple[float, float] | None:
    """Find the cam speeds that keep the contact force ≥ ``margin`` at every sample.

    Parameters
    ----------
    inertia
        (n,) A = m·a/1000 [N·s²]: inertia force per ω².
    static
        (n,) B = m·g + k·s + F0 [N].
    ratio
        (n,) c > 0 [1] with C = (A·ω² + B)/c.
    margin
        Required smallest contact force [N].

    Returns
    -------
    tuple[float, float] | None
        (ω_low, ω_high) [rad/s]: A·ω² + B ≥ margin·c holds at every sample for
        ω_low ≤ ω ≤ ω_high; ω_high is ``inf`` when no sample decelerates the
        follower. ``None`` when no speed works.

    Notes
    -----
    Each sample bounds ω² by (margin·c − B)/A: from above where A < 0 (the
    follower decelerates, the spring must hold it), from below where A > 0
    and B alone falls short. Where A = 0 it needs B ≥ margin·c.
    """
    flat, upper, lower = speed_bounds(inertia=inertia, static=static, ratio=ratio, margin=margin)
    if np.max(flat, initial=-np.inf) > 0.0:
        return None
    return speed_window(float(np.max(lower, initial=0.0)), float(np.min(upper, initial=math.inf)))


def speed_window(w2_low: float, w2_high: float) -> tuple[float, float] | None:
    """(ω_low, ω_high) [rad/s] from the bounds ω² ≥ ``w2_low`` and ω² ≤ ``w2_high`` [rad²/s²], or None."""
    w2_low = max(0.0, w2_low)
    if w2_high < 0.0 or w2_low > w2_high:
        return None
    return math.sqrt(w2_low), math.sqrt(w2_high)


def loss_runs(phi: ArrayLike, lost: ArrayLike) -> tuple[tuple[float, float], ...]:
    """Find the contiguous runs of samples where contact is lost, on the circle.

    Parameters
    ----------
    phi
        (n,) cam angles [rad], ascending.
    lost
        (n,) bool, True where contact is lost.

    Returns
    -------
    tuple[tuple[float, float], ...]
        (first, last) sample angle of each run [rad], in [0, 2π). When the
        samples cover the whole turn, a run through 360° → 0° is one run with
        first > last.
    """
    ang = np.mod(np.asarray(phi, dtype=float), TWO_PI)
    mask = np.asarray(lost, dtype=bool)
    if not mask.any():
        return ()
    if mask.all():
        return ((float(ang[0]), float(ang[-1])),)
    edges = np.flatnonzero(np.diff(mask.astype(np.int8)))
    starts = [0] if mask[0] else []
    starts += [int(e) + 1 for e in edges if not mask[e]]
    ends = [int(e) for e in edges if mask[e]]
    if mask[-1]:
        ends.append(mask.size - 1)
    runs = [(float(ang[i]), float(ang[k])) for i, k in zip(starts, ends, strict=True)]
    step = float(np.max(np.diff(ang))) if ang.size > 1 else TWO_PI
    wraps = mask[0] and mask[-1] and ang[0] + TWO_PI - ang[-1] <= 1.5 * step
    if wraps and len(runs) > 1:
        runs = [(runs[-1][0], runs[0][1]), *runs[1:-1]]
    return tuple(runs)


def covering_arc(runs: tuple[tuple[float, float], ...]) -> tuple[float, float] | None:
    """Find the shortest arc of the turn that contains every run.

    Parameters
    ----------
    runs
        (first, last) angles [rad] from :func:`loss_runs`.

    Returns
    -------
    tuple[float, float] | None
        (start, end) [rad] in [0, 2π), start > end when the arc passes 0;
        ``None`` without runs.
    """
    if not runs:
        return None
    if len(runs) == 1:
        return runs[0]
    ordered = sorted(runs, key=lambda r: r[0])
    # gap after each run, to the start of the next one (circularly)
    gaps = []
    for k, (_, end) in enumerate(ordered):
        nxt = ordered[(k + 1) % len(ordered)][0]
        gaps.append(((nxt - end) % TWO_PI, k))
    _, k = max(gaps)
    return ordered[(k + 1) % len(ordered)][0], ordered[k][1]
