"""What the user states about masses, springs, friction and materials: the dynamics stage's options."""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["DynamicsModel", "DynamicsSetup", "DynamicsSpec"]


class DynamicsModel(enum.Enum):
    """Dynamic models: energy method (Quintero & Vanegas 2016) or guided tappet (Hren et al.)."""

    ENERGY = "energy"
    GUIDED_TAPPET = "guided-tappet"


@dataclass(frozen=True, slots=True, kw_only=True)
class DynamicsSpec:
    """Masses, springs, friction and materials. SI-mm units: kg, N, N/mm, N·mm, MPa, mm."""

    model: DynamicsModel = DynamicsModel.ENERGY
    follower_mass: float = 0.0
    spring_rate: float = 0.0  # N/mm
    spring_preload: float = 0.0  # N at s = 0
    friction_torque: float = 0.0  # N·mm
    gravity: bool = True
    min_contact_force: float = 0.0  # N
    # guided tappet (Hren et al., section 2)
    f1: float = 0.0
    f2: float = 0.0
    f3: float = 0.0
    a_m: float = 0.0  # mm
    b_m: float = 0.0  # mm
    wire_diameter: float | None = None  # mm, coil spring by eq. 13
    coil_diameter: float | None = None  # mm
    active_coils: float | None = None
    shear_modulus: float | None = None  # MPa
    preload_deflection: float | None = None  # mm (y1)
    # contact stress
    contact_width: float | None = None  # mm; None: the cam thickness
    cam_modulus: float = 206000.0  # MPa
    cam_poisson: float = 0.3
    follower_modulus: float = 206000.0  # MPa
    follower_poisson: float = 0.3
    allowable_stress: float | None = None  # MPa
    # oscillating followers (energy method about the pivot)
    arm_inertia: float = 0.0  # kg·mm², arm and roller about the pivot
    spring_rate_torsional: float = 0.0  # N·mm/rad
    spring_preload_torsional: float = 0.0  # N·mm at ψ = 0
    spring_arm: float | None = None  # mm: a linear spring (spring_rate, spring_preload) at this lever
    cg_distance: float = 0.0  # mm, the arm's centre of mass from the pivot (its weight is follower_mass)

    @property
    def uses_coil_spring(self) -> bool:
        """Whether the spring is given by its coil geometry (Hren et al., eq. 13)."""
        return self.wire_diameter is not None


@dataclass(frozen=True, slots=True, kw_only=True)
class DynamicsSetup:
    """Everything the dynamics stage needs: the ``[dynamics]`` table and the few cam values it uses.

    Attributes
    ----------
    spec
        The ``[dynamics]`` table.
    omega
        Cam speed ω [rad/s].
    base_radius
        r_b [mm] (the guided tappet's geometry).
    contact_length
        Length of the line contact [mm]: ``contact_width`` or the cam thickness.
    roller_radius
        r_f [mm] of a roller follower; 0 for a flat face.
    tappet_offset
        The guided tappet's axis offset [mm] as Hren et al. draw it (their
        Fig. 2 is a ccw cam): e for a ccw cam, −e for a cw cam, its mirror image.
    positive_drive
        Groove and conjugate cams: no spring holds the follower on; the
        contact force changes sign where the other flank (or roller) takes
        over, which is a crossover, not a jump.
    clearance
        A groove's radial clearance [mm] (the impact estimate at crossovers).
    flank_offsets
        A groove's inner and outer flank as offsets of the profile [mm]
        (:func:`camcad.geometry.groove.flank_offsets`), None for any other
        cam: where the contact force is positive the inner flank drives (the
        roller outside it, ρ_inner = ρ + d_inner), where it is negative the
        outer flank (the roller inside it, conformal: 1/R* = 1/r_f − 1/ρ_outer),
        and every contact figure is taken on that flank.
    drive_sign
        −1 for a conjugate pair's second plate: its roller pushes the follower
        back, so its contact force is the generalised force with the sign turned.
    arm_angle
        Oscillating followers: the arm's direction at ψ = 0 in the machine
        frame [rad] (pivot → roller centre, or along the face towards the cam);
        None for a translating follower.
    """

    spec: DynamicsSpec
    omega: float
    base_radius: float
    contact_length: float
    roller_radius: float = 0.0
    tappet_offset: float = 0.0
    arm_angle: float | None = None
    positive_drive: bool = False
    clearance: float = 0.0
    drive_sign: float = 1.0
    flank_offsets: tuple[float, float] | None = None
