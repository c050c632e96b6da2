"""Monte Carlo on a million made cams: each figure as a quadratic in the errors, certified by exact re-solves.

Re-solving every made cam (:func:`camcad.inspect.tolerance.variant_figures`)
costs a few milliseconds of CPU per variant, so 10⁶ variants would take an
hour. But a made cam differs from its design by errors a thousand times
smaller than its radii, and every figure of the study (the dwell errors, and
each candidate peak of |a|, |α| and the contact stress, refined on the made
cam) is a smooth function of those errors. So :func:`response` re-solves a
fixed stencil of made cams exactly (the design, each error at ±its tolerance
and each pair at (±t_i, ±t_j): 1 + 2K + 2K(K − 1) cams for K errors) and fits
each figure by least squares as F(x) = F0 + Σ g_k x_k + Σ_{k≤l} h_kl x_k x_l
in the scaled errors x_k = δ_k / t_k (a central-difference quadratic; its
error is the third-order remainder, O(|x|³·F‴)). A peak is the largest of its
candidates' quadratics (a rise's and a return's peak may trade places); the
candidates are the design's grid peaks within half of its largest, each
refined by golden section between its grid neighbours on every stencil cam.

The fit is not trusted: :func:`certify` re-solves exactly a sample of the
study's own variants (the first ones drawn and those with the largest scaled
errors, where the remainder is largest) and reports the largest difference of
every figure; ``camcad tolerance`` writes it into ``tolerance.json`` and
refuses the study (:func:`untrusted`) where it exceeds :data:`TRUST` of the
figure's spread over the made cams.

:meth:`Response.figures` evaluates elementwise (no BLAS), in chunks of
:data:`BATCH` variants, so its numbers do not depend on how the variants are
chunked and its memory does not grow with their number.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camcad._typing import FloatArray, readonly
from camcad.geometry.cam import Cam
from camcad.geometry.made import made_motion
from camcad.geometry.sensitivity import Tol
from camcad.inspect.tolerance import (
    Quantity,
    Tolerance,
    _golden,
    _grid,
    dwell_angles,
    quantities,
    variant_figures,
)

if TYPE_CHECKING:
    from camcad.dynamics.spec import DynamicsSetup

__all__ = [
    "BATCH",
    "CERTIFY",
    "TRUST",
    "Certificate",
    "Quadratic",
    "Response",
    "certify",
    "response",
    "stencil",
    "untrusted",
]

BATCH = 50_000
"""Variants evaluated at once by :meth:`Response.figures` (memory: a few tens of MB)."""
CERTIFY = 200
"""Variants re-solved exactly by :func:`certify`: half the first drawn, half the largest scaled errors."""
TRUST = 1e-3
"""A figure's certified error must stay below this share of its spread (σ over the study's made cams)."""
_FLOOR = 1e-9  # ... or below this share of its size (a figure the errors do not move)
_KEEP = 0.5  # a grid peak of at least this share of the largest is a candidate
_MAX_CANDIDATES = 8


def stencil(k: int) -> FloatArray:
    """(1 + 2k + 2k(k − 1), k) scaled error points: the origin, ±e_i, and (±e_i ± e_j) for i < j."""
    rows = [np.zeros(k)]
    eye = np.eye(k)
    for i in range(k):
        rows += [eye[i], -eye[i]]
    for i in range(k):
        for j in range(i + 1, k):
            for si in (1.0, -1.0):
                for sj in (1.0, -1.0):
                    rows.append(si * eye[i] + sj * eye[j])
    out: FloatArray = np.array(rows, dtype=float).reshape(-1, k)
    return out


def _features(x: FloatArray) -> list[FloatArray]:
    """1, x_k, and x_k·x_l (k ≤ l): the quadratic's basis at the points x (V, K), each (V,)."""
    k = x.shape[1]
    out = [np.ones(x.shape[0]), *(x[:, i] for i in range(k))]
    out += [x[:, i] * x[:, j] for i in range(k) for j in range(i, k)]
    return out


@dataclass(frozen=True, slots=True)
class Quadratic:
    """F(x) = Σ c_m·basis_m(x) for F figures: ``coefficients`` (M, F) over :func:`_features`' basis."""

    coefficients: FloatArray

    def __call__(self, x: FloatArray) -> FloatArray:
        """(V, F) at the scaled errors x (V, K); elementwise sums, the same bytes however x is chunked."""
        out = np.zeros((x.shape[0], self.coefficients.shape[1]))
        for basis, c in zip(_features(x), self.coefficients, strict=True):
            out += basis[:, None] * c[None, :]
        return out

    @staticmethod
    def fit(x: FloatArray, values: FloatArray) -> Quadratic:
        """Least-squares quadratic through ``values`` (S, F) at the stencil points x (S, K)."""
        basis = np.column_stack(_features(x))
        solved, *_ = np.linalg.lstsq(basis, values, rcond=None)
        coef: FloatArray = np.asarray(solved, dtype=float)
        readonly(coef)
        return Quadratic(coef)


@dataclass(frozen=True, slots=True, kw_only=True)
class Response:
    """Every figure of the tolerance study as a quadratic in the scaled errors (see the module notes).

    Attributes
    ----------
    parameters, scale
        The K toleranced quantities and the tolerance t_k each error is scaled by (mm; ``PHASE`` rad).
    dwell
        The D dwell errors [lift unit].
    peaks
        ``acceleration``, ``pressure_angle``, ``stress`` → the quadratic of each candidate peak
        (|a| [lift unit/rad²], |α| [rad], σ [MPa]), or None where the figure does not exist (NaN).
    candidates
        The same keys → (C,) the design's grid angle of each candidate [rad].
    stencil_variants
        How many made cams were re-solved exactly to fit it.
    """

    parameters: tuple[Tol, ...]
    scale: FloatArray
    dwell: Quadratic
    peaks: Mapping[str, Quadratic | None]
    candidates: Mapping[str, FloatArray]
    stencil_variants: int

    def scaled(self, deltas: Mapping[Tol, FloatArray]) -> FloatArray:
        """(V, K) x_k = δ_k / t_k (0 where t_k = 0)."""
        cols = [
            np.asarray(deltas[p], dtype=float) / t if t > 0.0 else np.zeros(np.shape(deltas[p]))
            for p, t in zip(self.parameters, self.scale, strict=True)
        ]
        out: FloatArray = np.column_stack(cols) if cols else np.zeros((0, 0))
        return out

    def figures(
        self, deltas: Mapping[Tol, FloatArray], *, batch: int = BATCH
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """As :func:`~camcad.inspect.tolerance.variant_figures`: dwell errors (V, D); peaks |a|, |α|, σ."""
        x = self.scaled(deltas)
        nv = x.shape[0]
        dwell = np.empty((nv, self.dwell.coefficients.shape[1]))
        peaks = {key: np.full(nv, np.nan) for key in self.peaks}
        for lo in range(0, nv, max(1, batch)):
            part = x[lo : lo + batch]
            dwell[lo : lo + part.shape[0]] = self.dwell(part)
            for key, quad in self.peaks.items():
                if quad is not None:
                    peaks[key][lo : lo + part.shape[0]] = np.max(quad(part), axis=1)
        return dwell, peaks["acceleration"], peaks["pressure_angle"], peaks["stress"]


def _candidates(values: FloatArray) -> npt.NDArray[np.intp]:
    """Indices of the grid's local maxima within :data:`_KEEP` of the largest, largest first."""
    if np.all(np.isnan(values)):
        return np.zeros(0, dtype=int)
    local = (values >= np.roll(values, 1)) & (values >= np.roll(values, -1))
    keep = np.flatnonzero(local & (values >= _KEEP * np.max(values)))
    out: npt.NDArray[np.intp] = keep[np.argsort(-values[keep], kind="stable")][:_MAX_CANDIDATES]
    return out


def response(
    cam: Cam,
    tolerances: Sequence[Tolerance],
    *,
    setup: DynamicsSetup | None = None,
    step: float = math.radians(1.0),
) -> Response:
    """Fit every figure of the study on the stencil of made cams (see the module notes).

    The tolerances are those of a checked study
    (:func:`~camcad.inspect.tolerance.linear_dwell` refuses the wrong ones).
    """
    params = tuple(t.tol for t in tolerances)
    scale = np.array([t.value for t in tolerances], dtype=float)
    x = stencil(len(params))
    deltas = {p: x[:, k] * scale[k] for k, p in enumerate(params)}
    dwell = dwell_angles(cam)
    grid = _grid(cam, dwell, step, True)
    nominal = made_motion(cam, grid)
    made_dwell = made_motion(cam, np.mod(dwell, 2.0 * np.pi), deltas=deltas)
    dwell_err = made_dwell.lift.reshape(x.shape[0], -1) - cam.motion(np.mod(dwell, 2.0 * np.pi)).s
    n = grid.size
    peaks: dict[str, Quadratic | None] = {}
    where: dict[str, FloatArray] = {}
    for key, quantity in quantities(setup).items():
        idx = _candidates(np.asarray(quantity(nominal), dtype=float))
        where[key] = grid[idx] if idx.size else np.zeros(0)
        if idx.size == 0:
            peaks[key] = None
            continue
        a = grid[(idx - 1) % n] - np.where(idx == 0, 2.0 * np.pi, 0.0)
        b = grid[(idx + 1) % n] + np.where(idx == n - 1, 2.0 * np.pi, 0.0)
        shape = (x.shape[0], idx.size)
        a_all, b_all = np.broadcast_to(a, shape).ravel(), np.broadcast_to(b, shape).ravel()

        def f(phi: FloatArray, quantity: Quantity = quantity, shape: tuple[int, int] = shape) -> FloatArray:
            made = made_motion(cam, phi.reshape(shape), deltas=deltas)
            got: FloatArray = np.asarray(quantity(made), dtype=float).ravel()
            return got

        values = _golden(f, a_all, b_all).reshape(shape)
        peaks[key] = Quadratic.fit(x, values)
    for arr in (scale, *where.values()):
        readonly(arr)
    return Response(
        parameters=params,
        scale=scale,
        dwell=Quadratic.fit(x, dwell_err),
        peaks=peaks,
        candidates=where,
        stencil_variants=int(x.shape[0]),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class Certificate:
    """The largest |quadratic − exact re-solve| over ``indices``, per figure (NaN where it does not exist).

    ``dwell`` [lift unit], ``acceleration`` [lift unit/rad²], ``pressure_angle``
    [rad], ``stress`` [MPa].
    """

    indices: tuple[int, ...]
    dwell: float
    acceleration: float
    pressure_angle: float
    stress: float


def certify(
    cam: Cam,
    fitted: Response,
    deltas: Mapping[Tol, FloatArray],
    *,
    setup: DynamicsSetup | None = None,
    step: float = math.radians(1.0),
    count: int = CERTIFY,
) -> Certificate:
    """Re-solve ``count`` of the variants exactly and measure the quadratics' largest error on them.

    The variants: the first ``count // 2`` drawn and the ``count - count // 2``
    others with the largest scaled errors |x| (the remainder grows as |x|³).
    """
    x = fitted.scaled(deltas)
    nv = x.shape[0]
    first = list(range(min(nv, count // 2)))
    rest = np.argsort(-np.sum(x**2, axis=1), kind="stable")
    extreme = [int(i) for i in rest if i >= len(first)][: count - len(first)]
    idx = np.array(sorted(first + extreme), dtype=int)
    part = {p: np.asarray(v, dtype=float)[idx] for p, v in deltas.items()}
    exact = variant_figures(cam, part, step=step, setup=setup)
    approx = fitted.figures(part)

    def worst(a: FloatArray, b: FloatArray) -> float:
        diff = np.abs(np.asarray(a) - np.asarray(b))
        return math.nan if diff.size == 0 or np.all(np.isnan(diff)) else float(np.nanmax(diff))

    return Certificate(
        indices=tuple(int(i) for i in idx),
        dwell=worst(exact[0], approx[0]),
        acceleration=worst(exact[1], approx[1]),
        pressure_angle=worst(exact[2], approx[2]),
        stress=worst(exact[3], approx[3]),
    )


def untrusted(
    cert: Certificate, figures: tuple[FloatArray, FloatArray, FloatArray, FloatArray], *, lift: float
) -> tuple[str, ...]:
    """The figures whose certified error exceeds :data:`TRUST` of their spread over ``figures``.

    ``figures`` as :meth:`Response.figures` gives them for the study; ``lift``
    the cam's lift [lift unit], the size of a dwell error that does not move.
    The allowance is TRUST·σ + 1e-9·size (size: the lift for the dwell errors,
    the largest value for a peak but at least 1 in its unit), so a figure no
    error moves is held to round-off.
    """
    bad = []
    names = ("dwell", "acceleration", "pressure_angle", "stress")
    errors = (cert.dwell, cert.acceleration, cert.pressure_angle, cert.stress)
    for name, err, values in zip(names, errors, figures, strict=True):
        arr = np.asarray(values, dtype=float).reshape(len(values), -1)
        if math.isnan(err) or arr.size == 0 or np.all(np.isnan(arr)):
            continue
        spread = float(np.nanmin(np.nanstd(arr, axis=0)))
        size = lift if name == "dwell" else max(float(np.nanmax(np.abs(arr))), 1.0)  # ≥ 1 unit: a 0° angle
        if err > TRUST * spread + _FLOOR * size:
            bad.append(name)
    return tuple(bad)
