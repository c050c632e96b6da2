"""The exact discrete-time solution of the linear train driven by a motion program.

Between two grid angles the lift is the degree-7 Hermite polynomial that
matches s, v, a, j of the program at both ends (one-sided limits at joints,
and every joint is a grid angle), so its error is O(h⁸) of the law's 8th
derivative (below 1e-12 of the lift on the default grid) while the train's
response to that polynomial is exact: the train and the polynomial's
derivative chain form one linear system whose matrix exponential (the
augmented-matrix method of Van Loan 1978) carries the state across the step.
The periodic state follows from the monodromy matrix Φ of the turn,
z₀ = (I − Φ)⁻¹·(forced part) (Rothbart 2004, ch. 13: periodic response of the
linear train), with no transient run. Hand-written because ``solve_ivp``
needs thousands of steps per turn at speed for the same accuracy
(benchmarks/vibration.py) and cannot vectorise over speeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI

if TYPE_CHECKING:
    from camcad.dynamics.vibration.polydyne import CompensatedMotion
    from camcad.dynamics.vibration.train import Train
    from camcad.motion.program import MotionProgram

__all__ = [
    "Grid",
    "System",
    "grid_nodes",
    "hermite",
    "make_grid",
    "periodic_states",
    "propagate",
    "propagate_each",
    "train_system",
]

_MIN_INTERVALS = 32  # per piece where the lift moves: keeps the Hermite error ≤ 1e-12 of the lift
_ORDER = 8  # coefficients of the Hermite polynomial (degree 7)
_FACT = np.array([math.factorial(k) for k in range(_ORDER)], dtype=float)
# Right-end conditions p^(m)(1) = Σ_k e_k k!/(k−m)! for m = 0..3, on the unknowns e_4..e_7.
_RIGHT = np.array([[math.perm(k, m) for k in range(_ORDER)] for m in range(4)], dtype=float)
_RIGHT_SOLVE = np.linalg.inv(_RIGHT[:, 4:])


@dataclass(frozen=True, slots=True)
class Grid:
    """Grid angles of one turn, every joint and smooth knot among them.

    Attributes
    ----------
    phi
        (N + 1,) angles [rad] from 0 to 2π.
    piece
        (N,) the piece (run between joints) each interval lies in.
    step
        (P,) the interval length [rad] of each piece.
    coeff
        (N, 8) Hermite coefficients e_k of each interval: s(φ_i + u·h) =
        Σ e_k u^k [lift unit], u ∈ [0, 1].
    s, v, a, j
        (N,) the motion's right-hand values at the interval starts.
    """

    phi: FloatArray
    piece: np.ndarray
    step: FloatArray
    coeff: FloatArray
    s: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray


def grid_nodes(
    program: MotionProgram | CompensatedMotion, step: float
) -> tuple[FloatArray, np.ndarray, FloatArray]:
    """Grid angles (N + 1,) [rad], the piece of each interval (N,) and each piece's step (P,) [rad]."""
    edges = np.unique(np.concatenate(([0.0], np.mod(program.pieces, TWO_PI), [TWO_PI])))
    edges = edges[np.concatenate(([True], np.diff(edges) > 1e-12))]
    edges[-1] = TWO_PI
    mid = program.evaluate(0.5 * (edges[:-1] + edges[1:]))
    moving = (mid.v != 0.0) | (mid.a != 0.0)
    phis: list[FloatArray] = []
    pieces: list[np.ndarray] = []
    steps = []
    for p, (lo, hi) in enumerate(pairwise(edges)):
        n = max(_MIN_INTERVALS if moving[p] else 1, math.ceil((hi - lo) / step - 1e-9))
        phis.append(lo + (hi - lo) * np.arange(n) / n)
        pieces.append(np.full(n, p))
        steps.append((hi - lo) / n)
    phi = np.concatenate((*phis, [TWO_PI]))
    return phi, np.concatenate(pieces), np.asarray(steps)


def hermite(left: FloatArray, right: FloatArray, h: FloatArray) -> FloatArray:
    """(N, 8) coefficients e_k of the degree-7 polynomials Σ e_k u^k, u ∈ [0, 1], on intervals h (N,) [rad].

    ``left`` and ``right`` (4, N) hold the value and its first three
    φ-derivatives at the interval ends.
    """
    coeff = np.zeros((h.size, _ORDER))
    for m in range(4):
        coeff[:, m] = left[m] * h**m / _FACT[m]
    rhs = np.stack([right[m] * h**m for m in range(4)], axis=1) - coeff[:, :4] @ _RIGHT[:, :4].T
    coeff[:, 4:] = rhs @ _RIGHT_SOLVE.T
    return coeff


def make_grid(program: MotionProgram | CompensatedMotion, step: float) -> Grid:
    """Lay a grid of about ``step`` [rad] over each piece of the program and fit the Hermite polynomials."""
    phi, piece, steps = grid_nodes(program, step)
    left = program.evaluate(phi[:-1], side="right")
    right = program.evaluate(phi[1:], side="left")
    coeff = hermite(
        np.stack((left.s, left.v, left.a, left.j)),
        np.stack((right.s, right.v, right.a, right.j)),
        steps[piece],
    )
    return Grid(
        phi=phi,
        piece=piece,
        step=steps,
        coeff=coeff,
        s=np.asarray(left.s),
        v=np.asarray(left.v),
        a=np.asarray(left.a),
        j=np.asarray(left.j),
    )


System = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""(A, b_s, b_v, f) of ż = A z + b_s·s + b_v·ṡ + f, s in the grid's unit."""


def train_system(train: Train) -> System:
    """The train's state space with the motion's lift unit folded into b_s, b_v."""
    a, bs, bv, f = train.state_space()
    return a, bs * train.unit, bv * train.unit, f


def _augmented(system: System, tau: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Transition Φ (..., n, n) and input map G (..., n, 9) over time steps ``tau`` (...,) [s].

    z(τ) = Φ z(0) + G·(e_0..e_7, 1) for the input s(t) = Σ e_k (t/τ)^k.
    The chain w_k = p^(k)(u)/k! obeys ẇ_k = (k+1)/τ·w_{k+1}; s = w_0,
    ṡ = w_1/τ (scaled so that every entry of the exponent is O(1) per step).
    """
    a, bs, bv, f = system
    n = a.shape[0]
    size = n + _ORDER + 1
    tau = np.asarray(tau, dtype=float)
    m = np.zeros((*tau.shape, size, size))
    m[..., :n, :n] = a * tau[..., None, None]
    m[..., :n, n] = bs * tau[..., None]
    m[..., :n, n + 1] = bv
    m[..., :n, n + _ORDER] = f * tau[..., None]
    for k in range(_ORDER - 1):
        m[..., n + k, n + k + 1] = k + 1.0
    e = _expm(m)
    return e[..., :n, :n], e[..., :n, n:]


def _expm(m: FloatArray) -> FloatArray:
    """Matrix exponentials of a batch (..., k, k): Taylor series of degree 18 with scaling and squaring.

    Hand-written because ``scipy.linalg.expm`` works one matrix at a time
    (about 1 ms each for these 11 × 11 matrices; a 200-speed map needs
    hundreds); here every product is one batched ``matmul``. The scaled norm
    is ≤ 1/2, where the truncated series errs by < 0.5¹⁹/19! ≈ 2e-23
    (Moler & Van Loan 2003, method 3).
    """
    norm = np.max(np.sum(np.abs(m), axis=-2), axis=-1)  # 1-norm of each matrix
    top = float(np.max(norm, initial=0.0))
    squarings = max(0, math.ceil(math.log2(top / 0.5))) if top > 0.5 else 0
    x = m / 2.0**squarings
    eye = np.broadcast_to(np.eye(m.shape[-1]), m.shape)
    out = eye + x / 18.0
    for k in range(17, 0, -1):  # Horner: I + x/1 (I + x/2 (... (I + x/18)))
        out = eye + (x @ out) / k
    for _ in range(squarings):
        out = out @ out
    return out


def periodic_states(program_grid: Grid, system: System, omega: FloatArray) -> FloatArray:
    """Periodic state z = (q, q̇) at every grid angle, for each speed.

    Parameters
    ----------
    program_grid
        From :func:`make_grid`.
    system
        The linear system (:func:`train_system`).
    omega
        (S,) cam speeds [rad/s].

    Returns
    -------
    FloatArray
        (S, N + 1, n) states [generalised units, per s]; the last equals the first.
        NaN for a speed with no periodic state (an undamped train exactly at
        resonance).
    """
    g = program_grid
    omega = np.asarray(omega, dtype=float)
    tau = g.step[None, :] / omega[:, None]  # (S, P)
    phi_t, gain = _augmented(system, tau)  # (S, P, n, n), (S, P, n, 9)
    n = phi_t.shape[-1]
    coeff = np.concatenate((g.coeff, np.ones((g.coeff.shape[0], 1))), axis=1)  # (N, 9)
    forced = np.einsum("sikl,il->sik", gain[:, g.piece], coeff)  # (S, N, n)
    count = g.piece.size
    big_p = np.zeros((omega.size, count + 1, n, n))
    small = np.zeros((omega.size, count + 1, n))
    big_p[:, 0] = np.eye(n)
    for i in range(count):
        ph = phi_t[:, g.piece[i]]
        big_p[:, i + 1] = ph @ big_p[:, i]
        small[:, i + 1] = (ph @ small[:, i, :, None])[..., 0] + forced[:, i]
    lhs = np.eye(n) - big_p[:, -1]
    # Scale the velocities by the fastest rate of A so that I − Φ is O(1) entry-wise; a smallest
    # singular value below 1e-9 is an undamped train on a harmonic of the speed: no periodic state.
    rate = math.sqrt(max(float(np.max(np.abs(np.linalg.eigvals(system[0])))), 1e-300))
    scale = np.concatenate((np.ones(n // 2), np.full(n - n // 2, 1.0 / rate)))
    scaled = lhs * scale[:, None] / scale[None, :]
    sigma = np.linalg.svd(scaled, compute_uv=False)[:, -1]
    z0 = np.full((omega.size, n), np.nan)
    for k in range(omega.size):
        if sigma[k] > 1e-9:
            z0[k] = np.linalg.solve(lhs[k], small[k, -1])
    return np.asarray(np.einsum("sikl,sl->sik", big_p, z0) + small, dtype=float)


def propagate(
    program_grid: Grid, system: System, omega: float, state: FloatArray, phi: FloatArray
) -> FloatArray:
    """Carry the periodic grid states of one speed exactly to any angles ``phi`` (m,) [rad] in [0, 2π].

    ``state`` (N + 1, n) from :func:`periodic_states`; returns (m, n).
    """
    phi = np.asarray(phi, dtype=float)
    which = np.zeros(phi.size, dtype=int)
    return propagate_each(program_grid, system, np.array([omega]), state[None], which, phi)


def propagate_each(
    program_grid: Grid,
    system: System,
    omega: FloatArray,
    states: FloatArray,
    which: np.ndarray,
    phi: FloatArray,
) -> FloatArray:
    """Carry the periodic grid states of many speeds exactly to angles ``phi`` (m,) [rad] in [0, 2π].

    Point k belongs to speed ``which[k]``: ``omega`` (S,) [rad/s], ``states``
    (S, N + 1, n) from :func:`periodic_states`; returns (m, n). The state
    moves from the grid angle at or before φ over the partial step with the
    exact transition of the train and the sub-interval's Hermite lift, all
    points in one batch of matrix exponentials.
    """
    g = program_grid
    phi = np.asarray(phi, dtype=float)
    which = np.asarray(which, dtype=int)
    i = np.clip(np.searchsorted(g.phi, phi, side="right") - 1, 0, g.piece.size - 1)
    h = g.step[g.piece[i]]
    theta = np.clip((phi - g.phi[i]) / h, 0.0, 1.0)
    tau = np.maximum(theta * h / np.asarray(omega, dtype=float)[which], 1e-300)
    phi_t, gain = _augmented(system, tau)
    coeff = g.coeff[i] * theta[:, None] ** np.arange(_ORDER)  # the sub-interval's polynomial in its own u
    coeff = np.concatenate((coeff, np.ones((phi.size, 1))), axis=1)
    out = np.einsum("ikl,il->ik", phi_t, states[which, i]) + np.einsum("ikl,il->ik", gain, coeff)
    return np.asarray(out, dtype=float)
