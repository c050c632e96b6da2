"""Dynamically compensated (polydyne) cams: the contact lift whose output follows the program at one speed.

Given the motion program y(φ) as the **output** and a speed N, the contact
lift c(φ) of the cam solves the train's equations backwards (Rothbart 2004,
ch. 13 "polydyne cams"; Norton 2009, §15.5; Stoddart 1953). Single mass::

    k_f (c − y) + c_f (ċ − ẏ) = m ÿ + k_s y + F₀ (+ m g)   =: P₁

a linear first-order equation in e = c − y: its periodic solution (undamped,
e = P₁/k_f). Two masses: first the contact mass, x₁ − y = e₁ from
k₂ e₁ + c₂ ė₁ = m₂ ÿ + k_s y + F₀ + m₂ g =: P₁, then c − x₁ = e₂ from
k_f e₂ + c_f ė₂ = m₁ ẍ₁ + P₁ + m₁ g. The time derivatives are taken at N
(d/dt = ω·d/dφ). c is C² (no acceleration jumps) when y is C⁴ at every joint;
a law that is not is refused, naming ``motion[i].law``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.dynamics.vibration._exact import Grid, grid_nodes, hermite, periodic_states, propagate
from camcad.dynamics.vibration._higher import check_supported, program_derivatives
from camcad.errors import DesignError
from camcad.knobs import Knob
from camcad.motion.program import Breakpoint, Motion, MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec

if TYPE_CHECKING:
    from camcad.dynamics.vibration.train import Train
    from camcad.extremes import Side

__all__ = ["CompensatedMotion", "check_compensable", "compensate", "compensated_program"]

_RPM = 60.0 / TWO_PI
_JUMP_RTOL = 1e-9
_ORDINAL = ("lift", "1st derivative", "2nd derivative", "3rd derivative", "4th derivative")


@dataclass(frozen=True, slots=True)
class _Stage:
    """One first-order solve k·e + c·ė = P, P = mass·(x_prev)″ + P_prev + weight."""

    rate: float
    damping: float
    mass: float
    weight: float
    grid: Grid | None = None
    states: FloatArray | None = None  # (N + 1,) periodic e at the grid angles


@dataclass(frozen=True, slots=True)
class CompensatedMotion:
    """The contact lift c(φ) of a polydyne cam, motion-like: :meth:`evaluate` gives s, v, a, j of c.

    Attributes
    ----------
    program
        The motion program the output follows (y).
    train
        The follower train it is tuned for.
    speed_rpm
        The design speed N [rpm].
    """

    program: MotionProgram
    train: Train
    speed_rpm: float
    _stages: tuple[_Stage, ...]
    _orders: int

    @property
    def omega(self) -> float:
        """ω [rad/s] at the design speed."""
        return self.speed_rpm / _RPM

    def _chain(self, phi: FloatArray, side: Side, values: list[FloatArray | None] | None) -> FloatArray:
        """Derivatives in time (generalised units) of the contact lift: (orders − 2·stages + 1, m)."""
        w, u = self.omega, self.train.unit
        y = program_derivatives(self.program, phi, self._orders, side=side)
        y = y * u * w ** np.arange(self._orders + 1)[:, None]
        spring, preload = self.train.spring_rate, self.train.preload
        p = np.zeros((self._orders - 1, y.shape[1]))
        p[:] = spring * y[: self._orders - 1]
        p[0] += preload
        x = y
        for i, st in enumerate(self._stages):
            p = st.mass * x[2 : 2 + p.shape[0]] + p
            p[0] += st.weight
            if st.damping == 0.0:
                e = p / st.rate
            else:
                e = np.zeros_like(p)
                if values is not None and values[i] is not None:
                    e[0] = values[i]
                else:
                    assert st.grid is not None and st.states is not None
                    system = _first_order(st.rate, st.damping)
                    e[0] = propagate(st.grid, system, w, st.states[:, None], np.mod(phi, TWO_PI))[:, 0]
                for k in range(p.shape[0] - 1):
                    e[k + 1] = (p[k] - st.rate * e[k]) / st.damping
            x = x[: e.shape[0]] + e
            p = p[: x.shape[0] - 2]
        return x

    def evaluate(self, phi: ArrayLike, *, side: Side = "right") -> Motion:
        """s, v, a, j of the contact lift c [lift unit, per rad^k] at cam angles ``phi`` [rad].

        Parameters
        ----------
        phi
            Cam angles [rad], any shape.
        side
            One-sided limit at joints, as :meth:`MotionProgram.evaluate`.
        """
        phi_in = np.asarray(phi, dtype=float).ravel()
        c = self._chain(phi_in, side, None)[:4]
        c = c / self.train.unit / self.omega ** np.arange(4)[:, None]
        out = Motion(phi=phi_in.copy(), s=c[0], v=c[1], a=c[2], j=c[3])
        readonly(out.phi, out.s, out.v, out.a, out.j)
        return out

    def correction(self, phi: ArrayLike) -> FloatArray:
        """The lift correction c − y [lift unit] at angles ``phi`` [rad]: the lift added to the program."""
        phi_in = np.asarray(phi, dtype=float).ravel()
        out = np.asarray(self.evaluate(phi_in).s - self.program.evaluate(phi_in).s, dtype=float)
        readonly(out)
        return out

    @property
    def breakpoints(self) -> tuple[Breakpoint, ...]:
        """The program's joints, with the continuity of c there (2 when only c‴ may jump, 3 when smooth)."""
        out = []
        for bp in self.program.breakpoints:
            left = self.evaluate(np.array([bp.phi]), side="left")
            right = self.evaluate(np.array([bp.phi]), side="right")
            scale = max(self.lift, 1.0)
            cont = 3
            for order, (lv, rv) in enumerate(
                ((left.v, right.v), (left.a, right.a), (left.j, right.j)), start=1
            ):
                if abs(float(rv[0] - lv[0])) > 1e-7 * scale * max(1.0, abs(float(lv[0]))):
                    cont = order - 1
                    break
            out.append(Breakpoint(phi=bp.phi, continuity=cont))
        return tuple(out)

    @property
    def starts(self) -> tuple[float, ...]:
        """The program's segment starts [rad] (a dwell of y is a dwell of c)."""
        return self.program.starts

    @property
    def segments(self) -> tuple[SegmentSpec, ...]:
        """The program's segments (their kinds: a dwell of y is a dwell of c)."""
        return self.program.segments

    @property
    def pieces(self) -> tuple[float, ...]:
        """Where the formula of c changes: the program's pieces [rad]."""
        return self.program.pieces

    @property
    def lift(self) -> float:
        """Largest contact lift [lift unit] on a 0.1° grid and at the joints."""
        phi = np.union1d(np.linspace(0.0, TWO_PI, 3600, endpoint=False), np.mod(self.program.pieces, TWO_PI))
        return float(np.max(self.evaluate(phi).s))

    def sample_phi(self, step: float) -> FloatArray:
        """The program's sample angles [rad] (its joints are c's)."""
        return self.program.sample_phi(step)


def _first_order(rate: float, damping: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """ė = −(k/c)·e + P/c as a one-state system driven by P through the grid's polynomial."""
    return (
        np.array([[-rate / damping]]),
        np.array([1.0 / damping]),
        np.zeros(1),
        np.zeros(1),
    )


def _check_smooth(program: MotionProgram) -> None:
    """Refuse a program whose lift is not C⁴ at some joint (a polydyne cam's acceleration would jump)."""
    segs = program.segments
    n = len(segs)
    for k, start in enumerate(program.starts):
        phi = np.array([start])
        left = program_derivatives(program, phi, 4, side="left")[:, 0]
        right = program_derivatives(program, phi, 4, side="right")[:, 0]
        spans = min(segs[k].span, segs[(k - 1) % n].span)
        for order in range(5):
            ref = max(program.lift, 1.0) / spans**order
            jump = float(right[order] - left[order])
            if abs(jump) > _JUMP_RTOL * ref:
                i = k if segs[k].kind is not SegmentKind.DWELL else (k - 1) % n
                law = segs[i].law
                name = law.describe() if law is not None else "dwell"
                raise DesignError(
                    f"motion[{i}].law",
                    f"{name} is not smooth enough for a compensated (polydyne) cam: its {_ORDINAL[order]} "
                    f"jumps by {jump:.4g} at {math.degrees(start):g}°; the output needs s "
                    "continuous to the 4th derivative (e.g. law = 'dudley' with degree ≥ 9 between dwells)",
                )


def check_compensable(program: MotionProgram) -> None:
    """Refuse a program a polydyne cam cannot be made from (the checks :func:`compensate` runs first).

    Raises
    ------
    DesignError
        ``motion[i].law``: a law without closed-form higher derivatives, or a
        lift not continuous to its 4th derivative at some joint (exit 2).
    """
    check_supported(program)
    _check_smooth(program)


def compensate(
    program: MotionProgram, train: Train, *, speed_rpm: float, step: float = math.radians(0.5)
) -> CompensatedMotion:
    """Make the polydyne cam for ``speed_rpm``: the contact lift whose output follows ``program``.

    Parameters
    ----------
    program
        The motion the output must follow, y(φ). Every law must have closed-form
        higher derivatives (``_higher.SUPPORTED_LAWS``) and y must be C⁴ at
        every joint.
    train
        The follower train (single or two masses).
    speed_rpm
        Design speed N [rpm], > 0.
    step
        Grid step [rad] of the damped periodic solution (degree-7 Hermite
        input per step, exact response).

    Returns
    -------
    CompensatedMotion
        c(φ) with its exact φ-derivatives to the 3rd.

    Raises
    ------
    DesignError
        ``motion[i].law`` for a law without higher derivatives or not smooth
        enough; ``vibration.compensate_rpm`` for a speed ≤ 0.
    """
    if not (math.isfinite(speed_rpm) and speed_rpm > 0.0):
        raise DesignError(Knob.COMPENSATE_RPM, f"{speed_rpm!r} must be a finite speed > 0 rpm")
    check_compensable(program)
    t = train
    if t.dof == 1:
        specs = [(t.contact_rate, t.contact_damping, t.mass[0], t.weight[0])]
    else:
        specs = [
            (t.coupling_rate, t.coupling_damping, t.mass[1], t.weight[1]),
            (t.contact_rate, t.contact_damping, t.mass[0], t.weight[0]),
        ]
    orders = 3 + 2 * len(specs)
    stages: list[_Stage] = [_Stage(rate=r, damping=c, mass=m, weight=w) for r, c, m, w in specs]
    phi, piece, steps = grid_nodes(program, step)
    omega = speed_rpm / _RPM
    node_values: list[FloatArray | None] = [None] * len(stages)
    for i in range(len(stages)):
        st = stages[i]
        if st.damping == 0.0:
            continue
        partial = CompensatedMotion(program, train, speed_rpm, tuple(stages[: i + 1]), orders)
        data = []
        sides: tuple[tuple[Side, FloatArray], ...] = (("right", phi[:-1]), ("left", phi[1:]))
        for side, at in sides:
            vals: list[FloatArray | None] = [
                None if v is None else (v[:-1] if side == "right" else v[1:]) for v in node_values[: i + 1]
            ]
            data.append(_stage_input(partial, at, side, vals, i, omega))
        grid = Grid(
            phi=phi,
            piece=piece,
            step=steps,
            coeff=hermite(data[0], data[1], steps[piece]),
            s=data[0][0],
            v=data[0][1],
            a=data[0][2],
            j=data[0][3],
        )
        states = periodic_states(grid, _first_order(st.rate, st.damping), np.array([omega]))[0, :, 0]
        stages[i] = _Stage(
            rate=st.rate, damping=st.damping, mass=st.mass, weight=st.weight, grid=grid, states=states
        )
        node_values[i] = states
    return CompensatedMotion(program, train, speed_rpm, tuple(stages), orders)


def _stage_input(
    partial: CompensatedMotion,
    phi: FloatArray,
    side: Side,
    values: list[FloatArray | None],
    index: int,
    omega: float,
) -> FloatArray:
    """(4, m) P of stage ``index`` and its first three φ-derivatives at ``phi`` (earlier ones: ``values``)."""
    w, u = omega, partial.train.unit
    y = program_derivatives(partial.program, phi, partial._orders, side=side)
    y = y * u * w ** np.arange(partial._orders + 1)[:, None]
    p = partial.train.spring_rate * y[: partial._orders - 1]
    p[0] += partial.train.preload
    x = y
    for i, st in enumerate(partial._stages):
        p = st.mass * x[2 : 2 + p.shape[0]] + p
        p[0] += st.weight
        if i == index:
            return p[:4] / w ** np.arange(4)[:, None]
        if st.damping == 0.0:
            e = p / st.rate
        else:
            e = np.zeros_like(p)
            v = values[i]
            assert v is not None
            e[0] = v
            for k in range(p.shape[0] - 1):
                e[k + 1] = (p[k] - st.rate * e[k]) / st.damping
        x = x[: e.shape[0]] + e
        p = p[: x.shape[0] - 2]
    raise AssertionError("stage index out of range")


@dataclass(frozen=True, slots=True)
class CompensatedProgram(MotionProgram):
    """A polydyne cam's contact lift c(φ) as a :class:`MotionProgram`: what the geometry stage cuts.

    The segments, starts and joints are the motion program's (its kinds, laws
    and lifts name what the *output* does), but every evaluation gives c and
    its exact φ-derivatives from :class:`CompensatedMotion`; :attr:`lift` is
    c's true largest value. Everything built on ``Cam.program`` (profile,
    fit, toolpath, every export) is then made from c, not from the program.
    """

    # equality and hash by what decides c (program, train, speed), not by the solver's arrays
    compensated: CompensatedMotion | None = field(default=None, compare=False, hash=False)
    train: Train | None = None
    speed_rpm: float = 0.0
    _peak: dict[str, float] = field(default_factory=dict, init=False, compare=False, hash=False, repr=False)

    def _evaluate_segment(
        self, index: int, x: FloatArray, side: Side = "right"
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """c, c′, c″, c‴ on segment ``index`` at normalised x ∈ [0, 1] (one-sided: ``side``)."""
        assert self.compensated is not None
        span = self.segments[index].span
        phi = self.starts[index] + np.asarray(x, dtype=float) * span
        # a segment's end is the left limit at the next start, its start the right limit
        at_end = np.asarray(x, dtype=float) >= 1.0
        out = [np.zeros_like(phi) for _ in range(4)]
        for mask, where in ((~at_end, side if side == "left" else "right"), (at_end, "left")):
            if mask.any():
                m = self.compensated.evaluate(phi[mask], side=where)  # type: ignore[arg-type]
                for k, values in enumerate((m.s, m.v, m.a, m.j)):
                    out[k][mask] = values
        return out[0], out[1], out[2], out[3]

    @property
    def lift(self) -> float:
        """Largest contact lift c [lift unit]: a 0.05° grid and the joints, polished by Newton on c′ = 0."""
        assert self.compensated is not None
        if "lift" not in self._peak:  # asked for at every joint's derivative scale: found once
            self._peak["lift"] = _largest(self.compensated)
        return self._peak["lift"]


def _largest(cam: CompensatedMotion) -> float:
    """The true maximum of c: the densest sample, then Newton steps on c′ = 0 with c″ (exact derivatives)."""
    pieces = np.mod(np.asarray(cam.program.pieces, dtype=float), TWO_PI)
    grid = np.union1d(np.linspace(0.0, TWO_PI, 7200, endpoint=False), pieces)
    m = cam.evaluate(grid)
    best = float(np.max(m.s))
    k = int(np.argmax(m.s))
    x = float(grid[k])
    lo, hi = x - TWO_PI / 7200, x + TWO_PI / 7200
    for _ in range(8):
        here = cam.evaluate(np.array([x]))
        a = float(here.a[0])
        if a >= 0.0:  # not a smooth interior maximum (a joint or a flat rest): the sample stands
            break
        x = min(max(x - float(here.v[0]) / a, lo), hi)
        best = max(best, float(cam.evaluate(np.array([x])).s[0]))
    for joint in pieces:  # one-sided values at the joints
        for side in ("left", "right"):
            best = max(best, float(cam.evaluate(np.array([joint]), side=side).s[0]))  # type: ignore[arg-type]
    return best


def compensated_program(cam: CompensatedMotion) -> CompensatedProgram:
    """The polydyne cam's contact lift as a motion program (see :class:`CompensatedProgram`)."""
    p = cam.program
    return CompensatedProgram(
        p.segments, p.starts, p.base_s, compensated=cam, train=cam.train, speed_rpm=cam.speed_rpm
    )
