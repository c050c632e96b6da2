"""Tolerance statistics of a cam: Monte Carlo on the made cam, the linear method, and allocation.

Each toleranced quantity (:class:`~camcad.geometry.sensitivity.Tol`) is a
symmetric tolerance ±t drawn uniformly, or a normal spread whose ±t holds
99.73 % of the parts (t = 3σ, the process-capability convention). The
profile form tolerance is drawn as one normal offset of the whole profile
per variant (the part of a form error that moves a dwell; a form error that
varies along the profile is what :mod:`camcad.inspect.measure` measures).

* :func:`monte_carlo` re-solves the follower on each made cam
  (:func:`~camcad.geometry.made.made_motion`, vectorised over the variants):
  the dwell position error (at the middle of every dwell), the peak |a| of the
  rebuilt motion and the peak |α| (each variant's grid maximum refined by a
  golden-section search on the re-solved motion), with percentiles.
* :func:`linear_dwell` gives the same dwell errors to first order from the
  sensitivities: mean 0, σ = √Σ(c_k·σ_k)² (RSS) and the worst case Σ|c_k|·t_k.
* :func:`allocate` finds the largest symmetric tolerances that keep every
  dwell within a required accuracy, by the worst case (100 %) or by RSS at a
  stated confidence (the sum taken as normal: exact for normal tolerances, the
  central-limit approximation for uniform ones; Rothbart 2004, §10; Chase &
  Parkinson 1991).

References
----------
.. [1] Rothbart (2004), Cam Design Handbook, McGraw-Hill, §10.
.. [2] Chase & Parkinson (1991), A survey of research in the application of
   tolerance analysis to the design of mechanical assemblies, Research in
   Engineering Design 3, 23–37. doi:10.1007/BF01580066
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.stats import norm

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.made import MadeMotion, made_motion
from camcad.geometry.sensitivity import Tol, applicable, mount_of, sensitivities
from camcad.knobs import Knob, TableKey
from camcad.motion.segments import SegmentKind

if TYPE_CHECKING:
    from camcad.dynamics.spec import DynamicsSetup

__all__ = [
    "PERCENTILES",
    "Allocation",
    "Distribution",
    "LinearDwell",
    "Method",
    "MonteCarlo",
    "Tolerance",
    "allocate",
    "draw",
    "dwell_angles",
    "linear_dwell",
    "made_stress",
    "monte_carlo",
    "quantities",
    "variant_figures",
]

PERCENTILES = (0.135, 2.5, 50.0, 97.5, 99.865)
"""Percentiles reported [%]: ±3σ and ±2σ of a normal spread, and the median."""

_CHUNK = 200_000  # variant × angle points per re-solve (memory: a few tens of MB)
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_CANDIDATES = 3  # grid peaks refined per variant
_REFINE = 40  # golden-section steps: the bracket of two grid steps shrinks by 0.618⁴⁰ ≈ 4e-9


class Distribution(enum.Enum):
    """How a tolerance is drawn: uniform over ±t, or normal with σ = t/3."""

    UNIFORM = "uniform"
    NORMAL = "normal"

    @property
    def sigma_per_tolerance(self) -> float:
        """σ of the drawn error per unit of the tolerance t: 1/√3 (uniform) or 1/3 (normal)."""
        return 1.0 / math.sqrt(3.0) if self is Distribution.UNIFORM else 1.0 / 3.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Tolerance:
    """A symmetric tolerance ±``value`` of one quantity (mm; ``PHASE`` rad)."""

    tol: Tol
    value: float
    distribution: Distribution = Distribution.UNIFORM


def _largest(cam: Cam, tol: Tol) -> tuple[float, str]:
    """The size no tolerance of ``tol`` can reach (a tolerance larger than the part), and its unit."""
    if tol is Tol.PHASE:
        return math.pi / 2.0, "rad (a quarter turn)"
    if tol is Tol.ROLLER_RADIUS:
        return cam.roller_radius, "mm (the roller radius)"
    return cam.base_radius, "mm (the base radius)"


def _check(cam: Cam, tolerances: Sequence[Tolerance]) -> None:
    allowed = applicable(mount_of(cam))
    for t in tolerances:
        field = TableKey(Knob.TOLERANCE_TABLE, t.tol.value)
        if t.tol not in allowed:
            names = ", ".join(a.value for a in allowed)
            raise DesignError(field, f"does not apply to this follower; allowed: {names}")
        if not (math.isfinite(t.value) and t.value >= 0.0):
            raise DesignError(field, f"{t.value!r}; allowed: a finite tolerance ≥ 0")
        limit, unit = _largest(cam, t.tol)
        if t.value >= limit:
            raise DesignError(field, f"±{t.value:g} is larger than the part; allowed: below {limit:g} {unit}")
    if len({t.tol for t in tolerances}) != len(tolerances):
        raise DesignError("tolerance", "a quantity is toleranced twice; allowed: one entry each")


def dwell_angles(cam: Cam) -> FloatArray:
    """(D,) the middle of every dwell [rad], in program order."""
    prog = cam.program
    out = np.array(
        [
            start + 0.5 * seg.span
            for start, seg in zip(prog.starts, prog.segments, strict=True)
            if seg.kind is SegmentKind.DWELL
        ],
        dtype=float,
    )
    readonly(out)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class MonteCarlo:
    """Monte Carlo over made cams.

    Attributes
    ----------
    deltas
        The drawn errors, each (V,) (mm; ``PHASE`` rad).
    dwell_phi
        (D,) dwell middles [rad].
    dwell_error
        (V, D) lift minus the design's there [lift unit].
    peak_acceleration
        (V,) max |d²q/dφ²| [lift unit/rad²], refined between grid points; NaN for a face on an arm.
    peak_pressure_angle
        (V,) max |α| [rad], refined between grid points.
    percentiles
        Quantity name → (len(PERCENTILES),) values; dwell errors as ``dwell_error[i]``.
    """

    deltas: Mapping[Tol, FloatArray]
    dwell_phi: FloatArray
    dwell_error: FloatArray
    peak_acceleration: FloatArray
    peak_pressure_angle: FloatArray
    percentiles: Mapping[str, FloatArray]


def _draw(tolerances: Sequence[Tolerance], samples: int, seed: int) -> dict[Tol, FloatArray]:
    rng = np.random.default_rng(seed)
    out = {}
    for t in tolerances:  # drawn in the order given: same seed, same variants
        if t.distribution is Distribution.UNIFORM:
            out[t.tol] = rng.uniform(-t.value, t.value, samples)
        else:
            out[t.tol] = rng.normal(0.0, t.value / 3.0, samples)
    return out


def monte_carlo(
    cam: Cam,
    tolerances: Sequence[Tolerance],
    *,
    samples: int = 1000,
    seed: int = 0,
    step: float = math.radians(1.0),
    peaks: bool = True,
) -> MonteCarlo:
    """Draw ``samples`` made cams and re-solve each follower's motion.

    Parameters
    ----------
    cam
        The design.
    tolerances
        The toleranced quantities.
    samples
        Number of variants V ≥ 2.
    seed
        Seed of NumPy's default generator (same seed, same numbers).
    step
        Angle step of the grid the peaks are found on before refining [rad]; the
        dwell middles and breakpoints are always included.
    peaks
        False: only the dwell errors (the peaks are NaN), re-solved at the dwells alone.
    """
    _check(cam, tolerances)
    if samples < 2:
        raise DesignError(Knob.TOLERANCE_SAMPLES, f"{samples}; allowed: at least 2")
    deltas = _draw(tolerances, samples, seed)
    dwell = dwell_angles(cam)
    phi = _grid(cam, dwell, step, peaks)
    per = max(1, _CHUNK // phi.size)
    dwell_err, acc, alpha = [], [], []
    for lo in range(0, samples, per):
        part = {k: v[lo : lo + per] for k, v in deltas.items()}
        d_err, p_acc, p_alpha, _ = variant_figures(cam, part, step=step, peaks=peaks)
        dwell_err.append(d_err)
        acc.append(p_acc)
        alpha.append(p_alpha)
    dwell_error = np.vstack(dwell_err) if dwell.size else np.zeros((samples, 0))
    peak_acc, peak_alpha = np.concatenate(acc), np.concatenate(alpha)
    pct: dict[str, FloatArray] = {
        "peak_acceleration": np.percentile(peak_acc, PERCENTILES),
        "peak_pressure_angle": np.percentile(peak_alpha, PERCENTILES),
    }
    for i in range(dwell.size):
        pct[f"dwell_error[{i}]"] = np.percentile(dwell_error[:, i], PERCENTILES)
    for arr in (*deltas.values(), dwell_error, peak_acc, peak_alpha, *pct.values()):
        readonly(arr)
    return MonteCarlo(
        deltas=deltas,
        dwell_phi=dwell,
        dwell_error=dwell_error,
        peak_acceleration=peak_acc,
        peak_pressure_angle=peak_alpha,
        percentiles=pct,
    )


def draw(tolerances: Sequence[Tolerance], *, samples: int, seed: int) -> dict[Tol, FloatArray]:
    """The errors of ``samples`` made cams, each (V,) (mm; ``PHASE`` rad), as :func:`monte_carlo` draws them.

    Unchecked: :func:`linear_dwell` or :func:`monte_carlo` on the cam checks the tolerances.
    """
    return _draw(tolerances, samples, seed)


def _grid(cam: Cam, dwell: FloatArray, step: float, peaks: bool) -> FloatArray:
    marks = np.mod(dwell, 2.0 * np.pi)
    out: FloatArray = np.union1d(cam.sample_phi(step), marks) if peaks else np.unique(marks)
    return out


def made_stress(made: MadeMotion, setup: DynamicsSetup) -> FloatArray:
    """Hertz contact stress [MPa] of made cams at their contacts, shaped as ``made.lift``.

    The design's dynamic model (:func:`camcad.dynamics.model.contact_stress_at`)
    fed with the made cam's own lift, velocity, acceleration and pressure
    angle (the load) and its profile radius, roller radius and lever at the
    contact (the curvature): Hertz line contact, Johnson 1985, eq. 4.45.
    """
    from camcad.dynamics.model import contact_stress_at
    from camcad.motion.program import Motion

    shape = made.lift.shape
    flat = made.lift.ravel()
    motion = Motion(
        phi=np.broadcast_to(made.phi, shape).ravel(),
        s=flat,
        v=made.velocity.ravel(),
        a=made.acceleration.ravel(),
        j=np.zeros_like(flat),
    )
    lever = made.lever.ravel()
    stress = contact_stress_at(
        motion,
        pressure_angle=made.pressure_angle.ravel(),
        profile_rho=made.profile_rho.ravel(),
        setup=setup,
        lever=None if np.all(np.isnan(lever)) else lever,
        roller_radius=made.roller_radius.ravel() if setup.roller_radius else None,
    )
    out: FloatArray = np.asarray(stress, dtype=float).reshape(shape)
    return out


Quantity = Callable[[MadeMotion], FloatArray]
"""A figure of made cams at their contacts whose maximum is reported, shaped as ``made.lift``."""


def quantities(setup: DynamicsSetup | None) -> dict[str, Quantity]:
    """The peaked figures: |acceleration| [lift unit/rad²], |pressure angle| [rad], contact stress [MPa].

    The stress is NaN without a dynamics setup, or for a groove (one flank's model only).
    """

    def stress(made: MadeMotion) -> FloatArray:
        if setup is None or setup.flank_offsets is not None:
            return np.full(made.lift.shape, np.nan)
        return made_stress(made, setup)

    return {
        "acceleration": lambda made: np.abs(made.acceleration),
        "pressure_angle": lambda made: np.abs(made.pressure_angle),
        "stress": stress,
    }


def variant_figures(
    cam: Cam,
    deltas: Mapping[Tol, FloatArray],
    *,
    step: float = math.radians(1.0),
    peaks: bool = True,
    setup: DynamicsSetup | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """One batch of made cams re-solved together: dwell errors (V, D), peak |a|, |α| and contact stress (V,).

    What :func:`monte_carlo` computes for each of its batches (see there for
    the units; the stress in MPa, NaN without ``setup``); a batch's figures
    depend only on the variants in it, so the same batches give the same
    bytes on any machine or worker.
    """
    dwell = dwell_angles(cam)
    phi = _grid(cam, dwell, step, peaks)
    where = np.searchsorted(phi, np.mod(dwell, 2.0 * np.pi))
    nominal = cam.motion(phi).s
    made = made_motion(cam, phi, deltas=deltas)
    lift = made.lift.reshape(-1, phi.size)
    dwell_err: FloatArray = lift[:, where] - nominal[where]
    if not peaks:
        nan: FloatArray = np.full(lift.shape[0], np.nan)
        return dwell_err, nan, nan.copy(), nan.copy()
    found = [_peak(cam, phi, q(made).reshape(-1, phi.size), deltas, q) for q in quantities(setup).values()]
    return dwell_err, found[0], found[1], found[2]


def _golden(f: Callable[[FloatArray], FloatArray], a: FloatArray, b: FloatArray) -> FloatArray:
    """Max of f on each bracket [a, b] by golden section (:data:`_REFINE` steps)."""
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(_REFINE):
        left = fc > fd  # the maximum lies in [a, d]
        a, b = np.where(left, a, c), np.where(left, d, b)
        x = np.where(left, b - _GOLDEN * (b - a), a + _GOLDEN * (b - a))
        fx = f(x)
        c, d = np.where(left, x, d), np.where(left, c, x)
        fc, fd = np.where(left, fx, fd), np.where(left, fc, fx)
    out: FloatArray = np.maximum(fc, fd)
    return out


def _peak(
    cam: Cam, grid: FloatArray, values: FloatArray, part: Mapping[Tol, FloatArray], quantity: Quantity
) -> FloatArray:
    """Each variant's max of ``quantity``: its largest grid peaks, each refined by golden section.

    The ``_CANDIDATES`` largest local maxima of the grid are refined between
    their neighbours on the re-solved motion (a rise and a return often peak
    alike, and the grid may favour the wrong one). Where the quantity jumps
    at a joint the search closes in on the larger one-sided limit; the result
    is never below the grid's maximum.
    """
    if np.all(np.isnan(values)):
        none: FloatArray = np.array(values[:, 0])  # a face on an arm: no acceleration
        return none
    nv, n = values.shape
    local = (values >= np.roll(values, 1, axis=1)) & (values >= np.roll(values, -1, axis=1))
    ranked = np.argsort(np.where(local, values, -np.inf), axis=1)[:, ::-1][:, :_CANDIDATES]
    k = ranked.ravel()
    a = grid[(k - 1) % n] - np.where(k == 0, 2.0 * np.pi, 0.0)
    b = grid[(k + 1) % n] + np.where(k == n - 1, 2.0 * np.pi, 0.0)
    phi_shape = (nv, ranked.shape[1])

    def f(x: FloatArray) -> FloatArray:
        return quantity(made_motion(cam, x.reshape(phi_shape), deltas=part)).ravel()

    refined = np.max(_golden(f, a, b).reshape(phi_shape), axis=1)
    out: FloatArray = np.maximum(np.max(values, axis=1), refined)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearDwell:
    """First-order dwell errors: coefficients (D, K) [lift unit per mm or rad], σ (D,), worst case (D,)."""

    dwell_phi: FloatArray
    parameters: tuple[Tol, ...]
    coefficients: FloatArray
    sigma: FloatArray
    worst_case: FloatArray


def linear_dwell(cam: Cam, tolerances: Sequence[Tolerance]) -> LinearDwell:
    """The dwell errors to first order: σ = √Σ(c_k·σ_k)² and worst case Σ|c_k|·t_k, at each dwell middle."""
    _check(cam, tolerances)
    dwell = dwell_angles(cam)
    sens = sensitivities(cam, dwell)
    params = tuple(t.tol for t in tolerances)
    coef = np.array([sens.lift[sens.row(p)] for p in params]).T.reshape(dwell.size, len(params))
    sig = np.array([t.value * t.distribution.sigma_per_tolerance for t in tolerances])
    t_val = np.array([t.value for t in tolerances])
    out = LinearDwell(
        dwell_phi=dwell,
        parameters=params,
        coefficients=coef,
        sigma=np.sqrt(np.sum((coef * sig) ** 2, axis=1)),
        worst_case=np.sum(np.abs(coef) * t_val, axis=1),
    )
    readonly(out.coefficients, out.sigma, out.worst_case)
    return out


class Method(enum.Enum):
    """How tolerances add: worst case (every error at its limit) or root-sum-square."""

    WORST_CASE = "worst-case"
    RSS = "rss"


@dataclass(frozen=True, slots=True, kw_only=True)
class Allocation:
    """The largest symmetric tolerances meeting a dwell accuracy.

    ``tolerances`` maps each quantity to ±t (mm; ``PHASE`` rad); ``inf`` where
    the quantity does not move any dwell. ``predicted`` (D,) is the dwell
    error at the confidence (RSS) or the worst case, with these tolerances.
    """

    tolerances: Mapping[Tol, float]
    method: Method
    confidence: float
    required: float
    predicted: FloatArray


def allocate(
    coefficients: FloatArray,
    parameters: Sequence[Tol],
    *,
    required: float,
    method: Method = Method.RSS,
    confidence: float = 0.9973,
    distribution: Distribution = Distribution.UNIFORM,
    weights: Mapping[Tol, float] | None = None,
) -> Allocation:
    """Largest symmetric tolerances keeping every dwell error within ±``required``.

    Parameters
    ----------
    coefficients
        (D, K) or (K,) first-order dwell sensitivities (:attr:`LinearDwell.coefficients`).
    parameters
        The K quantities.
    required
        The dwell accuracy ±E [lift unit], > 0.
    method
        ``WORST_CASE``: Σ|c_k|·t_k ≤ E (every part). ``RSS``: z·√Σ(c_k·f·t_k)² ≤ E,
        z the two-sided normal quantile of ``confidence``, f = σ per unit t.
    confidence
        Fraction of parts within ±E (RSS only), in (0, 1).
    distribution
        How each error is spread within its tolerance (RSS only).
    weights
        Relative tolerances t_k = λ·w_k (one common scale λ); None: equal effect,
        each quantity moving the binding dwell by the same amount.

    Notes
    -----
    Equal effect: t_k = E/(K·|c_k|) (worst case) or E/(z·f·√K·|c_k|) (RSS),
    K the quantities that move the dwell, taken at the dwell that binds each one.
    """
    if not (math.isfinite(required) and required > 0.0):
        raise DesignError(Knob.DWELL_ACCURACY, f"{required!r}; allowed: > 0")
    if not 0.0 < confidence < 1.0:
        raise DesignError(Knob.CONFIDENCE, f"{confidence!r}; allowed: between 0 and 1")
    coef = np.abs(np.atleast_2d(np.asarray(coefficients, dtype=float)))
    coef = np.where(coef < 1e-12 * max(float(np.max(coef)), 1e-300), 0.0, coef)
    if method is Method.WORST_CASE:
        z, f = 1.0, 1.0
    else:
        z, f = float(norm.ppf(0.5 + 0.5 * confidence)), distribution.sigma_per_tolerance
    if weights is None:
        moving = np.maximum(np.count_nonzero(coef, axis=1), 1)[:, None]
        share = required / (moving if method is Method.WORST_CASE else z * f * np.sqrt(moving))
        with np.errstate(divide="ignore"):
            t = np.min(np.where(coef > 0.0, share / coef, np.inf), axis=0)
    else:
        w = np.array([weights.get(p, 0.0) for p in parameters])
        if np.any(~np.isfinite(w)) or np.any(w < 0.0) or not np.any(w > 0.0):
            raise DesignError(Knob.TOLERANCE_WEIGHTS, "allowed: finite weights ≥ 0, at least one > 0")
        if method is Method.WORST_CASE:
            spread = np.sum(coef * w, axis=1)
        else:
            spread = z * f * np.sqrt(np.sum((coef * w) ** 2, axis=1))
        lam = required / float(np.max(spread))
        t = lam * w
    finite = np.where(np.isfinite(t), t, 0.0)
    if method is Method.WORST_CASE:
        predicted = np.sum(coef * finite, axis=1)
    else:
        predicted = z * f * np.sqrt(np.sum((coef * finite) ** 2, axis=1))
    readonly(predicted)
    return Allocation(
        tolerances={p: float(v) for p, v in zip(parameters, t, strict=True)},
        method=method,
        confidence=1.0 if method is Method.WORST_CASE else confidence,
        required=required,
        predicted=predicted,
    )
