"""Will it run and last: life, lubricant film and drive of one cam from its rigid dynamics.

:func:`analyse_duty` runs the analyses a design asks for (``[life]``,
``[lubrication]``, ``[drive]``) on the samples of the rigid dynamics, so
they cost one more profile evaluation and a few array operations:

- the contact's speeds (:func:`camcad.dynamics.rolling.contact_motion`);
- the roller's L10 and the track's K–N life (:mod:`camcad.dynamics.life`),
  or, for a face that slides, its sliding speed instead;
- the film thickness and film ratio (:mod:`camcad.dynamics.film`);
- the motor's duty and the laws' VDI 2143 characteristic values
  (:mod:`camcad.dynamics.drive`).

The plate's profile carries the contact where the contact force is
positive; a groove's other flank (or a conjugate pair's second plate), which
carries it where the force is negative, is not analysed for film and track
life (its roller is: the roller's load is |F|).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.dynamics.arm import arm_speed
from camcad.dynamics.contact import contact_curvature, effective_modulus
from camcad.dynamics.drive import (
    CharacteristicValues,
    DriveMode,
    DriveResult,
    DriveSpec,
    analyse_drive,
    segment_characteristics,
)
from camcad.dynamics.energy import FollowerLoad
from camcad.dynamics.film import (
    FilmResult,
    LubricationSpec,
    analyse_film,
    film_findings,
    film_ratio,
    minimum_film_thickness,
    reduced_modulus,
)
from camcad.dynamics.life import (
    LifeSpec,
    RollerLife,
    TrackLife,
    life_findings,
    load_stress_factor,
    roller_life,
    summary_entry,
    track_life,
)
from camcad.dynamics.model import _arm_load, _model
from camcad.dynamics.rolling import ContactMotion, contact_motion
from camcad.dynamics.spring import spring_from_spec
from camcad.extremes import Side, maximum, minimum
from camcad.findings import Finding

if TYPE_CHECKING:
    from camcad.dynamics.results import DynamicsResult
    from camcad.dynamics.spec import DynamicsSetup
    from camcad.geometry.cam import Cam, CamState
    from camcad.geometry.curves import CurveSample

__all__ = ["DutyResult", "analyse_duty"]

_MM2_PER_M2 = 1e6


@dataclass(frozen=True, slots=True, kw_only=True)
class DutyResult:
    """Life, film and drive of one cam.

    Attributes
    ----------
    contact
        The contact's speeds over the turn.
    roller, track
        The roller's and the track's lives, or ``None`` (no ``[life]``, a
        sliding face, or no rating / material given).
    film
        The film over the turn, or ``None`` without ``[lubrication]``.
    drive
        The motor's duty, or ``None`` without ``[drive]``.
    characteristics
        VDI 2143 values of every rise and return (with ``[drive]``).
    findings
        Every soft finding of the three analyses.
    """

    contact: ContactMotion
    roller: RollerLife | None = None
    track: TrackLife | None = None
    life: LifeSpec | None = None
    film: FilmResult | None = None
    drive: DriveResult | None = None
    characteristics: tuple[tuple[int, str, CharacteristicValues], ...] = ()
    findings: tuple[Finding, ...] = ()

    def summary(self) -> dict[str, Any]:
        """The ``life``, ``lubrication`` and ``drive`` sections of ``summary.json`` (those computed)."""
        out: dict[str, Any] = {}
        if self.life is not None:
            sliding = None if self.contact.rolling else float(np.max(self.contact.sliding_speed))
            out["life"] = summary_entry(self.roller, self.track, sliding_max=sliding)
        if self.film is not None:
            out["lubrication"] = self.film.summary()
        if self.drive is not None:
            drive = self.drive.summary()
            drive["characteristic_values"] = [
                {
                    "segment": index,
                    "law": law,
                    "C_v": cv.c_v,
                    "C_a": cv.c_a,
                    "C_j": cv.c_j,
                    "C_Mdyn": cv.c_mdyn,
                }
                for index, law, cv in self.characteristics
            ]
            out["drive"] = drive
        return out

    def csv_columns(self) -> dict[str, FloatArray]:
        """Extra ``dynamics.csv`` columns: film thickness [µm], λ, motor torque [N·m] (those computed)."""
        out: dict[str, FloatArray] = {}
        if self.film is not None:
            out["film_thickness_um"] = self.film.thickness_um
            out["film_ratio"] = self.film.ratio
        if self.drive is not None:
            out["motor_torque_Nm"] = self.drive.motor_torque
        return out


def analyse_duty(
    cam: Cam,
    dynamics: DynamicsResult,
    *,
    setup: DynamicsSetup,
    profile: CurveSample,
    life: LifeSpec | None = None,
    lubrication: LubricationSpec | None = None,
    drive: DriveSpec | None = None,
) -> DutyResult:
    """Roller and track life, lubricant film and drive over the samples of the rigid dynamics.

    Parameters
    ----------
    cam
        The exact cam.
    dynamics
        The rigid dynamics over ``dynamics.phi``.
    setup
        The dynamics stage's options (speed, contact length, materials).
    profile
        The cam profile at ``dynamics.phi`` (the geometry stage's).
    life, lubrication, drive
        The design's ``[life]``, ``[lubrication]`` and ``[drive]`` tables, or ``None``.

    Returns
    -------
    DutyResult
    """
    phi = dynamics.phi
    omega = setup.omega
    motion = cam.motion(phi)
    contact = contact_motion(cam, phi, omega=omega, profile=profile, motion=motion)
    curvature = contact_curvature(profile.rho, roller_radius=setup.roller_radius or None)
    force = np.asarray(dynamics.contact_force, dtype=float)
    dyn = setup.spec
    findings: list[Finding] = []
    roller = track = None
    if life is not None:
        if contact.rolling and life.roller_dynamic_load_rating is not None:
            roller = roller_life(
                phi,
                np.abs(force),  # a groove's roller carries |F| on either flank
                contact.arc_speed,
                roller_radius=setup.roller_radius,
                omega=omega,
                spec=life,
            )
        if life.track is not None:
            track = track_life(
                phi, force, curvature=curvature, length=setup.contact_length, omega=omega, spec=life
            )
            track = _exact_track(cam, setup, phi, track, life)
        findings += life_findings(life, roller=roller, track=track)
    film = None
    if lubrication is not None:
        modulus = effective_modulus(
            modulus_1=dyn.cam_modulus,
            poisson_1=dyn.cam_poisson,
            modulus_2=dyn.follower_modulus,
            poisson_2=dyn.follower_poisson,
        )
        film = analyse_film(
            phi,
            force,
            curvature=curvature,
            length=setup.contact_length,
            speed=contact.entraining_speed,
            contact_modulus=modulus,
            spec=lubrication,
        )
        film = _exact_film(cam, setup, film, lubrication, modulus)
        findings += film.findings
    result = None
    characteristics: tuple[tuple[int, str, CharacteristicValues], ...] = ()
    if drive is not None:
        result = _drive(cam, dynamics, setup=setup, spec=drive)
        characteristics = segment_characteristics(cam.program)
        findings += result.findings
    return DutyResult(
        contact=contact,
        roller=roller,
        track=track,
        life=life,
        film=film,
        drive=result,
        characteristics=characteristics,
        findings=tuple(findings),
    )


def _joints(cam: Cam) -> list[float]:
    return [bp.phi for bp in cam.program.breakpoints]


def _pointwise(cam: Cam, setup: DynamicsSetup) -> Callable[[FloatArray, Side], tuple[CamState, FloatArray]]:
    """The exact cam state and contact force at any angles (the rigid model, one-sided at joints)."""
    model = _model(setup)

    def at(p: FloatArray, side: Side) -> tuple[CamState, FloatArray]:
        st = cam.state(p, side=side)
        return st, model(st.motion, st.pressure_angle, st.profile.rho, st.lever).force

    return at


def _exact_film(
    cam: Cam, setup: DynamicsSetup, film: FilmResult, spec: LubricationSpec, modulus: float
) -> FilmResult:
    """The true smallest film ratio λ over the turn: the samples' refined on the exact cam."""
    at = _pointwise(cam, setup)
    roller = setup.roller_radius or None

    def ratio(p: FloatArray, side: Side) -> FloatArray:
        st, force = at(p, side)
        u = contact_motion(cam, p, omega=setup.omega, profile=st.profile, motion=st.motion).entraining_speed
        h = minimum_film_thickness(
            load_per_length=force / setup.contact_length,
            speed=u,
            curvature=contact_curvature(st.profile.rho, roller_radius=roller),
            modulus=reduced_modulus(modulus),
            viscosity_Pa_s=spec.viscosity_Pa_s,
            pressure_viscosity_coefficient=spec.pressure_viscosity_coefficient,
        )
        rq = (spec.roughness_cam_um, spec.roughness_follower_um)
        return film_ratio(h * 1e3, roughness_cam_um=rq[0], roughness_follower_um=rq[1])

    if not np.isfinite(film.min_ratio):
        return film
    low = minimum(ratio, film.phi, _joints(cam), values=film.ratio)
    if not low.value < film.min_ratio:
        return film
    exact = replace(
        film, min_ratio=low.value, angle=low.phi, min_thickness_um=low.value * spec.composite_roughness_um
    )
    return replace(exact, findings=film_findings(exact))


def _exact_track(
    cam: Cam, setup: DynamicsSetup, phi: FloatArray, track: TrackLife, spec: LifeSpec
) -> TrackLife:
    """The track's true largest load-stress factor (and so its life), refined on the exact cam."""
    at = _pointwise(cam, setup)
    roller = setup.roller_radius or None

    def factor(p: FloatArray, side: Side) -> FloatArray:
        st, force = at(p, side)
        curvature = contact_curvature(st.profile.rho, roller_radius=roller)
        return load_stress_factor(force, curvature=curvature, length=setup.contact_length)

    high = maximum(factor, phi, _joints(cam), values=track.factor)
    if spec.track is None or not high.value > track.factor_max:
        return track
    cycles = float(spec.track.cycles(high.value))
    hours = cycles * TWO_PI / setup.omega / 3600.0
    return replace(
        track,
        factor_max=high.value,
        angle=high.phi,
        cycles=cycles,
        hours=hours,
        days=None if spec.hours_per_day is None else hours / spec.hours_per_day,
    )


def _drive(cam: Cam, dynamics: DynamicsResult, *, setup: DynamicsSetup, spec: DriveSpec) -> DriveResult:
    """The motor's duty: the camshaft's, or the follower axis' of an electronic cam."""
    phi = dynamics.phi
    motion = cam.motion(phi)
    dyn = setup.spec
    arm = setup.arm_angle is not None
    speed = arm_speed(motion) if arm else np.asarray(motion.v, dtype=float)  # rad/rad or mm/rad
    if spec.mode is DriveMode.CAMSHAFT:
        # the follower's equivalent inertia at the camshaft: I·ψ′² or m·s′² [kg·m²]
        follower = dyn.arm_inertia if arm else dyn.follower_mass
        equivalent = follower * speed**2 / _MM2_PER_M2
        extremes = None
        if dynamics.torque_min is not None and dynamics.torque_max is not None:
            extremes = (dynamics.torque_min, dynamics.torque_max)
        return analyse_drive(
            phi,
            axis_load=dynamics.torque,
            axis_speed=1.0,
            axis_acceleration=0.0,
            omega=setup.omega,
            spec=spec,
            load_inertia=equivalent,
            load_extremes=extremes,
        )
    if arm:
        load = _arm_load(setup).axial_force(motion, omega=setup.omega)  # N·mm about the pivot
        accel = np.asarray(motion.a, dtype=float) * math.pi / 180.0
        inertia = dyn.arm_inertia / _MM2_PER_M2  # kg·m²
    else:
        axial = FollowerLoad(mass=dyn.follower_mass, spring=spring_from_spec(dyn), gravity=dyn.gravity)
        load = axial.axial_force(motion, omega=setup.omega)  # N
        accel = np.asarray(motion.a, dtype=float)
        inertia = dyn.follower_mass  # kg at the slide
    return analyse_drive(
        phi,
        axis_load=load,
        axis_speed=speed,
        axis_acceleration=accel,
        omega=setup.omega,
        spec=spec,
        load_inertia=inertia,
    )
