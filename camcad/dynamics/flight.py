"""Free flight across a groove's clearance: where and how fast the roller meets the other flank.

At a crossover the force that would hold a positively driven follower on
its flank passes through zero and changes sign: the follower leaves the
flank that drove it and flies free, under its own forces only (its inertia,
the spring and its weight; the cam no longer touches it), while the groove
turns under it. With e = q − s(φ) the follower's lead over the cam's motion
(q its coordinate: mm on a slide, degrees of swing on an arm) the flight is

    M·q̈ = −B(q),   ë = −B(s + e)/M − ω²·s″(φ),   φ = φ0 + ω·t,

e(0) = ė(0) = 0 (it left the flank moving with it), M the generalised mass
and B the speed-independent load of :mod:`camcad.dynamics.energy` and
:mod:`camcad.dynamics.arm` (Norton 2009, §8.11 "crossover shock"; Rothbart
2004, ch. 10). The roller centre is then e·L·cos α from the groove's centre
line along the common normal (L = 1 on a slide, r·π/180 on an arm, r the
lever from the pivot to the roller centre, α the pressure angle): it meets
the other flank when that gap reaches the clearance c, and the impact speed
is the normal approach speed |ė|·L·cos α there. Should the flight turn back
first, it lands on the flank it left, at the speed it has then.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.dynamics.arm import ArmLoad
    from camcad.dynamics.energy import FollowerLoad
    from camcad.geometry.cam import Cam

__all__ = ["impact_speed"]

_RAD_PER_DEG = math.pi / 180.0
_RTOL = 1e-10  # DOP853's relative tolerance: the flight is a few hundred steps at most


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
        The normal approach speed [mm/s] at touch-down; NaN for a massless
        follower (it has no free flight: the rigid model jumps it across at once).

    Notes
    -----
    Integrated by scipy's DOP853 (rtol 1e-10) with the touch-down as a
    terminal event located on its dense output; the free flight starts on the
    right-hand side of a joint. See the module docstring for the equations.
    """
    from scipy.integrate import solve_ivp  # here: only a groove's crossovers need it

    mass = _generalised_mass(load)
    if mass <= 0.0:
        return math.nan
    program = cam.program

    # The integrator asks for the cam at one time more than once (the last stage of a step and the
    # first of the next; both events at each step's end): each is evaluated once per time.
    motions: dict[float, tuple[float, float]] = {}
    scales: dict[float, float] = {}

    def motion_at(t: float) -> tuple[float, float]:
        if t not in motions:
            m = program.evaluate(np.array([phi + omega * t]), side="right")
            motions[t] = float(m.s[0]), float(m.a[0])
        return motions[t]

    def scale(t: float) -> float:
        """The normal gap [mm] per unit of lead e: L·cos α."""
        if t not in scales:
            st = cam.state(np.array([phi + omega * t]), side="right")
            out = math.cos(float(st.pressure_angle[0]))
            if st.lever is not None:
                out *= float(st.lever[0]) * _RAD_PER_DEG
            scales[t] = out
        return scales[t]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        s, a = motion_at(t)
        q = np.array([s + y[0]])
        static = float(load.static_force(_at(q))[0])  # spring and weight where the follower is
        return [y[1], -static / mass - omega**2 * a]

    def other(t: float, y: np.ndarray) -> float:  # reaches the other flank
        return leaving * y[0] * scale(t) - clearance

    def back(t: float, y: np.ndarray) -> float:  # lands again on the flank it left
        return leaving * y[0] * scale(t) + 1e-9 * clearance

    other.terminal = True  # type: ignore[attr-defined]
    back.terminal = True  # type: ignore[attr-defined]
    back.direction = -1.0  # type: ignore[attr-defined]
    turn = TWO_PI / omega
    sol = solve_ivp(
        rhs,
        (0.0, turn),
        [0.0, 0.0],
        method="DOP853",
        rtol=_RTOL,
        atol=1e-14 * max(clearance, 1.0),
        events=(other, back),
        max_step=turn / 360.0,
    )
    for k in (0, 1):
        if sol.t_events[k].size:
            t, rate = float(sol.t_events[k][0]), float(sol.y_events[k][0][1])
            return abs(rate) * scale(t)
    return 0.0  # never meets a flank within a turn: no impact


def _at(s: FloatArray, a: float = 0.0) -> Motion:
    """A one-sample motion at displacement s with s″ = a (what the loads read: ``s`` and ``a``)."""
    zero = np.zeros(1)
    return Motion(phi=zero, s=s, v=zero, a=np.full(1, a), j=zero)


def _generalised_mass(load: FollowerLoad | ArmLoad) -> float:
    """M in M·q̈ [N or N·mm] per unit of q̈ [mm/s² or °/s²]: the inertia coefficient at s″ = 1."""
    return float(load.inertia_coefficient(_at(np.zeros(1), 1.0))[0])
