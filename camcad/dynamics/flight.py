"""Free flight across a groove's clearance: where and how fast the roller meets the other flank.

At a crossover the force that would hold a positively driven follower on
its flank passes through zero and changes sign: the follower leaves the
flank that drove it and flies free, under its own forces only (its inertia,
the spring and its weight; the cam no longer touches it), while the groove
turns under it. With q the follower's coordinate (mm on a slide, degrees of
swing on an arm) and e = q − s(φ) its lead over the cam's motion, the flight
is

    M·q̈ = −B(q),   q(0) = s(φ0),   q̇(0) = ω·s′(φ0),   φ = φ0 + ω·t,

M the generalised mass and B the speed-independent load of
:mod:`camcad.dynamics.energy` and :mod:`camcad.dynamics.arm` (Norton 2009,
§8.11 "crossover shock"; Rothbart 2004, ch. 10). The roller centre is then
e·L·cos α from the groove's centre line along the common normal (L = 1 on a
slide, r·π/180 on an arm, r the lever from the pivot to the roller centre,
α the pressure angle): it meets the other flank when that gap reaches the
clearance c, and the impact speed is the normal approach speed |ė|·L·cos α
there. Should the flight turn back first, it lands on the flank it left, at
the speed it has then.

The free follower does not feel the cam, so its equation is autonomous and
smooth even where s″ jumps at a joint; only the gap reads the motion law. It
is integrated for the part the load adds to a flight straight on,
w = q − q(0) − q̇(0)·t (ẅ = −B(q)/M, w(0) = ẇ(0) = 0), which is as small as
the lead itself, so the step-size control works on the lead's own scale.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.motion.program import Motion
from camcad.roots import brent_root

if TYPE_CHECKING:
    from camcad.dynamics.arm import ArmLoad
    from camcad.dynamics.energy import FollowerLoad
    from camcad.geometry.cam import Cam

__all__ = ["Landing", "free_flight", "impact_speed"]

_RAD_PER_DEG = math.pi / 180.0
_RTOL = 1e-10  # relative tolerance of the step-size control

# Dormand & Prince 1980, Table 2 (Hairer, Nørsett & Wanner 1993, §II.5, Table 5.2): the 5(4) pair.
_C = (0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0)
_A = (
    (),
    (1.0 / 5.0,),
    (3.0 / 40.0, 9.0 / 40.0),
    (44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0),
    (19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0),
    (9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0),
    (35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0),
)
# b − b̂: the fifth-order weights (the last row of _A, FSAL) less the embedded fourth-order ones
_E = (
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
)

_Rhs = Callable[[float, FloatArray], FloatArray]


@dataclass(frozen=True, slots=True, kw_only=True)
class Landing:
    """Where a free flight ends.

    Attributes
    ----------
    time
        Time of flight [s] from the crossover to the touch-down.
    speed
        Normal approach speed [mm/s] at the touch-down.
    far
        True if it met the other flank, False if it landed back on the one it left.
    """

    time: float
    speed: float
    far: bool


def impact_speed(
    cam: Cam,
    phi: float,
    *,
    load: FollowerLoad | ArmLoad,
    omega: float,
    clearance: float,
    leaving: float,
) -> float:
    """Speed [mm/s] at which the roller meets a flank after leaving one at cam angle φ [rad].

    Parameters
    ----------
    cam
        The exact cam (motion, pressure angle, lever).
    phi
        The crossover's cam angle [rad], where the free flight starts.
    load
        The follower's inertia, spring and weight (generalised to the pivot on an arm).
    omega
        Cam speed ω [rad/s].
    clearance
        The groove's clearance c [mm] (normal distance between the flanks the
        roller can travel).
    leaving
        +1 if the flank it leaves drove the follower forwards (positive
        contact force), −1 if backwards.

    Returns
    -------
    float
        The normal approach speed [mm/s] at touch-down (:func:`free_flight`);
        NaN for a massless follower (it has no free flight: the rigid model
        jumps it across at once); 0 if it meets no flank within a turn.
    """
    if _generalised_mass(load) <= 0.0:
        return math.nan
    landing = free_flight(cam, phi, load=load, omega=omega, clearance=clearance, leaving=leaving)
    return 0.0 if landing is None else landing.speed


def free_flight(
    cam: Cam,
    phi: float,
    *,
    load: FollowerLoad | ArmLoad,
    omega: float,
    clearance: float,
    leaving: float,
    rtol: float = _RTOL,
) -> Landing | None:
    """The free flight from cam angle φ [rad] to the flank it meets (parameters as :func:`impact_speed`).

    Parameters
    ----------
    rtol
        Relative tolerance of the step-size control; the touch-down time and
        speed come out to about rtol/10 relative against closed forms
        (``tests/dynamics/test_flight.py``).

    Returns
    -------
    Landing or None
        None if it meets no flank within a turn, or the follower is massless.

    Notes
    -----
    Hand-written, numpy only: ``scipy.integrate`` costs 0.6–0.8 s of CPU to
    import on this project's (shared, loaded) machine, measured after
    ``import camcad.cli``; ``camcad check samples/groove_rocker.toml`` took
    2.0–2.4 s of CPU with it and 1.45–1.5 s without. The flights themselves
    are a dozen steps each (about a hundred right-hand sides per crossover),
    and every groove build has crossovers; a build of a plate or a groove
    loads no SciPy (``tests/test_imports.py``). The integrator is
    Dormand & Prince's embedded 5(4) pair with local extrapolation (Dormand &
    Prince 1980; Hairer, Nørsett & Wanner 1993, §II.5), the standard step-size
    control and starting step (ibid., §II.4), steps of at most 1° of cam
    angle. A touch-down is sought where the gap function changes sign over a
    step, by Brent's method (:func:`camcad.roots.brent_root`) on the step's
    quintic Hermite interpolant of w (value, slope and curvature at both
    ends: error O(h⁶)); the speed there is one more Runge–Kutta step from the
    step's start, so it has the integrator's accuracy, not the interpolant's.
    """
    mass = _generalised_mass(load)
    if mass <= 0.0:
        return None
    program = cam.program
    start = program.evaluate(np.array([phi]), side="right")
    q0, dq0 = float(start.s[0]), float(start.v[0]) * omega  # on the flank, moving with it

    def rhs(t: float, y: FloatArray) -> FloatArray:
        q = q0 + dq0 * t + float(y[0])
        return np.array([y[1], -float(load.static_force(_at(np.array([q])))[0]) / mass])

    def gap(t: float, w: float) -> tuple[float, float, float]:
        """(lead e, its rate of change ė [q-units/s], the normal gap per unit of lead L·cos α)."""
        st = cam.state(np.array([phi + omega * t]), side="right")
        scale = math.cos(float(st.pressure_angle[0]))
        if st.lever is not None:
            scale *= float(st.lever[0]) * _RAD_PER_DEG
        return q0 + dq0 * t + w - float(st.motion.s[0]), dq0 - omega * float(st.motion.v[0]), scale

    def events(t: float, w: float) -> tuple[float, float]:
        """(reaches the other flank, lands again on the flank it left): zero at a touch-down."""
        lead, _, scale = gap(t, w)
        return leaving * lead * scale - clearance, leaving * lead * scale + 1e-9 * clearance

    turn = TWO_PI / omega
    max_step = turn / 360.0
    atol = 1e-14 * max(clearance, 1.0)
    t, y = 0.0, np.zeros(2)
    k1 = rhs(t, y)
    g = events(t, 0.0)
    h = min(_first_step(rhs, t, y, k1, rtol=rtol, atol=atol), max_step)
    rejected = False
    while t < turn:
        h = min(h, turn - t)
        y_new, k7, err = _dopri_step(rhs, t, y, k1, h)
        ratio = _error_ratio(err, y, y_new, rtol=rtol, atol=atol)
        # Hairer, Nørsett & Wanner 1993, §II.4, eq. 4.13: safety 0.9, growth in [0.2, 10]
        grow = 10.0 if ratio == 0.0 else min(10.0, max(0.2, 0.9 * ratio**-0.2))
        if ratio > 1.0:  # rejected: retry smaller, and do not grow the step that follows
            h *= grow
            rejected = True
            continue
        if rejected:
            grow, rejected = min(grow, 1.0), False
        g_new = events(t + h, float(y_new[0]))
        crossed: list[int] = []  # the events whose sign changed over the step (as scipy's solve_ivp)
        if g[0] * g_new[0] <= 0.0:  # at the other flank
            crossed.append(0)
        if g[1] >= 0.0 >= g_new[1]:  # back on the flank it left, coming down only
            crossed.append(1)
        if crossed:
            return _landing(rhs, gap, events, crossed, (t, h, y, y_new, k1, k7))
        t, y, k1, g = t + h, y_new, k7, g_new
        h = min(h * grow, max_step)
    return None  # never meets a flank within a turn: no impact


def _landing(
    rhs: _Rhs,
    gap: Callable[[float, float], tuple[float, float, float]],
    events: Callable[[float, float], tuple[float, float]],
    crossed: list[int],
    step: tuple[float, float, FloatArray, FloatArray, FloatArray, FloatArray],
) -> Landing:
    """The earliest touch-down in the step (t, h, y, y_new, k1, k7), located on the interpolant."""
    t, h, y, y_new, k1, k7 = step
    ends = (float(y[0]), float(y[1]), float(k1[1]), float(y_new[0]), float(y_new[1]), float(k7[1]))

    hits = []
    for k in crossed:

        def g(tau: float, k: int = k) -> float:
            return events(tau, _hermite(ends, h, tau - t))[k]

        hits.append((brent_root(g, t, t + h, xtol=1e-15 * h), k))
    t_hit, k = min(hits)
    y_hit = _dopri_step(rhs, t, y, k1, t_hit - t)[0] if t_hit > t else y
    _, rate, scale = gap(t_hit, float(y_hit[0]))
    return Landing(time=t_hit, speed=abs(rate + float(y_hit[1])) * scale, far=k == 0)


def _dopri_step(
    rhs: _Rhs, t: float, y: FloatArray, k1: FloatArray, h: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """One Dormand–Prince step of size h from (t, y) with k1 = f(t, y).

    Returns the fifth-order solution at t + h, f there (the next step's k1:
    "first same as last") and the local error estimate h·Σ(b − b̂)·k
    (Hairer, Nørsett & Wanner 1993, §II.5, Table 5.2).
    """
    ks = [k1]
    y_new = y
    for c, row in zip(_C[1:], _A[1:], strict=True):
        y_new = y + h * _combine(row, ks)  # after the last stage: the solution (its weights are _A[6])
        ks.append(rhs(t + c * h, y_new))
    return y_new, ks[6], h * _combine(_E, ks)


def _combine(weights: tuple[float, ...], ks: list[FloatArray]) -> FloatArray:
    """Σ weights[i]·ks[i], summed in order."""
    out = np.zeros_like(ks[0])
    for w, k in zip(weights, ks, strict=False):
        out = out + w * k
    return out


def _error_ratio(err: FloatArray, y: FloatArray, y_new: FloatArray, *, rtol: float, atol: float) -> float:
    """‖err / (atol + rtol·max(|y|, |y_new|))‖ in the RMS norm: ≤ 1 accepts the step (HNW 1993, eq. 4.11)."""
    scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
    return float(np.sqrt(np.mean((err / scale) ** 2)))


def _first_step(rhs: _Rhs, t: float, y: FloatArray, f0: FloatArray, *, rtol: float, atol: float) -> float:
    """The starting step size of Hairer, Nørsett & Wanner 1993, §II.4 ("starting step size"), order 5."""
    scale = atol + rtol * np.abs(y)
    d0 = float(np.sqrt(np.mean((y / scale) ** 2)))
    d1 = float(np.sqrt(np.mean((f0 / scale) ** 2)))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    f1 = rhs(t + h0, y + h0 * f0)
    d2 = float(np.sqrt(np.mean(((f1 - f0) / scale) ** 2))) / h0
    big = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** 0.2
    return min(100.0 * h0, h1)


def _hermite(ends: tuple[float, float, float, float, float, float], h: float, x: float) -> float:
    """w(t + x) on a step from (w0, ẇ0, ẅ0, w1, ẇ1, ẅ1) at its ends: the quintic Hermite interpolant."""
    w0, dw0, ddw0, w1, dw1, ddw1 = ends
    u = x / h
    u3 = u**3
    # the quintic Hermite basis on [0, 1] (value, slope, curvature at 0; then at 1)
    p0 = 1.0 - u3 * (10.0 - 15.0 * u + 6.0 * u * u)
    p1 = u - u3 * (6.0 - 8.0 * u + 3.0 * u * u)
    p2 = 0.5 * u * u - u3 * (1.5 - 1.5 * u + 0.5 * u * u)
    p4 = -u3 * (4.0 - 7.0 * u + 3.0 * u * u)
    p5 = u3 * (0.5 - u + 0.5 * u * u)
    return p0 * w0 + (1.0 - p0) * w1 + h * (p1 * dw0 + p4 * dw1) + h * h * (p2 * ddw0 + p5 * ddw1)


def _at(s: FloatArray, a: float = 0.0) -> Motion:
    """A one-sample motion at displacement s with s″ = a (what the loads read: ``s`` and ``a``)."""
    zero = np.zeros(1)
    return Motion(phi=zero, s=s, v=zero, a=np.full(1, a), j=zero)


def _generalised_mass(load: FollowerLoad | ArmLoad) -> float:
    """M in M·q̈ [N or N·mm] per unit of q̈ [mm/s² or °/s²]: the inertia coefficient at s″ = 1."""
    return float(load.inertia_coefficient(_at(np.zeros(1), 1.0))[0])
