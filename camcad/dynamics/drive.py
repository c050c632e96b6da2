"""The drive that turns the cam, or drives the follower directly as an electronic cam.

Two set-ups, one computation:

- ``camshaft``: a motor turns the camshaft through a gearbox of ratio i
  (motor speed / cam speed) and efficiency η. The load is the exact input
  torque of the rigid dynamics.
- ``servo-follower`` (electronic cam): a servo axis drives the follower
  itself along the motion, through a screw of lead p (a slide) or directly
  (a rotary axis on an arm's pivot), with a gearbox i, η. The load is the
  axis force (or moment) of mass, spring, gravity and friction.

Either way the axis load Q (N·mm on a shaft, N on a screw) reaches the motor
through k, the motor's angle per unit of axis travel (k = i on a shaft,
k = 2π·i/p on a screw), and the losses act against the power flow:

- driving (Q·ẋ ≥ 0, the motor delivers power): T_m = Q/(k·η);
- regenerating (Q·ẋ < 0, the load drives the motor back): T_m = Q·η/k

(Norton 2009, ch. 11 "motor sizing": the efficiency divides the torque the
motor supplies and multiplies the torque it gets back), plus the rotor's own
J_m·ε_m. Sizing follows the usual servo lines: peak torque ≤ the motor's peak,
RMS torque ≤ its rated (continuous) torque, speed ≤ its maximum, and the load
inertia reflected to the motor over the rotor's below ``max_inertia_ratio``.

Units: torques at the motor N·m, at the cam N·mm; speeds rpm at the edges.

References
----------
.. [1] R. L. Norton (2009), Cam Design and Manufacturing Handbook, 2nd ed.,
   Industrial Press, ch. 11.
.. [2] VDI 2143 Blatt 1 (1980), Bewegungsgesetze für Kurvengetriebe —
   Theoretische Grundlagen: the characteristic values C_v = max|y′|,
   C_a = max|y″|, C_j = max|y‴| and C_Mdyn = max|y′·y″| of a normalised law
   y(x), x, y ∈ [0, 1] (its Tafel 2: modified sine C_v = 1.76, C_a = 5.53;
   cycloid 2, 6.28; modified trapezoid 2, 4.89).
"""

from __future__ import annotations

import enum
import itertools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.dynamics._cycle import cycle_mean, cycle_weights
from camcad.errors import DesignError
from camcad.extremes import Extreme
from camcad.findings import Finding, Severity
from camcad.knobs import Knob, TableKey
from camcad.motion.segments import SegmentKind

if TYPE_CHECKING:
    from camcad.motion.laws import Law
    from camcad.motion.program import MotionProgram

__all__ = [
    "CharacteristicValues",
    "DriveCheck",
    "DriveMode",
    "DriveResult",
    "DriveSpec",
    "analyse_drive",
    "characteristic_values",
    "motor_torque",
    "rms",
    "segment_characteristics",
]

_RAD_S_TO_RPM = 60.0 / TWO_PI
_NMM_PER_NM = 1000.0
_MM2_PER_M2 = 1e6


class DriveMode(enum.Enum):
    """What the motor drives: the camshaft, or the follower directly (electronic cam)."""

    CAMSHAFT = "camshaft"
    SERVO_FOLLOWER = "servo-follower"


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveSpec:
    """The ``[drive]`` table.

    Attributes
    ----------
    mode
        :class:`DriveMode`.
    gear_ratio
        i = motor speed / driven speed [1] (> 0).
    gear_efficiency
        η ∈ (0, 1].
    motor_rated_torque_Nm, motor_peak_torque_Nm
        The motor's continuous (rated) and peak torque [N·m]; ``None``: not checked.
    motor_max_rpm
        The motor's highest speed [rpm]; ``None``: not checked.
    motor_inertia_kg_m2
        The rotor's inertia J_m [kg·m²]; ``None``: no inertia ratio, no rotor torque.
    camshaft_inertia_kg_m2
        The camshaft's own inertia (cam, hub, shaft, couplings) [kg·m²].
    max_inertia_ratio
        The largest reflected load inertia over J_m (default 10).
    screw_lead_mm
        Electronic cam on a slide: the screw's lead p [mm/rev]; ``None`` on a
        rotary axis (an arm's pivot) or in camshaft mode.
    axis_friction
        Electronic cam: Coulomb friction on the axis, against the motion
        [N on a slide, N·mm on a rotary axis].
    """

    mode: DriveMode = DriveMode.CAMSHAFT
    gear_ratio: float = 1.0
    gear_efficiency: float = 1.0
    motor_rated_torque_Nm: float | None = None
    motor_peak_torque_Nm: float | None = None
    motor_max_rpm: float | None = None
    motor_inertia_kg_m2: float | None = None
    camshaft_inertia_kg_m2: float = 0.0
    max_inertia_ratio: float = 10.0
    screw_lead_mm: float | None = None
    axis_friction: float = 0.0

    def __post_init__(self) -> None:
        """Check every value: one-line errors naming the field."""
        for name in (
            "gear_ratio",
            "motor_rated_torque_Nm",
            "motor_peak_torque_Nm",
            "motor_max_rpm",
            "motor_inertia_kg_m2",
            "max_inertia_ratio",
            "screw_lead_mm",
        ):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0.0):
                raise DesignError(
                    TableKey(Knob.DRIVE_TABLE, name), f"must be a positive number, got {value!r}"
                )
        eff = self.gear_efficiency
        if not (math.isfinite(eff) and 0.0 < eff <= 1.0):
            raise DesignError(Knob.GEAR_EFFICIENCY, f"must be in (0, 1], got {eff!r}")
        for name in ("camshaft_inertia_kg_m2", "axis_friction"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise DesignError(TableKey(Knob.DRIVE_TABLE, name), f"must be ≥ 0, got {value!r}")
        if self.mode is DriveMode.CAMSHAFT and self.screw_lead_mm is not None:
            raise DesignError(Knob.SCREW_LEAD, "applies to mode = 'servo-follower' only")

    @property
    def transmission(self) -> float:
        """k: motor radians per unit of axis travel (rad/rad on a shaft, rad/mm on a screw)."""
        if self.screw_lead_mm is not None:
            return self.gear_ratio * TWO_PI / self.screw_lead_mm
        return self.gear_ratio


def motor_torque(
    load: ArrayLike, velocity: ArrayLike, *, transmission: float, efficiency: float
) -> FloatArray:
    """Torque at the motor shaft [N·m] from the axis load, losses against the power flow.

    Parameters
    ----------
    load
        (n,) Q: torque on the camshaft [N·mm] or force on a screw-driven slide [N].
    velocity
        (n,) the axis velocity in any positive unit (only its sign with Q's matters).
    transmission
        k = motor radians per unit of axis travel (i, or 2π·i/p [rad/mm]).
    efficiency
        η ∈ (0, 1].

    Returns
    -------
    FloatArray
        (n,) T_m = Q/(k·η) where Q·ẋ ≥ 0 (driving) and Q·η/k where Q·ẋ < 0
        (regenerating) (Norton 2009, ch. 11), in N·m.
    """
    q = np.asarray(load, dtype=float)
    driving = q * np.asarray(velocity, dtype=float) >= 0.0
    ideal = q / transmission / _NMM_PER_NM  # N·mm per rad → N·m
    out = np.where(driving, ideal / efficiency, ideal * efficiency)  # η against the power flow
    readonly(out)
    return out


def rms(phi: ArrayLike, values: ArrayLike) -> float:
    """Root mean square over the cam turn, √((1/2π)∮ f² dφ): over time at constant cam speed."""
    f = np.asarray(values, dtype=float)
    return math.sqrt(cycle_mean(phi, f * f))


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveCheck:
    """One line of the drive's check: a value against the motor's limit."""

    name: str
    value: float
    limit: float | None
    unit: str

    @property
    def ok(self) -> bool | None:
        """Whether the value stays within the limit; ``None`` without a limit."""
        return None if self.limit is None else self.value <= self.limit


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveResult:
    """The motor's duty over the cycle.

    Attributes
    ----------
    mode
        :class:`DriveMode`.
    phi
        (n,) cam (or master) angle [rad].
    motor_torque
        (n,) torque at the motor [N·m].
    motor_speed_rpm
        (n,) motor speed [rpm] (constant in camshaft mode).
    axis_load
        (n,) the load the axis carries: cam torque [N·mm], or the follower's
        axis force [N] / moment [N·mm] with friction.
    peak_torque, peak_angle
        max |T_m| [N·m] and where [rad].
    rms_torque
        [N·m].
    max_speed_rpm
        [rpm].
    inertia_ratio
        Reflected load inertia over J_m (its largest over the cycle), or ``None``.
    regenerated_energy_J
        Energy the load drives back into the motor per cycle [J].
    checks
        Peak, RMS, speed and inertia lines, each with its limit.
    findings
        One soft finding per failed line.
    """

    mode: DriveMode
    phi: FloatArray
    motor_torque: FloatArray
    motor_speed_rpm: FloatArray
    axis_load: FloatArray
    peak_torque: float
    peak_angle: float
    rms_torque: float
    max_speed_rpm: float
    inertia_ratio: float | None
    regenerated_energy_J: float
    checks: tuple[DriveCheck, ...] = ()
    findings: tuple[Finding, ...] = ()

    def summary(self) -> dict[str, Any]:
        """The ``drive`` section of ``summary.json``."""
        return {
            "mode": self.mode.value,
            "motor_peak_torque_Nm": self.peak_torque,
            "motor_peak_torque_angle_deg": round(math.degrees(self.peak_angle) % 360.0, 6),
            "motor_rms_torque_Nm": self.rms_torque,
            "motor_max_speed_rpm": self.max_speed_rpm,
            "inertia_ratio": self.inertia_ratio,
            "regenerated_energy_per_cycle_J": self.regenerated_energy_J,
            "checks": [
                {"name": c.name, "value": c.value, "limit": c.limit, "unit": c.unit, "ok": c.ok}
                for c in self.checks
            ],
        }


def analyse_drive(
    phi: ArrayLike,
    *,
    axis_load: ArrayLike,
    axis_speed: ArrayLike,
    axis_acceleration: ArrayLike,
    omega: float,
    spec: DriveSpec,
    load_inertia: ArrayLike | float = 0.0,
    load_extremes: tuple[Extreme, Extreme] | None = None,
) -> DriveResult:
    """Motor torque, speed and inertia over the cycle, checked against the motor.

    Parameters
    ----------
    phi
        (n,) sorted cam (master) angles in [0, 2π) [rad].
    axis_load
        (n,) camshaft mode: the cam's input torque [N·mm] (friction included);
        servo-follower: the force the axis must apply to the follower [N]
        (slide) or the moment about the pivot [N·mm] (arm), without friction:
        ``spec.axis_friction`` is added here against the motion.
    axis_speed
        (n,) axis travel per radian of master angle: 1 on the camshaft,
        ds/dφ [mm/rad] on a slide, dψ/dφ [rad/rad] on an arm.
    axis_acceleration
        (n,) d²(travel)/dφ²: 0 on the camshaft (constant speed).
    omega
        Cam (master) speed ω [rad/s].
    spec
        The ``[drive]`` table.
    load_inertia
        (n,) or scalar: the load's inertia at the axis besides the camshaft's
        own (the follower's equivalent inertia m·(ds/dφ)² on a camshaft
        [kg·m²]; the follower mass on a slide [kg]; the arm's inertia [kg·m²]).
    load_extremes
        Camshaft mode: the true (min, max) of the cam torque over the turn
        (one-sided limits at joints included, e.g. ``DynamicsResult.torque_min``
        and ``torque_max``). The motor torque is T/(iη) for T ≥ 0 and Tη/i
        below, increasing in T, so its peak |T_m| is reached at one of them:
        the peak reported is then the true one, not the samples'.

    Returns
    -------
    DriveResult

    Notes
    -----
    The motor turns at ω_m = k·ẋ and accelerates at ε_m = k·ẍ; its rotor
    adds J_m·ε_m to the torque. The reflected load inertia is J_load/k²
    (k in rad/m on a screw), taken at its largest over the cycle. The
    regenerated energy is ∮ max(0, −T_m·ω_m) dt = (1/ω)∮ max(0, −T_m·ω_m) dφ.
    """
    p = np.array(phi, dtype=float).ravel()
    k = spec.transmission
    speed = np.asarray(axis_speed, dtype=float) * np.ones_like(p)
    velocity = speed * omega  # axis units per second
    load = np.asarray(axis_load, dtype=float) * np.ones_like(p)
    if spec.mode is DriveMode.SERVO_FOLLOWER and spec.axis_friction > 0.0:
        load = load + spec.axis_friction * np.sign(velocity)  # Coulomb friction against the motion
    torque = motor_torque(load, velocity, transmission=k, efficiency=spec.gear_efficiency)
    motor_omega = k * velocity  # rad/s
    if spec.motor_inertia_kg_m2 is not None:
        eps = k * np.asarray(axis_acceleration, dtype=float) * (omega * omega)  # rad/s² (ω·ω: see jump.py)
        torque = torque + spec.motor_inertia_kg_m2 * eps
    motor_rpm = np.abs(motor_omega) * _RAD_S_TO_RPM
    w = cycle_weights(p)
    regen = float(np.dot(w, np.clip(-torque * motor_omega, 0.0, None))) / omega if omega > 0.0 else 0.0
    i = int(np.argmax(np.abs(torque)))
    ratio = None
    if spec.motor_inertia_kg_m2 is not None:
        j_load = np.max(np.asarray(load_inertia, dtype=float) * np.ones_like(p))
        k_si = k * 1000.0 if spec.screw_lead_mm is not None else k  # rad/mm → rad/m
        if spec.mode is DriveMode.CAMSHAFT:
            j_load = j_load + spec.camshaft_inertia_kg_m2
        ratio = float(j_load / k_si**2 / spec.motor_inertia_kg_m2)
    readonly(p, torque, motor_rpm, load)
    peak, peak_angle = float(abs(torque[i])), float(p[i])
    if load_extremes is not None and spec.mode is DriveMode.CAMSHAFT:
        for ext in load_extremes:  # T_m is increasing in T: its extremes sit at T's
            t = float(motor_torque([ext.value], [1.0], transmission=k, efficiency=spec.gear_efficiency)[0])
            if abs(t) > peak:
                peak, peak_angle = abs(t), ext.phi
    rms_t, top = rms(p, torque), float(np.max(motor_rpm))
    checks = (
        DriveCheck(name="peak torque", value=peak, limit=spec.motor_peak_torque_Nm, unit="N·m"),
        DriveCheck(name="RMS torque", value=rms_t, limit=spec.motor_rated_torque_Nm, unit="N·m"),
        DriveCheck(name="speed", value=top, limit=spec.motor_max_rpm, unit="rpm"),
        *(
            ()
            if ratio is None
            else (DriveCheck(name="inertia ratio", value=ratio, limit=spec.max_inertia_ratio, unit="1"),)
        ),
    )
    return DriveResult(
        mode=spec.mode,
        phi=p,
        motor_torque=torque,
        motor_speed_rpm=motor_rpm,
        axis_load=load,
        peak_torque=peak,
        peak_angle=peak_angle,
        rms_torque=rms_t,
        max_speed_rpm=top,
        inertia_ratio=ratio,
        regenerated_energy_J=regen,
        checks=checks,
        findings=_findings(checks, peak_angle=peak_angle),
    )


_CHECK_FIELDS = {
    "peak torque": (Knob.MOTOR_PEAK_TORQUE, "a stronger motor or a larger gear ratio"),
    "RMS torque": (
        Knob.MOTOR_RATED_TORQUE,
        "a motor with a higher rated torque or a larger gear ratio",
    ),
    "speed": (Knob.MOTOR_MAX_RPM, "a faster motor or a smaller gear ratio"),
    "inertia ratio": (Knob.MAX_INERTIA_RATIO, "a motor with more rotor inertia or a larger gear ratio"),
}


def _findings(checks: tuple[DriveCheck, ...], *, peak_angle: float) -> tuple[Finding, ...]:
    out = []
    for c in checks:
        if c.ok is False:
            assert c.limit is not None
            field, fix = _CHECK_FIELDS[c.name]
            out.append(
                Finding(
                    kind=f"drive {c.name}",
                    severity=Severity.SOFT,
                    field=field,
                    message=(
                        f"motor {c.name} {c.value:.4g} {c.unit} exceeds the limit {c.limit:g} {c.unit}: {fix}"
                    ),
                    angle=peak_angle if c.name == "peak torque" else None,
                    value=c.value,
                    limit=c.limit,
                    unit=c.unit,
                )
            )
    return tuple(out)


# ------------------------------------------------------------ VDI 2143 characteristic values


@dataclass(frozen=True, slots=True, kw_only=True)
class CharacteristicValues:
    """VDI 2143 characteristic values of a normalised motion law y(x) (Kennwerte).

    Attributes
    ----------
    c_v, c_a, c_j
        max|y′|, max|y″|, max|y‴| over x ∈ [0, 1] (one-sided limits at the
        law's breakpoints included).
    c_mdyn
        max|y′·y″|: the peak dynamic torque of a pure mass load, in units of
        m·h²·ω³/β³ (VDI 2143: C_Mdyn).
    """

    c_v: float
    c_a: float
    c_j: float
    c_mdyn: float


_ZOOMS = 6  # each zoom narrows a bracket 64-fold: 2/512 → 1e-13 of the span
_FIRST, _ZOOM = 513, 129  # samples per piece, then per bracket


def _law_maxima(law: Law, pieces: list[tuple[float, float]]) -> tuple[float, float, float, float]:
    """Maxima of |y′|, |y″|, |y‴| and |y′y″| over the pieces, one law evaluation per zoom for all.

    Hand-written instead of a scalar optimizer: a law evaluates a whole array
    in the time of a few points, so every bracket of every quantity is
    sampled in one call per zoom (7 calls in all, where a bounded Brent
    search per bracket takes some 500). Each zoom resamples the interval
    between the neighbours of the best sample; piece ends are taken a hair
    inside, so one-sided limits at the law's breakpoints count.
    """

    def quantities(x: FloatArray) -> FloatArray:
        d = law.evaluate(x)
        y1, y2, y3 = (np.asarray(d[k], dtype=float) for k in (1, 2, 3))
        out: FloatArray = np.abs(np.vstack((y1, y2, y3, y1 * y2)))  # VDI 2143: C_v, C_a, C_j, C_Mdyn
        return out

    grids = []
    for lo, hi in pieces:
        x = np.linspace(lo, hi, _FIRST)
        x[0], x[-1] = np.nextafter(lo, hi), np.nextafter(hi, lo)  # the one-sided limits at the ends
        grids.append(x)
    values = quantities(np.concatenate(grids))
    bounds = np.cumsum([0, *(g.size for g in grids)])
    best = np.zeros(4)
    brackets: list[tuple[int, float, float]] = []  # (quantity, a, b)
    for q in range(4):
        for k, g in enumerate(grids):
            seg = values[q, bounds[k] : bounds[k + 1]]
            i = int(np.argmax(seg))
            best[q] = max(best[q], float(seg[i]))
            brackets.append((q, float(g[max(i - 1, 0)]), float(g[min(i + 1, g.size - 1)])))
    for _ in range(_ZOOMS):
        xs = [np.linspace(a, b, _ZOOM) for _, a, b in brackets]
        values = quantities(np.concatenate(xs))
        nxt = []
        for n, ((q, _, _), x) in enumerate(zip(brackets, xs, strict=True)):
            seg = values[q, n * _ZOOM : (n + 1) * _ZOOM]
            i = int(np.argmax(seg))
            best[q] = max(best[q], float(seg[i]))
            nxt.append((q, float(x[max(i - 1, 0)]), float(x[min(i + 1, _ZOOM - 1)])))
        brackets = nxt
    return float(best[0]), float(best[1]), float(best[2]), float(best[3])


def characteristic_values(law: Law) -> CharacteristicValues:
    """The VDI 2143 characteristic values of a normalised law (VDI 2143 Blatt 1, Tafel 2).

    Parameters
    ----------
    law
        A normalised law y(x) (:mod:`camcad.motion.laws`).

    Returns
    -------
    CharacteristicValues
        Each maximum is refined on the exact law (to ~1e-12), piece by piece
        between the law's breakpoints, so a one-sided limit at a breakpoint
        counts.

    Examples
    --------
    >>> from camcad.motion.laws import make_law
    >>> cv = characteristic_values(make_law("cycloidal"))
    >>> round(cv.c_v, 6), round(cv.c_a, 6)
    (2.0, 6.283185)
    """
    edges = [0.0, *sorted(law.breakpoints), 1.0]
    pieces = [(a, b) for a, b in itertools.pairwise(edges) if b > a]
    c_v, c_a, c_j, c_mdyn = _law_maxima(law, pieces)  # VDI 2143 Blatt 1: C_v, C_a, C_j, C_Mdyn
    return CharacteristicValues(c_v=c_v, c_a=c_a, c_j=c_j, c_mdyn=c_mdyn)


def segment_characteristics(program: MotionProgram) -> tuple[tuple[int, str, CharacteristicValues], ...]:
    """The characteristic values of every rise and return of a motion program.

    Returns
    -------
    tuple
        ``(segment index, law description, values)`` for each segment with a
        law; dwells and point tables (no normalised law) are left out.
    """
    out = []
    for index, seg in enumerate(program.segments):
        if seg.law is None or seg.kind not in (SegmentKind.RISE, SegmentKind.RETURN):
            continue
        out.append((index, seg.law.describe(), characteristic_values(seg.law)))
    return tuple(out)
