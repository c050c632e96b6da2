"""One entry point: run the dynamic model a design asks for.

:func:`analyse_dynamics` takes the follower motion and two geometric arrays
(pressure angle, profile curvature radius) from the earlier stages, so it does
not depend on how the geometry was computed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.design import DynamicsModel, FollowerKind
from camcad.dynamics.contact import contact_curvature, effective_modulus, hertz_stress
from camcad.dynamics.energy import FollowerLoad, contact_force, input_torque
from camcad.dynamics.jump import covering_arc, loss_runs, min_preload, speed_limits
from camcad.dynamics.results import DynamicsResult
from camcad.dynamics.spring import spring_from_spec
from camcad.dynamics.tappet import GuidedTappet, tappet_forces

if TYPE_CHECKING:
    from camcad.design import Design
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
) -> str:
    arc = covering_arc(runs)
    assert arc is not None
    if margin > 0.0:
        head = f"contact force falls below min_contact_force = {margin:g} N {_arc_text(arc)}"
    else:
        head = f"follower jumps {_arc_text(arc)}"
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


def analyse_dynamics(
    motion: Motion, *, pressure_angle: ArrayLike, profile_rho: ArrayLike, design: Design
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

    Returns
    -------
    DynamicsResult
        Per-sample arrays, jump limits and warnings.

    Raises
    ------
    ValueError
        If the arrays do not match the motion's length.
    DesignLimitError
        If the guided tappet self-locks in its guides.

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
    spring = spring_from_spec(dyn)
    load = FollowerLoad(mass=dyn.follower_mass, spring=spring, gravity=dyn.gravity)
    omega = design.cam.omega
    warnings: list[str] = []
    near = far = normal = None
    if dyn.model is DynamicsModel.GUIDED_TAPPET:
        tappet = GuidedTappet(
            base_radius=design.cam.base_radius,
            a_m=dyn.a_m,
            b_m=dyn.b_m,
            f1=dyn.f1,
            f2=dyn.f2,
            f3=dyn.f3,
            offset=design.follower.offset,
        )
        forces = tappet_forces(motion, load=load, omega=omega, tappet=tappet)
        force = normal = forces.normal_force
        near, far = forces.guide_force_near, forces.guide_force_far
        torque = forces.torque + dyn.friction_torque
        ratio = forces.load_ratio
        for name, guide, f in (("N2", near, dyn.f2), ("N3", far, dyn.f3)):
            # eq. 25 keeps the guide sides of Fig. 2; where N < 0 its friction points the
            # wrong way, an error of 2·f·|N| along the axis: flag it above 1 % of N1.
            misdirected = (guide < 0.0) & (2.0 * f * np.abs(guide) > _GUIDE_FLIP_RTOL * np.abs(force))
            flipped = loss_runs(motion.phi, misdirected)
            if flipped:
                arc = covering_arc(flipped)
                assert arc is not None
                warnings.append(
                    f"guide force {name} changes side {_arc_text(arc)}: Hren et al. eq. 25 "
                    "assumes the guide contacts of its Fig. 2, so the guide friction there "
                    "is approximate"
                )
    else:
        axial = load.axial_force(motion, omega=omega)
        force = contact_force(axial, alpha)
        torque = input_torque(axial, motion.v, friction_torque=dyn.friction_torque)
        ratio = np.cos(alpha)

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
    stress = hertz_stress(
        force,
        curvature=contact_curvature(rho, roller_radius=roller),
        length=length,
        modulus=modulus,
    )

    margin = dyn.min_contact_force
    inertia = load.inertia_coefficient(motion)
    static = load.static_force(motion)
    runs = loss_runs(motion.phi, force < margin)
    preload = min_preload(
        inertia=inertia,
        static_without_preload=static - spring.preload,
        ratio=ratio,
        omega=omega,
        margin=margin,
    )
    deflection = preload / spring.rate if dyn.uses_coil_spring and spring.rate > 0.0 else None
    limits = speed_limits(inertia=inertia, static=static, ratio=ratio, margin=margin)
    speeds = None
    if limits is not None:
        speeds = (limits[0] * _RAD_S_TO_RPM, limits[1] * _RAD_S_TO_RPM)
    if runs:
        warnings.insert(
            0,
            _jump_warning(
                runs=runs,
                margin=margin,
                omega=omega,
                preload=preload,
                deflection=deflection,
                speeds=speeds,
            ),
        )
    k = int(np.argmax(stress))
    if dyn.allowable_stress is not None and stress[k] > dyn.allowable_stress:
        warnings.append(
            f"Hertz contact stress reaches {stress[k]:.1f} MPa at "
            f"{math.degrees(float(motion.phi[k])) % 360.0:.1f}°, above the allowable "
            f"{dyn.allowable_stress:g} MPa: widen the contact, enlarge the roller or the "
            "base circle, or lower the spring load"
        )
    phi = np.array(motion.phi, dtype=float)
    torque = np.asarray(torque, dtype=float)
    readonly(phi, torque)
    return DynamicsResult(
        model=dyn.model,
        phi=phi,
        contact_force=force,
        torque=torque,
        hertz_stress=stress,
        normal_force=normal,
        guide_force_near=near,
        guide_force_far=far,
        margin=margin,
        jump_ranges=runs,
        min_preload=preload,
        preload_deflection=deflection,
        speed_range_rpm=speeds,
        allowable_stress=dyn.allowable_stress,
        warnings=tuple(warnings),
    )
