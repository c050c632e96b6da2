"""A spring-loaded follower that leaves the cam: free flight, landing, and the periodic motion.

Where the contact force F = k_f (s − q₀) + c_f (ṡ − q̇₀) of the contact-held
train would turn negative, the cam can only push: the contact spring's free
end then relaxes by k_f δ + c_f δ̇ = 0 (δ its extension, δ = s − q₀ at
lift-off) while the masses fly on under the return spring, until the end
p = q₀ + δ meets the cam again (s = p, rising through zero), with impact speed
ṡ − ṗ. Free flight and contact are integrated with event detection
(``solve_ivp``, DOP853) and the turn map is iterated to its fixed point, the
periodic motion (DYNACAM's follower-jump simulation, Norton 2009, §15.4;
Rothbart 2004, ch. 13).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.integrate import solve_ivp

from camcad._typing import FloatArray
from camcad.angles import TWO_PI

if TYPE_CHECKING:
    from camcad.dynamics.vibration._exact import Grid
    from camcad.dynamics.vibration.polydyne import CompensatedMotion
    from camcad.dynamics.vibration.train import Train
    from camcad.motion.program import MotionProgram

__all__ = ["Flight", "HybridMotion", "periodic_with_flight"]

_MAX_SWITCHES = 64  # contact changes per turn before the motion counts as chattering
_MAX_TURNS = 80


@dataclass(frozen=True, slots=True)
class Flight:
    """One loss of contact: lift-off and landing angles [rad] and the impact speed [lift unit/s]."""

    leave: float
    land: float
    impact_speed: float


@dataclass(frozen=True, slots=True)
class HybridMotion:
    """The periodic motion with free flights over one turn from ``start`` [rad].

    ``phases`` hold (φ₀, φ₁, in contact, dense solution in t from φ₀/ω);
    ``periodic`` is False when the turn map did not settle (chatter, chaos).
    """

    omega: float
    start: float
    phases: tuple[tuple[float, float, bool, Any], ...]
    flights: tuple[Flight, ...]
    periodic: bool
    dof: int

    def state(self, phi: FloatArray) -> tuple[FloatArray, np.ndarray]:
        """State z (m, 2·dof) and the contact flag (m,) at angles ``phi`` [rad]."""
        phi = np.asarray(phi, dtype=float)
        rel = np.mod(phi - self.start, TWO_PI)
        out = np.zeros((phi.size, 2 * self.dof))
        contact = np.ones(phi.size, dtype=bool)
        for lo, hi, touching, sol in self.phases:
            mask = (rel >= lo - self.start) & (rel <= hi - self.start)
            if mask.any():
                out[mask] = sol((self.start + rel[mask]) / self.omega).T[:, : 2 * self.dof]
                contact[mask] = touching
        return out, contact


def _hermite_lift(grid: Grid, phi: float, omega: float, unit: float) -> tuple[float, float]:
    """Lift s and ṡ [generalised units, per s] at ``phi`` [rad] from the grid's Hermite polynomials."""
    p = phi % TWO_PI
    i = min(max(int(np.searchsorted(grid.phi, p, side="right")) - 1, 0), grid.piece.size - 1)
    h = float(grid.step[grid.piece[i]])
    u = (p - float(grid.phi[i])) / h
    e = grid.coeff[i]
    s = ds = 0.0
    for k in range(e.size - 1, 0, -1):  # Horner for s and s′ together
        ds = ds * u + k * e[k]
        s = s * u + e[k]
    s = s * u + e[0]
    return s * unit, ds / h * omega * unit


def periodic_with_flight(
    program: MotionProgram | CompensatedMotion,
    train: Train,
    *,
    omega: float,
    start: float,
    state: FloatArray,
    grid: Grid | None = None,
) -> HybridMotion:
    """Iterate the turn map with free flights to the periodic motion.

    Parameters
    ----------
    program
        The motion program (lift s(φ)).
    train
        The linear train (its contact can only push).
    omega
        Cam speed [rad/s].
    start
        Cam angle [rad] the turn map starts at: one where the contact-held
        solution presses hardest.
    state
        The contact-held periodic state there (the first guess).
    grid
        The response's grid (:func:`~camcad.dynamics.vibration._exact.make_grid`):
        the integrator then reads the lift from its degree-7 Hermite pieces,
        the same lift the contact-held solution is exact for, at a few µs a
        call instead of a program evaluation's 0.5 ms.
    """
    n = 2 * train.dof
    a, bs, bv, f = train.state_space()
    free = dataclasses.replace(train, contact_rate=0.0, contact_damping=0.0)
    a_free, _, _, f_free = free.state_space()
    unit, kf, cf = train.unit, train.contact_rate, train.contact_damping
    relax = kf / cf if cf > 0.0 else math.inf

    def lift(t: float) -> tuple[float, float]:
        if grid is not None:
            return _hermite_lift(grid, omega * t, omega, unit)
        m = program.evaluate(np.array([omega * t]))
        return float(m.s[0]) * unit, float(m.v[0]) * omega * unit

    def contact_rhs(t: float, y: FloatArray) -> FloatArray:
        s, sd = lift(t)
        return np.asarray(a @ y + bs * s + bv * sd + f)

    def flight_rhs(t: float, y: FloatArray) -> FloatArray:
        out = np.zeros(n + 1)
        out[:n] = a_free @ y[:n] + f_free
        out[n] = -relax * y[n] if math.isfinite(relax) else 0.0
        return out

    def force(t: float, y: FloatArray) -> float:
        s, sd = lift(t)
        return float(kf * (s - y[0]) + cf * (sd - y[train.dof]))

    def gap(t: float, y: FloatArray) -> float:
        return float(lift(t)[0] - y[0] - y[n])

    force.terminal = True  # type: ignore[attr-defined]
    force.direction = -1.0  # type: ignore[attr-defined]
    gap.terminal = True  # type: ignore[attr-defined]
    gap.direction = 1.0  # type: ignore[attr-defined]
    scale = max(program.lift * unit, 1e-9)
    atol = 1e-12 * scale

    def turn(
        z: FloatArray, delta: float, touching: bool, record: bool
    ) -> tuple[FloatArray, float, bool, list[Any], bool]:
        t0 = start / omega
        t_end = (start + TWO_PI) / omega
        phases: list[Any] = []
        switches = 0
        y = np.concatenate((z, [delta]))
        while t0 < t_end and switches <= _MAX_SWITCHES:
            if touching:
                sol = solve_ivp(
                    contact_rhs,
                    (t0, t_end),
                    y[:n],
                    method="DOP853",
                    rtol=1e-11,
                    atol=atol,
                    events=force,
                    dense_output=record,
                )
            else:
                sol = solve_ivp(
                    flight_rhs,
                    (t0, t_end),
                    y,
                    method="DOP853",
                    rtol=1e-11,
                    atol=atol,
                    events=gap,
                    dense_output=record,
                )
            t1 = float(sol.t[-1])
            y_end = sol.y[:, -1]
            if touching:
                s_now, _ = lift(t1)
                y = np.concatenate((y_end, [s_now - y_end[0]]))
            else:
                y = y_end
            if record:
                phases.append((t0 * omega, t1 * omega, touching, sol.sol))
            if sol.status == 1:  # an event: switch
                touching = not touching
                switches += 1
            t0 = t1
        return y[:n], float(y[n]), touching, phases, switches <= _MAX_SWITCHES

    z = np.asarray(state, dtype=float)
    delta, touching = 0.0, True
    periodic = False
    for _ in range(_MAX_TURNS):
        z_new, delta_new, touching_new, _, ok = turn(z, delta, touching, False)
        if not ok:
            break
        step = np.max(np.abs(z_new[: train.dof] - z[: train.dof]))
        z, delta, same = z_new, delta_new, touching_new == touching
        touching = touching_new
        if same and step <= 1e-10 * scale:
            periodic = True
            break
    _, _, _, phases, _ = turn(z, delta, touching, True)
    flights = []
    for k, (lo, hi, touching_k, sol) in enumerate(phases):
        if touching_k:
            continue
        t_land = hi / omega
        y = sol(t_land)
        m = program.evaluate(np.array([hi]))
        p_dot = y[train.dof] + (-relax * y[n] if math.isfinite(relax) else 0.0)
        impact = float(m.v[0]) * omega * unit - p_dot
        landed = k + 1 < len(phases)
        flights.append(
            Flight(leave=lo % TWO_PI, land=hi % TWO_PI if landed else math.nan, impact_speed=impact / unit)
        )
    return HybridMotion(
        omega=omega,
        start=start,
        phases=tuple(phases),
        flights=tuple(flights),
        periodic=periodic,
        dof=train.dof,
    )
