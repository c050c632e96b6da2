"""Will it run and last: life and lubricant film of each part, and the drive of the follower train.

:func:`analyse_duty` runs the analyses of one part of a cam family
(``[life]``, ``[lubrication]``) on the samples of its rigid dynamics, by the
same code for every part, so they cost one more profile evaluation and a few
array operations:

- the contact's speeds (:func:`camcad.dynamics.rolling.contact_motion`) over
  the surface that carries it;
- the roller's L10 and the track's K–N life (:mod:`camcad.dynamics.life`),
  or, for a face that slides, its sliding speed instead;
- the film thickness and film ratio (:mod:`camcad.dynamics.film`).

A part carries the contact where its contact force is positive (its
``drive_sign`` turns the force of a conjugate pair's second plate, whose own
roller then sets its curvature, speed and life). A groove's one part carries
it on both flanks: the inner where F ≥ 0, the outer, with its own curvature
and arc speed, where F < 0 (:func:`carried_contact`).

:func:`analyse_train_drive` sizes the motor (:mod:`camcad.dynamics.drive`)
and gives the laws' VDI 2143 characteristic values: figures of the follower
train (the camshaft torque is the same whichever part drives), once per design.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.dynamics.arm import arm_speed
from camcad.dynamics.contact import driving_curvature, effective_modulus
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
from camcad.dynamics.results import FLANK_WORDS
from camcad.dynamics.rolling import ContactMotion, contact_motion
from camcad.dynamics.spring import spring_from_spec
from camcad.extremes import Side, maximum, minimum
from camcad.findings import Finding

if TYPE_CHECKING:
    from camcad.dynamics.results import DynamicsResult
    from camcad.dynamics.spec import DynamicsSetup
    from camcad.geometry.cam import Cam, CamState
    from camcad.geometry.curves import CurveSample
    from camcad.motion.program import Motion

__all__ = [
    "CarriedContact",
    "DriveDuty",
    "DutyResult",
    "analyse_duty",
    "analyse_train_drive",
    "carried_contact",
    "carried_in_state",
    "film_ratio_of",
    "track_factor_of",
]

_MM2_PER_M2 = 1e6


@dataclass(frozen=True, slots=True, kw_only=True)
class CarriedContact:
    """The contact as the part's surface carries it, arrays (n,) over the cam angles.

    Attributes
    ----------
    load
        The force the part's surface carries [N]: F where F > 0 (the other
        part, or nothing, carries it elsewhere), |F| on a groove's two flanks.
    curvature
        The carrying surface's relative curvature 1/R* [1/mm]
        (:func:`~camcad.dynamics.contact.driving_curvature`).
    motion
        The contact's speeds over the carrying surface.
    outer
        A groove's (n,) mask where its outer flank carries the contact, else None.
    """

    load: FloatArray
    curvature: FloatArray
    motion: ContactMotion
    outer: npt.NDArray[np.bool_] | None = None

    def flank_at(self, i: int) -> str | None:
        """The groove flank that carries sample ``i`` (``"inner"``/``"outer"``), else None."""
        return None if self.outer is None else FLANK_WORDS[int(bool(self.outer[i]))]


def carried_contact(
    cam: Cam,
    phi: FloatArray,
    force: ArrayLike,
    *,
    setup: DynamicsSetup,
    profile: CurveSample,
    motion: Motion | None = None,
    side: Side = "right",
) -> CarriedContact:
    """Load, curvature and speeds of the contact on the surface of the part that carries it.

    Parameters
    ----------
    cam
        The part's exact cam (its own roller).
    phi
        (n,) cam angles [rad].
    force
        (n,) the part's contact force F [N] (its drive sign applied).
    setup
        The part's dynamics setup (its ``roller_radius``, a groove's ``flank_offsets``).
    profile
        ``cam.profile(phi)``.
    motion
        ``cam.motion(phi)`` if already computed.
    side
        The one-sided limit at joints (for a groove's flanks).

    Returns
    -------
    CarriedContact
        Without flanks the profile carries the contact where F > 0. On a
        groove the flank offset d of the profile carries it (inner where
        F ≥ 0, outer where F < 0): its speeds are those of ``cam.offset_curve(φ, d)``
        (in pure rolling u = w, the speed at which the contact runs over that flank).
    """
    f = np.asarray(force, dtype=float)
    curvature = driving_curvature(
        profile.rho, f, roller_radius=setup.roller_radius, flank_offsets=setup.flank_offsets
    )
    if setup.flank_offsets is None:
        contact = contact_motion(cam, phi, omega=setup.omega, profile=profile, motion=motion)
        load = np.clip(f, 0.0, None)
        readonly(load)
        return CarriedContact(load=load, curvature=curvature, motion=contact)
    inner_at, outer_at = setup.flank_offsets
    inner, outer = (
        contact_motion(
            cam, phi, omega=setup.omega, profile=cam.offset_curve(phi, d, side=side), motion=motion
        )
        for d in (inner_at, outer_at)
    )
    on_outer = f < 0.0

    def pick(a: FloatArray, b: FloatArray) -> FloatArray:
        out: FloatArray = np.where(on_outer, b, a)
        readonly(out)
        return out

    contact = ContactMotion(
        arc_speed=pick(inner.arc_speed, outer.arc_speed),
        contact_speed=pick(np.abs(inner.contact_speed), np.abs(outer.contact_speed)),
        slip=pick(inner.slip, outer.slip),
        sliding_speed=pick(inner.sliding_speed, outer.sliding_speed),
        entraining_speed=pick(inner.entraining_speed, outer.entraining_speed),
        rolling=inner.rolling,
    )
    load = np.abs(f)
    readonly(load)
    on_outer.flags.writeable = False
    return CarriedContact(load=load, curvature=curvature, motion=contact, outer=on_outer)


@dataclass(frozen=True, slots=True, kw_only=True)
class DutyResult:
    """Life and lubricant film of one part.

    Attributes
    ----------
    contact
        The contact's speeds over the turn, over the surface that carries it.
    load
        (n,) the force the part's surface and roller carry [N] (:attr:`CarriedContact.load`).
    roller, track
        The part's roller's and track's lives, or ``None`` (no ``[life]``, a
        sliding face, or no rating / material given).
    life
        The ``[life]`` table, or ``None``.
    film
        The film over the turn, or ``None`` without ``[lubrication]``.
    findings
        Every soft finding of the two analyses.
    """

    contact: ContactMotion
    load: FloatArray
    roller: RollerLife | None = None
    track: TrackLife | None = None
    life: LifeSpec | None = None
    film: FilmResult | None = None
    findings: tuple[Finding, ...] = ()

    def summary(self) -> dict[str, Any]:
        """The ``life`` and ``lubrication`` sections of ``summary.json`` (those computed)."""
        out: dict[str, Any] = {}
        if self.life is not None:
            sliding = None if self.contact.rolling else float(np.max(self.contact.sliding_speed))
            out["life"] = summary_entry(self.roller, self.track, sliding_max=sliding)
        if self.film is not None:
            out["lubrication"] = self.film.summary()
        return out

    def csv_columns(self) -> dict[str, FloatArray]:
        """Extra ``dynamics.csv`` columns: film thickness [µm] and λ (with ``[lubrication]``)."""
        out: dict[str, FloatArray] = {}
        if self.film is not None:
            out["film_thickness_um"] = self.film.thickness_um
            out["film_ratio"] = self.film.ratio
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class DriveDuty:
    """The drive of the follower train: the motor's duty and the laws' VDI 2143 values.

    Attributes
    ----------
    drive
        The motor's duty.
    characteristics
        VDI 2143 values of every rise and return.
    """

    drive: DriveResult
    characteristics: tuple[tuple[int, str, CharacteristicValues], ...] = ()

    @property
    def findings(self) -> tuple[Finding, ...]:
        """The drive's soft findings."""
        return self.drive.findings

    def summary(self) -> dict[str, Any]:
        """The ``drive`` section of ``summary.json``."""
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
        return {"drive": drive}

    def csv_columns(self) -> dict[str, FloatArray]:
        """The extra ``dynamics.csv`` column: motor torque [N·m]."""
        return {"motor_torque_Nm": self.drive.motor_torque}


def analyse_duty(
    cam: Cam,
    dynamics: DynamicsResult,
    *,
    setup: DynamicsSetup,
    profile: CurveSample,
    life: LifeSpec | None = None,
    lubrication: LubricationSpec | None = None,
) -> DutyResult:
    """Roller and track life and lubricant film of one part, over the samples of its rigid dynamics.

    Parameters
    ----------
    cam
        The part's exact cam (its own follower and roller).
    dynamics
        The part's rigid dynamics over ``dynamics.phi`` (its drive sign applied).
    setup
        The part's dynamics options (speed, contact length, materials, its
        roller radius and drive sign, a groove's flank offsets).
    profile
        The part's cam profile at ``dynamics.phi`` (the geometry stage's).
    life, lubrication
        The design's ``[life]`` and ``[lubrication]`` tables, or ``None``.

    Returns
    -------
    DutyResult
    """
    phi = dynamics.phi
    omega = setup.omega
    motion = cam.motion(phi)
    carried = carried_contact(cam, phi, dynamics.contact_force, setup=setup, profile=profile, motion=motion)
    contact = carried.motion
    dyn = setup.spec
    findings: list[Finding] = []
    roller = track = None
    if life is not None:
        if contact.rolling and life.roller_dynamic_load_rating is not None:
            roller = roller_life(
                phi,
                carried.load,  # the load on the part's own roller
                contact.arc_speed,
                roller_radius=setup.roller_radius,
                omega=omega,
                spec=life,
            )
        if life.track is not None:
            track = track_life(
                phi,
                carried.load,
                curvature=carried.curvature,
                length=setup.contact_length,
                omega=omega,
                spec=life,
            )
            track = replace(track, flank=carried.flank_at(int(np.argmax(track.factor))))
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
            carried.load,
            curvature=carried.curvature,
            length=setup.contact_length,
            speed=contact.entraining_speed,
            contact_modulus=modulus,
            spec=lubrication,
        )
        film = replace(film, flank=carried.flank_at(int(np.argmin(film.ratio))))
        film = _exact_film(cam, setup, film, lubrication, modulus)
        findings += film.findings
    return DutyResult(
        contact=contact,
        load=carried.load,
        roller=roller,
        track=track,
        life=life,
        film=film,
        findings=tuple(findings),
    )


def analyse_train_drive(
    cam: Cam,
    dynamics: DynamicsResult,
    *,
    setup: DynamicsSetup,
    spec: DriveSpec,
    characteristics: tuple[tuple[int, str, CharacteristicValues], ...] | None = None,
) -> DriveDuty:
    """The motor's duty and the laws' VDI 2143 values: figures of the follower train, not of a part.

    ``dynamics`` is any part's (the camshaft torque is the same whichever part
    drives); ``setup`` the design's dynamics options. ``characteristics`` is
    ``segment_characteristics(cam.program)`` if already computed (a batch of
    variants of one motion program shares it).
    """
    if characteristics is None:
        characteristics = segment_characteristics(cam.program)
    return DriveDuty(drive=_drive(cam, dynamics, setup=setup, spec=spec), characteristics=characteristics)


def _joints(cam: Cam) -> list[float]:
    return [bp.phi for bp in cam.program.breakpoints]


def _carried_at(cam: Cam, setup: DynamicsSetup) -> Callable[[FloatArray, Side], CarriedContact]:
    """The exact contact the part carries at any angles (the rigid model, one-sided at joints)."""
    model = _model(setup)

    def at(p: FloatArray, side: Side) -> CarriedContact:
        return carried_in_state(cam, p, cam.state(p, side=side), setup=setup, side=side, model=model)

    return at


def carried_in_state(
    cam: Cam,
    phi: FloatArray,
    state: CamState,
    *,
    setup: DynamicsSetup,
    side: Side = "right",
    model: Any = None,
) -> CarriedContact:
    """:func:`carried_contact` under the rigid model's force, from the cam's state at angles φ (n,) [rad].

    ``model`` is ``_model(setup)`` if already built. The exact searches of
    :func:`analyse_duty` evaluate it; a batch analysis
    (:mod:`camcad.explore.batch`) evaluates it on many variants at once,
    with ``cam``, ``state`` and ``setup`` holding one value per angle.
    """
    st = state
    force = (_model(setup) if model is None else model)(
        st.motion, st.pressure_angle, st.profile.rho, st.lever
    ).force
    return carried_contact(cam, phi, force, setup=setup, profile=st.profile, motion=st.motion, side=side)


def film_ratio_of(
    carried: CarriedContact, *, setup: DynamicsSetup, spec: LubricationSpec, modulus: float
) -> FloatArray:
    """The film ratio λ of a carried contact (as :func:`~camcad.dynamics.film.analyse_film` on the samples).

    ``modulus`` is the contact modulus E* [MPa] (:func:`~camcad.dynamics.contact.effective_modulus`).
    """
    h = minimum_film_thickness(
        load_per_length=carried.load / setup.contact_length,
        speed=carried.motion.entraining_speed,
        curvature=carried.curvature,
        modulus=reduced_modulus(modulus),
        viscosity_Pa_s=spec.viscosity_Pa_s,
        pressure_viscosity_coefficient=spec.pressure_viscosity_coefficient,
    )
    rq = (spec.roughness_cam_um, spec.roughness_follower_um)
    return film_ratio(h * 1e3, roughness_cam_um=rq[0], roughness_follower_um=rq[1])


def track_factor_of(carried: CarriedContact, *, setup: DynamicsSetup) -> FloatArray:
    """The track's load-stress factor of a carried contact (as :func:`~camcad.dynamics.life.track_life`)."""
    return load_stress_factor(carried.load, curvature=carried.curvature, length=setup.contact_length)


def _exact_film(
    cam: Cam, setup: DynamicsSetup, film: FilmResult, spec: LubricationSpec, modulus: float
) -> FilmResult:
    """The true smallest film ratio λ over the turn: the samples' refined on the exact cam."""
    at = _carried_at(cam, setup)

    def ratio(p: FloatArray, side: Side) -> FloatArray:
        return film_ratio_of(at(p, side), setup=setup, spec=spec, modulus=modulus)

    if not np.isfinite(film.min_ratio):
        return film
    low = minimum(ratio, film.phi, _joints(cam), values=film.ratio)
    if not low.value < film.min_ratio:
        return film
    exact = replace(
        film,
        min_ratio=low.value,
        angle=low.phi,
        min_thickness_um=low.value * spec.composite_roughness_um,
        flank=at(np.array([low.phi]), low.side or "right").flank_at(0),
    )
    return replace(exact, findings=film_findings(exact))


def _exact_track(
    cam: Cam, setup: DynamicsSetup, phi: FloatArray, track: TrackLife, spec: LifeSpec
) -> TrackLife:
    """The track's true largest load-stress factor (and so its life), refined on the exact cam."""
    at = _carried_at(cam, setup)

    def factor(p: FloatArray, side: Side) -> FloatArray:
        return track_factor_of(at(p, side), setup=setup)

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
        flank=at(np.array([high.phi]), high.side or "right").flank_at(0),
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
        equivalent = follower * (speed * speed) / _MM2_PER_M2  # ω·ω: see jump.py
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
