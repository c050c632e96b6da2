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
from camcad.dynamics.arm import ArmLoad, arm_speed
from camcad.dynamics.contact import driving_curvature, effective_modulus, hertz_stress
from camcad.dynamics.energy import FollowerLoad, contact_force, input_torque
from camcad.dynamics.flight import impact_speed
from camcad.dynamics.jump import covering_arc, loss_runs, preload_need, speed_bounds, speed_window
from camcad.dynamics.results import FLANK_WORDS, DynamicsResult
from camcad.dynamics.spec import DynamicsModel, DynamicsSetup, DynamicsSpec
from camcad.dynamics.spring import spring_from_spec
from camcad.dynamics.tappet import GuidedTappet, tappet_forces
from camcad.extremes import Extreme, Kind, Side, extremes_rows
from camcad.findings import Finding, Severity
from camcad.knobs import Knob
from camcad.roots import brent_roots

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam
    from camcad.motion.program import Motion

__all__ = ["DynamicsRows", "analyse_dynamics", "contact_stress_at", "dynamics_rows", "extreme_rows"]

_RAD_S_TO_RPM = 60.0 / (2.0 * math.pi)
# the extremes analyse_dynamics reports, one per row of its quantity
_KINDS: tuple[Kind, ...] = ("min", "max", "min", "max", "max", "max", "max", "min", "max")
# a groove's further extremes: the load and the stress on each flank where it drives (inner, outer)
_FLANK_KINDS: tuple[Kind, ...] = ("max", "max", "max", "max")
_SPEED_BOUND_ROWS = (6, 7, 8)  # flat, upper, lower of speed_bounds (see _reported)
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
    torsional: bool,
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
    unit = "N·mm" if torsional else "N"
    fix = f"raise the preload to ≥ {math.ceil(preload * 10.0 - 1e-9) / 10.0:.1f} {unit}"
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


_Model = Callable[["Motion", FloatArray, FloatArray, "FloatArray | None"], _Pointwise]


def _arm_load(setup: DynamicsSetup) -> ArmLoad:
    """An oscillating follower's load: torsion spring, or a linear spring at ``spring_arm``."""
    dyn = setup.spec
    assert setup.arm_angle is not None
    if dyn.spring_arm is not None:
        rate, preload = dyn.spring_rate * dyn.spring_arm**2, dyn.spring_preload * dyn.spring_arm
    else:
        rate, preload = dyn.spring_rate_torsional, dyn.spring_preload_torsional
    return ArmLoad(
        inertia=dyn.arm_inertia,
        spring_rate=rate,
        preload=preload,
        mass=dyn.follower_mass if dyn.gravity else 0.0,
        cg_distance=dyn.cg_distance,
        arm_angle=setup.arm_angle,
    )


def _preload(setup: DynamicsSetup) -> float:
    """The spring's preload in the model's generalised force: N on a slide, N·mm about an arm's pivot."""
    if setup.arm_angle is None:
        return spring_from_spec(setup.spec).preload
    return _arm_load(setup).preload


def _load(setup: DynamicsSetup) -> FollowerLoad | ArmLoad:
    """What the follower carries: its inertia, spring and weight (about the pivot on an arm)."""
    dyn = setup.spec
    if setup.arm_angle is None:
        return FollowerLoad(mass=dyn.follower_mass, spring=spring_from_spec(dyn), gravity=dyn.gravity)
    return _arm_load(setup)


def _model(setup: DynamicsSetup) -> _Model:
    """The design's dynamic model as a pointwise function of (motion, α, profile ρ, lever r).

    ``lever`` is the distance from an oscillating follower's pivot to the
    driven point [mm] (None for a slide): the contact force is the generalised
    force over c = cos α (slide) or c = r·cos α (arm, :mod:`camcad.dynamics.arm`).
    """
    dyn = setup.spec
    load = _load(setup)
    omega = setup.omega
    roller = setup.roller_radius
    modulus = effective_modulus(
        modulus_1=dyn.cam_modulus,
        poisson_1=dyn.cam_poisson,
        modulus_2=dyn.follower_modulus,
        poisson_2=dyn.follower_poisson,
    )
    length = setup.contact_length
    flanks = setup.flank_offsets
    tappet = None
    if dyn.model is DynamicsModel.GUIDED_TAPPET:
        tappet = GuidedTappet(
            base_radius=setup.base_radius,
            a_m=dyn.a_m,
            b_m=dyn.b_m,
            f1=dyn.f1,
            f2=dyn.f2,
            f3=dyn.f3,
            offset=setup.tappet_offset,
        )

    def evaluate(motion: Motion, alpha: FloatArray, rho: FloatArray, lever: FloatArray | None) -> _Pointwise:
        near = far = None
        if lever is not None:  # an arm: moments about the pivot
            moment = setup.drive_sign * load.axial_force(motion, omega=omega)
            ratio = lever * np.cos(alpha)
            force = moment / ratio
            torque = moment * setup.drive_sign * arm_speed(motion) + dyn.friction_torque
        elif tappet is not None:
            forces = tappet_forces(motion, load=load, omega=omega, tappet=tappet)
            force = forces.normal_force
            near, far = forces.guide_force_near, forces.guide_force_far
            torque = forces.torque + dyn.friction_torque
            ratio = forces.load_ratio
        else:
            axial = setup.drive_sign * load.axial_force(motion, omega=omega)
            force = contact_force(axial, alpha)
            torque = input_torque(axial, setup.drive_sign * motion.v, friction_torque=dyn.friction_torque)
            ratio = np.cos(alpha)
        # a groove: the flank that drives, the inner one where F ≥ 0, the outer one where F < 0
        curvature = driving_curvature(rho, force, roller_radius=roller, flank_offsets=flanks)
        force = np.asarray(force, dtype=float)
        pressing = force if flanks is None else np.abs(force)
        stress = hertz_stress(pressing, curvature=curvature, length=length, modulus=modulus)
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


def contact_stress_at(
    motion: Motion,
    *,
    pressure_angle: ArrayLike,
    profile_rho: ArrayLike,
    setup: DynamicsSetup,
    lever: ArrayLike | None = None,
    roller_radius: ArrayLike | None = None,
) -> FloatArray:
    """The Hertz contact stress [MPa] of the design's dynamic model at the given samples alone.

    What :func:`analyse_dynamics` computes at each sample (same model, same
    load), without its extremes and findings: for a made cam whose motion,
    pressure angle and profile radius differ from the design's (camcad's
    tolerance study). ``roller_radius`` (n,) [mm] is each sample's own roller
    (a made roller), None for the design's; the relative curvature is then
    1/ρ + 1/r_f with that r_f (Johnson 1985, §4.3). A groove's flanks are not
    supported (ValueError).
    """
    if setup.flank_offsets is not None:
        raise ValueError("the contact stress of single samples is for a plate's one flank, not a groove")
    rho = np.asarray(profile_rho, dtype=float)
    if roller_radius is not None and setup.roller_radius:
        # the model adds 1/r_f of the design: hand it the ρ with 1/ρ' = 1/ρ + 1/r_made − 1/r_f
        with np.errstate(divide="ignore", invalid="ignore"):
            rho = 1.0 / (1.0 / rho + 1.0 / np.asarray(roller_radius, dtype=float) - 1.0 / setup.roller_radius)
    n = np.asarray(motion.phi).size
    alpha = _array("pressure_angle", pressure_angle, n)
    lev = None if lever is None else _array("lever", lever, n)
    out: FloatArray = np.asarray(_model(setup)(motion, alpha, _array("profile_rho", rho, n), lev).stress)
    return out


def analyse_dynamics(
    motion: Motion,
    *,
    pressure_angle: ArrayLike,
    profile_rho: ArrayLike,
    setup: DynamicsSetup,
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
    setup
        The ``[dynamics]`` table with the cam speed and contact geometry
        (``Design.dynamics_setup()`` builds it from a design).
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
        Per-sample arrays, true extremes, jump limits and findings (notes included).

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
    dyn = setup.spec
    omega = setup.omega
    model = _model(setup)
    lever = None
    if setup.arm_angle is not None:
        if cam is None:
            raise ValueError("an oscillating follower's dynamics needs the cam (for the pivot's lever)")
        lever = cam.state(motion.phi).lever
    sampled = model(motion, alpha, rho, lever)
    phi = np.array(motion.phi, dtype=float)
    margin = dyn.min_contact_force
    spring_preload = _preload(setup)

    grooved = setup.flank_offsets is not None
    found = _extremes(
        model,
        sampled,
        phi,
        cam,
        margin=margin,
        omega=omega,
        preload=spring_preload,
        flanks=grooved,
        unloaded=_load(setup).unloaded,
    )
    force_min, force_max, torque_min, torque_max, stress_max, need, flat_need, upper, lower = found[:9]
    flank_force = flank_stress = None
    stress_flank = None
    if grooved:
        flank_force, flank_stress = (found[9], found[10]), (found[11], found[12])
        stress_flank = FLANK_WORDS[0 if flank_stress[0].value >= flank_stress[1].value else 1]
    preload = max(0.0, need.value)
    if setup.arm_angle is not None and dyn.spring_arm is not None:
        preload /= dyn.spring_arm  # the linear spring's force at its lever [N]
    deflection = preload / _rate(dyn) if dyn.uses_coil_spring and _rate(dyn) > 0.0 else None
    speeds = None
    if flat_need.value <= 0.0:
        window = speed_window(max(lower.value, 0.0), upper.value)
        speeds = None if window is None else (window[0] * _RAD_S_TO_RPM, window[1] * _RAD_S_TO_RPM)

    notes = _guide_notes(phi, sampled, dyn)
    runs = loss_runs(motion.phi, sampled.force < margin)
    if not runs and force_min.value < margin:  # lost only between samples or just before/after a joint
        runs = ((force_min.phi % TWO_PI, force_min.phi % TWO_PI),)
    crossovers: tuple[float, ...] = ()
    impacts: tuple[float, ...] = ()
    if setup.positive_drive:  # the other flank takes over: crossovers, not jumps
        runs = ()
        crossovers, impacts = _crossovers(model, phi, sampled.force, cam, setup)
    findings = _findings(
        dyn,
        torsional=setup.arm_angle is not None and dyn.spring_arm is None,
        runs=runs,
        omega=omega,
        preload=preload,
        deflection=deflection,
        speeds=speeds,
        force_min=force_min,
        stress_max=stress_max,
        stress_flank=stress_flank,
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
        preload_unit="N·mm" if setup.arm_angle is not None and dyn.spring_arm is None else "N",
        preload_deflection=deflection,
        speed_range_rpm=speeds,
        allowable_stress=dyn.allowable_stress,
        findings=(*findings, *notes),
        contact_force_min=force_min,
        contact_force_max=force_max,
        torque_min=torque_min,
        torque_max=torque_max,
        hertz_stress_max=stress_max,
        crossovers=crossovers,
        impact_speeds=impacts,
        positive_drive=setup.positive_drive,
        flank_force_max=flank_force,
        flank_stress_max=flank_stress,
    )


def _crossovers(
    model: _Model, phi: FloatArray, force: FloatArray, cam: Cam | None, setup: DynamicsSetup
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Where a positively driven follower's contact force changes sign, and the impact speed there.

    Samples where the force vanishes (a rest: no spring holds a positively
    driven follower, so a dwell loads neither flank) are passed over: the
    driving flank changes only where the force on the two sides of a zero
    stretch has opposite signs. A change between neighbouring samples is
    refined by Brent's method on the exact model (when the cam is given); one
    across a rest is placed where the rest ends, at the joint where the new
    flank starts to drive. From a crossover the follower flies free across
    the clearance c under its own inertia, spring and weight until it meets a
    flank; the impact speed is its normal approach speed then
    (:func:`camcad.dynamics.flight.impact_speed`, Norton 2009, §8.11
    "crossover shock").
    """
    scale = float(np.max(np.abs(force), initial=0.0))
    live = np.flatnonzero(np.abs(force) > 1e-9 * scale)
    if live.size < 2:
        return (), ()
    sign = force[live] > 0.0
    joints = np.sort(np.asarray([bp.phi for bp in cam.program.breakpoints])) if cam is not None else None
    changes = np.flatnonzero(sign != np.roll(sign, -1))
    roots: list[float] = []
    brackets: list[tuple[int, float, float]] = []  # (which change, a, b) to refine on the exact model
    for at, k in enumerate(changes):
        i, n = int(live[k]), int(live[(k + 1) % live.size])
        a, b = float(phi[i]), float(phi[n])
        if b <= a:
            b += TWO_PI
        roots.append(0.5 * (a + b))
        rest = []  # the joints between the last sample of one sign and the first of the other
        if joints is not None and (n - i) % phi.size > 1:
            rest = [q for q in np.concatenate((joints, joints + TWO_PI)) if a < q <= b]
        if rest:  # across a rest: the new flank drives from the joint where the rest ends
            roots[at] = float(max(rest))
        elif cam is not None:
            brackets.append((at, a, b))
    if brackets and cam is not None:
        exact = cam

        def f(p: FloatArray) -> FloatArray:
            st = exact.state(p)
            return model(st.motion, st.pressure_angle, st.profile.rho, st.lever).force

        which = [at for at, _, _ in brackets]
        a_s = np.array([a for _, a, _ in brackets])
        b_s = np.array([b for _, _, b in brackets])
        ends = f(np.concatenate((a_s, b_s)))  # both ends of every bracket in one evaluation
        fa, fb = ends[: a_s.size], ends[a_s.size :]
        crossed = fa * fb < 0.0  # else the midpoint stays
        if crossed.any():
            refined = brent_roots(f, a_s[crossed], b_s[crossed], fa=fa[crossed], fb=fb[crossed], xtol=1e-12)
            for at, root in zip(np.asarray(which)[crossed].tolist(), refined.tolist(), strict=True):
                roots[at] = root
    found: list[float] = []
    speeds: list[float] = []
    for at, k in enumerate(changes):
        root = roots[at] % TWO_PI
        found.append(root)
        if cam is not None and setup.clearance > 0.0:
            leaving = 1.0 if sign[k] else -1.0  # the flank it leaves drove it forwards (F > 0) or back
            speeds.append(
                impact_speed(
                    cam,
                    root,
                    load=_load(setup),
                    omega=setup.omega,
                    clearance=setup.clearance,
                    leaving=leaving,
                )
            )
    return tuple(found), tuple(speeds)


def _extremes(
    model: _Model,
    sampled: _Pointwise,
    phi: FloatArray,
    cam: Cam | None,
    *,
    margin: float,
    omega: float,
    preload: float,
    flanks: bool = False,
    unloaded: bool = False,
) -> tuple[Extreme, ...]:
    """The true extremes of every reported quantity (``_KINDS``, then a groove's ``_FLANK_KINDS``).

    Without a cam, the samples' extremes. ``unloaded``: no spring and no
    weight load the follower (B ≡ 0, a positively driven one, say); with a
    zero margin the need margin·c − B of the speed bounds is then 0 wherever
    it applies and ±inf elsewhere, so their sampled extremes are exact.
    """
    kinds = _KINDS + _FLANK_KINDS if flanks else _KINDS

    def rows(r: _Pointwise) -> FloatArray:
        return _rows_of(r, margin=margin, omega=omega, preload=preload, flanks=flanks)

    values = rows(sampled)
    if cam is None:
        return tuple(_sampled_extreme(phi, row, kind) for row, kind in zip(values, kinds, strict=True))
    exact = cam

    def quantity(p: FloatArray, side: Side) -> FloatArray:
        st = exact.state(p, side=side)
        return rows(model(st.motion, st.pressure_angle, st.profile.rho, st.lever))

    joints = [bp.phi for bp in cam.program.breakpoints]
    settled = [unloaded and margin == 0.0 and k in _SPEED_BOUND_ROWS for k in range(len(kinds))]
    return extremes_rows(quantity, phi, joints, kinds, values=values, rests=cam.rests, settled=settled)


def _rows_of(r: _Pointwise, *, margin: float, omega: float, preload: float, flanks: bool) -> FloatArray:
    """The rows whose extremes :func:`analyse_dynamics` reports (``_KINDS``, a groove's ``_FLANK_KINDS``)."""
    out = _reported(r, margin=margin, omega=omega, preload=preload)
    if flanks:  # load and stress of the flank that drives: the inner one where F > 0
        inner = r.force > 0.0
        on_inner, on_outer = np.where(inner, r.stress, 0.0), np.where(inner, 0.0, r.stress)
        out = np.vstack((out, np.maximum(r.force, 0.0), np.maximum(-r.force, 0.0), on_inner, on_outer))
    return out


DynamicsRows = Callable[["Motion", FloatArray, FloatArray, "FloatArray | None"], FloatArray]
"""(motion, α [rad], profile ρ [mm], lever [mm] or None) at n angles → (k, n) rows."""


def extreme_rows(setup: DynamicsSetup) -> tuple[tuple[Kind, ...], tuple[bool, ...], DynamicsRows]:
    """What :func:`analyse_dynamics` refines with an exact cam: each row's kind, its settled flag, the rows.

    The rows are the same function of the model's pointwise inputs as in
    :func:`analyse_dynamics` (contact force, torque, stress, the preload
    need and the speed bounds; a groove's flank loads and stresses), so a
    batch of design variants (:mod:`camcad.explore.batch`) can search their
    extremes together and hand each analysis its own
    (:func:`camcad.extremes.served`).
    """
    margin = setup.spec.min_contact_force
    kinds = _KINDS + _FLANK_KINDS if setup.flank_offsets is not None else _KINDS
    unloaded = _load(setup).unloaded
    settled = tuple(unloaded and margin == 0.0 and k in _SPEED_BOUND_ROWS for k in range(len(kinds)))
    return kinds, settled, dynamics_rows(setup)


def dynamics_rows(setup: DynamicsSetup) -> DynamicsRows:
    """The rows of :func:`extreme_rows` alone (no kinds, no settled flags); see there."""
    model = _model(setup)
    margin, omega, preload = setup.spec.min_contact_force, setup.omega, _preload(setup)
    flanks = setup.flank_offsets is not None

    def rows(motion: Motion, alpha: FloatArray, rho: FloatArray, lever: FloatArray | None) -> FloatArray:
        r = model(motion, alpha, rho, lever)
        return _rows_of(r, margin=margin, omega=omega, preload=preload, flanks=flanks)

    return rows


def _findings(
    dyn: DynamicsSpec,
    *,
    torsional: bool,
    runs: tuple[tuple[float, float], ...],
    omega: float,
    preload: float,
    deflection: float | None,
    speeds: tuple[float, float] | None,
    force_min: Extreme,
    stress_max: Extreme,
    stress_flank: str | None = None,
) -> list[Finding]:
    """The soft limits the dynamics breaks: follower jump (with its remedies) and Hertz stress."""
    margin = dyn.min_contact_force
    findings: list[Finding] = []
    if runs:
        message = _jump_warning(
            torsional=torsional,
            runs=runs,
            margin=margin,
            omega=omega,
            preload=preload,
            deflection=deflection,
            speeds=speeds,
            worst=force_min,
        )
        field = Knob.SPRING_PRELOAD_TORSIONAL if torsional else Knob.SPRING_PRELOAD
        findings.append(_limit("jump", field, message, force_min, margin, "N"))
    if dyn.allowable_stress is not None and stress_max.value > dyn.allowable_stress:
        on = "" if stress_flank is None else f" on the {stress_flank} flank"
        message = (
            f"Hertz contact stress reaches {stress_max.value:.1f} MPa {stress_max.where()}{on}, above the "
            f"allowable {dyn.allowable_stress:g} MPa: widen the contact, enlarge the roller or the "
            "base circle, or lower the spring load"
        )
        findings.append(
            _limit(
                "contact stress",
                Knob.ALLOWABLE_STRESS,
                message,
                stress_max,
                dyn.allowable_stress,
                "MPa",
            )
        )
    return findings


def _reported(r: _Pointwise, *, margin: float, omega: float, preload: float) -> FloatArray:
    """Every quantity whose extreme analyse_dynamics reports, one row each (kinds in ``_KINDS``).

    Contact force (min, max), torque (min, max), Hertz stress (max); the
    preload need F0* = max(margin·c − A·ω² − (B − F0)) (jump.min_preload); and
    the three speed bounds of jump.speed_limits: where A = 0 the need
    margin·c − B must be ≤ 0, ω² ≤ (margin·c − B)/A where A < 0 (its min),
    ω² ≥ (margin·c − B)/A where A > 0 (its max).
    """
    need = preload_need(
        inertia=r.inertia,
        static_without_preload=r.static - preload,
        ratio=r.ratio,
        omega=omega,
        margin=margin,
    )
    flat, upper, lower = speed_bounds(inertia=r.inertia, static=r.static, ratio=r.ratio, margin=margin)
    return np.vstack((r.force, r.force, r.torque, r.torque, r.stress, need, flat, upper, lower))


def _guide_notes(phi: FloatArray, sampled: _Pointwise, dyn: DynamicsSpec) -> list[Finding]:
    """Notes where the guided tappet's guide forces change side (eq. 25's friction is then approximate)."""
    notes: list[Finding] = []
    if sampled.near is None or sampled.far is None:
        return notes
    for name, guide, f in (("N2", sampled.near, dyn.f2), ("N3", sampled.far, dyn.f3)):
        # eq. 25 keeps the guide sides of Fig. 2; where N < 0 its friction points the
        # wrong way, an error of 2·f·|N| along the axis: flag it above 1 % of N1.
        misdirected = (guide < 0.0) & (2.0 * f * np.abs(guide) > _GUIDE_FLIP_RTOL * np.abs(sampled.force))
        flipped = loss_runs(phi, misdirected)
        if flipped:
            arc = covering_arc(flipped)
            assert arc is not None
            message = (
                f"guide force {name} changes side {_arc_text(arc)}: Hren et al. eq. 25 "
                "assumes the guide contacts of its Fig. 2, so the guide friction there "
                "is approximate"
            )
            notes.append(
                Finding(
                    kind="guide force side",
                    severity=Severity.NOTE,
                    field=Knob.DYNAMICS_MODEL,
                    message=message,
                    angle=arc[0],
                )
            )
    return notes


def _limit(kind: str, field: str, message: str, worst: Extreme, limit: float, unit: str) -> Finding:
    """A soft finding of the dynamics (follower jump, contact stress)."""
    return Finding(
        kind=kind,
        severity=Severity.SOFT,
        field=field,
        message=message,
        angle=worst.phi,
        value=worst.value,
        limit=limit,
        unit=unit,
    )


def _rate(dyn: DynamicsSpec) -> float:
    return spring_from_spec(dyn).rate


def _sampled_extreme(phi: FloatArray, values: FloatArray, kind: Kind) -> Extreme:
    """The extreme of the samples alone (when no exact cam is given)."""
    i = int(np.argmax(values) if kind == "max" else np.argmin(values))
    return Extreme(value=float(values[i]), phi=float(phi[i]))
