"""The validated design: every stage's options gathered in one frozen aggregate.

Each stage owns its options (``motion.segments``, ``geometry.spec``,
``dynamics.spec``, ``fit.spec``, ``toolpath.spec``,
``export.spec``); :class:`Design` gathers
them with the cam plate's own values and hands each stage its own small
object (``Design.plate()``, ``Design.dynamics_setup()``, ``design.fit`` …).
Defaults are written once, here and in those dataclasses; the schema
(:mod:`camcad.design.schema`) only converts and checks what the file states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from camcad.design.paths import path_of
from camcad.dynamics.drive import DriveSpec
from camcad.dynamics.film import LubricationSpec
from camcad.dynamics.life import LifeSpec
from camcad.dynamics.spec import DynamicsSetup, DynamicsSpec
from camcad.dynamics.vibration.spec import VibrationSpec
from camcad.export.spec import DxfSpec, MeshSpec, TablesSpec
from camcad.fea.spec import FeaSpec
from camcad.fit.spec import FitSpec
from camcad.geometry.cam import follower_from_spec
from camcad.geometry.families import BarrelSpec, FamilyOptions, family_of
from camcad.geometry.plate import BoreOutline, Plate
from camcad.geometry.spec import CamStyle, ConjugateSpec, FollowerSpec, GrooveSpec, LinearSpec, Rotation
from camcad.motion.segments import SegmentSpec
from camcad.toolpath.spec import Dialect, Direction, GcodeSpec

__all__ = ["DEG", "CamSpec", "Design", "Dialect", "Direction", "GcodeSpec"]

DEG = math.pi / 180.0


@dataclass(frozen=True, slots=True, kw_only=True)
class CamSpec:
    """The cam plate. Lengths mm; ``max_pressure_angle`` and ``sample_step`` rad."""

    name: str = "cam"
    base_radius: float
    rotation: Rotation = Rotation.CCW
    speed_rpm: float = 100.0
    thickness: float = 10.0
    bore: float = 0.0  # bore diameter [mm]; 0: no bore
    keyway_width: float = 0.0
    keyway_depth: float = 0.0
    max_pressure_angle: float = 30.0 * DEG
    min_curvature_radius: float | None = None  # mm; None: 0 for roller, 1 mm for flat
    sample_step: float = 0.1 * DEG
    style: CamStyle = CamStyle.PLATE
    outer_radius: float | None = None  # mm, a groove cam's blank

    @property
    def omega(self) -> float:
        """Cam angular speed ω [rad/s]."""
        return self.speed_rpm * 2.0 * math.pi / 60.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Design:
    """A validated design: everything camcad needs, in mm and radians."""

    cam: CamSpec
    follower: FollowerSpec
    motion: tuple[SegmentSpec, ...]
    dynamics: DynamicsSpec = field(default_factory=DynamicsSpec)
    fit: FitSpec = field(default_factory=FitSpec)
    dxf: DxfSpec = field(default_factory=DxfSpec)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    tables: TablesSpec = field(default_factory=TablesSpec)
    gcode: GcodeSpec = field(default_factory=lambda: GcodeSpec(name_of=path_of))  # notes name TOML paths
    groove: GrooveSpec = field(default_factory=GrooveSpec)
    conjugate: ConjugateSpec = field(default_factory=ConjugateSpec)
    linear: LinearSpec = field(default_factory=LinearSpec)  # a linear cam's bar ([linear])
    fea: FeaSpec | None = None  # the [fea] table: None when absent (the FE check then runs only on request)
    life: LifeSpec | None = None  # [life], [lubrication], [drive] (issue 35): None when absent
    lubrication: LubricationSpec | None = None
    drive: DriveSpec | None = None
    vibration: VibrationSpec | None = None  # [vibration] (issue 34): None when absent
    barrel: BarrelSpec | None = None  # a barrel cam's own keys (issue 36): None for every other style
    source: str = ""

    def plate(self) -> Plate:
        """The plate the writers take: name, thickness, bore and keyway."""
        cam = self.cam
        return Plate(
            name=cam.name,
            thickness=cam.thickness,
            bore=BoreOutline.from_cam_spec(cam.bore, cam.keyway_width, cam.keyway_depth),
        )

    def family_options(self) -> FamilyOptions:
        """What the cam families read: ``[groove]``, ``[conjugate]``, the blank, the bore's reach."""
        bore = self.plate().bore
        return FamilyOptions(
            groove=self.groove,
            conjugate=self.conjugate,
            linear=self.linear,
            outer_radius=self.cam.outer_radius,
            hole_radius=0.0 if bore is None else bore.reach,
            barrel=self.barrel,
            bore=self.cam.bore,
        )

    def dynamics_setup(self) -> DynamicsSetup:
        """The dynamics stage's options: ``[dynamics]`` with the speed and contact geometry it uses."""
        dyn, cam, fol = self.dynamics, self.cam, self.follower
        module = follower_from_spec(fol, cam.base_radius)
        # the line contact's length: the roller's on a barrel, else the plate's thickness
        length = cam.thickness if self.barrel is None else self.barrel.roller_length
        return DynamicsSetup(
            spec=dyn,
            omega=cam.omega,
            base_radius=cam.base_radius,
            contact_length=dyn.contact_width if dyn.contact_width is not None else length,
            roller_radius=module.contact_radius,  # the radius that sets the contact stress; 0: flat
            # Hren et al.'s Fig. 2 is a ccw cam; a cw cam is its mirror image, follower at −e
            tappet_offset=fol.eccentricity if cam.rotation is Rotation.CCW else -fol.eccentricity,
            arm_angle=module.arm_direction,
            **family_of(cam.style).drive(fol.roller_radius, self.family_options()),
        )

    def with_base_radius(self, base_radius: float) -> Design:
        """The same design with another base radius [mm]."""
        return replace(self, cam=replace(self.cam, base_radius=base_radius))

    @property
    def min_curvature_radius(self) -> float:
        """Required smallest convex profile radius [mm]; by default the follower kind's (0 roller, 1 flat)."""
        if self.cam.min_curvature_radius is not None:
            return self.cam.min_curvature_radius
        return self.follower.kind.min_curvature_radius
