"""Checks across the fields of a design, each naming the field to change."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from camcad.design.rules import (
    BORE_HELIX_MIN_PITCH,
    MAX_HELIX_TURNS,
    MAX_LENGTH_MM,
    MAX_PASSES,
    MIN_LENGTH_MM,
    TOLERANCE_PER_BASE_RADIUS,
)
from camcad.design.spec import CamSpec, Design, Dialect
from camcad.dynamics.drive import DriveMode
from camcad.dynamics.spec import DynamicsModel
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families import FAMILIES, family_of
from camcad.geometry.followers import (
    FOLLOWER_TYPES,
    FollowerType,
)
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec
from camcad.toolpath.spec import Cutter, Machine


def _check_service(design: Design) -> None:
    """[drive] against the follower: a screw drives a slide, a rotary axis an arm."""
    drive = design.drive
    if drive is None or drive.mode is not DriveMode.SERVO_FOLLOWER:
        return
    if design.follower.kind.lift.angular and drive.screw_lead_mm is not None:
        raise DesignError(
            "drive.screw_lead_mm", "an oscillating follower is driven on its pivot (a rotary axis): no lead"
        )
    if not design.follower.kind.lift.angular and drive.screw_lead_mm is None:
        raise DesignError(
            "drive.screw_lead_mm",
            "is required for mode = 'servo-follower' on a translating follower (mm/rev)",
        )


def _check_vibration(design: Design) -> None:
    """``[vibration]`` (issue 34) against the follower, the drive, the speed and the laws (exit 2)."""
    vib = design.vibration
    if vib is None:
        return
    from camcad.dynamics.vibration import check_compensable, train_from_specs

    arm = design.follower.kind.lift.angular  # its train turns about the pivot
    wrong = "stiffness" if arm else "stiffness_torsional"
    if getattr(vib, wrong) is not None:
        right = "stiffness_torsional (N·mm/rad about the pivot)" if arm else "stiffness (N/mm)"
        raise DesignError(
            f"vibration.{wrong}", f"does not apply to a {design.follower.kind.word} follower; give {right}"
        )
    setup = design.dynamics_setup()
    train_from_specs(vib, design.dynamics, arm_angle=setup.arm_angle)  # required keys, masses, rates
    speed = design.cam.speed_rpm
    lo = vib.speed_min_rpm if vib.speed_min_rpm is not None else 0.5 * speed
    hi = vib.speed_max_rpm if vib.speed_max_rpm is not None else 1.5 * speed
    if not lo < hi:
        field = "speed_max_rpm" if vib.speed_max_rpm is not None else "speed_min_rpm"
        raise DesignError(
            f"vibration.{field}",
            f"the speed map's range {lo:g} to {hi:g} rpm is empty (the default range is 0.5 to 1.5 times "
            f"cam.speed_rpm = {speed:g}); allowed: speed_min_rpm < speed_max_rpm",
        )
    if vib.compensate_rpm is not None:
        if setup.positive_drive:
            raise DesignError(
                "vibration.compensate_rpm",
                f"a {design.cam.style.value} cam drives its follower both ways (no return spring to tune "
                "against); allowed: compensate_rpm on a spring-loaded plate cam only",
            )
        check_compensable(MotionProgram.from_segments(design.motion))


def _check_design(design: Design) -> None:
    """The checks across fields, each naming the field to change."""
    _check_follower(design)
    _check_style(design)
    _check_bore(design.cam)
    _check_dynamics(design)
    _check_tolerances(design)
    _check_gcode(design)
    _check_fea(design)
    _check_service(design)
    _check_vibration(design)


def _check_follower(design: Design) -> None:
    """A kind's required lengths > 0, then its module's own check (an arm's triangle and swing, …)."""
    fol = design.follower
    for name in fol.kind.required:
        value = fol.value(name)
        if value is not None and value <= 0:
            raise DesignError(
                f"follower.{name}",
                f"{value:g} must be > 0 for a {fol.kind.word} follower "
                f"(allowed: {MIN_LENGTH_MM:g} to {MAX_LENGTH_MM:g} mm)",
            )
    swing = max(_lift_profile(design.motion))  # the largest lift, in the kind's lift unit
    if design.barrel is not None:
        return  # a barrel's arm has its own checks (camcad.geometry.barrel_limits), not a plate's
    problem = fol.kind.check(fol, design.cam.base_radius, swing)
    if problem is not None:
        raise DesignError(*problem)


def _lift_profile(segments: tuple[SegmentSpec, ...]) -> list[float]:
    """The follower's position after each segment (lift units), starting at 0."""
    out, s = [0.0], 0.0
    for seg in segments:
        if seg.kind is SegmentKind.RISE:
            s += seg.lift
        elif seg.kind is SegmentKind.RETURN:
            s -= seg.lift
        elif seg.kind is SegmentKind.TABLE:
            out.append(float(getattr(seg.law, "peak", 0.0)))  # a point table's highest lift
        out.append(s)
    return out


def _check_style(design: Design) -> None:
    """The cam family's own checks (a groove's blank); positive drive needs a roller follower."""
    cam, fol = design.cam, design.follower
    family = family_of(cam.style)
    if family.needs_roller and not fol.kind.two_sided:
        raise DesignError("cam.style", f"a {family.name} cam needs a roller follower, not {fol.kind.word}")
    options = design.family_options()
    family.check(
        options, base_radius=cam.base_radius, roller_radius=fol.roller_radius, thickness=cam.thickness
    )
    if options.conjugate.single_plate:  # only a [conjugate] table sets it, and only a pair may have one
        _check_constant_breadth(design)
    family.check_cam(lambda: Cam.from_design(design), options)  # a pair's rollers must clear each other


def _check_constant_breadth(design: Design) -> None:
    """One plate for both rollers: a radial slide, rollers 180° apart, s(φ + 180°) = lift − s(φ)."""
    fol, conj = design.follower, design.conjugate
    if not fol.kind.radial_slide or fol.eccentricity != 0.0:
        raise DesignError(
            "conjugate.single_plate", "a constant-breadth cam needs a translating roller with offset 0"
        )
    if abs(conj.angle - math.pi) > 1e-12:
        raise DesignError("conjugate.angle", "a constant-breadth cam needs the rollers 180° apart")
    if conj.roller_radius is not None and conj.roller_radius != fol.roller_radius:
        raise DesignError(
            "conjugate.roller_radius", "a constant-breadth cam needs both rollers of the same radius"
        )
    program = MotionProgram.from_segments(design.motion)
    phi = np.union1d(program.sample_phi(math.radians(0.25)), [bp.phi for bp in program.breakpoints])
    phi = phi[phi < math.pi]
    lift = program.lift
    gap = program.evaluate(phi).s + program.evaluate(phi + math.pi).s - lift
    worst = int(np.argmax(np.abs(gap)))
    if abs(gap[worst]) > 1e-9 * max(lift, 1.0):
        raise DesignError(
            "motion",
            f"a constant-breadth cam needs s(φ + 180°) = lift − s(φ) (both rollers touch one plate), but at "
            f"φ = {math.degrees(phi[worst]):.2f}° s(φ) + s(φ + 180°) = {gap[worst] + lift:.6g} mm, not the "
            f"lift {lift:g} mm; only the first 180° of the program is free, the second half mirrors it "
            "(or set conjugate.single_plate = false for two plates)",
        )


def _check_bore(cam: CamSpec) -> None:
    if cam.bore / 2.0 >= cam.base_radius:
        raise DesignError(
            "cam.bore",
            f"{cam.bore:g} mm must fit inside the base circle; allowed: < {2.0 * cam.base_radius:g} mm "
            f"(twice base_radius)",
        )
    if (cam.keyway_width > 0) != (cam.keyway_depth > 0):
        missing = "cam.keyway_depth" if cam.keyway_width > 0 else "cam.keyway_width"
        raise DesignError(missing, "keyway_width and keyway_depth must both be > 0 or both 0")
    if cam.keyway_width > 0 and cam.bore <= 0:
        raise DesignError("cam.keyway_width", "a keyway needs a bore (cam.bore > 0)")
    if cam.keyway_width >= cam.bore > 0:
        raise DesignError(
            "cam.keyway_width", f"{cam.keyway_width:g} mm must be narrower than the bore {cam.bore:g} mm"
        )
    bore_reach = cam.bore / 2.0 + cam.keyway_depth
    if cam.keyway_width > 0 and bore_reach >= cam.base_radius:
        raise DesignError(
            "cam.keyway_depth",
            f"{cam.keyway_depth:g} mm takes the keyway to radius {bore_reach:g} mm, outside the base "
            f"circle of radius {cam.base_radius:g} mm; allowed: < {cam.base_radius - cam.bore / 2.0:g} mm",
        )


def _check_dynamics(design: Design) -> None:
    fol = design.follower
    dyn = design.dynamics
    coil = (dyn.wire_diameter, dyn.coil_diameter, dyn.active_coils, dyn.shear_modulus)
    if any(v is not None for v in coil) and any(v is None for v in coil):
        names = ("wire_diameter", "coil_diameter", "active_coils", "shear_modulus")
        missing = next(n for n, v in zip(names, coil, strict=True) if v is None)
        raise DesignError(
            f"dynamics.{missing}",
            "is required: a coil spring needs wire_diameter, coil_diameter, active_coils and shear_modulus",
        )
    if dyn.uses_coil_spring and dyn.wire_diameter >= dyn.coil_diameter:  # type: ignore[operator]
        raise DesignError(
            "dynamics.wire_diameter",
            f"{dyn.wire_diameter:g} mm must be smaller than the mean coil diameter {dyn.coil_diameter:g} mm",
        )
    angular = fol.kind.lift.angular  # an arm: its generalised force is a torque about the pivot
    if angular and (dyn.spring_rate > 0 or dyn.spring_preload != 0) and dyn.spring_arm is None:
        raise DesignError(
            "dynamics.spring_arm",
            "is required for a linear spring on an oscillating follower (mm, the spring's lever about "
            "the pivot); or give spring_rate_torsional and spring_preload_torsional for a torsion spring",
        )
    if angular and dyn.uses_coil_spring:
        raise DesignError(
            "dynamics.wire_diameter", "coil-spring geometry applies to translating followers only"
        )
    if dyn.model is DynamicsModel.GUIDED_TAPPET:
        if not fol.kind.guided_tappet:
            kinds = " or ".join(k.word for k in FOLLOWER_TYPES.values() if k.guided_tappet)
            raise DesignError("dynamics.model", f"'guided-tappet' needs a {kinds} follower")
        if dyn.b_m <= dyn.a_m:
            raise DesignError("dynamics.b_m", f"{dyn.b_m:g} mm must be greater than a_m = {dyn.a_m:g} mm")


def _check_tolerances(design: Design) -> None:
    cam = design.cam
    largest = TOLERANCE_PER_BASE_RADIUS * cam.base_radius
    for path, tol in (
        ("fit.tolerance", design.fit.tolerance),
        ("dxf.chord_tolerance", design.dxf.chord_tolerance),
        ("mesh.chord_tolerance", design.mesh.chord_tolerance),
        ("gcode.tolerance", design.gcode.tolerance),
    ):
        if tol > largest:
            raise DesignError(
                path,
                f"{tol:g} mm is too coarse for a base radius of {cam.base_radius:g} mm; "
                f"allowed: ≤ {largest:g} mm ({TOLERANCE_PER_BASE_RADIUS:g} × base_radius)",
            )


def _check_fea(design: Design) -> None:
    """The FE check holds a plain plate at its bore, and its keyway fillet must fit."""
    if design.fea is None:
        return
    from camcad.fea.mesh import MAX_ELEMENTS, estimated_triangles, smallest_mesh_size
    from camcad.fea.model import keyway_fillet

    if not family_of(design.cam.style).plates:
        style, allowed = (
            design.cam.style.value,
            " or ".join(repr(s.value) for s, f in FAMILIES.items() if f.plates),
        )
        raise DesignError(
            "fea", f"the finite-element check applies to cam.style = {allowed} only, not {style}"
        )
    bore = design.plate().bore
    if bore is None:
        raise DesignError(
            "cam.bore", "the finite-element check ([fea]) holds the plate at its bore: give cam.bore > 0"
        )
    if bore.has_keyway:
        keyway_fillet(design.fea, bore)
    size = design.fea.mesh_size
    area = math.pi * (design.cam.base_radius**2 - bore.radius**2)  # at least the base circle's ring
    if size is not None and estimated_triangles(area, size) > MAX_ELEMENTS:
        raise DesignError(
            "fea.mesh_size",
            f"{size:g} mm would fill the plate (at least the {area:.0f} mm² of the base circle outside the "
            f"bore) with {estimated_triangles(area, size):.3g} triangles or more; allowed: at most "
            f"{MAX_ELEMENTS} (mesh_size ≥ {smallest_mesh_size(area):.3g} mm for this base circle, more "
            "for the whole plate)",
        )


def _check_gcode(design: Design) -> None:
    cam = design.cam
    gc = design.gcode
    if gc.machine is Machine.ROTARY and gc.dialect is Dialect.GRBL:
        raise DesignError(
            "gcode.dialect",
            "'grbl' cannot run a rotary program (no rotary axis, no G93 inverse-time feed); "
            "allowed with machine = 'rotary': linuxcnc, generic",
        )
    if gc.machine is Machine.ROTARY and not family_of(cam.style).one_plate:
        raise DesignError(
            "gcode.machine", f"'rotary' cuts a plate cam's outline, not a {cam.style.value} cam (allowed: xy)"
        )
    if gc.machine is Machine.XY and gc.cutter is Cutter.WHEEL:
        raise DesignError("gcode.cutter", "'wheel' applies to machine = 'rotary' only (allowed: end-mill)")
    if gc.machine is Machine.ROTARY and (gc.tab_count > 0 or gc.mill_bore):
        field = "gcode.tab_count" if gc.tab_count > 0 else "gcode.mill_bore"
        raise DesignError(
            field, "the rotary program cuts the profile only: no tabs, no bore (allowed: 0 and false)"
        )
    if gc.machine is Machine.ROTARY and gc.fewest_arcs:
        raise DesignError(
            "gcode.fewest_arcs", "the rotary program has no XY arcs to refit (allowed: false; xy only)"
        )
    if gc.safe_height >= gc.clearance_height:
        raise DesignError(
            "gcode.safe_height",
            f"{gc.safe_height:g} mm must be below clearance_height {gc.clearance_height:g} mm",
        )
    depth = cam.thickness + gc.breakthrough
    if depth / gc.step_down > MAX_PASSES:
        raise DesignError(
            "gcode.step_down",
            f"{gc.step_down:g} mm would cut the {depth:g} mm depth (thickness + breakthrough) in "
            f"{math.ceil(depth / gc.step_down)} passes; allowed: ≥ {depth / MAX_PASSES:.4g} mm "
            f"(at most {MAX_PASSES} passes)",
        )
    finest_pitch = min(gc.step_down, BORE_HELIX_MIN_PITCH * gc.tool_diameter)
    if gc.mill_bore and depth / finest_pitch > MAX_HELIX_TURNS:
        raise DesignError(
            "gcode.tool_diameter",
            f"a Ø{gc.tool_diameter:g} mm tool may need up to {math.ceil(depth / finest_pitch)} helix turns "
            f"(pitch ≥ {BORE_HELIX_MIN_PITCH:g} × tool diameter) to mill the bore {depth:g} mm deep; "
            f"allowed: at most {MAX_HELIX_TURNS} turns, so tool_diameter ≥ "
            f"{depth / (BORE_HELIX_MIN_PITCH * MAX_HELIX_TURNS):.6g} mm with mill_bore = true",
        )
    if gc.tab_count > 0 and gc.tab_height >= cam.thickness:
        raise DesignError(
            "gcode.tab_height",
            f"{gc.tab_height:g} mm must be below the plate thickness {cam.thickness:g} mm",
        )


# Dynamics keys of a follower whose lift is an angle (an arm) only.
_ARM_DYNAMICS = (
    "arm_inertia",
    "spring_rate_torsional",
    "spring_preload_torsional",
    "spring_arm",
    "cg_distance",
)


def _foreign_key(kind: FollowerType, key: str) -> str:
    """Why ``follower.key``, declared by other kinds, does not apply to ``kind``."""
    owners = [k for k in FOLLOWER_TYPES.values() if any(fk.name == key for fk in k.keys)]
    lifts = {k.lift for k in owners}
    if len(lifts) == 1 and kind.lift not in lifts:
        return f"applies to {lifts.pop().followers} followers only, not to a {kind.word} follower"
    if len(owners) == 1:
        article = "an" if owners[0].word[0] in "aeiou" else "a"
        return f"applies to {article} {owners[0].word} follower only"
    return f"applies to {', '.join(k.word for k in owners)} followers only, not to a {kind.word} follower"


def _check_follower_keys(kind: FollowerType, follower: Mapping[str, Any], dynamics: Any) -> None:
    """Each follower kind's required keys present, and no key another kind declares."""
    declared = {k.name: k for k in kind.keys}
    for name in kind.required:
        if name not in follower:
            raise DesignError(
                f"follower.{name}", f"is required for a {kind.word} follower ({declared[name].unit})"
            )
    for key in follower:
        if key != "type" and key not in declared:
            raise DesignError(f"follower.{key}", _foreign_key(kind, key))
    if isinstance(dynamics, Mapping):
        for key in _ARM_DYNAMICS:
            if key in dynamics and not kind.lift.angular:
                arms = next(k.lift.followers for k in FOLLOWER_TYPES.values() if k.lift.angular)
                raise DesignError(f"dynamics.{key}", f"applies to {arms} followers only, not {kind.word}")
        if "spring_arm" in dynamics and (
            "spring_rate_torsional" in dynamics or "spring_preload_torsional" in dynamics
        ):
            raise DesignError(
                "dynamics.spring_arm",
                "a linear spring at a lever arm and a torsion spring cannot both be given; choose one",
            )
