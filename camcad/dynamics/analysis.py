"""One entry point: run the dynamic model a design asks for.

:func:`analyse_dynamics` takes the follower motion and two geometric arrays
(pressure angle, profile curvature radius) from the earlier stages, so it does
not depend on how the geometry was computed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.design import DynamicsModel, DynamicsSpec, FollowerKind, Rotation
from camcad.dynamics.contact import contact_curvature, effective_modulus, hertz_stress
from camcad.dynamics.energy import FollowerLoad, contact_force, input_torque
from camcad.dynamics.jump import covering_arc, loss_runs, speed_window
from camcad.dynamics.results import DynamicsResult
from camcad.dynamics.spring import spring_from_spec
from camcad.dynamics.tappet import GuidedTappet, tappet_forces
from camcad.extremes import Extreme, Kind, Quantity, Side, extremes
from camcad.findings import Finding, Severity

if TYPE_CHECKING:
    from camcad.design import Design
    from camcad.geometry.cam import Cam
    from camcad.motion.program import Motion

__all__ = ["analyse_dynamics"]

_RAD_S_TO_RPM = 60.0 / (2.0 * math.pi)
# Warn when a guide force changes side and its misdirected friction exceeds this share of N1.
_GUIDE_FLIP_RTOL = 0.01


def _array(name: str, values: ArrayLike, n: int) -> FloatArray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.shape != (n,):
        raise ValueError(f"{name} has {arr.size} samples, the motion has {n}")
    return arr


def _arc_text(arc: tuple[float, float]) -> str:
    return f"between {math.degrees(arc[0]):.1f}° and {math.degrees(arc[1]):.1f}°"


def _jump_warning(
    *,
    runs: tuple[tuple[float, float], ...],
    margin: float,
    omega: float,
    preload: float,
    deflection: float | None,
    speeds: tuple[float, float] | None,
    worst: Extreme,
) -> str:
    arc = covering_arc(runs)
    assert arc is not None
    where = _arc_text(arc) if arc[0] != arc[1] else worst.where()
    lowest = f"(contact force {worst.value:.3g} N {worst.where()})"
    if margin > 0.0:
        head = f"contact force falls below min_contact_force = {margin:g} N {where} {lowest}"
    else:
        head = f"follower jumps {where} {lowest}"
    # round the advice to the safe side: preload up, speed down
    fix = f"raise the preload to ≥ {math.ceil(preload * 10.0 - 1e-9) / 10.0:.1f} N"
    if deflection is not None:
        fix += f" (preload deflection ≥ {math.ceil(deflection * 100.0 - 1e-9) / 100.0:.2f} mm)"
    if speeds is None:
        fix += "; no cam speed keeps contact at the present preload"
    elif speeds[0] > 0.0 and math.isinf(speeds[1]):
        fix += f" or run the cam at ≥ {math.ceil(speeds[0] * 10.0 - 1e-9) / 10.0:.1f} rpm"
    elif speeds[0] > 0.0:
        fix += f" or run the cam between {speeds[0]:.1f} and {speeds[1]:.1f} rpm"
    else:
        fix += f" or keep the speed ≤ {math.floor(speeds[1] * 10.0 + 1e-9) / 10.0:.1f} rpm"
    return f"{head} at {omega * _RAD_S_TO_RPM:g} rpm: {fix}"


@dataclass(frozen=True, slots=True)
class _Pointwise:
    """The dynamic model evaluated at some cam angles: every array (n,)."""

    force: FloatArray  # contact force [N]
    torque: FloatArray  # drive torque [N·mm]
    stress: FloatArray  # Hertz stress [MPa]
    ratio: FloatArray  # c in C = F/c [1]
    inertia: FloatArray  # A [N·s²]: inertia force per ω²
    static: FloatArray  # B [N]: m·g + k·s + F0
    near: FloatArray | None = None  # guide forces N2, N3 [N] (guided tappet)
    far: FloatArray | None = None


def _model(design: Design) -> Callable[[Motion, FloatArray, FloatArray], _Pointwise]:
    """The design's dynamic model as a pointwise function of (motion, pressure angle α, profile ρ)."""
    dyn = design.dynamics
    spring = spring_from_spec(dyn)
    load = FollowerLoad(mass=dyn.follower_mass, spring=spring, gravity=dyn.gravity)
    omega = design.cam.omega
    roller = design.follower.roller_radius
    if design.follower.kind is not FollowerKind.TRANSLATING_ROLLER:
        roller = 0.0
    modulus = effective_modulus(
        modulus_1=dyn.cam_modulus,
        poisson_1=dyn.cam_poisson,
        modulus_2=dyn.follower_modulus,
        poisson_2=dyn.follower_poisson,
    )
    length = dyn.contact_width if dyn.contact_width is not None else design.cam.thickness
    tappet = None
    if dyn.model is DynamicsModel.GUIDED_TAPPET:
        tappet = GuidedTappet(
            base_radius=design.cam.base_radius,
            a_m=dyn.a_m,
            b_m=dyn.b_m,
            f1=dyn.f1,
            f2=dyn.f2,
            f3=dyn.f3,
            # a cw cam is the mirror image of a ccw cam with the follower at −e
            offset=design.follower.offset * (1.0 if design.cam.rotation is Rotation.CCW else -1.0),
        )

    def evaluate(motion: Motion, alpha: FloatArray, rho: FloatArray) -> _Pointwise:
        near = far = None
        if tappet is not None:
            forces = tappet_forces(motion, load=load, omega=omega, tappet=tappet)
            force = forces.normal_force
            near, far = forces.guide_force_near, forces.guide_force_far
            torque = forces.torque + dyn.friction_torque
            ratio = forces.load_ratio
        else:
            axial = load.axial_force(motion, omega=omega)
            force = contact_force(axial, alpha)
            torque = input_torque(axial, motion.v, friction_torque=dyn.friction_torque)
            ratio = np.cos(alpha)
        stress = hertz_stress(
            force, curvature=contact_curvature(rho, roller_radius=roller), length=length, modulus=modulus
        )
        return _Pointwise(
            force=np.asarray(force, dtype=float),
            torque=np.asarray(torque, dtype=float),
            stress=np.asarray(stress, dtype=float),
            ratio=np.asarray(ratio, dtype=float),
            inertia=load.inertia_coefficient(motion),
            static=load.static_force(motion),
            near=near,
            far=far,
        )

    return evaluate


def analyse_dynamics(
    motion: Motion,
    *,
    pressure_angle: ArrayLike,
    profile_rho: ArrayLike,
    design: Design,
    cam: Cam | None = None,
) -> DynamicsResult:
    """Analyse contact force, drive torque, jump limits and Hertz stress over the cam turn.

    Parameters
    ----------
    motion
        (n,) samples of the follower motion: ``phi`` [rad], ``s`` [mm],
        ``v`` [mm/rad], ``a`` [mm/rad²].
    pressure_angle
        (n,) pressure angle α [rad] at the same angles (0 for a flat face).
    profile_rho
        (n,) signed radius of curvature of the cam profile at the contact
        [mm]: positive convex, negative concave.
    design
        Uses ``cam.omega`` [rad/s], ``cam.base_radius`` and ``cam.thickness``
        [mm], ``follower`` (kind, roller radius, offset) and ``dynamics``.
    cam
        The exact cam. With it every reported extreme (forces, torque,
        stress, the jump verdict, the preload and speed limits) is the true
        one over the turn: both one-sided limits at every joint are evaluated
        and every sampled extremum is refined on the exact functions
        (:func:`camcad.extremes.extremes`). Without it they are those of the
        samples.

    Returns
    -------
    DynamicsResult
        Per-sample arrays, true extremes, jump limits and warnings.

    Raises
    ------
    ValueError
        If the arrays do not match the motion's length.

    Notes
    -----
    ``[dynamics].model = "energy"``: Quintero & Vanegas (2016), eqs. 15-19;
    ``"guided-tappet"``: Hren et al., eqs. 13-29. The shaft friction
    torque ``friction_torque`` is added to the torque of either model. The
    contact stress is the Hertz line contact (Johnson 1985, eq. 4.45) over
    ``contact_width`` (default: the cam thickness).
    """
    n = np.asarray(motion.phi).size
    alpha = _array("pressure_angle", pressure_angle, n)
    rho = _array("profile_rho", profile_rho, n)
    dyn = design.dynamics
    omega = design.cam.omega
    model = _model(design)
    sampled = model(motion, alpha, rho)
    phi = np.array(motion.phi, dtype=float)
    margin = dyn.min_contact_force
    spring_preload = spring_from_spec(dyn).preload

    def exact(quantity: Callable[[_Pointwise], FloatArray]) -> Quantity:
        assert cam is not None

        def q(p: FloatArray, side: Side) -> FloatArray:
            m = cam.motion(p, side=side)
            return quantity(model(m, cam.pressure_angle(p, side=side), cam.profile(p, side=side).rho))

        return q

    def find(quantity: Callable[[_Pointwise], FloatArray], *kinds: Kind) -> tuple[Extreme, ...]:
        values = quantity(sampled)
        if cam is None:
            return tuple(_sampled_extreme(phi, values, kind) for kind in kinds)
        joints = [bp.phi for bp in cam.program.breakpoints]
        return extremes(exact(quantity), phi, joints, values=values, find=kinds)

    force_min, force_max = find(lambda r: r.force, "min", "max")
    torque_min, torque_max = find(lambda r: r.torque, "min", "max")
    (stress_max,) = find(lambda r: r.stress, "max")
    # F0* = max(margin·c − A·ω² − (B − F0)) (camcad.dynamics.jump.min_preload, at the true maximum)
    (need,) = find(lambda r: margin * r.ratio - r.inertia * omega**2 - (r.static - spring_preload), "max")
    preload = max(0.0, need.value)
    deflection = preload / _rate(dyn) if dyn.uses_coil_spring and _rate(dyn) > 0.0 else None
    speeds = _speed_range(find, margin)

    warnings: list[str] = []
    if sampled.near is not None and sampled.far is not None:
        for name, guide, f in (("N2", sampled.near, dyn.f2), ("N3", sampled.far, dyn.f3)):
            # eq. 25 keeps the guide sides of Fig. 2; where N < 0 its friction points the
            # wrong way, an error of 2·f·|N| along the axis: flag it above 1 % of N1.
            misdirected = (guide < 0.0) & (2.0 * f * np.abs(guide) > _GUIDE_FLIP_RTOL * np.abs(sampled.force))
            flipped = loss_runs(motion.phi, misdirected)
            if flipped:
                arc = covering_arc(flipped)
                assert arc is not None
                warnings.append(
                    f"guide force {name} changes side {_arc_text(arc)}: Hren et al. eq. 25 "
                    "assumes the guide contacts of its Fig. 2, so the guide friction there "
                    "is approximate"
                )

    runs = loss_runs(motion.phi, sampled.force < margin)
    if not runs and force_min.value < margin:  # lost only between samples or just before/after a joint
        runs = ((force_min.phi % TWO_PI, force_min.phi % TWO_PI),)
    findings: list[Finding] = []
    if runs:
        message = _jump_warning(
            runs=runs,
            margin=margin,
            omega=omega,
            preload=preload,
            deflection=deflection,
            speeds=speeds,
            worst=force_min,
        )
        warnings.insert(0, message)
        findings.append(
            Finding(
                kind="jump",
                severity=Severity.SOFT,
                field="dynamics.spring_preload",
                message=message,
                angle=force_min.phi,
                value=force_min.value,
                limit=margin,
                unit="N",
            )
        )
    if dyn.allowable_stress is not None and stress_max.value > dyn.allowable_stress:
        message = (
            f"Hertz contact stress reaches {stress_max.value:.1f} MPa {stress_max.where()}, above the "
            f"allowable {dyn.allowable_stress:g} MPa: widen the contact, enlarge the roller or the "
            "base circle, or lower the spring load"
        )
        warnings.append(message)
        findings.append(
            Finding(
                kind="contact stress",
                severity=Severity.SOFT,
                field="dynamics.allowable_stress",
                message=message,
                angle=stress_max.phi,
                value=stress_max.value,
                limit=dyn.allowable_stress,
                unit="MPa",
            )
        )
    torque = np.asarray(sampled.torque, dtype=float)
    readonly(phi, torque)
    return DynamicsResult(
        model=dyn.model,
        phi=phi,
        contact_force=sampled.force,
        torque=torque,
        hertz_stress=sampled.stress,
        normal_force=sampled.force if sampled.near is not None else None,
        guide_force_near=sampled.near,
        guide_force_far=sampled.far,
        margin=margin,
        jump_ranges=runs,
        min_preload=preload,
        preload_deflection=deflection,
        speed_range_rpm=speeds,
        allowable_stress=dyn.allowable_stress,
        warnings=tuple(warnings),
        findings=tuple(findings),
        contact_force_min=force_min,
        contact_force_max=force_max,
        torque_min=torque_min,
        torque_max=torque_max,
        hertz_stress_max=stress_max,
    )


def _rate(dyn: DynamicsSpec) -> float:
    return spring_from_spec(dyn).rate


def _sampled_extreme(phi: FloatArray, values: FloatArray, kind: Kind) -> Extreme:
    """The extreme of the samples alone (when no exact cam is given)."""
    i = int(np.argmax(values) if kind == "max" else np.argmin(values))
    return Extreme(value=float(values[i]), phi=float(phi[i]))


def _speed_range(find: Callable[..., tuple[Extreme, ...]], margin: float) -> tuple[float, float] | None:
    """(low, high) cam speeds [rpm] keeping C ≥ margin, from true extremes (jump.speed_limits' closed form).

    Each angle bounds ω² by (margin·c − B)/A: from above where A < 0, from
    below where A > 0; where A = 0 it needs B ≥ margin·c.
    """

    def bound(r: _Pointwise, sign: float) -> FloatArray:
        need = margin * r.ratio - r.static
        with np.errstate(divide="ignore", invalid="ignore"):
            out = need / r.inertia
        return np.where(sign * r.inertia > 0.0, out, -sign * np.inf)

    (flat_need,) = find(lambda r: np.where(r.inertia == 0.0, margin * r.ratio - r.static, -np.inf), "max")
    if flat_need.value > 0.0:
        return None
    (upper,) = find(lambda r: bound(r, -1.0), "min")  # ω² ≤ min over A < 0
    (lower,) = find(lambda r: bound(r, 1.0), "max")  # ω² ≥ max over A > 0
    window = speed_window(max(lower.value, 0.0), upper.value)
    return None if window is None else (window[0] * _RAD_S_TO_RPM, window[1] * _RAD_S_TO_RPM)
