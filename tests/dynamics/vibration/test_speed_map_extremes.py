"""The speed map's per-speed figures are true extremes, against a brute force through the exact propagator.

The truth: the periodic state on a different grid (0.2°), carried by the
exact partial-step propagator to 2·10⁴ + 1 angles over the turn plus both sides
of every joint, then 1001 angles across the two dense steps around each of
the six best dense peaks: no bracket, no Brent step, no sampled seed of the map.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.dynamics.vibration import Train, speed_map
from camcad.dynamics.vibration._exact import make_grid, periodic_states, propagate, train_system
from camcad.dynamics.vibration.response import DEFAULT_STEP
from camcad.motion.laws import ConstantVelocity, Cycloidal, Harmonic, Law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec

DEG = math.pi / 180.0
RPM = 60.0 / (2.0 * math.pi)
G = 9.80665


def rdrd(rise: Law, ret: Law, span: float, lift: float = 10.0) -> MotionProgram:
    dwell = math.pi - span
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=span, lift=lift, law=rise),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
            SegmentSpec(kind=SegmentKind.RETURN, span=span, lift=lift, law=ret),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
        ]
    )


def single(m_kg: float, kf: float, zeta: float) -> Train:
    m = m_kg / 1000.0
    return Train(
        mass=(m,),
        contact_rate=kf,
        contact_damping=2.0 * zeta * math.sqrt(kf * m),
        spring_rate=10.0,
        preload=40.0,
        weight=(m_kg * G,),
    )


def brute(program: MotionProgram, train: Train, rpm: float) -> tuple[float, float]:
    """max |x − s| and min contact force over the turn by dense evaluation (see the module docstring)."""
    omega = rpm / RPM
    grid = make_grid(program, 0.2 * DEG)
    system = train_system(train)
    states = periodic_states(grid, system, np.array([omega]))[0]
    u = train.unit

    def both(phi: np.ndarray, side: str = "right") -> tuple[np.ndarray, np.ndarray]:
        mo = program.evaluate(phi, side=side)  # type: ignore[arg-type]
        z = propagate(grid, system, omega, states, phi)
        err = np.abs(z[:, 0] / u - mo.s)
        force = train.contact_rate * (mo.s * u - z[:, 0]) + train.contact_damping * (
            mo.v * omega * u - z[:, 1]
        )
        return err, force

    dense = np.linspace(0.0, 2.0 * math.pi, 20_001)
    h = dense[1] - dense[0]
    err, force = both(dense)
    joints = np.array([bp.phi for bp in program.breakpoints] + [2.0 * math.pi])
    out = []
    for values, sign in ((err, 1.0), (force, -1.0)):
        signed = sign * values
        best = [float(np.max(signed))]
        peaks = np.flatnonzero((signed >= np.roll(signed, 1)) & (signed >= np.roll(signed, -1)))
        for i in peaks[np.argsort(signed[peaks])[-6:]]:
            zoom = np.clip(np.linspace(dense[i] - h, dense[i] + h, 1001), 0.0, 2.0 * math.pi)
            e, f = both(zoom)
            best.append(float(np.max(sign * (e if sign > 0 else f))))
        for side in ("left", "right"):
            e, f = both(joints, side)
            best.append(float(np.max(sign * (e if sign > 0 else f))))
        out.append(sign * max(best))
    return out[0], out[1]


CASES = [
    pytest.param(rdrd(Cycloidal(), Cycloidal(), 80 * DEG), single(0.5, 200.0, 0.05), id="cycloidal"),
    # constant velocity: the lift's velocity jumps at the joints, so the damped force jumps there too
    pytest.param(
        rdrd(ConstantVelocity(), Harmonic(), 100 * DEG), single(0.8, 150.0, 0.2), id="constant-velocity"
    ),
]


@pytest.mark.parametrize(("program", "train"), CASES)
def test_speed_map_extremes_are_true_extremes(program: MotionProgram, train: Train) -> None:
    speeds = np.array([150.0, 733.0, 2400.0])
    sm = speed_map(program, train, speeds_rpm=speeds, spring_loaded=False)
    # the map's own grid samples: the refined figure is never below (above, for the minimum) them
    grid = make_grid(program, DEFAULT_STEP)
    states = periodic_states(grid, train_system(train), speeds / RPM)
    x = states[:, :-1, 0] / train.unit
    sample_peak = np.max(np.abs(x - grid.s), axis=1)
    sample_force = np.min(
        train.contact_rate * (grid.s * train.unit - states[:, :-1, 0])
        + train.contact_damping * (grid.v * (speeds / RPM)[:, None] * train.unit - states[:, :-1, 1]),
        axis=1,
    )
    assert np.all(sm.error_peak >= sample_peak)
    assert np.all(sm.contact_force_min <= sample_force)
    gained = 0.0
    for k, rpm in enumerate(speeds):
        peak, fmin = brute(program, train, float(rpm))
        assert sm.error_peak[k] == pytest.approx(peak, rel=1e-9, abs=1e-12 * program.lift)
        assert sm.contact_force_min[k] == pytest.approx(fmin, rel=1e-9, abs=1e-9 * train.preload)
        gained = max(gained, (peak - sample_peak[k]) / peak, (sample_force[k] - fmin) / abs(fmin))
    assert gained > 1e-6  # the grid samples alone would fail these comparisons
