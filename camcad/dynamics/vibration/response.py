"""The train's periodic response at one speed and over a speed map.

:func:`train_response` gives the dynamic error, contact force, residual
vibration in every dwell and the lift-off of a spring-loaded follower at one
speed; :func:`speed_map` the same figures (without flights) over many speeds,
vectorised. Both rest on the exact discrete-time solution of
:mod:`camcad.dynamics.vibration._exact`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.dynamics.vibration._exact import (
    Grid,
    make_grid,
    periodic_states,
    propagate,
    propagate_each,
    train_system,
)
from camcad.dynamics.vibration.separation import Flight, periodic_with_flight
from camcad.extremes import Extreme, Side, extremes_each, extremes_rows
from camcad.motion.segments import SegmentKind

if TYPE_CHECKING:
    from camcad.dynamics.vibration.polydyne import CompensatedMotion
    from camcad.dynamics.vibration.train import Train
    from camcad.motion.program import MotionProgram

    Lift = MotionProgram | CompensatedMotion

__all__ = ["DEFAULT_STEP", "Dwell", "SpeedMap", "TrainResponse", "dwells", "speed_map", "train_response"]

DEFAULT_STEP = math.radians(0.5)
"""Largest grid step [rad]; finer where the train vibrates faster (16 samples a period)."""
_SAMPLES_PER_PERIOD = 16
_MIN_STEP = math.radians(0.01)
_RPM = 60.0 / TWO_PI


@dataclass(frozen=True, slots=True)
class Dwell:
    """A dwell of the program: start and end angle [rad]."""

    start: float
    end: float


def dwells(program: Lift) -> tuple[Dwell, ...]:
    """Every dwell segment of the program, in order."""
    return tuple(
        Dwell(start=p, end=p + seg.span)
        for p, seg in zip(program.starts, program.segments, strict=True)
        if seg.kind is SegmentKind.DWELL
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class TrainResponse:
    """The periodic response of the train at one speed (lift unit: mm, or degrees of swing on an arm).

    Attributes
    ----------
    speed_rpm
        Cam speed [rpm].
    phi
        (N,) grid angles [rad] over one turn.
    s, x
        (N,) the cam's lift at the contact and the output [lift unit].
    error
        (N,) dynamic error x − y [lift unit], y the target motion (s, or the
        program of a polydyne cam).
    contact_force
        (N,) contact force [N] (a moment [N·mm] on an arm); 0 in flight.
    in_contact
        (N,) False where the follower has left the cam.
    error_max, error_min
        True extremes of x − s over the turn (refined between samples on
        the exact solution, one-sided limits at joints).
    contact_force_min
        True minimum of the contact-held force F (negative: the follower
        would leave a spring-loaded cam there).
    residuals
        Residual vibration amplitude [lift unit] of the output at the start
        of every dwell (:func:`dwells`), the sum of its modal amplitudes
        about the dwell's rest position (that of the lift at the dwell's end:
        the lift of a damped polydyne cam settles within the dwell).
    leaves
        Whether a spring-loaded follower leaves the cam.
    flights
        Lift-off, landing and impact speed of each flight (periodic motion).
    periodic
        False when no periodic state exists (an undamped train exactly on a
        harmonic) or the motion with flights did not settle.
    natural_frequencies
        The train's undamped natural frequencies ω_n [rad/s].
    """

    speed_rpm: float
    phi: FloatArray
    s: FloatArray
    x: FloatArray
    error: FloatArray
    contact_force: FloatArray
    in_contact: np.ndarray
    error_max: Extreme
    error_min: Extreme
    contact_force_min: Extreme
    residuals: tuple[float, ...]
    leaves: bool
    flights: tuple[Flight, ...]
    periodic: bool
    natural_frequencies: FloatArray

    @property
    def error_peak(self) -> Extreme:
        """The larger of |max| and |min| of x − s, with its sign."""
        return self.error_max if abs(self.error_max.value) >= abs(self.error_min.value) else self.error_min


def _step(train: Train, omega_max: float, step: float) -> float:
    top = float(np.max(train.natural_frequencies(), initial=0.0))
    if top <= 0.0:
        return step
    return max(min(step, TWO_PI / _SAMPLES_PER_PERIOD * omega_max / top), _MIN_STEP)


def _modal(train: Train) -> tuple[FloatArray, FloatArray]:
    """Eigenvectors V and V⁻¹ of the state matrix, for the residual envelope."""
    a, _, _, _ = train.state_space()
    _, vec = np.linalg.eig(a)
    return vec, np.linalg.inv(vec)


def _residuals(train: Train, grid: Grid, states: FloatArray, program: Lift) -> FloatArray:
    """(S, D) residual amplitudes [lift unit] at the start of each dwell, for states (S, N + 1, n)."""
    spans = dwells(program)
    out = np.zeros((states.shape[0], len(spans)))
    if not spans:
        return out
    vec, inv = _modal(train)
    dof = train.dof
    for d, dw in enumerate(spans):
        i = int(np.argmin(np.abs(grid.phi - dw.start % TWO_PI)))
        # the rest position at the dwell's end: a damped polydyne lift still settles early in the dwell
        s = float(program.evaluate(np.array([dw.end]), side="left").s[0]) * train.unit
        q_eq = _equilibrium(train, s)
        dz = states[:, i].copy()
        dz[:, :dof] -= q_eq
        coef = dz @ inv.T  # (S, n) modal coordinates
        amp = np.sum(np.abs(coef * vec[dof - 1]), axis=1)  # Σ over modes of |output share|
        out[:, d] = amp / train.unit
    return out


def _equilibrium(train: Train, s: float) -> FloatArray:
    _, _, k = train.matrices()
    load = np.asarray(train.weight, dtype=float).copy()
    load[-1] += train.preload
    rhs = -load
    rhs[0] += train.contact_rate * s
    return np.asarray(np.linalg.solve(k, rhs), dtype=float)


def _force(train: Train, s: FloatArray, v: FloatArray, omega: float, z: FloatArray) -> FloatArray:
    """Contact force k_f (s − q₀) + c_f (ṡ − q̇₀) for lift s, v [lift unit, per rad] and states z (m, n)."""
    u = train.unit
    return train.contact_rate * (s * u - z[:, 0]) + train.contact_damping * (v * omega * u - z[:, train.dof])


def _refined(
    program: Lift,
    aim: Lift,
    train: Train,
    grid: Grid,
    system: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    omega: FloatArray,
    states: FloatArray,
    joints: list[float],
    error: FloatArray,
    force: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """True max |x − y| and min contact force (S,) of speeds ``omega`` (S,) from their grid values (S, N).

    Rows 2k and 2k + 1 of :func:`extremes_each` are speed k's |x − y| and
    force; a speed without a periodic state (NaN) gives NaN.
    """
    count = omega.size
    u = train.unit

    def pick(p: FloatArray, rows: np.ndarray, side: Side) -> FloatArray:
        k = rows // 2
        m = program.evaluate(p, side=side)
        ys = np.asarray(aim.evaluate(p, side=side).s)
        z = propagate_each(grid, system, omega, states, k, np.mod(p, TWO_PI) if side == "right" else p)
        err = np.abs(z[:, train.dof - 1] / u - ys)
        f = train.contact_rate * (np.asarray(m.s) * u - z[:, 0]) + train.contact_damping * (
            np.asarray(m.v) * omega[k] * u - z[:, train.dof]
        )
        return np.where(rows % 2 == 0, err, f)

    values = np.empty((2 * count, error.shape[1]))
    values[0::2] = np.abs(error)
    values[1::2] = force
    found = extremes_each(pick, 2 * count, grid.phi[:-1], joints, ("max", "min") * count, values=values)
    ok = np.all(np.isfinite(states), axis=(1, 2))
    peak = np.array([found[2 * k].value for k in range(count)])
    low = np.array([found[2 * k + 1].value for k in range(count)])
    return np.where(ok, peak, np.nan), np.where(ok, low, np.nan)


def train_response(
    program: Lift,
    train: Train,
    *,
    speed_rpm: float,
    spring_loaded: bool = True,
    step: float = DEFAULT_STEP,
    target: MotionProgram | None = None,
) -> TrainResponse:
    """The periodic response of the train to the program at one cam speed.

    Parameters
    ----------
    program
        The motion program: the cam's lift at the contact.
    train
        The linear follower train.
    speed_rpm
        Cam speed [rpm], > 0.
    spring_loaded
        True for a cam that can only push (a plate cam with a return spring):
        where the contact force would turn negative the follower flies free
        (:mod:`camcad.dynamics.vibration.separation`). False for a groove or
        conjugate cam: the force changes sign, the follower stays.
    step
        Largest grid step [rad] (finer when the train is fast).
    target
        The motion the output should follow (the program of a polydyne
        cam); ``None``: ``program`` itself. The dynamic error is x − target.

    Returns
    -------
    TrainResponse
        Arrays on the grid and the true extremes.
    """
    omega = speed_rpm / _RPM
    grid = make_grid(program, _step(train, omega, step))
    aim = program if target is None else target
    y = np.asarray(aim.evaluate(grid.phi[:-1]).s)
    states = periodic_states(grid, train_system(train), np.array([omega]))[0]
    phi = grid.phi[:-1]
    periodic = bool(np.all(np.isfinite(states)))
    u = train.unit
    residuals = tuple(float(r) for r in _residuals(train, grid, states[None], program)[0])
    z = states[:-1]
    force = _force(train, grid.s, grid.v, omega, z) if periodic else np.full(phi.size, np.nan)
    contact = np.ones(phi.size, dtype=bool)
    flights: tuple[Flight, ...] = ()
    leaves = periodic and spring_loaded and bool(np.min(force) < 0.0)

    def exact(p: FloatArray, side: Side) -> tuple[FloatArray, FloatArray]:
        m = program.evaluate(p, side=side)
        ys = aim.evaluate(p, side=side).s
        zz = propagate(grid, train_system(train), omega, states, np.mod(p, TWO_PI))
        return np.asarray(m.s), np.vstack(
            ((zz[:, train.dof - 1] / u - ys), _force(train, m.s, m.v, omega, zz))
        )

    def rows(p: FloatArray, side: Side) -> FloatArray:
        _, r = exact(p, side)
        return np.vstack((r[0], r[0], r[1]))

    joints = [bp.phi for bp in program.breakpoints]
    if periodic:
        values = np.vstack((z[:, train.dof - 1] / u - y, z[:, train.dof - 1] / u - y, force))
        emax, emin, fmin = extremes_rows(rows, phi, joints, ("max", "min", "min"), values=values)
        leaves = spring_loaded and fmin.value < 0.0
    else:
        emax = emin = fmin = Extreme(value=math.nan, phi=0.0)
    x = z[:, train.dof - 1] / u
    if leaves:
        start = float(phi[int(np.argmax(force))])
        i0 = int(np.argmax(force))
        hybrid = periodic_with_flight(program, train, omega=omega, start=start, state=z[i0], grid=grid)
        zh, contact = hybrid.state(phi)
        x = zh[:, train.dof - 1] / u
        force = np.where(contact, _force(train, grid.s, grid.v, omega, zh), 0.0)
        flights = hybrid.flights
        periodic = hybrid.periodic
        err = x - y
        emax = Extreme(value=float(np.max(err)), phi=float(phi[int(np.argmax(err))]))
        emin = Extreme(value=float(np.min(err)), phi=float(phi[int(np.argmin(err))]))
    error = x - y
    s = np.array(grid.s)
    readonly(phi, s, x, error, force, contact)
    nat = train.natural_frequencies()
    return TrainResponse(
        speed_rpm=speed_rpm,
        phi=phi,
        s=s,
        x=x,
        error=error,
        contact_force=force,
        in_contact=contact,
        error_max=emax,
        error_min=emin,
        contact_force_min=fmin,
        residuals=residuals,
        leaves=leaves,
        flights=flights,
        periodic=periodic,
        natural_frequencies=nat,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class SpeedMap:
    """Figures of the contact-held periodic response over many speeds.

    Attributes
    ----------
    speeds_rpm
        (S,) cam speeds [rpm].
    residuals
        (S, D) residual vibration amplitude at the start of each dwell [lift unit].
    error_peak
        (S,) true largest |x − y| over the turn [lift unit] (refined between
        grid angles on the exact solution, one-sided limits at joints).
    contact_force_min
        (S,) true smallest contact-held force over the turn [N or N·mm],
        one-sided limits at joints included.
    leaves
        (S,) whether a spring-loaded follower would leave the cam there.
    dwells
        The dwells the residual columns belong to.
    """

    speeds_rpm: FloatArray
    residuals: FloatArray
    error_peak: FloatArray
    contact_force_min: FloatArray
    leaves: np.ndarray
    dwells: tuple[Dwell, ...]


def speed_map(
    program: Lift,
    train: Train,
    *,
    speeds_rpm: ArrayLike,
    spring_loaded: bool = True,
    step: float = DEFAULT_STEP,
    target: MotionProgram | None = None,
) -> SpeedMap:
    """The contact-held periodic response at many speeds, vectorised over the speeds.

    Parameters
    ----------
    program, train, spring_loaded, step, target
        As for :func:`train_response`.
    speeds_rpm
        (S,) cam speeds [rpm], each > 0.

    Returns
    -------
    SpeedMap
        Residuals are exact (from the state at each dwell's start); the peak
        error and minimum force are true extremes, as in
        :func:`train_response`: every speed's samples and both sides of every
        joint, then each promising sampled peak refined on the exact solution
        between grid angles (:func:`camcad.extremes.extremes_each`, all speeds
        of a chunk in one batch of partial-step propagations). At speeds
        where the follower leaves the cam the figures are the contact-held
        ones, flagged by ``leaves``.
    """
    speeds = np.asarray(speeds_rpm, dtype=float).ravel()
    omega = speeds / _RPM
    grid = make_grid(program, step)
    aim = program if target is None else target
    y = np.asarray(aim.evaluate(grid.phi[:-1]).s)
    u = train.unit
    system = train_system(train)
    joints = [bp.phi for bp in program.breakpoints]
    res = np.zeros((speeds.size, len(dwells(program))))
    peak = np.zeros(speeds.size)
    fmin = np.zeros(speeds.size)
    chunk = 50  # bounds the memory of the state history
    for lo in range(0, speeds.size, chunk):
        sl = slice(lo, lo + chunk)
        states = periodic_states(grid, system, omega[sl])
        res[sl] = _residuals(train, grid, states, program)
        x = states[:, :-1, train.dof - 1] / u
        force = train.contact_rate * (grid.s * u - states[:, :-1, 0]) + train.contact_damping * (
            grid.v[None, :] * omega[sl, None] * u - states[:, :-1, train.dof]
        )
        peak[sl], fmin[sl] = _refined(
            program, aim, train, grid, system, omega[sl], states, joints, x - y, force
        )
    leaves = (fmin < 0.0) & spring_loaded
    leaves = (fmin < 0.0) & spring_loaded
    readonly(speeds, res, peak, fmin)
    leaves.flags.writeable = False
    return SpeedMap(
        speeds_rpm=speeds,
        residuals=res,
        error_peak=peak,
        contact_force_min=fmin,
        leaves=leaves,
        dwells=dwells(program),
    )
