"""Harmonic content of the cam's acceleration and the train's resonances with it.

The Cam Design Handbook (Rothbart 2004, ch. 13) judges a law by the Fourier
series of its acceleration over the turn, a(φ) = Σ_k (A_k cos kφ + B_k sin kφ):
a train whose natural frequency ω_n sits on the k-th harmonic of the cam speed
(ω_n ≈ k·ω) with a strong A_k, B_k rings.
"""

from __future__ import annotations

import math
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.findings import Finding, Severity
from camcad.knobs import Knob

if TYPE_CHECKING:
    from camcad.motion.program import MotionProgram

__all__ = ["acceleration_harmonics", "resonances"]

_RPM = 60.0 / TWO_PI


def acceleration_harmonics(program: MotionProgram, count: int = 30) -> tuple[FloatArray, FloatArray]:
    """Fourier coefficients A_k, B_k (k = 1..count) of a(φ) = d²s/dφ² [lift unit/rad²].

    A_k = (1/π) ∫ a cos kφ dφ, B_k = (1/π) ∫ a sin kφ dφ over the turn
    (Rothbart 2004, ch. 13), by Gauss-Legendre quadrature on each smooth piece
    of the program (joints split it, so the quadrature is exact to round-off
    for polynomial laws and converges exponentially for trigonometric ones).

    Returns
    -------
    tuple[FloatArray, FloatArray]
        (count,) A_k and (count,) B_k.
    """
    edges = np.unique(np.concatenate(([0.0], np.mod(program.pieces, TWO_PI), [TWO_PI])))
    nodes, weights = np.polynomial.legendre.leggauss(max(64, 2 * count + 32))
    k = np.arange(1, count + 1)[:, None]
    a_k = np.zeros(count)
    b_k = np.zeros(count)
    for lo, hi in pairwise(edges):
        if hi - lo <= 0.0:
            continue
        phi = 0.5 * (hi - lo) * nodes + 0.5 * (hi + lo)
        w = 0.5 * (hi - lo) * weights
        acc = program.evaluate(phi).a
        a_k += (np.cos(k * phi) * acc * w).sum(axis=1) / math.pi
        b_k += (np.sin(k * phi) * acc * w).sum(axis=1) / math.pi
    readonly(a_k, b_k)
    return a_k, b_k


def resonances(
    natural_frequencies: FloatArray,
    harmonics: tuple[FloatArray, FloatArray],
    *,
    speed_rpm: float,
    tolerance: float = 0.02,
    share: float = 0.01,
) -> tuple[Finding, ...]:
    """Soft findings where a natural frequency sits on a strong harmonic of the cam speed.

    Parameters
    ----------
    natural_frequencies
        ω_n [rad/s] of the train.
    harmonics
        (A_k, B_k) from :func:`acceleration_harmonics`.
    speed_rpm
        Cam speed [rpm].
    tolerance
        |ω_n/(k·ω) − 1| at or below this counts as on the harmonic.
    share
        Harmonics weaker than this share of the strongest are ignored.
    """
    omega = speed_rpm / _RPM
    amp = np.hypot(*harmonics)
    top = float(np.max(amp, initial=0.0))
    out = []
    for wn in natural_frequencies:
        k = round(float(wn) / omega)
        if k < 1 or k > amp.size or top <= 0.0:
            continue
        if abs(float(wn) / (k * omega) - 1.0) <= tolerance and amp[k - 1] >= share * top:
            out.append(
                Finding(
                    kind="resonance",
                    severity=Severity.SOFT,
                    field=Knob.VIBRATION_STIFFNESS,
                    message=(
                        f"the train's natural frequency {wn / TWO_PI:.4g} Hz sits on harmonic {k} of the cam "
                        f"speed {speed_rpm:g} rpm (its acceleration amplitude {amp[k - 1]:.4g}, "
                        f"{100.0 * amp[k - 1] / top:.0f} % of the largest): change the speed or the stiffness"
                    ),
                    value=float(k),
                    unit="harmonic",
                )
            )
    return tuple(out)
